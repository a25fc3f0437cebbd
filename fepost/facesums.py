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
meshes. Many chunks are shared by two threads (`fepost._chunks`);
every chunk's totals are kept and added in chunk order afterwards, so the
result does not depend on the number of threads, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._blas import one_blas_thread
from ._chunks import map_chunks, slices

#: Faces per chunk: the (9, chunk) corner matrix and its weighted copy, 576 kB together,
#: stay in a core's cache (16 384 faces, twice that, ran 2-3x slower on a 1 MB L2 cache).
CHUNK = 1 << 13

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
    """Exact load, load moments and area moments of the field over the faces.

    ``x``, ``y`` (n,) are the in-plane node coordinates (m), ``tri`` (m, 3) the
    faces, ``values`` the pressure per node or per face (``location``).
    """
    # gathers from contiguous columns are several times faster than from the columns of an (n, 2) array
    X = np.ascontiguousarray(x, dtype=float)
    Y = np.ascontiguousarray(y, dtype=float)
    V = np.ascontiguousarray(values, dtype=float)
    # one BLAS thread for the chunks' thin matrix products (more would only spin beside map_chunks')
    with one_blas_thread():
        parts = map_chunks(lambda sl: _chunk_sums(X, Y, V, tri, sl, location), slices(len(tri), CHUNK))
    # the chunks' totals in their order: the same sums on one thread or two
    gram = np.zeros((_ROWS, _ROWS))
    first = np.zeros(_ROWS)
    area2 = 0.0
    for g, f, a, _ in parts:
        gram += g
        first += f
        area2 += a
    e2 = max((e for *_, e in parts), default=0.0)
    return _integrals(gram, first, area2, location, float(np.sqrt(e2)))


#: Rows of a chunk's corner matrix: x (3 corners), y (3), then the corner pressures (3) or,
#: for face data, the face's pressure (1).
_ROWS = 9
_X, _Y, _P = slice(0, 3), slice(3, 6), slice(6, 9)


def _chunk_sums(
    X, Y, V, tri: np.ndarray, sl: slice, location: str
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The weighted Gram matrix G = Σ 2A c cᵀ of the faces ``tri[sl]``' corner vectors c (the
    rows of `_ROWS`), their first sums Σ 2A c, Σ 2A and their longest edge².

    Every integral of the module docstring is 2A times a quadratic or linear form in c, so
    sums of G's entries and of the first sums give them all (`_integrals`): one matrix
    product instead of a pass per integral.
    """
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
    x0, x1, x2 = c[_X]
    y0, y1, y2 = c[_Y]
    ax, ay = x1 - x0, y1 - y0
    bx, by = x2 - x0, y2 - y0
    a = ax * by
    a -= ay * bx
    np.abs(a, out=a)  # twice the area
    e = ax * ax
    e += ay * ay
    e2 = float(e.max())
    np.multiply(bx, bx, out=e)
    e += by * by
    e2 = max(e2, float(e.max()))
    bx -= ax
    by -= ay
    np.multiply(bx, bx, out=e)
    e += by * by
    e2 = max(e2, float(e.max()))
    w = c * a
    return w @ c.T, w.sum(axis=1), float(a.sum()), e2


def _integrals(gram: np.ndarray, first: np.ndarray, area2: float, location: str, max_edge: float) -> FaceSums:
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
    reach = []
    for sl in slices(len(tri), CHUNK):
        f = far[tri[sl]]
        hit = np.flatnonzero(f[:, 0] | f[:, 1] | f[:, 2])
        if hit.size:
            reach.append(hit + sl.start)
    faces = np.concatenate(reach)
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
