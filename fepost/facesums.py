"""Exact integrals of an FE pressure field over its triangles, in one chunked pass.

For a field linear on each triangle (nodal data) or constant per triangle
(face data) the load, the first moments of load and the second moments of
area have closed forms per triangle; with corner coordinates x_k, y_k,
corner pressures s_k and area A:

    ∬ σ dA    = A Σs/3
    ∬ σ x dA  = A/12 (Σs Σx + Σ s_k x_k)
    ∬ x x dA  = A/12 (Σ x_k² + (Σx)²)        (and likewise xy, yy)

The pass runs over chunks of faces with the corners laid out as rows (x, y and
the pressure of the three corners): each of these integrals is 2A times a
quadratic or linear form in those nine numbers, so one weighted Gram matrix
per chunk (a matrix product) and its first sums give them all. The
temporaries stay in cache and their memory stays bounded on million-node
meshes. With many chunks, a second thread gathers the corners of the next block
of chunks while the caller's sums the last (`fepost._chunks.map_gathered`);
every chunk's totals are kept and added in chunk order afterwards, so the
result does not depend on the number of threads, bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ._blas import one_blas_thread
from ._chunks import map_chunks, map_gathered, slices

#: Faces per chunk: the (9, chunk) corner matrix and its weighted copy, 576 kB together,
#: stay in a core's cache (16 384 faces, twice that, ran 2-3x slower on a 1 MB L2 cache).
CHUNK = 1 << 13
#: Faces per block of gathered corners (`fepost._chunks.map_gathered`): a few chunks, so that
#: the gathering thread makes few, long numpy calls.
BLOCK = 4 * CHUNK

# 7-point degree-5 rule on the triangle (barycentric coordinates; weights sum to 1)
_A1, _B1 = 0.059715871789770, 0.470142064105115
_A2, _B2 = 0.797426985353087, 0.101286507323456
TRI_BARY = np.array(
    [
        [1 / 3, 1 / 3, 1 / 3],
        [_A1, _B1, _B1],
        [_B1, _A1, _B1],
        [_B1, _B1, _A1],
        [_A2, _B2, _B2],
        [_B2, _A2, _B2],
        [_B2, _B2, _A2],
    ]
)
TRI_W = np.array([0.225, *([0.132394152788506] * 3), *([0.125939180544827] * 3)])


#: Radius about the sums' origin, as a fraction of the nodes' extent, inside which a face's
#: term of the polar-moment enclosure takes its wide form (`PolarSums`).
POLAR_NEAR = 0.01


class PolarSums(NamedTuple):
    """What the face pass adds up for an enclosure of the polar moment ∬ σ r dA about a point
    near the coordinates' origin (`fepost.refine` decides from it whether a grid is refined).

    Per face, W its load and r̄ the distance of its centre of pressure from the origin:
    ``lo`` = Σ W r̄, ``load`` = Σ W and ``slack`` = Σ W min(2d, d²/r̄) (d the face's longest
    edge; 2d where r̄ < ``near``). ``origin``: where that origin lies in the coordinates of
    the caller (the patch frame moves it, `fepost.patch.build_patch`).
    """

    lo: float
    slack: float
    load: float
    near: float
    origin: tuple[float, float] = (0.0, 0.0)

    def bounds(self, centre: tuple[float, float]) -> tuple[float, float] | None:
        """(lo, hi) enclosing ∬ σ |x − ``centre``| dA, or None when ``centre`` is more than
        ``near``/2 from the origin.

        Each face's term moves by at most δ = |centre − origin| (the triangle inequality):
        Jensen's lower bound W r̄ (`fepost.refine.polar_moment_bounds`) by at most W δ; its
        upper slack, min(2d, d²/(2 r̄_c)) about the centre, is at most min(2d, d²/r̄)
        where r̄ ≥ ``near`` ≥ 2δ (then r̄_c ≥ r̄/2), and 2d is always an upper bound."""
        delta = math.hypot(centre[0] - self.origin[0], centre[1] - self.origin[1])
        if not delta <= 0.5 * self.near:
            return None
        return self.lo - delta * self.load, self.lo + delta * self.load + self.slack


@dataclass(frozen=True)
class FaceSums:
    """Totals over the faces (SI): load N, load moments, area and its moments."""

    N: float
    Mx: float
    My: float
    A: float
    Sx: float  # ∬ x dA
    Sy: float
    Sxx: float  # ∬ x² dA
    Syy: float
    Sxy: float
    max_edge: float  # longest face edge, m
    polar: PolarSums | None = None  # None: the pressure has negative values (no enclosure)

    @property
    def centre_of_pressure(self) -> np.ndarray:
        return np.array([self.Mx / self.N, self.My / self.N])

    @property
    def centroid(self) -> np.ndarray:
        return np.array([self.Sx / self.A, self.Sy / self.A])

    def covariance(self) -> np.ndarray:
        """Area covariance about the area centroid (m²)."""
        c = self.centroid
        raw = np.array([[self.Sxx, self.Sxy], [self.Sxy, self.Syy]]) / self.A
        return raw - np.outer(c, c)


def _rows(a: np.ndarray) -> np.ndarray:
    """Sum of the three corner rows of a (3, c) array."""
    s = a[0] + a[1]
    s += a[2]
    return s


def triangle_areas(xy: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Areas (m²) of the triangles ``tri`` with in-plane node coordinates ``xy``."""
    x, y = xy[:, 0][tri], xy[:, 1][tri]
    return 0.5 * np.abs((x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (y[:, 1] - y[:, 0]) * (x[:, 2] - x[:, 0]))


def face_sums(x: np.ndarray, y: np.ndarray, tri: np.ndarray, values: np.ndarray, location: str) -> FaceSums:
    """Exact load, load moments and area moments of the field over the faces, and the
    terms of an enclosure of its polar moment (`PolarSums`, for a non-negative field).

    ``x``, ``y`` (n,) are the in-plane node coordinates (m), ``tri`` (m, 3) the
    faces, ``values`` the pressure per node or per face (``location``).
    """
    # gathers from contiguous columns are several times faster than from the columns of an (n, 2) array
    X = np.ascontiguousarray(x, dtype=float)
    Y = np.ascontiguousarray(y, dtype=float)
    V = np.ascontiguousarray(values, dtype=float)
    near = POLAR_NEAR * max(float(np.ptp(X)), float(np.ptp(Y))) if X.size else 0.0

    def work(c: np.ndarray, block: slice) -> list:
        return [_chunk_sums(c[:, k : k + CHUNK], location, near) for k in range(0, c.shape[1], CHUNK)]

    # the blocks' corners gathered on a second thread while this one sums the block before
    # (`fepost._chunks.map_gathered`); one BLAS thread for the chunks' thin matrix products
    with one_blas_thread():
        blocks = map_gathered(
            lambda sl: _corners(X, Y, V, tri, sl, location),
            work,
            slices(len(tri), BLOCK),
            chunks=-(-len(tri) // CHUNK),
        )
    parts = [part for block in blocks for part in block]
    # the chunks' totals in their order: the same sums on one thread or two
    gram = np.zeros((_ROWS, _ROWS))
    first = np.zeros(_ROWS)
    area2 = 0.0
    polar = np.zeros(3)
    for g, f, a, _, p in parts:
        gram += g
        first += f
        area2 += a
        polar += p
    e2 = max((p[3] for p in parts), default=0.0)
    # Jensen's lower bound of the enclosure needs σ ≥ 0
    signed = V.size == 0 or float(V.min()) >= 0.0
    pol = PolarSums(float(polar[0]), float(polar[1]), float(polar[2]), near) if signed else None
    return _integrals(gram, first, area2, location, float(np.sqrt(e2)), pol)


#: Rows of a chunk's corner matrix: x (3 corners), y (3), then the corner pressures (3) or,
#: for face data, the face's pressure (1).
_ROWS = 9
_X, _Y, _P = slice(0, 3), slice(3, 6), slice(6, 9)


def _corners(X, Y, V, tri: np.ndarray, sl: slice, location: str) -> np.ndarray:
    """The corner vectors of the faces ``tri[sl]``, as the rows of `_ROWS` (one column a face)."""
    t = np.ascontiguousarray(tri[sl].T)
    c = np.empty((_ROWS, t.shape[1]))
    # the faces' indices are in range (the reader checked them): no bounds check per gather
    X.take(t, out=c[_X], mode="clip")
    Y.take(t, out=c[_Y], mode="clip")
    if location == "point":
        V.take(t, out=c[_P], mode="clip")
    else:
        c[6] = V[sl]
        c[7:] = 0.0
    return c


def _chunk_sums(
    c: np.ndarray, location: str, near: float
) -> tuple[np.ndarray, np.ndarray, float, float, np.ndarray]:
    """The weighted Gram matrix G = Σ 2A c cᵀ of a chunk's corner vectors c (the rows of
    `_ROWS`, one column a face: `_corners`), their first sums Σ 2A c, Σ 2A, their longest
    edge² and their terms of `PolarSums` (`_polar_terms`).

    Every integral of the module docstring is 2A times a quadratic or linear form in c, so
    sums of G's entries and of the first sums give them all (`_integrals`): one matrix
    product instead of a pass per integral.
    """
    x0, x1, x2 = c[_X]
    y0, y1, y2 = c[_Y]
    ax, ay = x1 - x0, y1 - y0
    bx, by = x2 - x0, y2 - y0
    a = ax * by
    a -= ay * bx
    np.abs(a, out=a)  # twice the area
    d2 = ax * ax  # the longest edge², face by face
    d2 += ay * ay
    e = bx * bx
    e += by * by
    np.maximum(d2, e, out=d2)
    bx -= ax
    by -= ay
    np.multiply(bx, bx, out=e)
    e += by * by
    np.maximum(d2, e, out=d2)
    w = c * a
    polar = _polar_terms(c, a, d2, location, near)
    return w @ c.T, w.sum(axis=1), float(a.sum()), float(d2.max()), polar


def _polar_terms(c: np.ndarray, a: np.ndarray, d2: np.ndarray, location: str, near: float) -> np.ndarray:
    """[Σ W r̄, Σ W min(2d, d²/r̄) (2d where r̄ < ``near``), Σ W] over a chunk's faces
    (`PolarSums`): W a face's load, r̄ the distance of its centre of pressure from the origin,
    d its longest edge (``d2``: d²), ``a`` twice its area, ``c`` its corner rows.

    With σ linear the centre of pressure is P / (4 Σσ), P = Σ_k (Σσ + σ_k) x_k, so W r̄ =
    2A |P| / 24; with σ constant it is the centroid Σ x_k / 3."""
    if location == "point":
        vs = _rows(c[_P])
        px = np.einsum("ij,ij->j", c[_P], c[_X])  # Σ σ_k x_k, then + Σσ Σx
        px += vs * _rows(c[_X])
        py = np.einsum("ij,ij->j", c[_P], c[_Y])
        py += vs * _rows(c[_Y])
        scale = 4.0 * vs  # r̄ = |P| / scale
        load = a * vs
        load /= 6.0
    else:
        px, py = _rows(c[_X]), _rows(c[_Y])
        scale = np.full(len(a), 3.0)
        load = a * c[6]
        load /= 2.0
    pn = px * px
    pn += py * py
    np.sqrt(pn, out=pn)
    lo = float(a @ pn) / 24.0 if location == "point" else float(load @ pn) / 3.0
    q = np.full(len(a), np.inf)
    # d²/r̄ = d² scale / |P| where r̄ ≥ near; elsewhere infinite, so fmin takes 2d
    far = pn >= near * scale
    far &= pn > 0.0
    np.divide(d2 * scale, pn, out=q, where=far)
    np.fmin(q, 2.0 * np.sqrt(d2), out=q)
    return np.array([lo, float(load @ q), float(load.sum())])


def _integrals(
    gram: np.ndarray, first: np.ndarray, area2: float, location: str, max_edge: float, polar: PolarSums | None
) -> FaceSums:
    """The `FaceSums` from the sums of `_chunk_sums` (``area2``: Σ 2A) and the longest edge.

    With 2A-weighted sums ⟨·⟩: ∬ x x dA = (⟨Σ x_k²⟩ + ⟨(Σx)²⟩)/24, the trace and the sum
    of a 3 × 3 block of G; ∬ x dA = ⟨Σx⟩/6; for nodal data ∬ σ dA = ⟨Σs⟩/6 and
    ∬ σ x dA = (⟨Σ s_k x_k⟩ + ⟨Σs Σx⟩)/24; for face data (σ constant) ∬ σ dA = ⟨σ⟩/2 and
    ∬ σ x dA = ⟨σ Σx⟩/6.
    """

    def quad(r: slice, s: slice) -> float:
        block = gram[r, s]
        return float(np.trace(block) + block.sum()) / 24.0

    if location == "point":
        N = float(first[_P].sum()) / 6.0
        Mx, My = quad(_P, _X), quad(_P, _Y)
    else:
        N = float(first[6]) / 2.0
        Mx, My = float(gram[6, _X].sum()) / 6.0, float(gram[6, _Y].sum()) / 6.0
    return FaceSums(
        N,
        Mx,
        My,
        area2 / 2.0,
        float(first[_X].sum()) / 6.0,
        float(first[_Y].sum()) / 6.0,
        quad(_X, _X),
        quad(_Y, _Y),
        quad(_X, _Y),
        max_edge,
        polar,
    )


def face_loads(xy: np.ndarray, tri: np.ndarray, values: np.ndarray, location: str) -> np.ndarray:
    """Exact load (N) of each face, an (m,) array."""
    a = triangle_areas(xy, tri)
    if location == "point":
        return a * _rows(np.asarray(values, float)[tri.T]) / 3.0
    return a * values


def load_outside(
    x: np.ndarray,
    y: np.ndarray,
    tri: np.ndarray,
    values: np.ndarray,
    location: str,
    radius: float,
    sums: FaceSums,
    r2: np.ndarray | None = None,
) -> float:
    """Share of the load outside the circle of ``radius`` about the origin of (``x``, ``y``).

    Faces wholly inside count nothing; the faces that reach past the circle
    (usually few) are integrated with a 7-point rule of degree 5, exact for the
    faces wholly outside. ``r2``: x² + y² per node, when the caller has it already.
    """
    total = sums.N
    if total <= 0:
        return 0.0
    X = np.asarray(x, dtype=float)
    Y = np.asarray(y, dtype=float)
    R2 = X * X + Y * Y if r2 is None else r2
    rad2 = radius * radius
    far = R2 > rad2  # a face reaches past the circle when a corner does (one byte per node: cached gathers)
    if not far.any():
        return 0.0

    def reaching(sl: slice) -> np.ndarray:
        f = far[tri[sl]]
        return np.flatnonzero(f[:, 0] | f[:, 1] | f[:, 2]) + sl.start

    faces = np.concatenate(map_chunks(reaching, slices(len(tri), 8 * CHUNK)))  # in face order
    out = 0.0
    for part in slices(len(faces), CHUNK):
        idx = faces[part]
        tc = tri[idx]
        xc, yc = X[tc], Y[tc]
        px = xc @ TRI_BARY.T
        py = yc @ TRI_BARY.T
        if location == "point":
            sig = values[tc] @ TRI_BARY.T
        else:
            sig = np.repeat(values[idx][:, None], len(TRI_W), axis=1)
        area = 0.5 * np.abs(
            (xc[:, 1] - xc[:, 0]) * (yc[:, 2] - yc[:, 0]) - (yc[:, 1] - yc[:, 0]) * (xc[:, 2] - xc[:, 0])
        )
        dl = sig * TRI_W[None, :] * area[:, None]
        out += float(dl[px * px + py * py > rad2].sum())
    return float(out / total)
