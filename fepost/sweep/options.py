"""What every row of a sweep is run with: the options of ``fepost coefficients``.

A sweep row is one call of :func:`fepost.analysis.analyse`; :class:`RowOptions`
holds that call's keyword arguments as plain values, so it pickles to any Dask
worker and hashes into the row's identity (a row computed with other options is
not reused by a later run).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

from ..errors import ArgumentError
from ..patch import DEFAULT_THRESHOLD
from ..polar import DEFAULT_NPHI, DEFAULT_NR, PolarGrid


@dataclass(frozen=True)
class RowOptions:
    """Keyword arguments of :func:`fepost.analysis.analyse` for every row.

    Attributes
    ----------
    friction : float
        Friction coefficient f (dimensionless).
    field : str or None
        Contact-pressure array name (``NAME:K`` for a component); None: by name.
    displacement : str or None
        ``"auto"``, an array name, or None to use the coordinates as written.
    threshold : float
        A face is loaded when its pressure exceeds ``threshold`` × peak.
    nr, nphi : int
        Polar grid nodes in r and φ.
    rule : str
        Radial quadrature rule, ``"gauss"`` or ``"trapezoid"``.
    rolling_axis : tuple of 3 floats or None
        Global rolling direction (default global x).
    extra : tuple of (name, value) pairs
        Any other keyword argument of ``analyse`` (reading options added to
        the single-file commands later reach every row through here). Values
        must be plain (str, number, bool, None, or tuples of them).
    """

    friction: float = 0.3
    field: str | None = None
    displacement: str | None = "auto"
    threshold: float = DEFAULT_THRESHOLD
    nr: int = DEFAULT_NR
    nphi: int = DEFAULT_NPHI
    rule: str = "gauss"
    rolling_axis: tuple[float, float, float] | None = None
    extra: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        f = self.friction
        if isinstance(f, bool) or not isinstance(f, int | float) or not (math.isfinite(f) and f > 0):
            raise ArgumentError(f"friction must be a positive number, got {self.friction!r}")
        if self.rolling_axis is not None:
            object.__setattr__(self, "rolling_axis", tuple(float(v) for v in self.rolling_axis))
        PolarGrid.make(self.nr, self.nphi, self.rule)  # type: ignore[arg-type]  # raises on a bad grid
        object.__setattr__(self, "extra", tuple(sorted((str(k), v) for k, v in dict(self.extra).items())))
        clash = [k for k, _ in self.extra if k in _NAMED or k in ("step", "grid")]
        if clash:
            raise ArgumentError(f"extra analysis option {clash[0]!r} is set through its own field")

    @classmethod
    def from_analysis_kwargs(cls, kwargs: dict, friction: float = 0.3) -> RowOptions:
        """Options from the keyword arguments the single-file commands pass to ``analyse``.

        ``kwargs`` is what :func:`fepost.cli._common.analysis_kwargs` returns
        (its ``step`` is the sweep's business and is ignored here).
        """
        grid = kwargs.get("grid") or PolarGrid.make()
        axis = kwargs.get("rolling_axis")
        known = {"field", "displacement", "threshold", "grid", "rolling_axis", "step", "friction"}
        return cls(
            friction=friction,
            field=kwargs.get("field"),
            displacement=kwargs.get("displacement", "auto"),
            threshold=float(kwargs.get("threshold", DEFAULT_THRESHOLD)),
            nr=int(grid.shape[0]),
            nphi=int(grid.shape[1]),
            rule=str(grid.rule),
            rolling_axis=None if axis is None else tuple(axis),
            extra=tuple((k, v) for k, v in kwargs.items() if k not in known),
        )

    @property
    def units(self) -> Any:
        """The model's unit system among the reading options (it scales the time values), if set."""
        return dict(self.extra).get("units")

    def analyse_kwargs(self) -> dict:
        """The keyword arguments of :func:`fepost.analysis.analyse` (without ``step``)."""
        return {
            "friction": self.friction,
            "field": self.field,
            "displacement": self.displacement,
            "grid": PolarGrid.make(self.nr, self.nphi, self.rule),  # type: ignore[arg-type]
            "threshold": self.threshold,
            "rolling_axis": self.rolling_axis,
            **dict(self.extra),
        }

    def to_dict(self) -> dict:
        d = asdict(self)
        d["rolling_axis"] = None if self.rolling_axis is None else list(self.rolling_axis)
        d["extra"] = {
            k: v if isinstance(v, str | int | float | bool | None) else repr(v) for k, v in self.extra
        }
        return d

    def key_dict(self) -> dict:
        """:meth:`to_dict` for a row's identity: an extra option left at None (the analysis
        default) gives the same row as one not given, so a sweep started from Python and
        resumed from the command line reuses its rows."""
        d = self.to_dict()
        d["extra"] = {k: v for k, v in d["extra"].items() if v is not None and v is not False}
        return d


_NAMED = tuple(f.name for f in fields(RowOptions) if f.name != "extra")
