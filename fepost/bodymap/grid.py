"""Which polar grid carries a body map's load: small supports need a fine one.

fepost resamples a map on a polar grid about its centre of pressure, with the
radius of its farthest loaded point (`fepost.resample`), and warns when the
grid carries the FE load worse than `fepost.analysis.RESAMPLE_TOL` (1 %). A
support disc of radius a at distance R from the centre needs grid spacings
well below a there, in r (R/nr) and in φ (2πR/nphi): the default 64 × 128 grid
carries about 43 % of the load of the 2 mm legs of the planar-sliding block
(measured by `grid_load`), and on its closest legs (30_63.33_...) it carries
the load within 0.5 % but the pure-spin moment ∬ σ r dA 1.3 % off.
`recommended_grid` tries the grids of `LADDER` in turn and returns the first
that carries both the load and that moment within `GRID_TOL`: the map command
prints it and the sidecar records it, for ``--nr``/``--nphi``. With the default
options fepost needs neither: the analysis refines its grid where a map's pressure
is when the default grid misses it (`fepost.refine`, a tenth of these nodes on the
legs); the uniform grid recommended here is for a caller who wants one.
"""

from __future__ import annotations

import numpy as np

from ..locate import interpolate
from ..polar import PolarGrid
from ..refine import triangle_polar_moment
from .maps import BodyMap

#: Grids tried, coarsest first (nr, nphi): the library default, then finer.
LADDER = ((64, 128), (128, 256), (128, 512), (256, 1024), (512, 2048), (1024, 4096))
#: Largest |grid load / map load − 1| a recommended grid leaves (half the pipeline's 1 % warning).
GRID_TOL = 0.005


def grid_load(bmap: BodyMap, nr: int, nphi: int, rule: str = "gauss") -> tuple[float, float]:
    """The load and the polar moment ∬ σ r dA a polar grid of ``nr`` × ``nphi`` nodes carries,
    as fractions of the map's own (`map_moment`).

    The grid is centred on the map's centre of pressure with the radius of the farthest
    node of a loaded triangle, as fepost's pipeline places it. The polar moment is the
    pure-spin torque over f (M0 = f ∬ σ r dA).
    """
    grid = PolarGrid.make(nr, nphi, rule)  # type: ignore[arg-type]
    cx, cy = bmap.centre_of_pressure
    loaded = np.any(bmap.pressure[bmap.triangles] > 0, axis=1)
    nodes = np.unique(bmap.triangles[loaded])
    radius = float(np.max(np.hypot(bmap.xy[nodes, 0] - cx, bmap.xy[nodes, 1] - cy)))
    x, y = grid.xy(radius)
    query = np.column_stack([x.ravel() + cx, y.ravel() + cy])
    sigma, ok = interpolate(bmap.xy, bmap.triangles, bmap.pressure, "point", query)
    sigma = np.where(ok, sigma, 0.0).reshape(grid.shape)
    dA = grid.area_weights(radius)
    r = radius * grid.rho[:, None]
    return float(np.sum(sigma * dA) / bmap.load), float(np.sum(sigma * r * dA) / map_moment(bmap))


def map_moment(bmap: BodyMap) -> float:
    """∬ σ r dA over the map's triangles about its centre of pressure (N·m), by the degree-4
    rule of `fepost.refine.triangle_polar_moment`."""
    return triangle_polar_moment(bmap.xy, bmap.triangles, bmap.pressure, "point", bmap.centre_of_pressure)


def recommended_grid(bmap: BodyMap) -> dict:
    """The first grid of `LADDER` that carries the load and the polar moment within `GRID_TOL`.

    Returns
    -------
    dict
        ``nr``, ``nphi``, ``load_carried`` and ``moment_carried`` (fractions) of the recommended
        grid, and ``default_load_carried``, ``default_moment_carried`` (the default grid's);
        ``nr`` and ``nphi`` are those of the finest grid tried when none is within `GRID_TOL`.
    """
    out: dict = {}
    for nr, nphi in LADDER:
        carried, moment = grid_load(bmap, nr, nphi)
        out.setdefault("default_load_carried", carried)
        out.setdefault("default_moment_carried", moment)
        out.update(nr=nr, nphi=nphi, load_carried=carried, moment_carried=moment)
        if abs(carried - 1.0) <= GRID_TOL and abs(moment - 1.0) <= GRID_TOL:
            break
    out["tolerance"] = GRID_TOL
    return out
