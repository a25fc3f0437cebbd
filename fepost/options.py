"""The options of one analysis, validated once: `AnalysisOptions`, and the friction rule.

`fepost.analyse` takes an `AnalysisOptions` (how to read the maps, the polar
grid, the threshold, the pairing rule, the inflation pressure) and, beside it,
the friction coefficient or a `fepost.friction.law.FrictionLaw`. The command
line builds one from its options, the sweep sends it to every worker (it is
frozen, made of plain values, so it pickles and hashes into a row's identity),
the report passes it to its sections.

The friction coefficient has one default, `DEFAULT_FRICTION`, and one rule,
`check_friction` (a finite number in `FRICTION_RANGE`, [0.001, 10]), defined in
`fepost.friction_coefficient` and re-exported here.

This module is light at import (the standard library, `fepost.errors` and
`fepost.friction_coefficient`):
the command line's option types use it before numpy is imported. The library
defaults that live in heavy modules (grid size, threshold) are read when an
`AnalysisOptions` is made.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from .errors import ArgumentError
from .friction_coefficient import DEFAULT_FRICTION as DEFAULT_FRICTION
from .friction_coefficient import FRICTION_RANGE as FRICTION_RANGE
from .friction_coefficient import check_friction as check_friction
from .friction_coefficient import is_real as _real

#: Largest accepted inflation pressure, Pa (1 GPa: no tire; a unit slip above it).
PRESSURE_MAX = 1e9


def check_pressure(p: object, *, name: str = "inflation_pressure") -> float:
    """``p`` as a float when it is a pressure in (0, `PRESSURE_MAX`] Pa."""
    if not _real(p) or not (math.isfinite(float(p)) and 0.0 < float(p) <= PRESSURE_MAX):  # type: ignore[arg-type]
        raise ArgumentError(f"{name} must be a positive pressure in Pa up to 1 GPa, got {p!r}")
    return float(p)  # type: ignore[arg-type]


@dataclass(frozen=True)
class AnalysisOptions:
    """How one analysis runs, validated when made (`ArgumentError` naming the field).

    Attributes
    ----------
    field : str or None
        Contact-pressure array (``NAME:K`` for component K); None: found by name.
    step : int or None
        Time step to read (0-based); None: the last.
    displacement : str or None
        ``"auto"``, an array name added to the coordinates, or None to use them as written.
    units : str or None
        The model's unit system (a name of `fepost.reader.units.SYSTEMS`); None: SI.
    surface : str or None
        Exodus side set or element block holding the contact faces.
    nr, nphi : int
        Polar grid nodes in r and φ (default the library's, 64 x 128).
    rule : str
        Radial quadrature rule, ``"gauss"`` or ``"trapezoid"``.
    threshold : float
        A face is loaded when its pressure exceeds ``threshold`` x peak (0 < t < 1).
    rolling_axis : tuple of 3 floats or None
        Global rolling direction; None: global x.
    allow_load_mismatch : bool
        Accept a rolling map whose load is more than `fepost.analysis.LOAD_TOL`
        off the static map's (recorded in the outputs).
    inflation_pressure : float or None
        P* in Pa for σ/P* in the report's figures; None: the sidecar's, else the paper's.
    """

    field: str | None = None
    step: int | None = None
    displacement: str | None = "auto"
    units: str | None = None
    surface: str | None = None
    nr: int = 0
    nphi: int = 0
    rule: str = "gauss"
    threshold: float = 0.0
    rolling_axis: tuple[float, float, float] | None = None
    allow_load_mismatch: bool = False
    inflation_pressure: float | None = None

    def __post_init__(self) -> None:
        from .patch import DEFAULT_THRESHOLD
        from .polar import DEFAULT_NPHI, DEFAULT_NR, PolarGrid
        from .reader.units import unit_system

        for name in ("field", "displacement", "surface"):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, str) or not value.strip()):
                raise ArgumentError(f"{name} must be a non-empty name or None, got {value!r}")
        if self.displacement is not None and self.displacement.lower() == "none":
            object.__setattr__(self, "displacement", None)
        if self.step is not None and (not isinstance(self.step, int) or isinstance(self.step, bool)):
            raise ArgumentError(f"step must be an integer or None, got {self.step!r}")
        if self.units is not None:
            system = unit_system(self.units)  # an unknown name fails here
            object.__setattr__(self, "units", None if system is None else system.name)
        object.__setattr__(self, "nr", self.nr or DEFAULT_NR)
        object.__setattr__(self, "nphi", self.nphi or DEFAULT_NPHI)
        PolarGrid.make(self.nr, self.nphi, self.rule)  # type: ignore[arg-type]  # raises on a bad grid
        t = self.threshold or DEFAULT_THRESHOLD
        if not (_real(t) and 0.0 < t < 1.0):
            raise ArgumentError(f"threshold must be a number between 0 and 1 (exclusive), got {t!r}")
        object.__setattr__(self, "threshold", float(t))
        object.__setattr__(self, "rolling_axis", _axis(self.rolling_axis))
        if not isinstance(self.allow_load_mismatch, bool):
            raise ArgumentError(
                f"allow_load_mismatch must be True or False, got {self.allow_load_mismatch!r}"
            )
        if self.inflation_pressure is not None:
            object.__setattr__(self, "inflation_pressure", check_pressure(self.inflation_pressure))

    @classmethod
    def make(cls, options: AnalysisOptions | None = None, **changes: Any) -> AnalysisOptions:
        """``options`` (default: the defaults) with ``changes``, validated.

        A ``grid`` (`fepost.polar.PolarGrid`) is taken apart into ``nr``, ``nphi``
        and ``rule``; a change to None keeps the option's value, except for
        ``displacement``, where None means "the coordinates as written".
        """
        grid = changes.pop("grid", None)
        if grid is not None:
            changes.update(nr=int(grid.shape[0]), nphi=int(grid.shape[1]), rule=str(grid.rule))
        unknown = sorted(set(changes) - {f.name for f in fields(cls)})
        if unknown:
            raise ArgumentError(f"unknown analysis option {unknown[0]!r}")
        given = {k: v for k, v in changes.items() if v is not None or k == "displacement"}
        base = options if options is not None else cls()
        return replace(base, **given) if given else base

    @property
    def grid(self):
        """The polar grid (`fepost.polar.PolarGrid`)."""
        from .polar import PolarGrid

        return PolarGrid.make(self.nr, self.nphi, self.rule)  # type: ignore[arg-type]

    @property
    def unit_system(self):
        """The unit system (`fepost.reader.units.UnitSystem`); None when none was given
        (read as SI, implausible scales refused)."""
        from .reader.units import unit_system

        return unit_system(self.units)

    def reading(self) -> dict[str, Any]:
        """The keyword arguments of `fepost.reader.start_reading`."""
        return {
            "field": self.field,
            "step": self.step,
            "displacement": self.displacement,
            "units": self.unit_system,
            "surface": self.surface,
        }

    def to_dict(self) -> dict[str, Any]:
        """Plain values (JSON), every field."""
        d = asdict(self)
        d["rolling_axis"] = None if self.rolling_axis is None else list(self.rolling_axis)
        return d

    def __repr__(self) -> str:
        defaults = AnalysisOptions()
        changed = [f"{f.name}={getattr(self, f.name)!r}" for f in fields(self)
                   if getattr(self, f.name) != getattr(defaults, f.name)]  # fmt: skip
        return f"AnalysisOptions({', '.join(changed)})"


def _axis(axis: object) -> tuple[float, float, float] | None:
    if axis is None:
        return None
    try:
        values = tuple(float(v) for v in axis)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ArgumentError(f"rolling_axis must be three numbers X,Y,Z, got {axis!r}") from None
    if len(values) != 3 or not all(math.isfinite(v) for v in values) or not any(values):
        raise ArgumentError(f"rolling_axis must be three finite numbers X,Y,Z, not all 0, got {axis!r}")
    return values  # type: ignore[return-value]
