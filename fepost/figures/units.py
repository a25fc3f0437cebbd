"""How the figures and the report write numbers and units: one style everywhere.

* SI units: lengths in m, areas in m², forces in N, torques in N·m; pressures
  in kPa (the JSON files keep Pa); dimensionless values bare.
* A narrow no-break space (U+202F) between a number and its unit, so the pair
  never breaks across lines: ``0.1202 m``, ``200 kPa``, ``3215 N·m``.
* Six significant digits in tables, four in running text.

The JSON and CSV files are plain SI (Pa, m, N, N·m) whatever the display.
"""

from __future__ import annotations

import math
import re

#: Narrow no-break space, between a number and its unit.
NNBSP = "\u202f"

#: Display unit of each quantity kind (the report's tables and text).
UNITS = {
    "length": "m",
    "area": "m²",
    "force": "N",
    "torque": "N·m",
    "pressure": "kPa",
    "inverse_area": "m⁻²",
    "time": "s",
}


def number(value, fmt: str = "{:.6g}") -> str:
    """``value`` formatted, ``n/a`` for NaN/inf, ``—`` for None; a true minus sign."""
    if value is None:
        return "—"
    v = float(value)
    if not math.isfinite(v):
        return "n/a"
    return fmt.format(v).replace("-", "−")


def quantity(value, unit: str = "", fmt: str = "{:.4g}", scale: float = 1.0) -> str:
    """``value × scale`` with its unit after a narrow no-break space (no unit: the number)."""
    shown = number(None if value is None else float(value) * scale, fmt)
    return f"{shown}{NNBSP}{unit}" if unit and value is not None else shown


def kpa(value_pa, fmt: str = "{:.4g}") -> str:
    """A pressure given in Pa, written in kPa."""
    return quantity(value_pa, "kPa", fmt, 1e-3)


def display_unit(unit: str | None) -> str:
    """A unit string of the JSON documents in the report's style ("N m" -> "N·m", "1" -> "")."""
    if not unit or unit == "1":
        return ""
    return {"N m": "N·m", "1/m^2": "m⁻²", "1/m²": "m⁻²", "m^2": "m²", "Pa": "Pa"}.get(unit, unit)


_UNIT_AFTER_NUMBER = re.compile(r"(\d) (N m|N·m|kPa|MPa|Pa|m²|m|N|s)(?![\w²])")


#: ASCII spellings in free text from elsewhere (notes of Table 1, rules) and the report's
#: Unicode for them, so a page never mixes "<x^2>" with "⟨x²⟩".
ASCII_MATH = (
    ("<x^2>", "⟨x²⟩"),
    (" m^1/2", " √m"),
    ("|dF|", "|ΔF|"),
    ("|dMz|", "|ΔMz|"),
    ("0-180 deg", "0–180°"),
    ("^2", "²"),
    ("+-", "±"),
)
_WORDS = {"theta": "θ", "sigma": "σ"}
_SQRT = re.compile(r"sqrt\(([^()]*)\)")


def unicode_math(text: str) -> str:
    """`ASCII_MATH` and ``sqrt(x)`` -> ``√x`` (``√(x y)`` when x has a space or operator)."""
    for ascii_, uni in ASCII_MATH:
        text = text.replace(ascii_, uni)
    text = re.sub(r"\b(theta|sigma)\b", lambda m: _WORDS[m.group(1)], text)
    return _SQRT.sub(
        lambda m: f"√{m.group(1)}" if re.fullmatch(r"\w+", m.group(1)) else f"√({m.group(1)})", text
    )


def normalise(text: str) -> str:
    """Free text from elsewhere (notes, rules) in the report's style: "N m" -> "N·m",
    "<=" -> "≤", `unicode_math`, a narrow no-break space between a number and its unit."""
    text = unicode_math(text)
    text = text.replace("<=", "≤").replace(">=", "≥")
    text = _UNIT_AFTER_NUMBER.sub(lambda m: f"{m.group(1)}{NNBSP}{display_unit(m.group(2))}", text)
    return text.replace(" N m", f"{NNBSP}N·m")
