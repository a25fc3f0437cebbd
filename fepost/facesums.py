"""Exact integrals of an FE pressure field over its triangles, in one chunked pass.

For a field linear on each triangle (nodal data) or constant per triangle
(face data) the load, the first moments of load and the second moments of
area have closed forms per triangle; with corner coordinates x_k, y_k,
corner pressures s_k and area A:

    ∬ σ dA    = A Σs/3
    ∬ σ x dA  = A/12 (Σs Σx + Σ s_k x_k)
    ∬ x x dA  = A/12 (Σ x_k² + (Σx)²)        (and likewise xy, yy)

The pass runs over chunks of faces with the corners laid out as (3, chunk)
rows: the temporaries stay in cache and their memory stays bounded on
million-node meshes. Many chunks are shared by two threads (`fepost._chunks`);
every chunk's totals are kept and added in chunk order afterwards, so the
result does not depend on the number of threads, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._chunks import map_chunks, slices

#: Faces per chunk: (3, chunk) float temporaries of 384 kB each (they stay in cache).
CHUNK = 1 << 14

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


def _corner_products(u: np.ndarray, v: np.ndarray, su: np.ndarray, sv: np.ndarray) -> np.ndarray:
    """Σ_k u_k v_k + Σu Σv per face, from (3, c) corner rows ``u``, ``v`` and their sums.

    The corner sum of every closed form in the module docstring that has the 1/12:
    Σs Σx + Σ s_k x_k, Σ x_k² + (Σx)², ... In place on one (c,) temporary.
    """
    q = u[0] * v[0]
    q += u[1] * v[1]
    q += u[2] * v[2]
    q += su * sv
    return q


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
    # per chunk: 2A·(3σ̄, 12σ̄x̄ terms …) and the longest edge²; the constant factors are applied once
    parts = map_chunks(lambda sl: _chunk_sums(X, Y, V, tri, sl, location), slices(len(tri), CHUNK))
    tot = np.zeros(9)
    for part in parts:  # the chunks' totals in their order: the same sums on one thread or two
        tot += part[:9]
    e2 = max((float(part[9]) for part in parts), default=0.0)
    # 2A → A, with the 1/3, 1/12 of the closed forms
    N, Mx, My, A, Sx, Sy, Sxx, Syy, Sxy = (float(v) for v in tot * _SCALE)
    return FaceSums(N, Mx, My, A, Sx, Sy, Sxx, Syy, Sxy, float(np.sqrt(e2)))


def _chunk_sums(X, Y, V, tri: np.ndarray, sl: slice, location: str) -> np.ndarray:
    """The running totals' terms of the faces ``tri[sl]`` and their longest edge², a (10,) array."""
    out = np.empty(10)
    t = np.ascontiguousarray(tri[sl].T)
    px, py = X.take(t), Y.take(t)  # corner coordinates, (3, chunk)
    x0, x1, x2 = px
    y0, y1, y2 = py
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
    out[9] = max(e2, float(e.max()))
    sx, sy = _rows(px), _rows(py)
    if location == "point":
        ps = V.take(t)  # corner pressures, (3, chunk)
        ss = _rows(ps)
        out[0] = _dot(a, ss)
        out[1] = _dot(a, _corner_products(ps, px, ss, sx))
        out[2] = _dot(a, _corner_products(ps, py, ss, sy))
    else:
        ld = a * V[sl]
        out[0] = 3.0 * float(ld.sum())
        out[1] = 4.0 * _dot(ld, sx)
        out[2] = 4.0 * _dot(ld, sy)
    out[3] = float(a.sum())
    out[4] = _dot(a, sx)
    out[5] = _dot(a, sy)
    out[6] = _dot(a, _corner_products(px, px, sx, sx))
    out[7] = _dot(a, _corner_products(py, py, sy, sy))
    out[8] = _dot(a, _corner_products(px, py, sx, sy))
    return out


#: From the running totals (2A times the corner sums) to the integrals.
_SCALE = np.array([1 / 6, 1 / 24, 1 / 24, 1 / 2, 1 / 6, 1 / 6, 1 / 24, 1 / 24, 1 / 24])


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """Σ a·b without BLAS (whose threads only slow a chunk-long dot product)."""
    return float(np.einsum("i,i->", a, b))


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
