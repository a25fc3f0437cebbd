"""Landing-gear parameters for the shimmy model, and the gear file that holds them.

A gear file is a JSON object. Every parameter is SI, a finite number, and none
may be negative (a count at least 1); unknown keys are refused, so a misspelt
name never falls back silently on a default. Keys (see docs/shimmy.md for the
model they enter):

=======================  ========  ==============================================
``yaw_inertia``          kg m²     I_ψ: wheels, axle and lower strut about the strut axis (> 0)
``torsional_stiffness``  N m/rad   k_ψ: torque links and strut in torsion
``torsional_damping``    N m s/rad c_ψ: structural/damper torque per yaw rate
``trail``                m         e: mechanical trail, contact centre behind the strut axis
``lateral_mass``         kg        m_y: modal mass of the strut's lateral bending (> 0)
``lateral_stiffness``    N/m       k_y: lateral bending stiffness at the axle (> 0)
``lateral_damping``      N s/m     c_y
``wheels``               count     1 (on the strut axis) or 2 (twin wheels at ±half_track)
``half_track``           m         lateral offset of each twin wheel from the strut axis
``slip_ratio``           –         κ in (0, 1]: the steady longitudinal sliding speed is κV
                                   (1 = locked wheel at touchdown; small = nearly spun up)
=======================  ========  ==============================================

Optional: ``name`` (text), ``sources`` (an object: parameter name → where the value
comes from), ``notes`` (text). Every problem is one `GearFileError` line naming the
file and the key.
"""

from __future__ import annotations

import difflib
import json
import math
from dataclasses import dataclass, field, fields
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ..errors import FepostError

#: Parameter names, units and whether zero is allowed.
PARAMETERS: dict[str, tuple[str, bool]] = {
    "yaw_inertia": ("kg m^2", False),
    "torsional_stiffness": ("N m/rad", True),
    "torsional_damping": ("N m s/rad", True),
    "trail": ("m", True),
    "lateral_mass": ("kg", False),
    "lateral_stiffness": ("N/m", False),
    "lateral_damping": ("N s/m", True),
    "wheels": ("count", False),
    "half_track": ("m", True),
    "slip_ratio": ("", False),
}
#: Optional keys besides the parameters.
OPTIONAL = ("name", "sources", "notes")


class GearFileError(FepostError, ValueError):
    """A gear file is missing, not JSON, or holds a missing, unknown or bad parameter."""


@dataclass(frozen=True)
class Gear:
    """A landing gear for the shimmy model (units in the module docstring)."""

    yaw_inertia: float
    torsional_stiffness: float
    torsional_damping: float
    trail: float
    lateral_mass: float
    lateral_stiffness: float
    lateral_damping: float
    wheels: int = 1
    half_track: float = 0.0
    slip_ratio: float = 1.0
    name: str = ""
    sources: Any = field(default_factory=dict)
    notes: str = ""

    def __post_init__(self) -> None:
        for key in PARAMETERS:
            _check_value(getattr(self, key), key, "Gear")
        if self.wheels not in (1, 2):
            raise GearFileError(f"Gear: wheels must be 1 or 2, got {self.wheels!r}")
        if self.wheels == 1 and self.half_track != 0.0:
            raise GearFileError("Gear: half_track must be 0 with one wheel (it sits on the strut axis)")
        if self.slip_ratio > 1.0:
            raise GearFileError(f"Gear: slip_ratio must be in (0, 1], got {self.slip_ratio!r}")
        object.__setattr__(self, "sources", MappingProxyType(dict(self.sources)))

    @property
    def offsets(self) -> tuple[float, ...]:
        """Lateral positions of the wheels' contact centres in the gear frame (m)."""
        return (0.0,) if self.wheels == 1 else (-self.half_track, self.half_track)

    def replace(self, **changes) -> Gear:
        """A copy with ``changes`` (validated again)."""
        d = {f.name: getattr(self, f.name) for f in fields(self)}
        d["sources"] = dict(self.sources)
        d.update(changes)
        return Gear(**d)

    def to_dict(self) -> dict:
        """The parameters with units (the ``gear`` key of shimmy.json)."""
        out: dict[str, Any] = {"name": self.name}
        for key, (unit, _) in PARAMETERS.items():
            out[key] = {"value": getattr(self, key), "unit": unit}
        if self.sources:
            out["sources"] = dict(self.sources)
        if self.notes:
            out["notes"] = self.notes
        return out


def _check_value(value, key: str, where: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise GearFileError(f"{where}: {key} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise GearFileError(f"{where}: {key} must be finite, got {value!r}")
    zero_ok = PARAMETERS[key][1]
    if value < 0 or (value == 0 and not zero_ok):
        need = ">= 0" if zero_ok else "> 0"
        raise GearFileError(f"{where}: {key} must be {need}, got {value!r}")
    if key == "wheels" and int(value) != value:
        raise GearFileError(f"{where}: wheels must be 1 or 2, got {value!r}")


def gear_from_dict(data: Any, where: str = "gear") -> Gear:
    """A `Gear` from a parsed gear file; ``where`` names it in messages."""
    if not isinstance(data, dict):
        raise GearFileError(f"{where}: must hold a JSON object, got {type(data).__name__}")
    unknown = sorted(set(data) - set(PARAMETERS) - set(OPTIONAL))
    if unknown:
        known = ", ".join([*PARAMETERS, *OPTIONAL])
        close = difflib.get_close_matches(unknown[0], [*PARAMETERS, *OPTIONAL], n=1, cutoff=0.6)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise GearFileError(f"{where}: unknown key {unknown[0]!r}{hint} (known: {known})")
    missing = [k for k in PARAMETERS if k not in ("wheels", "half_track", "slip_ratio") and k not in data]
    if missing:
        raise GearFileError(f"{where}: missing key {missing[0]!r}")
    for key in PARAMETERS:
        if key in data:
            _check_value(data[key], key, where)
    if "sources" in data and not (
        isinstance(data["sources"], dict) and all(isinstance(v, str) for v in data["sources"].values())
    ):
        raise GearFileError(f"{where}: sources must be an object of texts")
    for key in ("name", "notes"):
        if key in data and not isinstance(data[key], str):
            raise GearFileError(f"{where}: {key} must be a text, got {data[key]!r}")
    values = {k: data[k] for k in PARAMETERS if k in data}
    if "wheels" in values:
        values["wheels"] = int(values["wheels"])
    try:
        return Gear(
            **values, name=data.get("name", ""), sources=data.get("sources", {}), notes=data.get("notes", "")
        )
    except GearFileError as exc:
        raise GearFileError(str(exc).replace("Gear:", f"{where}:", 1)) from None


def load_gear(path) -> Gear:
    """Read and check a gear file (module docstring)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise GearFileError(f"{p}: gear file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise GearFileError(f"{p}: cannot read the gear file ({type(exc).__name__})") from None
    try:
        data = json.loads(text)
    except ValueError as exc:
        line = getattr(exc, "lineno", "?")
        raise GearFileError(f"{p}: not JSON (line {line}: {getattr(exc, 'msg', exc)})") from None
    return gear_from_dict(data, str(p))
