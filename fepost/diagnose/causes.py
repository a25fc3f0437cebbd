"""The candidate causes: physical extensions of the simulation, as parametrised models.

Every model predicts the three channels of every test point through the exact
integrals (docs/theory.md, `friction_resultants`),
in the dimensionless units of `Simulation.scales <fepost.diagnose.simulation.Simulation.scales>`:
Fx/(f₀N), Fy/(f₀N), Mz/(f₀NR) with the nominal f₀ and the static map's N and R.

All extensions share the friction level f; each adds its own 1–3 parameters,
which equal a "no effect" value on the nested model ``friction_level``:

============================== ===================== ===============================
cause                          parameters            no-effect value
============================== ===================== ===============================
``none``                       (f = f₀ fixed)        –
``friction_level``             f                     f = f₀ (→ ``none``)
``pressure_dependent_friction`` f, c_p               c_p = 0
``speed_dependent_friction``   f, c_v (s/m)          c_v = 0
``anisotropic_friction``       f, α = f_y/f_x        α = 1
``elliptic_patch``             f, s                  s = 1
``pressure_shift``             f, dx, dy (m)         dx = dy = 0
``sensor_offset``              f, oFx, oFy (N), oMz  offsets = 0
``pressure_shape``             f, c_rim              c_rim = 0
============================== ===================== ===============================

Two extensions at once (`joint_candidate`) share f and keep both
parameter sets; the effects combine exactly (`fepost.diagnose.models`).

Linear structure (the speed of the fits). The exact resultants are linear in f,
and — while no local coefficient is clipped at zero — in c_p, in c_v and in α.
So a few exact evaluations at the data's kinematics give those models exactly
for every parameter value in their bounds: c_p ∈ [−1/(λσ_max/σ_ref − 1), 1] and
c_v > −1/max|w|, where no clipping occurs. Only ``elliptic_patch`` (stretch
x → sx, y → y/s at equal area and load) and ``pressure_shift`` move the pressure
map and need new exact integrals per geometry; f stays linear there too. The
load scaling σ → λσ multiplies the Coulomb part by λ and the pressure-dependent
part by λ².
"""

from __future__ import annotations

import numpy as np

from .causenames import CAUSES
from .models import Candidate, Parameter, Predictor, extension_model, with_fixed
from .shape import rim_bounds
from .transfer import load_transfer_model

__all__ = [
    "CAUSES",
    "EXTENSIONS",
    "Candidate",
    "Parameter",
    "Predictor",
    "build_candidates",
    "joint_candidate",
    "with_fixed",
]

#: The causes that extend ``friction_level`` with parameters of their own.
EXTENSIONS = CAUSES[2:]

#: What each cause means, in words (the summary and the docs use these).
MEANING = {
    "none": "the simulation as it is: exact integrals, nominal f",
    "friction_level": "one friction coefficient other than the nominal one",
    "pressure_dependent_friction": "the local friction coefficient depends on the contact pressure",
    "speed_dependent_friction": "the local friction coefficient depends on the sliding speed",
    "elliptic_patch": "the real patch is elongated relative to the simulated one",
    "anisotropic_friction": "friction differs along x and along y",
    "pressure_shift": "the real centre of pressure lies elsewhere",
    "sensor_offset": "constant offsets in the measured channels",
    "sensor_crosstalk": "the load cell's calibration matrix has off-diagonal terms",
    "load_transfer": "the centre of pressure moves with the friction force",
    "pressure_shape": "the same load and centre of pressure, carried more towards the rim (c_rim > 0) "
    "or the centre (c_rim < 0)",
}

#: Causes the load-transfer model combines with (applied after the force, on the sensor).
SENSOR_CAUSES = ("sensor_offset", "sensor_crosstalk")


def extension_parameters(pred: Predictor) -> dict[str, tuple[Parameter, ...]]:
    """The parameters of each extension (without f), with bounds for these data."""
    R = pred.sim.radius
    scale = pred.scale
    ratio = pred.max_pressure_ratio()
    cp_low = -1.0 / (ratio - 1.0) if ratio > 1.0 else -10.0
    top = pred.max_slip_speed()
    cv_low = -1.0 / top if top > 0 else -10.0
    rim_lo, rim_hi = shape_bounds(pred)
    return {
        "pressure_dependent_friction": (
            Parameter("c_p", "1", 0.0, cp_low, 1.0, 0.1, 0.0, "μ = f (1 + c_p (σ/σ_ref − 1))"),
        ),
        "speed_dependent_friction": (
            Parameter("c_v", "s/m", 0.0, 0.999 * cv_low, 10.0, 0.05, 0.0, "μ = f (1 + c_v |w|)"),
        ),
        "elliptic_patch": (
            Parameter("s", "1", 1.0, 0.5, 2.0, 0.05, 1.0, "stretch x → s·x, y → y/s (aspect s²)"),
        ),
        "anisotropic_friction": (Parameter("alpha", "1", 1.0, 0.2, 5.0, 0.1, 1.0, "α = f_y/f_x"),),
        "pressure_shift": (
            Parameter("dx", "m", 0.0, -0.5 * R, 0.5 * R, 0.05 * R, 0.0, "shift of the pressure map along x"),
            Parameter("dy", "m", 0.0, -0.5 * R, 0.5 * R, 0.05 * R, 0.0, "shift of the pressure map along y"),
        ),
        "sensor_offset": tuple(
            Parameter(f"offset_{ch}", unit, 0.0, -np.inf, np.inf, 0.01 * s, 0.0, f"constant added to {ch}")
            for ch, unit, s in zip(("Fx", "Fy", "Mz"), ("N", "N", "N·m"), scale, strict=True)
        ),
        "sensor_crosstalk": tuple(
            Parameter(name, unit, 0.0, -0.5 * s, 0.5 * s, 0.01 * s, 0.0, what)
            for name, unit, s, what in (
                ("c_xy", "1", 1.0, "measured Fx gains c_xy Fy"),
                ("c_xz", "1/m", 1.0 / R, "measured Fx gains c_xz Mz"),
                ("c_yx", "1", 1.0, "measured Fy gains c_yx Fx"),
                ("c_yz", "1/m", 1.0 / R, "measured Fy gains c_yz Mz"),
                ("c_zx", "m", R, "measured Mz gains c_zx Fx"),
                ("c_zy", "m", R, "measured Mz gains c_zy Fy"),
            )
        ),
        "load_transfer": tuple(
            Parameter(name, "m", 0.0, -R, R, 0.05 * R, 0.0, f"centre of pressure moves by {name}·{F}/N")
            for name, F in (("h_x", "Fx"), ("h_y", "Fy"))
        ),
        "pressure_shape": (
            Parameter("c_rim", "1", 0.0, rim_lo, rim_hi, 0.1, 0.0, "σ → σ (1 + c_rim r), r the rim weight"),
        ),
    }


#: c_rim is kept within ± this, whatever the map allows (a uniform disc allows ±1).
RIM_LIMIT = 5.0


def shape_bounds(pred: Predictor) -> tuple[float, float]:
    """Bounds of c_rim: the pressure stays non-negative on every map (`fepost.diagnose.shape`)."""
    lo, hi = -RIM_LIMIT, RIM_LIMIT
    for quad in pred.sim.quads.values():
        a, b = rim_bounds(quad)
        lo, hi = max(lo, a), min(hi, b)
    return lo, hi


def friction_parameter(pred: Predictor) -> Parameter:
    f0 = pred.sim.friction
    return Parameter("f", "1", f0, 0.01 * f0, 10.0 * f0, f0, None, "friction coefficient (along x)")


_DESCRIPTION = {
    "pressure_dependent_friction": "local friction coefficient depends on local contact pressure",
    "speed_dependent_friction": "local friction coefficient depends on local sliding speed |w|",
    "elliptic_patch": "the real patch is elongated along x (equal area and load)",
    "anisotropic_friction": "friction differs along x and along y",
    "pressure_shift": "the real centre of pressure lies elsewhere than the simulated one",
    "sensor_offset": "constant offsets in the measured Fx, Fy, Mz",
    "sensor_crosstalk": "the load cell's calibration matrix has off-diagonal terms (measured = C·true)",
    "load_transfer": "the centre of pressure moves with the friction force (dx = h_x Fx/N, dy = h_y Fy/N)",
    "pressure_shape": "the same load and centre of pressure, distributed more towards the rim or the centre",
}


def combinable(extensions) -> bool:
    """Whether one model can hold all of ``extensions``: ``load_transfer`` only with the sensor causes."""
    extensions = tuple(extensions)
    if "load_transfer" not in extensions:
        return True
    return all(e in SENSOR_CAUSES for e in extensions if e != "load_transfer")


def pair_name(extensions) -> str:
    """The name of a joint model: its extensions joined by ``+``, primary first."""
    return "+".join(extensions)


def joint_candidate(pred: Predictor, extensions, params: dict | None = None) -> Candidate:
    """One model with every extension in ``extensions`` (order kept: primary first) and a shared f.

    It nests ``none``, ``friction_level`` and each extension alone. ``params``
    (from `extension_parameters`) saves rebuilding the parameter table.
    """
    extensions = tuple(extensions)
    unknown = [e for e in extensions if e not in EXTENSIONS]
    if unknown or len(set(extensions)) != len(extensions) or not extensions:
        raise ValueError(f"extensions must be distinct names of {EXTENSIONS}, got {extensions!r}")
    if not combinable(extensions):
        raise ValueError(f"load_transfer combines only with {', '.join(SENSOR_CAUSES)}, got {extensions!r}")
    table = params or extension_parameters(pred)
    parameters = (friction_parameter(pred),) + tuple(p for e in extensions for p in table[e])
    nested = ("none", "friction_level") + (extensions if len(extensions) > 1 else ())
    description = "; ".join(_DESCRIPTION[e] for e in extensions)
    build = load_transfer_model if "load_transfer" in extensions else extension_model
    return build(pred, pair_name(extensions), parameters, nested, description, extensions)


def build_candidates(pred: Predictor) -> dict[str, Candidate]:
    """Every cause of `CAUSES` as a `Candidate` over the predictor's points."""
    f_par = friction_parameter(pred)
    table = extension_parameters(pred)
    level = extension_model(
        pred, "friction_level", (f_par,), ("none",), "one friction coefficient f ≠ f₀", ()
    )
    none = with_fixed(level, "f", pred.sim.friction, "none")
    cands = {
        "none": Candidate(
            "none", (), none.predict, (), "the simulation as it is: exact integrals, nominal f"
        ),
        "friction_level": level,
    }
    for ext in EXTENSIONS:
        cands[ext] = joint_candidate(pred, (ext,), table)
    return cands
