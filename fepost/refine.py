"""A polar grid refined where a patch's pressure is, for maps the default grid misses.

The default polar grid (`fepost.polar.DEFAULT_NR` × `fepost.polar.DEFAULT_NPHI`) suits
a tire's patch, which fills most of its disc of radius R. A map whose pressure sits in
a few small regions far apart (the legs of a block, `fepost.bodymap`: 2 mm discs up to
130 mm apart) falls between its nodes: the grid carries 43 % of the load of the
planar-sliding block's legs, and on its closest legs the load within 0.5 % but the
pure-spin moment ∬ σ r dA 1.2 % off. Refining the whole grid (256 × 1024, 33 times the
nodes) costs every later integral as much.

`refined_map` refines where the pressure is instead:

* **radially**, a composite Gauss–Legendre rule: the rings that hold loaded faces
  (`loaded_segments`, the union of each loaded triangle's extent in r about the
  centre) get `SEGMENT_NODES` nodes per segment, or more in proportion to its length,
  doubled at every level; the empty gaps between them (zero pressure) a few
  (`GAP_NODES`), enough for the smooth integrands the exact friction integrals
  subtract over the whole disc (`fepost.friction.exact`);
* **angularly**, the periodic trapezoid stays uniform (the friction integrals turn
  the kinematics along it, `fepost.friction.turns`, and `fepost.polar.PolarMap.interpolate`
  assumes it), its count doubled at every level.

Levels are tried in turn until the grid carries the FE load (N_fe) and the polar
moment ∬ σ r dA of the FE faces (`polar_moment`) both within `REFINE_TOL`, up to
`MAX_NODES` nodes. The refinement starts only where the default grid misses either by
more than `TRIGGER_TOL` (the pipeline's own 1 % warning), so a map the default grid
carries keeps its numbers bit for bit (the sample tire maps: within 0.12 %).

Whether it starts is decided first from an enclosure of the FE polar moment. The patch
step's face pass already sums one (`fepost.facesums.PolarSums`, about the fitted plane's
centre, widened by the distance to the centre of pressure): on a fine map it decides
with no pass of its own (on a 2.2 M-triangle map 0.035 s of CPU added to the face pass,
against 0.13 s for a separate pass). Where it is missing or too wide, the enclosure of a
separate pass (`polar_moment_bounds`: one distance per face instead of the six of the
degree-4 rule) decides; only where that straddles the trigger too, or the refinement
runs, is the degree-4 value computed. On the
planar-sliding legs the refined grids are 27 × 256 (30_63.33_...) to 45 × 960 nodes
(10_90_...), 3-6 times the default's 8192 and a tenth of the uniform 256 × 1024 that carries
them as well; they carry the load and the polar moment within 0.17 %.
"""

from __future__ import annotations

import math

import numpy as np

from ._arrays import frozen
from ._chunks import map_chunks, slices
from .moments import Moments, moments
from .patch import Patch
from .polar import DEFAULT_NPHI, DEFAULT_NR, PolarGrid, PolarMap
from .resample import resample

#: A map the default grid carries within this (load and polar moment) is left as it is.
TRIGGER_TOL = 0.01
#: The refined grid carries the load and the polar moment within this.
REFINE_TOL = 0.002
#: Gauss nodes of a loaded radial segment at level 0 (more for a long one: its share of `DEFAULT_NR`).
SEGMENT_NODES = 8
#: Gauss nodes of an empty radial gap (every level).
GAP_NODES = 4
#: Angle counts tried, one per level: the default's, then multiples of 960 = lcm(32, 40, 48, 64),
#: the direction counts the generalised model's fits and checks turn by (`fepost.friction.turns`:
#: a count they divide keeps their sums turned, 1/T of the work).
ANGLES = (DEFAULT_NPHI, 2 * DEFAULT_NPHI, 960, 1920, 3840)
#: Largest refined grid, nodes.
MAX_NODES = 1 << 19
#: Grid rule name of a refined grid (``Analysis.to_dict()["grid"]["rule"]``).
RULE = "refined"

#: Barycentric points and weights of a degree-4 rule on a triangle (Dunavant, 6 points).
_B = np.array([[0.108103018168070, 0.445948490915965], [0.816847572980459, 0.091576213509771]])
_WB = np.array([0.223381589678011, 0.109951743655322])
#: The rule as (6, 3) barycentric coordinates and (6,) weights.
_BARY = np.array([p for u, w in _B for p in ((u, w, w), (w, u, w), (w, w, u))])
_WEIGHTS = np.repeat(_WB, 3)
#: Triangles per chunk of `polar_moment` (its arrays stay in the cache).
_CHUNK = 1 << 15


def polar_moment(patch: Patch, centre: tuple[float, float] = (0.0, 0.0)) -> float:
    """∬ σ r dA (N·m) over the patch's triangles, r the distance from ``centre``
    (`triangle_polar_moment` of its faces).

    It runs on every analysis at the default grid."""
    return triangle_polar_moment(patch.xy, patch.triangles, patch.values, patch.location, centre)


def triangle_polar_moment(
    xy: np.ndarray,
    tri: np.ndarray,
    values: np.ndarray,
    location: str,
    centre: tuple[float, float] = (0.0, 0.0),
) -> float:
    """∬ σ r dA (N·m) over the triangles ``tri`` of the nodes ``xy``, r the distance from
    ``centre``, by a degree-4 rule on each triangle (``values`` at the nodes, linear on a
    triangle, for ``location`` ``"point"``; one per triangle otherwise).

    It works in chunks of `_CHUNK` triangles, gathering each chunk's corners and values once
    (a gather per rule point, and small matrix products, cost 0.8-1.2 s of CPU on a
    2.2 M-triangle map; this 0.25 s)."""
    xy = np.ascontiguousarray(xy - np.asarray(centre, float))
    v = np.asarray(values, float)
    pointwise = location == "point"
    total = 0.0
    for start in range(0, len(tri), _CHUNK):
        t = tri[start : start + _CHUNK]
        ax, ay = xy[t[:, 0], 0], xy[t[:, 0], 1]
        bx, by = xy[t[:, 1], 0] - ax, xy[t[:, 1], 1] - ay
        cx, cy = xy[t[:, 2], 0] - ax, xy[t[:, 2], 1] - ay
        area = 0.5 * np.abs(bx * cy - by * cx)
        if pointwise:
            va, vb, vc = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        else:
            va = vb = vc = v[start : start + _CHUNK]
        acc = np.zeros_like(ax)
        for (l1, l2, l3), w in zip(_BARY, _WEIGHTS, strict=True):
            acc += (
                w * (l1 * va + l2 * vb + l3 * vc) * np.hypot(ax + l2 * bx + l3 * cx, ay + l2 * by + l3 * cy)
            )
        total += float(area @ acc)
    return total


def polar_moment_bounds(
    xy: np.ndarray,
    tri: np.ndarray,
    values: np.ndarray,
    location: str,
    centre: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, float]:
    """Bounds (lo, hi) on ∬ σ r dA (N·m) over the triangles ``tri`` of the nodes ``xy``,
    r the distance from ``centre``, for σ ≥ 0 linear on each triangle (``location``
    ``"point"``) or constant on it.

    On a triangle of load W = ∫σ dA and centre of pressure x̄ (r̄ = |x̄|), r is convex and
    its tangent plane at x̄ integrates to W r̄ against σ ≥ 0, so W r̄ ≤ ∫σ r dA (Jensen).
    Above, r(x) − r̄ − ∇r(x̄)·(x − x̄) ≤ min(2δ, δ²/(2r̄)) with δ = |x − x̄| ≤ d, the
    triangle's longest edge (the triangle inequality; √(r̄² + u) ≤ r̄ + u/(2r̄)). Hence
    Σ W r̄ ≤ ∬ σ r dA ≤ Σ W (r̄ + min(2d, d²/(2r̄))): the enclosure narrows as (d/r)²,
    about 1e-5 of the moment on a million-node tire map, a percent on a coarse one."""
    xyc = xy - np.asarray(centre, float)
    X = np.ascontiguousarray(xyc[:, 0])
    Y = np.ascontiguousarray(xyc[:, 1])
    V = np.ascontiguousarray(values, dtype=float)
    pointwise = location == "point"
    if len(V) and float(V.min()) < 0.0:  # Jensen's bound needs σ ≥ 0: no enclosure
        return 0.0, math.inf

    def chunk(sl: slice) -> tuple[float, float]:
        t = np.ascontiguousarray(tri[sl].T)  # (3, n): gathers from contiguous rows
        x, y = X.take(t, mode="clip"), Y.take(t, mode="clip")  # indices checked by the reader
        ex, ey = x[1] - x[0], y[1] - y[0]
        fx, fy = x[2] - x[0], y[2] - y[0]
        area = 0.5 * np.abs(ex * fy - ey * fx)
        if pointwise:
            v = V.take(t, mode="clip")
            vs = v.sum(axis=0)
            # the centre of pressure of σ linear: ∫σx dA / ∫σ dA = (Σσ Σx + Σ σᵢxᵢ) / (4 Σσ)
            mx = np.zeros_like(vs)
            my = np.zeros_like(vs)
            loaded = vs > 0
            np.divide(vs * x.sum(axis=0) + np.einsum("ij,ij->j", v, x), 4.0 * vs, out=mx, where=loaded)
            np.divide(vs * y.sum(axis=0) + np.einsum("ij,ij->j", v, y), 4.0 * vs, out=my, where=loaded)
            w = area * vs / 3.0
        else:
            mx, my = x.mean(axis=0), y.mean(axis=0)
            w = area * V[sl]
        gx, gy = x[2] - x[1], y[2] - y[1]
        d2 = np.maximum(np.maximum(ex * ex + ey * ey, fx * fx + fy * fy), gx * gx + gy * gy)
        rbar = np.sqrt(mx * mx + my * my)  # not hypot: 6x slower, and lengths here are far from overflow
        with np.errstate(divide="ignore", invalid="ignore"):
            slack = np.fmin(2.0 * np.sqrt(d2), d2 / (2.0 * rbar))  # fmin: 0/0 of a point face gives 0
        lo = float(w @ rbar)
        return lo, lo + float(w @ slack)

    parts = map_chunks(chunk, slices(len(tri), _CHUNK))
    return sum(p[0] for p in parts), sum(p[1] for p in parts)


def _segment_distance(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Distance from the origin to the segments p–q (rows)."""
    d = q - p
    dd = np.einsum("ij,ij->i", d, d)
    t = np.clip(-np.einsum("ij,ij->i", p, d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    return np.hypot(p[:, 0] + t * d[:, 0], p[:, 1] + t * d[:, 1])


def loaded_segments(patch: Patch, centre: tuple[float, float], radius: float) -> list[tuple[float, float]]:
    """The union of the loaded triangles' extents in ρ = r / ``radius`` about ``centre``:
    sorted, disjoint intervals within [0, 1]."""
    xy = patch.xy - np.asarray(centre, float)
    tri = patch.triangles
    vals = patch.values[tri] if patch.location == "point" else patch.values[:, None]
    tri = tri[np.any(vals > 0, axis=1)]
    if not len(tri):
        return []
    a, b, c = xy[tri[:, 0]], xy[tri[:, 1]], xy[tri[:, 2]]
    hi = np.maximum.reduce([np.hypot(*a.T), np.hypot(*b.T), np.hypot(*c.T)])
    lo = np.minimum.reduce([_segment_distance(a, b), _segment_distance(b, c), _segment_distance(c, a)])
    # the origin inside a triangle: its extent starts at 0
    d1 = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    d2 = b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0]
    d3 = c[:, 0] * a[:, 1] - c[:, 1] * a[:, 0]
    inside = ((d1 >= 0) & (d2 >= 0) & (d3 >= 0)) | ((d1 <= 0) & (d2 <= 0) & (d3 <= 0))
    lo = np.where(inside, 0.0, lo)
    order = np.argsort(lo)
    out: list[list[float]] = []
    for s, e in zip(np.clip(lo[order] / radius, 0, 1), np.clip(hi[order] / radius, 0, 1), strict=True):
        if out and s <= out[-1][1]:
            out[-1][1] = max(out[-1][1], float(e))
        else:
            out.append([float(s), float(e)])
    return [(s, e) for s, e in out if e > s]


def _gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return a + (b - a) * 0.5 * (x + 1.0), (b - a) * 0.5 * w


def refined_grid(segments: list[tuple[float, float]], level: int) -> PolarGrid:
    """The composite radial rule over [0, 1] with the loaded ``segments`` refined at ``level``
    and the uniform angle count ``ANGLES[level]`` (module docstring): a segment [s, e] gets
    Gauss nodes about as far apart in r as the angles are on its outer ring (2π e / n_φ),
    at least `SEGMENT_NODES` and its share of `DEFAULT_NR`."""
    nphi = ANGLES[level]
    parts = []
    start = 0.0
    for s, e in segments:
        if s > start:
            parts.append(_gauss(start, s, GAP_NODES))
        n = max(SEGMENT_NODES, math.ceil((e - s) * DEFAULT_NR), math.ceil((e - s) * nphi / (2.0 * np.pi * e)))
        parts.append(_gauss(s, e, n))
        start = e
    if start < 1.0:
        parts.append(_gauss(start, 1.0, GAP_NODES))
    phi = np.arange(nphi) * (2.0 * np.pi / nphi)
    return PolarGrid(
        frozen(np.concatenate([p[0] for p in parts])),
        frozen(np.concatenate([p[1] for p in parts])),
        frozen(phi),
        frozen(np.full(nphi, 2.0 * np.pi / nphi)),
        RULE,
    )


def carried_within(patch: Patch, mom: Moments, bounds: tuple[float, float]) -> float:
    """The largest `carried` error over every polar moment within ``bounds`` (lo, hi)
    (infinite without a positive lower bound)."""
    if not bounds[0] > 0.0:
        return math.inf
    return max(carried(patch, mom, bounds[0]), carried(patch, mom, bounds[1]))


def carried(patch: Patch, mom: Moments, moment: float) -> float:
    """The larger of |N / N_fe − 1| and |∬ σ r dA (grid) / ``moment`` − 1|."""
    load = abs(mom.N / patch.N_fe - 1.0) if patch.N_fe else 0.0
    spin = abs(mom.spin / moment - 1.0) if moment else 0.0
    return max(load, spin)


def refined_map(patch: Patch, pmap: PolarMap, mom: Moments) -> tuple[PolarMap, Moments]:
    """``pmap`` (the patch resampled on the default grid) and its moments, or, when they miss
    the FE load or polar moment by more than `TRIGGER_TOL`, the first refined grid's that
    carries both within `REFINE_TOL` (the most accurate one tried when none does)."""
    centre, radius = pmap.centre, pmap.radius
    # |G/M − 1| is largest at an end of the enclosure of M: within the trigger there, it is for M.
    # The patch's own enclosure (summed in its face pass) first; where it is missing or too
    # wide to decide, the narrower one of a pass of its own
    bounds = None if patch.polar is None else patch.polar.bounds(centre)
    if bounds is not None and carried_within(patch, mom, bounds) <= TRIGGER_TOL:
        return pmap, mom
    bounds = polar_moment_bounds(patch.xy, patch.triangles, patch.values, patch.location, centre)
    if carried_within(patch, mom, bounds) <= TRIGGER_TOL:
        return pmap, mom
    moment = polar_moment(patch, centre)
    err = carried(patch, mom, moment)
    if err <= TRIGGER_TOL:
        return pmap, mom
    segments = loaded_segments(patch, centre, radius)
    best = (err, pmap, mom)
    for level in range(len(ANGLES)):
        grid = refined_grid(segments, level)
        if grid.rho.size * grid.phi.size > MAX_NODES:
            break
        m = resample(patch, grid, radius=radius, centre=centre)
        mo = moments(m)
        e = carried(patch, mo, moment)
        if e < best[0]:
            best = (e, m, mo)
        if e <= REFINE_TOL:
            break
    return best[1], best[2]
