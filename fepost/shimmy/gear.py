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
``wheel_spin_inertia``   kg m²     I_w: one wheel-tire-brake assembly about its axle (0: no
                                   gyroscopic coupling); needs ``rolling_radius``
``rolling_radius``       m         R_e: the wheel turns at Ω = (1 − κ) V / R_e
``bending_slope``        rad/m     s: roll of the axle per metre of lateral bending (φ = s y;
                                   1.5/L for a cantilever strut of length L)
``rake``                 rad       γ: tilt of the strut axis from the vertical (0: vertical)
``tire_stiffness_x``     N/m       the tire's tangential stiffness against the road, along x
``tire_stiffness_y``     N/m       … along y (the brush tire, `fepost.shimmy.brush`)
``tire_deflection``      m         the tire's vertical deflection under its full load (touchdown)
``tread_slip_stiffness`` –         C_κ/N of the tread alone: with it the tire is the brush on a
                                   carcass (`fepost.shimmy.carcass`), its elements calibrated to
                                   this slip stiffness, the carcass what is left of the standstill
                                   stiffness (0: the lumped brush)
``tire_stiffness_z``     N m/rad   the tire's standstill torsional stiffness about the patch centre
                                   (with ``tread_slip_stiffness``: the carcass's torsion; 0: rigid)
=======================  ========  ==============================================

The tire's stiffnesses and deflection serve the gripping tire and the touchdown
(`fepost.shimmy.touchdown`); ``tread_slip_stiffness`` and ``tire_stiffness_z`` (optional,
0 when absent: the lumped brush as before) put its tread on a carcass.
The four before them are optional and default to 0, which leaves the equations as they
were (no gyroscopic coupling, vertical strut). With them the wheels' spin couples
yaw and lateral bending gyroscopically, G = s Σ I_w Ω (`fepost.shimmy.equations`),
and a raked strut steers the wheels by ψ cos γ and takes the ground's moment
about its axis times cos γ.

Refused besides: twin wheels without a ``half_track`` (they would sit on the strut
axis, one on the other), and inertias or masses outside `INERTIA_RANGE` or whose mode
with the gear's stiffness lies above `MAX_MODE_HZ` (a typo of a few orders of
magnitude, which would make the time integration crawl or blow up).

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
#: Parameters added for the wheels' spin, the strut's rake, the gripping tire and the touchdown:
#: optional, 0 when absent (and then left out of `Gear.to_dict`).
ADDED: dict[str, tuple[str, bool]] = {
    "wheel_spin_inertia": ("kg m^2", True),
    "rolling_radius": ("m", True),
    "bending_slope": ("rad/m", True),
    "rake": ("rad", True),
    "tire_stiffness_x": ("N/m", True),
    "tire_stiffness_y": ("N/m", True),
    "tire_deflection": ("m", True),
    "tread_slip_stiffness": ("", True),
    "tire_stiffness_z": ("N m/rad", True),
}
ALL_PARAMETERS = {**PARAMETERS, **ADDED}
#: Optional keys besides the parameters.
OPTIONAL = ("name", "sources", "notes")
#: Parameters a gear file may leave out (defaults in `Gear`).
DEFAULTED = ("wheels", "half_track", "slip_ratio", *ADDED)
#: Plausible range of an inertia (kg m²) or modal mass (kg) of a landing gear, SI.
INERTIA_RANGE = (1e-4, 1e7)
#: Highest plausible frequency (Hz) of the gear's torsional or lateral mode.
MAX_MODE_HZ = 2000.0
#: Inertias with the stiffness their mode needs and that mode's name.
_MODES = (
    ("yaw_inertia", "torsional_stiffness", "torsional"),
    ("lateral_mass", "lateral_stiffness", "lateral bending"),
)


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
    wheel_spin_inertia: float = 0.0
    rolling_radius: float = 0.0
    bending_slope: float = 0.0
    rake: float = 0.0
    tire_stiffness_x: float = 0.0
    tire_stiffness_y: float = 0.0
    tire_deflection: float = 0.0
    tread_slip_stiffness: float = 0.0
    tire_stiffness_z: float = 0.0
    name: str = ""
    sources: Any = field(default_factory=dict)
    notes: str = ""

    def __post_init__(self) -> None:
        for key in ALL_PARAMETERS:
            _check_value(getattr(self, key), key, "Gear")
        if self.wheels not in (1, 2):
            raise GearFileError(f"Gear: wheels must be 1 or 2, got {self.wheels!r}")
        if self.wheels == 1 and self.half_track != 0.0:
            raise GearFileError("Gear: half_track must be 0 with one wheel (it sits on the strut axis)")
        if self.wheels == 2 and self.half_track == 0.0:
            raise GearFileError(
                "Gear: twin wheels (wheels = 2) need half_track > 0, the offset of each wheel"
            )
        if self.slip_ratio > 1.0:
            raise GearFileError(f"Gear: slip_ratio must be in (0, 1], got {self.slip_ratio!r}")
        if self.wheel_spin_inertia > 0 and self.rolling_radius == 0.0:
            raise GearFileError(
                "Gear: wheel_spin_inertia needs rolling_radius > 0 (the wheel's spin is V/R_e)"
            )
        if self.rake >= math.pi / 2:
            raise GearFileError(
                f"Gear: rake must be below pi/2 rad (a strut tilted to the ground), got {self.rake!r}"
            )
        _check_inertias(self)
        object.__setattr__(self, "sources", MappingProxyType(dict(self.sources)))

    @property
    def gyroscopic(self) -> float:
        """G / V (N m s/m per m/s): the gyroscopic coupling of yaw and lateral bending per
        forward speed at zero slip, s Σ I_w / R_e (0 without ``wheel_spin_inertia``)."""
        if self.wheel_spin_inertia == 0.0 or self.bending_slope == 0.0:
            return 0.0
        return self.bending_slope * self.wheels * self.wheel_spin_inertia / self.rolling_radius

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
        for key, (unit, _) in ALL_PARAMETERS.items():
            if key in PARAMETERS or getattr(self, key):
                out[key] = {"value": getattr(self, key), "unit": unit}
        if self.sources:
            out["sources"] = dict(self.sources)
        if self.notes:
            out["notes"] = self.notes
        return out


def _check_inertias(g: Gear) -> None:
    lo, hi = INERTIA_RANGE
    for key in ("yaw_inertia", "lateral_mass", "wheel_spin_inertia"):
        value = getattr(g, key)
        if key == "wheel_spin_inertia" and value == 0.0:
            continue
        unit = ALL_PARAMETERS[key][0]
        if not lo <= value <= hi:
            raise GearFileError(
                f"Gear: {key} = {value:g} {unit} is outside the plausible range {lo:g} to {hi:g} {unit} "
                "of a landing gear (SI units?)"
            )
    for inertia, stiffness, mode in _MODES:
        hz = math.sqrt(getattr(g, stiffness) / getattr(g, inertia)) / (2 * math.pi)
        if hz > MAX_MODE_HZ:
            raise GearFileError(
                f"Gear: {inertia} = {getattr(g, inertia):g} {ALL_PARAMETERS[inertia][0]} with {stiffness} = "
                f"{getattr(g, stiffness):g} gives a {mode} mode at {hz:.3g} Hz, above {MAX_MODE_HZ:g} Hz: "
                f"{inertia} is implausibly small"
            )


def _check_value(value, key: str, where: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise GearFileError(f"{where}: {key} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise GearFileError(f"{where}: {key} must be finite, got {value!r}")
    zero_ok = ALL_PARAMETERS[key][1]
    if value < 0 or (value == 0 and not zero_ok):
        need = ">= 0" if zero_ok else "> 0"
        raise GearFileError(f"{where}: {key} must be {need}, got {value!r}")
    if key == "wheels" and int(value) != value:
        raise GearFileError(f"{where}: wheels must be 1 or 2, got {value!r}")


def gear_from_dict(data: Any, where: str = "gear") -> Gear:
    """A `Gear` from a parsed gear file; ``where`` names it in messages."""
    if not isinstance(data, dict):
        raise GearFileError(f"{where}: must hold a JSON object, got {type(data).__name__}")
    unknown = sorted(set(data) - set(ALL_PARAMETERS) - set(OPTIONAL))
    if unknown:
        known = ", ".join([*ALL_PARAMETERS, *OPTIONAL])
        close = difflib.get_close_matches(unknown[0], [*ALL_PARAMETERS, *OPTIONAL], n=1, cutoff=0.6)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise GearFileError(f"{where}: unknown key {unknown[0]!r}{hint} (known: {known})")
    missing = [k for k in PARAMETERS if k not in DEFAULTED and k not in data]
    if missing:
        raise GearFileError(f"{where}: missing key {missing[0]!r}")
    for key in ALL_PARAMETERS:
        if key in data:
            _check_value(data[key], key, where)
    if "sources" in data and not (
        isinstance(data["sources"], dict) and all(isinstance(v, str) for v in data["sources"].values())
    ):
        raise GearFileError(f"{where}: sources must be an object of texts")
    for key in ("name", "notes"):
        if key in data and not isinstance(data[key], str):
            raise GearFileError(f"{where}: {key} must be a text, got {data[key]!r}")
    values = {k: data[k] for k in ALL_PARAMETERS if k in data}
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
