"""Exact integrals of an FE pressure field over its triangles, in one chunked pass.

For a field linear on each triangle (nodal data) or constant per triangle
(face data) the load, the first moments of load and the second moments of
area have closed forms per triangle; with corner coordinates x_k, y_k,
corner pressures s_k and area A:

    ∬ σ dA    = A Σs/3
    ∬ σ x dA  = A/12 (Σs Σx + Σ s_k x_k)
    ∬ x x dA  = A/12 (Σ x_k² + (Σx)²)        (and likewise xy, yy)

The pass runs over chunks of faces on a thread pool (numpy releases the GIL),
which bounds the temporary memory and uses both cores of a small machine on
million-node meshes.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

#: Faces per chunk: a few (chunk, 3) float arrays of ~6 MB each.
CHUNK = 1 << 18

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
    """Totals over the faces (SI): load N, load moments, area and its moments.

    ``area`` and ``load`` are per face, for later passes.
    """

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
    area: np.ndarray
    load: np.ndarray

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


def _chunks(m: int):
    return [slice(i, min(i + CHUNK, m)) for i in range(0, m, CHUNK)]


def _map(func, m: int):
    chunks = _chunks(m)
    if len(chunks) == 1:
        return [func(chunks[0])]
    with ThreadPoolExecutor(max_workers=min(len(chunks), os.cpu_count() or 1)) as pool:
        return list(pool.map(func, chunks))


def _rowsum(a: np.ndarray) -> np.ndarray:
    return a[:, 0] + a[:, 1] + a[:, 2]


def triangle_areas(xy: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Areas (m²) of the triangles ``tri`` with in-plane node coordinates ``xy``."""
    x, y = xy[:, 0][tri], xy[:, 1][tri]
    return 0.5 * np.abs((x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (y[:, 1] - y[:, 0]) * (x[:, 2] - x[:, 0]))


def face_sums(xy: np.ndarray, tri: np.ndarray, values: np.ndarray, location: str) -> FaceSums:
    """Exact load, load moments and area moments of the field over the faces."""
    X = np.ascontiguousarray(xy[:, 0])
    Y = np.ascontiguousarray(xy[:, 1])
    m = len(tri)
    area = np.empty(m)
    load = np.empty(m)

    def work(sl: slice) -> np.ndarray:
        t = tri[sl]
        x, y = X[t], Y[t]
        dx1, dy1 = x[:, 1] - x[:, 0], y[:, 1] - y[:, 0]
        dx2, dy2 = x[:, 2] - x[:, 0], y[:, 2] - y[:, 0]
        a = 0.5 * np.abs(dx1 * dy2 - dy1 * dx2)
        e2 = max(
            float(np.max(dx1 * dx1 + dy1 * dy1)),
            float(np.max(dx2 * dx2 + dy2 * dy2)),
            float(np.max((dx2 - dx1) ** 2 + (dy2 - dy1) ** 2)),
        )
        sx, sy = _rowsum(x), _rowsum(y)
        if location == "point":
            s = values[t]
            ss = _rowsum(s)
            ld = a * ss / 3.0
            w = a / 12.0
            mx = w @ (ss * sx + _rowsum(s * x))
            my = w @ (ss * sy + _rowsum(s * y))
        else:
            ld = a * values[sl]
            mx = ld @ sx / 3.0
            my = ld @ sy / 3.0
        area[sl] = a
        load[sl] = ld
        w = a / 12.0
        return np.array(
            [
                ld.sum(),
                mx,
                my,
                a.sum(),
                a @ sx / 3.0,
                a @ sy / 3.0,
                w @ (_rowsum(x * x) + sx * sx),
                w @ (_rowsum(y * y) + sy * sy),
                w @ (_rowsum(x * y) + sx * sy),
                e2,
            ]
        )

    parts = np.array(_map(work, m))
    tot = parts[:, :-1].sum(axis=0)
    N, Mx, My, A, Sx, Sy, Sxx, Syy, Sxy = (float(v) for v in tot)
    max_edge = float(np.sqrt(parts[:, -1].max()))
    return FaceSums(N, Mx, My, A, Sx, Sy, Sxx, Syy, Sxy, max_edge, area, load)


def load_outside(
    xy: np.ndarray, tri: np.ndarray, values: np.ndarray, location: str, radius: float, sums: FaceSums
) -> float:
    """Share of the load outside the circle of ``radius`` about the origin of ``xy``.

    Faces wholly inside count nothing, faces wholly outside their exact load;
    faces that straddle the circle are integrated with a 7-point rule.
    """
    total = sums.N
    if total <= 0:
        return 0.0
    X = np.ascontiguousarray(xy[:, 0])
    Y = np.ascontiguousarray(xy[:, 1])
    R2 = np.ascontiguousarray(X * X + Y * Y)
    rad2 = radius * radius

    def work(sl: slice) -> float:
        t = tri[sl]
        r2 = R2[t]
        lo = np.minimum(np.minimum(r2[:, 0], r2[:, 1]), r2[:, 2])
        hi = np.maximum(np.maximum(r2[:, 0], r2[:, 1]), r2[:, 2])
        out_all = lo > rad2
        cut = (hi > rad2) & ~out_all
        share = sums.load[sl][out_all].sum()
        if cut.any():
            tc = t[cut]
            px = X[tc] @ TRI_BARY.T
            py = Y[tc] @ TRI_BARY.T
            if location == "point":
                sig = values[tc] @ TRI_BARY.T
            else:
                sig = np.repeat(values[sl][cut][:, None], len(TRI_W), axis=1)
            dl = sig * TRI_W[None, :] * sums.area[sl][cut][:, None]
            share += dl[px * px + py * py > rad2].sum()
        return float(share)

    return float(sum(_map(work, len(tri))) / total)
