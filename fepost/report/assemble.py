"""Assembling the report's data: P*, the curves of Figures 4–6, the page's context.

Nothing here draws or writes: `friction_curves` computes the arrays the
curve figures plot, `page_context` gathers every value the HTML template
shows (from the JSON documents written beside it, so page and files agree).
"""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import identify
from ..analysis import Analysis
from ..errors import ArgumentError
from ..table1 import Table1
from .rollinglabel import OwnMeshKx, RollingLabel, rolling_label

if TYPE_CHECKING:
    from ..figures.curves import CurveData

#: Inflation pressure P* (Pa) when neither the option nor the sidecar gives one: the paper's.
DEFAULT_INFLATION_PRESSURE = 200e3
#: Points of the dense curves of Figures 4–6 (on [0, the span of Table 1's test curves]).
CURVE_POINTS = 201


def check_inflation_option(option) -> float:
    """The ``--inflation-pressure`` value P* in Pa: a finite positive number.

    Raises
    ------
    ArgumentError
        ``option`` is not a positive finite pressure (the message names the option).
    """
    try:
        p = float(option)
    except (TypeError, ValueError):
        p = math.nan
    if not (math.isfinite(p) and p > 0):
        raise ArgumentError(f"--inflation-pressure must be a positive pressure in Pa, got {option!r}")
    return p


#: Where a sidecar may keep the inflation pressure, in the order looked at: the top level
#: (``meshes/aircraft/*.json``) and the model block (``meshes/rig-aircraft/*.json``).
SIDECAR_PRESSURE_KEYS = (("inflation_pressure",), ("model", "inflation_pressure"))


def _sidecar_pressure(analysis: Analysis) -> tuple[float, str] | None:
    """(P* in Pa, the dotted sidecar key it was read from), or None when the sidecar has none.

    A top-level ``inflation_pressure`` was scaled to SI by the reader; one under
    ``model`` is scaled here with the same unit system."""
    field_ = analysis.static_field
    side = field_.sidecar or {}
    for path in SIDECAR_PRESSURE_KEYS:
        value: Any = side
        for part in path:
            value = value.get(part) if isinstance(value, Mapping) else None
        if value is None:
            continue
        key = ".".join(path)
        try:
            p = float(value)
        except (TypeError, ValueError):
            p = math.nan
        if not (math.isfinite(p) and p > 0):
            raise ArgumentError(
                f"{field_.source}: sidecar {key} must be a positive pressure in Pa, got {value!r}"
            )
        units = field_.units
        if len(path) > 1 and units is not None and not units.is_si:
            p *= units.pressure
        return p, key
    return None


def resolve_inflation_pressure(option: float | None, analysis: Analysis) -> tuple[float, str]:
    """P* (Pa) and where it came from: the option, the static mesh's sidecar (the key named:
    ``inflation_pressure`` or ``model.inflation_pressure``), or the default."""
    if option is not None:
        return check_inflation_option(option), "option --inflation-pressure"
    found = _sidecar_pressure(analysis)
    if found is not None:
        source = Path(str(analysis.static_field.source)).with_suffix(".json").name
        return found[0], f"sidecar {source}, key {found[1]}"
    return DEFAULT_INFLATION_PRESSURE, "default (the paper's 200 kPa)"


# --------------------------------------------------------------------------------------
# Curves of Figures 4–6
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class FrictionCurves:
    """The curves of Figures 4–6 and how far the closed forms lie from the exact integrals.

    ``curves``: one `CurveData` per figure (F∥, M_C and,
    with a rolling map, F⊥); ``errors``: per curve, the largest |exact − closed form|
    relative to the curve's scale (``max_abs_relative``), where (``at``, ψ or υ) and
    the scale (N or N·m).
    """

    curves: tuple[CurveData, ...]
    errors: Mapping[str, Mapping[str, Any]]

    def __post_init__(self) -> None:
        object.__setattr__(self, "curves", tuple(self.curves))
        object.__setattr__(
            self,
            "errors",
            MappingProxyType({k: MappingProxyType(dict(v)) for k, v in self.errors.items()}),
        )

    def errors_dict(self) -> dict:
        """``errors`` as plain dicts (the report's ``closed_form_vs_exact.json``)."""
        return {k: dict(v) for k, v in self.errors.items()}


def friction_curves(analysis: Analysis, table: Table1) -> FrictionCurves:
    """Assemble the arrays of Figures 4–6 from the analysis and its Table 1.

    Dense curves on `CURVE_POINTS` values of ψ, υ in [0, ``table.span``]: the
    exact Coulomb integrals over the static map (F∥, M_C) and the rolling map (F⊥);
    the closed forms (1.8) with the theoretical coefficients of ``table``; the
    generalised model built from the FE maps (``table.generalised.form``, at the
    maps' own coefficients; absent when ``table`` has no generalised rows); the
    fitted curves with their 95 % prediction band
    (`fepost.identify.Identification.prediction_band`); and the noisy test
    points of ``table.curves``. Figure 6 only with a rolling map.

    ``errors[curve]`` holds the closed form's largest gap (``max_abs_relative``,
    ``at``) and, with the generalised model, the model's
    (``model_max_abs_relative``, ``model_at``), both over the same scale.
    """
    from ..figures.curves import CurveData
    from ..friction.quadrature import PressureQuadrature

    c = analysis.coefficients
    R = table.R
    quad = PressureQuadrature.from_polar(analysis.static_map)
    rolling_map = analysis.rolling_map
    rquad = PressureQuadrature.from_polar(rolling_map) if rolling_map is not None else None
    has_roll = rquad is not None
    x = np.linspace(0.0, table.span, CURVE_POINTS)
    exact = dict(
        zip(
            identify.CURVES,
            identify.exact_curves(quad, x, x, R, rolling_quad=rquad, friction=c.f),
            strict=True,
        )
    )
    theory = [table.row(name).theory for name in identify.PARAMETERS]
    closed = {name: identify.curve_model(name, x, theory, R)[0] for name in identify.CURVES}
    gen = table.generalised.form.curves(x) if table.generalised is not None else None
    scales = {
        "f_parallel": ("psi", "F0", theory[0]),
        "torque": ("upsilon", "M0", theory[1]),
        "f_perp": ("upsilon", "|k_x| M0 / 2R", abs(theory[4]) * theory[1] / (2.0 * R)),
    }
    shown = ("f_parallel", "torque") + (("f_perp",) if has_roll else ())
    errors = {}
    for key in shown:
        x_name, scale_name, scale = scales[key]
        if scale == 0:
            continue
        d = np.abs(exact[key] - closed[key])
        i = int(np.argmax(d))
        errors[key] = {
            "max_abs_relative": float(d[i] / scale),
            "at": float(x[i]),
            "scale": float(scale),
            "x_name": x_name,
            "scale_name": scale_name,
        }
        if gen is not None:
            dm = np.abs(exact[key] - gen[key])
            j = int(np.argmax(dm))
            errors[key].update(model_max_abs_relative=float(dm[j] / scale), model_at=float(x[j]))
    fit = table.identification
    curves = []
    for key in shown:
        name, title, x_name, x_label, y_label, unit = _FIGURES[key]
        y, lo, hi = fit.prediction_band(key, x)
        test_x, test_y = table.curves.data(key)
        curves.append(
            CurveData(
                name=name,
                title=title,
                x_name=x_name,
                x_label=x_label,
                y_label=y_label,
                unit=unit,
                x=x,
                closed_form=closed[key],
                exact=exact[key],
                fit=y,
                band_lo=lo,
                band_hi=hi,
                test_x=test_x,
                test_y=test_y,
                model=None if gen is None else gen[key],
            )
        )
    return FrictionCurves(tuple(curves), errors)


#: Figures 4–6: curve -> (figure name, title, x name, x label, y label, unit); labels in mathtext.
_FIGURES = {
    "f_parallel": (
        "F_parallel",
        r"Figure 4: longitudinal friction force $F_\parallel$ against $\psi = u/v$",
        "psi",
        r"$\psi = u\,/\,v$",
        r"$F_\parallel$ (N)",
        "N",
    ),
    "torque": (
        "M_C",
        r"Figure 5: friction torque $M_C$ against $\upsilon = v/u$",
        "upsilon",
        r"$\upsilon = v\,/\,u$ (upsilon)",
        r"$M_C$ (N·m)",
        "N·m",
    ),
    "f_perp": (
        "F_perp",
        r"Figure 6: lateral friction force $F_\perp$ against $\upsilon = v/u$ (rolling map)",
        "upsilon",
        r"$\upsilon = v\,/\,u$ (upsilon)",
        r"$F_\perp = -F_y$ (N)",
        "N",
    ),
}


#: Rows of the coefficient table: (JSON key, symbol, unit kind, definition).
COEFFICIENT_ROWS = (
    ("N", "N", "force", "∬ σ dA on the polar grid"),
    ("N_fe", "N_fe", "force", "exact integral of the FE pressure over the FE faces"),
    ("N_rolling", "N (rolling)", "force", "∬ σ dA of the rolling map: its load, within 3 % of N"),
    (
        "R",
        "R",
        "length",
        "r_max: smallest circle about the static centre of pressure holding the loaded points",
    ),
    ("F0", "F0", "force", "2π f R² A¹ = f N"),
    ("M0", "M0", "torque", "2π f R³ A² = f ∬ σ r dA"),
    ("a", "a", None, "(2A¹/A⁰)²"),
    ("m", "m", None, "(2A²/A³)²"),
    ("b", "b", None, "m/4"),
    ("b1", "b1", "torque", "M0/2"),
    ("f", "f", None, "friction coefficient (input)"),
    ("aR2", "a·R²", "area", "a·R², independent of the choice of R"),
    ("m_over_R2", "m/R²", "inverse_area", "m/R², independent of the choice of R"),
    ("k_x", "k_x", None, "R·x_c/⟨x²⟩ (rolling shift of the centre of pressure)"),
    ("x_c", "x_c", "length", "centre of pressure of the rolling map along x"),
)
#: Rows of the generalised model in the coefficient table: (key under coefficients.json
#: "model", label, unit kind, definition). Directions: index 0 is β = 0° (x), 1 is β = 90° (y).
MODEL_ROWS = (
    (
        "direction_coefficients.a.0",
        "a(0°), sliding along x",
        None,
        "1/(x̂ᵀŜx̂)²: the force slope at pure spin",
    ),
    ("direction_coefficients.a.1", "a(90°), sliding along y", None, "1/(ŷᵀŜŷ)²"),
    (
        "direction_coefficients.m.0",
        "m(0°), sliding along x",
        None,
        "(Û0/x̂ᵀQ̂x̂)²: the torque slope at pure sliding",
    ),
    ("direction_coefficients.m.1", "m(90°), sliding along y", None, "(Û0/ŷᵀQ̂ŷ)²"),
    (
        "direction_coefficients.kappa1.0",
        "κ1(0°)",
        None,
        "x̂ᵀQ̂x̂/Û0² (κ1 = κ2 = 1: ellipsoidal limit surface)",
    ),
    ("direction_coefficients.kappa2.0", "κ2(0°)", None, "Û0·x̂ᵀŜx̂"),
    ("static.U0", "Û0", None, "M0/(F0 R)"),
    ("static.Q.0.0", "Q̂xx", None, "∬ σ x² dA/(N R²)"),
    ("static.Q.1.1", "Q̂yy", None, "∬ σ y² dA/(N R²)"),
    ("static.Q.0.1", "Q̂xy", None, "∬ σ x y dA/(N R²)"),
    ("static.S.0.0", "Ŝxx", None, "R ∬ σ cos²φ / r dA / N"),
    ("static.S.1.1", "Ŝyy", None, "R ∬ σ sin²φ / r dA / N"),
    ("static.S.0.1", "Ŝxy", None, "R ∬ σ cos φ sin φ / r dA / N"),
    ("static.K", "K", None, "correction: harmonics in the direction of the centre of rotation"),
    ("static.L", "L", None, "correction: Chebyshev polynomials in t; (2K + 1)·L numbers"),
    (
        "static.accuracy.model_force",
        "static map: generalised model, largest |ΔF|/F0",
        "fraction",
        "generalised model against the exact integrals",
    ),
    (
        "static.accuracy.model_torque",
        "static map: generalised model, largest |ΔMz|/M0",
        "fraction",
        "the same for the torque",
    ),
    (
        "static.accuracy.compare_force",
        "static map: paper's closed forms, largest |ΔF|/F0",
        "fraction",
        "the closed forms (1.8) with the coefficients above",
    ),
    (
        "static.accuracy.compare_torque",
        "static map: paper's closed forms, largest |ΔMz|/M0",
        "fraction",
        "the same for the torque",
    ),
    ("rolling.g.0", "ĝx (rolling map)", None, "−∬ σ cos φ dA / N: force at pure spin of the rolling map"),
    ("rolling.xc.0", "x̂c (rolling map)", None, "x_c/R: centre of pressure of the rolling map"),
    (
        "rolling.accuracy.model_force",
        "rolling map: generalised model, largest |ΔF|/F0",
        "fraction",
        "generalised model of the rolling map",
    ),
    (
        "rolling.accuracy.model_torque",
        "rolling map: generalised model, largest |ΔMz|/M0",
        "fraction",
        "the same for the torque",
    ),
    (
        "rolling.accuracy.compare_force",
        "rolling map: paper's closed forms, largest |ΔF|/F0",
        "fraction",
        "the closed forms with k_x",
    ),
    (
        "rolling.accuracy.compare_torque",
        "rolling map: paper's closed forms, largest |ΔMz|/M0",
        "fraction",
        "the same for the torque",
    ),
)
#: Rows of the patch table: (key in coefficients.json "patch", label, unit kind).
PATCH_ROWS = (
    ("r_max", "r_max (= R)", "length"),
    ("r_equiv", "r_equiv = √(area/π)", "length"),
    ("aspect", "aspect (ellipse length/width)", None),
    ("area", "area of the loaded faces", "area"),
    ("load_outside_r_equiv", "share of the load outside r_equiv", "fraction"),
    ("planarity_rms", "RMS distance from the plane", "length"),
)


def _row(key, label, kind, definition, value, prefix):
    from ..figures import units

    unit = units.UNITS[kind] if kind and kind != "fraction" else ""
    return {
        "key": f"{prefix}.{key}",
        "label": label,
        "value": value,
        "unit": unit,
        "scale": 1e-3 if kind == "pressure" else 1.0,
        "fmt": "{:.2%}" if kind == "fraction" else "{:.6g}",
        "definition": definition,
    }


def _dig(doc: Any, dotted: str) -> Any:
    """The value at ``dotted`` (keys and list indices) in ``doc``, None where it is missing."""
    for part in dotted.split("."):
        if isinstance(doc, list):
            i = int(part)
            doc = doc[i] if i < len(doc) else None
        elif isinstance(doc, Mapping):
            doc = doc.get(part)
        else:
            return None
        if doc is None:
            return None
    return doc


def _k_x_definition(key: str, definition: str, label: RollingLabel | None) -> str:
    """The k_x row's definition, naming what the rolling map is (`rolling_label`)."""
    if key != "k_x" or label is None:
        return definition
    from ..figures.units import normalise

    return normalise(f"R·x_c/⟨x²⟩: the centre-of-pressure shift of the {label.text}")


def model_rows(coef: Mapping[str, Any]) -> list[dict]:
    """Rows of the generalised model (`MODEL_ROWS`) present in ``coef["model"]``; ``main``:
    the accuracy rows, shown in the main table (the rest are the model's internals, in the
    page's appendix)."""
    model = coef.get("model")
    if not model:
        return []
    rows = []
    for key, label, kind, definition in MODEL_ROWS:
        value = _dig(model, key)
        if value is not None:
            row = _row(key, label, kind, definition, value, "coefficients.model")
            rows.append({**row, "main": ".accuracy." in key})
    return rows


def error_map_context(docs: Mapping[str, Mapping[str, Any]]) -> list[dict]:
    """Per error-map document (``{file stem: parsed JSON}``): its stem, map and the largest
    errors of the paper's forms and the generalised model, for the page."""
    out = []
    for stem, doc in docs.items():
        worst = doc["worst"]
        out.append(
            {
                "stem": stem,
                "map": "rolling" if stem.endswith("rolling") else "static",
                "source": doc.get("source", ""),
                "models": [name for name in ("paper", "base", "model") if name in worst],
                "worst": worst,
                "n_beta": len(doc["beta_deg"]),
                "n_t": len(doc["t"]),
            }
        )
    return out


#: Hex digits of an input's SHA-256 shown in the provenance table.
HASH_DIGITS = 16


def shown_input(path: str | os.PathLike) -> tuple[str, str]:
    """An input as the provenance table names it: (its path relative to the working folder,
    or its file name when it lies outside it, never the machine's absolute path; the first
    `HASH_DIGITS` hex digits of its SHA-256, "" when it cannot be read)."""
    p = Path(path)
    try:
        shown = str(p.resolve().relative_to(Path.cwd().resolve()))
    except (ValueError, OSError):
        shown = p.name
    try:
        with open(p, "rb") as fh:
            digest = hashlib.file_digest(fh, "sha256").hexdigest()[:HASH_DIGITS]
    except OSError:
        digest = ""
    return shown, digest


def page_context(
    analysis: Analysis,
    coef: Mapping[str, Any],
    table: Mapping[str, Any],
    errors: Mapping[str, Any],
    *,
    p_star: float,
    p_star_source: str,
    seed: int | None,
    version: str,
    error_maps: Mapping[str, Mapping[str, Any]] | None = None,
    own_mesh: OwnMeshKx | None = None,
) -> dict:
    """Every value ``report.html`` shows, from the JSON documents written beside it.

    ``coef``, ``table``, ``errors``: the parsed ``coefficients.json``,
    ``table1.json`` and ``closed_form_vs_exact.json``; ``error_maps``: the parsed
    ``error_map*.json`` by file stem (so the page shows exactly what the files
    hold). Figures, files, sections and timings are added by the caller. What the
    rolling map is comes from its sidecar (`fepost.report.rollinglabel`): said once in
    the provenance, in the k_x row and in Figure 2; ``own_mesh`` (a rolled map's k_x with
    its own-mesh static partner) is quoted beside the k_x of the pair.
    """
    a = analysis
    p = a.static_patch
    label = None if a.rolling_field is None else rolling_label(a.rolling_field.sidecar)
    coefficient_rows = [
        _row(key, label_, kind, _k_x_definition(key, d, label), coef[key], "coefficients")
        for key, label_, kind, d in COEFFICIENT_ROWS
        if coef.get(key) is not None
    ]
    moment_rows = [
        _row(f"A.{j}", f"A{j}", "pressure", f"∫₀¹ σ̄₀(ρ) ρ{'⁰¹²³'[j]} dρ", coef["A"][j], "coefficients")
        for j in range(4)
    ]
    if coef.get("reaction_z") is not None:
        coefficient_rows.append(
            _row(
                "reaction_z",
                "solver reaction",
                "force",
                "from the solver",
                coef["reaction_z"],
                "coefficients",
            )
        )
    pd = coef["patch"]
    patch_rows = [_row(k, label, kind, "", pd[k], "coefficients.patch") for k, label, kind in PATCH_ROWS]
    notes = list(table["notes"])
    return {
        "version": version,
        "static": {
            **dict(zip(("source", "sha256"), shown_input(a.static_field.source), strict=True)),
            "field": a.static_field.field,
            "location": p.location,
            "faces": len(p.triangles),
            "load": coef["N"],
        },
        "rolling": None
        if a.rolling_field is None
        else {
            **dict(zip(("source", "sha256"), shown_input(a.rolling_field.source), strict=True)),
            "field": a.rolling_field.field,
            "load": coef.get("N_rolling"),
            "mismatch_allowed": coef["rolling"]["load_mismatch_allowed"],
            "k_x": coef.get("k_x"),
            "label": label.text if label else "",
            "kind": label.kind if label else "",
            "own_mesh": None
            if own_mesh is None
            else {"source": shown_input(own_mesh.static)[0], "k_x": own_mesh.k_x},
        },
        "friction": a.coefficients.f,
        "p_star": p_star,
        "p_star_source": p_star_source,
        "seed": seed,
        "grid": {"rule": a.grid.rule, "nr": a.grid.shape[0], "nphi": a.grid.shape[1]},
        "R": coef["R"],
        "R_definition": coef.get("R_definition", ""),
        "coefficient_rows": coefficient_rows,
        "moment_rows": moment_rows,
        "k_x_label": "" if label is None else label.text,
        "patch": pd,
        "patch_rows": patch_rows,
        "rmax_over_requiv": pd["r_max"] / pd["r_equiv"],
        "patch_notes": list(p.notes),
        "table1": table,
        "table1_notes": [n for n in notes if not n.startswith("paper:")],
        "paper_notes": [n.removeprefix("paper:").strip() for n in notes if n.startswith("paper:")],
        "bias_names": ("F0", "M0", "a", "m", "k_x"),
        "errors": errors,
        "model_rows": model_rows(coef),
        "model_recommendation": _dig(coef, "model.recommendation"),
        "generalised": table.get("generalised"),
        "error_maps": error_map_context(error_maps or {}),
    }
