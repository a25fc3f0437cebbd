"""The simulation that diagnose judges: FE pressure maps on a modest friction grid.

`Simulation` holds the static map (and optionally the rolling map) resampled
onto `edge_grid` ``(nr, nphi)`` (default
`FIT_NR` × `FIT_NPHI`), the nominal friction coefficient and the
scales that make the channels dimensionless. Per test point the pressure map is

* ``roll = 0``: the static map;
* ``roll = +1``: the rolling map as given;
* ``roll = −1``: the rolling map mirrored x → −x about the patch origin (rolling
  the other way round).

When a row carries a load ``N``, the whole map's pressure is scaled by
λ = N_row / N_map (same patch shape: a documented simplification; a real
patch grows with load).

Fit grid accuracy (measured by ``benchmarks/bench_diagnose.py`` over the 400-point
rig programme): against a 128 × 256 grid the 24 × 48 resultants differ by at most
1.3e-3 f·N (Hertz), 2.1e-3 f·N (tire-like map), 7e-5 f·N (paraboloid) in force,
and 1.9e-3, 3.1e-3, 7e-5 f·N·R in torque; the largest errors sit at points whose
instantaneous centre lies on the patch edge (ε = 1). Rig noise of 1–2 % of each
channel's range (≈ 3e-2 f·N) is 10–15 times larger.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis import analyse
from ..coefficients import Coefficients, coefficients_from_moments
from ..errors import ArgumentError
from ..friction.quadrature import PressureQuadrature, edge_grid
from ..friction_coefficient import DEFAULT_FRICTION, check_friction
from ..moments import Moments, moments
from ..polar import PolarGrid, PolarMap

#: Default fit grid (radial × angular nodes of the sine-substituted polar rule).
FIT_NR = 24
FIT_NPHI = 48


#: A map that the fit grid misses by more than this (its load or its polar moment ∬ σ r dA,
#: relative) stays on its own grid: the small far-apart discs of a block's legs (`fepost.bodymap`)
#: fall between the fit grid's nodes (it keeps 16-54 % of their load, one loaded node), while
#: the sample tire maps lose at most 1.3 % on it.
FIT_GRID_TOL = 0.05


def on_fit_grid(pmap: PolarMap, grid: PolarGrid, *, own: Moments | None = None) -> PolarMap:
    """``pmap`` regridded on the fit ``grid``, or ``pmap`` itself where the fit grid misses its
    load or polar moment by more than `FIT_GRID_TOL` (``own``: ``pmap``'s moments, when known)."""
    fit = regrid(pmap, grid)
    a, b = own if own is not None else moments(pmap), moments(fit)
    if not (a.N > 0 and a.spin > 0):
        return fit
    return pmap if max(abs(b.N / a.N - 1.0), abs(b.spin / a.spin - 1.0)) > FIT_GRID_TOL else fit


def regrid(pmap: PolarMap, grid: PolarGrid, *, mirror: bool = False) -> PolarMap:
    """``pmap`` sampled on ``grid`` (same radius), optionally mirrored x → −x.

    Mirroring is about the patch origin: the centre (cx, cy) becomes (−cx, cy).
    Values come from the map's own bilinear (ρ, φ) interpolation.
    """
    x, y = grid.xy(pmap.radius)
    sign = -1.0 if mirror else 1.0
    sigma = pmap.interpolate(sign * x, y)
    cx, cy = pmap.centre
    return PolarMap(grid=grid, radius=pmap.radius, sigma=sigma, centre=(sign * cx, cy), source=pmap.source)


@dataclass(frozen=True)
class Simulation:
    """Static (and rolling) pressure maps on the fit grid, with the nominal friction.

    ``static``/``rolling``: maps on the fit grid (Pa, m); ``friction``: nominal f;
    ``coefficients``: the paper's coefficients of the input maps (for the closed
    forms, docs/theory.md); ``load`` N (N) and ``radius`` R (m) of the static map.
    """

    static: PolarMap
    rolling: PolarMap | None
    friction: float
    coefficients: Coefficients
    source: str = ""
    rolling_source: str = ""
    quads: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        check_friction(self.friction)
        quads = {0: PressureQuadrature.from_polar(self.static)}
        if self.rolling is not None:
            quads[1] = PressureQuadrature.from_polar(self.rolling)
            mirrored = regrid(self.rolling, self.rolling.grid, mirror=True)
            quads[-1] = PressureQuadrature.from_polar(mirrored)
        object.__setattr__(self, "quads", quads)
        if not quads[0].load > 0:
            raise ArgumentError("the static map carries no load")

    @property
    def load(self) -> float:
        """N of the static map (N)."""
        return self.quads[0].load

    @property
    def radius(self) -> float:
        """R (m): the static map's radius (r_max about the static centre of pressure)."""
        return self.static.radius

    @property
    def pressure_ref(self) -> float:
        """σ_ref (Pa) of the pressure-dependent law: the static map's mean pressure N/area."""
        return self.quads[0].mean_pressure

    def scales(self) -> np.ndarray:
        """Channel scales (f·N, f·N, f·N·R): N, N, N·m, with the nominal f and static N, R."""
        fn = self.friction * self.load
        return np.array([fn, fn, fn * self.radius])

    def to_dict(self) -> dict:
        return {
            "source": self.source,
            "rolling_source": self.rolling_source or None,
            "friction": self.friction,
            "N": self.load,
            "R": self.radius,
            "R_definition": "radius of the static polar map (r_max about the static centre of pressure)",
            "pressure_ref": self.pressure_ref,
            "grid": {
                "rule": self.static.grid.rule,
                "nr": self.static.grid.shape[0],
                "nphi": self.static.grid.shape[1],
            },
        }


def simulation_from_maps(
    static: PolarMap,
    rolling: PolarMap | None = None,
    *,
    friction: float = DEFAULT_FRICTION,
    nr: int = FIT_NR,
    nphi: int = FIT_NPHI,
    source: str = "",
    rolling_source: str = "",
) -> Simulation:
    """A `Simulation` from polar maps in the patch frame (centre = static centre of pressure)."""
    if not isinstance(static, PolarMap):
        raise ArgumentError(f"static must be a PolarMap, got {type(static).__name__}")
    if rolling is not None and not isinstance(rolling, PolarMap):
        raise ArgumentError(f"rolling must be a PolarMap or None, got {type(rolling).__name__}")
    if int(nphi) % 2:
        raise ArgumentError(f"nphi must be even, got {nphi!r}")
    grid = edge_grid(nr, nphi)
    s_mom = moments(static)
    r_mom = None if rolling is None else moments(rolling)
    coef = coefficients_from_moments(s_mom, r_mom, friction=friction)
    return Simulation(
        static=on_fit_grid(static, grid, own=s_mom),
        rolling=None if rolling is None else on_fit_grid(rolling, grid, own=r_mom),
        friction=float(friction),
        coefficients=coef,
        source=source or static.source,
        rolling_source=rolling_source or ("" if rolling is None else rolling.source),
    )


def load_simulation(
    simulation,
    rolling=None,
    *,
    friction: float = DEFAULT_FRICTION,
    nr: int = FIT_NR,
    nphi: int = FIT_NPHI,
    **analyse_kwargs,
) -> Simulation:
    """A `Simulation` from FE exports (paths or ContactFields) or PolarMaps.

    ``analyse_kwargs`` go to `fepost.analysis.analyse` (field, step, grid, ...).
    """
    if isinstance(simulation, Simulation):
        return simulation
    if isinstance(simulation, PolarMap):
        return simulation_from_maps(simulation, rolling, friction=friction, nr=nr, nphi=nphi)
    result = analyse(simulation, rolling, friction=friction, **analyse_kwargs)
    return simulation_from_maps(
        result.static_map,
        result.rolling_map,
        friction=friction,
        nr=nr,
        nphi=nphi,
        source=str(simulation),
        rolling_source="" if rolling is None else str(rolling),
    )
