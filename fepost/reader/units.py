"""Unit systems of FE models, and the scale check that catches a wrong one.

FE solvers have no units: a model is written in one *consistent* system, and
its results come out in it. fepost reports SI; ``--units`` names the system a
model was written in (`SYSTEMS`), and the reader scales lengths,
pressures, forces and times to SI on reading.

=================  =========  ===========  ==============  ========
system             length     force        pressure        time
=================  =========  ===========  ==============  ========
``SI`` (m-N-Pa)    m          N            Pa              s
``mm-N-MPa``       mm         N            MPa             s (mass in t; also ``mm-t-s``)
``mm-kN-GPa``      mm         kN           GPa             ms (mass in kg; also ``mm-kg-ms``)
``mm-mN-kPa``      mm         mN           kPa             s (mass in kg; also ``mm-kg-s``)
``m-kN-kPa``       m          kN           kPa             s (mass in t; also ``m-t-s``)
``cm-dyn-Ba``      cm         dyn          Ba (0.1 Pa)     s (CGS; also ``cm-g-s``)
``in-lbf-psi``     in         lbf          psi             s (mass in lbf·s²/in; also ``in-lbf-s``)
``ft-lbf-psf``     ft         lbf          lbf/ft²         s (mass in slug; also ``ft-lbf-s``)
=================  =========  ===========  ==============  ========

**Scale check.** A contact patch is between `RADIUS_RANGE` in radius
and its peak pressure within `PRESSURE_RANGE`; outside those a model
was almost surely read in the wrong units (a tire model in millimetres read as
metres has R ≈ 100 m). Without ``--units`` that is an error
(`fepost.errors.ScaleError`) naming the likely system; with
``--units`` given explicitly the user has vouched for the scale and it is a
`fepost.errors.ScaleWarning`.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass

from ..errors import ArgumentError, ScaleError, ScaleWarning

#: Plausible patch radius, m.
RADIUS_RANGE = (1.0e-5, 20.0)
#: Plausible peak contact pressure, Pa.
PRESSURE_RANGE = (1.0e-6, 1.0e12)


@dataclass(frozen=True)
class UnitSystem:
    """A consistent FE unit system: SI value of one unit of length (m), force (N), pressure (Pa), time (s)."""

    name: str
    length: float
    force: float
    pressure: float
    time: float
    aliases: tuple[str, ...] = ()

    @property
    def is_si(self) -> bool:
        return self.length == 1.0 and self.force == 1.0 and self.pressure == 1.0 and self.time == 1.0


_LBF = 4.4482216152605
_INCH = 0.0254
_FOOT = 0.3048

SYSTEMS: tuple[UnitSystem, ...] = (
    UnitSystem("SI", 1.0, 1.0, 1.0, 1.0, ("si", "m-n-pa", "m-kg-s", "m-n-s")),
    UnitSystem("mm-N-MPa", 1e-3, 1.0, 1e6, 1.0, ("mm-t-s", "mm-n-s")),
    UnitSystem("mm-kN-GPa", 1e-3, 1e3, 1e9, 1e-3, ("mm-kg-ms",)),
    UnitSystem("mm-mN-kPa", 1e-3, 1e-3, 1e3, 1.0, ("mm-kg-s",)),
    UnitSystem("m-kN-kPa", 1.0, 1e3, 1e3, 1.0, ("m-t-s",)),
    UnitSystem("cm-dyn-Ba", 1e-2, 1e-5, 0.1, 1.0, ("cm-g-s", "cgs")),
    UnitSystem("in-lbf-psi", _INCH, _LBF, _LBF / _INCH**2, 1.0, ("in-lbf-s",)),
    UnitSystem("ft-lbf-psf", _FOOT, _LBF, _LBF / _FOOT**2, 1.0, ("ft-lbf-s",)),
)
SI = SYSTEMS[0]


def _key(name: str) -> str:
    return re.sub(r"[\s_/]+", "-", name.strip().lower())


def unit_system(name: str | UnitSystem | None) -> UnitSystem | None:
    """The unit system called ``name`` (case-insensitive, aliases accepted); None stays None.

    Raises
    ------
    ArgumentError
        Unknown name (the message lists the systems).
    """
    if name is None or isinstance(name, UnitSystem):
        return name
    key = _key(str(name))
    for s in SYSTEMS:
        if key == _key(s.name) or key in s.aliases:
            return s
    names = ", ".join(s.name for s in SYSTEMS)
    raise ArgumentError(
        f"--units: unknown unit system {name!r}; known: {names} (aliases: mm-t-s, mm-kg-ms, ...)"
    )


def _guess(radius: float) -> str:
    """The unit system that would bring an implausibly large patch radius to tire size."""
    if radius > RADIUS_RANGE[1]:
        for s in SYSTEMS[1:]:
            if RADIUS_RANGE[0] <= radius * s.length <= 2.0:
                return (
                    f" (in millimetres? try --units {s.name})"
                    if s.length == 1e-3
                    else f" (try --units {s.name})"
                )
    return ""


def check_scale(source: str, radius: float, peak: float, units: UnitSystem | None) -> None:
    """Refuse (``units`` None: assumed SI) or warn (explicit ``units``) on implausible scales.

    ``radius`` in m and ``peak`` in Pa, after conversion to SI.
    """
    problems = []
    if not RADIUS_RANGE[0] <= radius <= RADIUS_RANGE[1]:
        problems.append(
            f"patch radius {radius:.3g} m is outside {RADIUS_RANGE[0]:g}-{RADIUS_RANGE[1]:g} m"
            + _guess(radius)
        )
    if not PRESSURE_RANGE[0] <= peak <= PRESSURE_RANGE[1]:
        problems.append(
            f"peak contact pressure {peak:.3g} Pa is outside {PRESSURE_RANGE[0]:g}-{PRESSURE_RANGE[1]:g} Pa"
        )
    if not problems:
        return
    text = "; ".join(problems)
    if units is None:
        raise ScaleError(
            f"{source}: implausible scale for a contact patch: {text}; the file is read as SI "
            "(m, N, Pa): give the model's unit system with --units (e.g. mm-N-MPa, or SI to accept)"
        )
    warnings.warn(f"{source}: implausible scale in {units.name}: {text}", ScaleWarning, stacklevel=3)


def describe(units: UnitSystem | None) -> str:
    """How the units were chosen, for outputs: ``"SI (assumed)"``, ``"mm-N-MPa (given)"``."""
    return "SI (assumed)" if units is None else f"{units.name} (given)"
