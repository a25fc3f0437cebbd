"""Planar triangle meshes of a body's contact: loaded discs and polygons, and their exact load.

A map's pressure is piecewise linear on its triangles (nodal values), as FE
contact output is. `linear_load` integrates such a field exactly: the load
(N) and its first moments (N·m), so that every map can be scaled to carry its
statics load to round-off and its centre of pressure checked.

* `disc_mesh` — a disc of radius a about a centre, meshed by rings and
  sectors with the same rotational symmetry (every ring has the same number of
  nodes, every quad is split the same way), so a radial profile's centre of
  pressure is the disc's centre to round-off.
* `polygon_mesh` — a simple polygon cut into triangles by ear clipping, each
  triangle then divided into k² similar triangles (nodes shared along the
  edges), k chosen for a target edge length.
"""

from __future__ import annotations

import numpy as np

from ..body import signed_area
from ..errors import DataError

#: Disc mesh: rings and sectors (the pressure of a small support is smooth; the load is
#: scaled to its exact value, so the mesh only shapes the profile).
DISC_RINGS = 8
DISC_SECTORS = 32


def triangle_areas(xy: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Signed areas (m²) of the triangles ``tri`` (m, 3) of the nodes ``xy`` (n, 2)."""
    a, b, c = xy[tri[:, 0]], xy[tri[:, 1]], xy[tri[:, 2]]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def linear_load(xy: np.ndarray, tri: np.ndarray, p: np.ndarray) -> tuple[float, np.ndarray]:
    """The load ∬ p dA (N) and its first moments ∬ p (x, y) dA (N·m) of a piecewise-linear field.

    Exact for nodal values ``p`` (Pa) interpolated linearly on each triangle: on a
    triangle of area A, ∬ p dA = A·mean(p) and ∬ p x dA = A/12·(Σp·Σx + Σ p_k x_k).
    """
    area = np.abs(triangle_areas(xy, tri))
    pk = p[tri]
    load = float(np.sum(area * pk.sum(axis=1)) / 3.0)
    first = np.empty(2)
    for d in range(2):
        xk = xy[tri, d]
        first[d] = float(np.sum(area * (pk.sum(axis=1) * xk.sum(axis=1) + (pk * xk).sum(axis=1))) / 12.0)
    return load, first


def disc_mesh(
    centre, radius: float, *, rings: int = DISC_RINGS, sectors: int = DISC_SECTORS
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes (n, 2), triangles (m, 3) and each node's radius / ``radius`` of a disc.

    The centre node, then ``rings`` rings of ``sectors`` nodes at radii
    ``radius``·i/``rings`` (the last on the rim); a fan about the centre, then each
    ring-to-ring quad split along the same diagonal.
    """
    cx, cy = float(centre[0]), float(centre[1])
    rho = np.repeat(np.arange(1, rings + 1) / rings, sectors)
    phi = np.tile(np.arange(sectors) * (2.0 * np.pi / sectors), rings)
    xy = np.vstack(
        [[cx, cy], np.column_stack([cx + radius * rho * np.cos(phi), cy + radius * rho * np.sin(phi)])]
    )
    j = np.arange(sectors)
    jn = (j + 1) % sectors
    fan = np.column_stack([np.zeros(sectors, int), 1 + j, 1 + jn])
    quads = []
    for i in range(rings - 1):
        a0, a1 = 1 + i * sectors + j, 1 + i * sectors + jn
        b0, b1 = a0 + sectors, a1 + sectors
        quads += [np.column_stack([a0, b0, b1]), np.column_stack([a0, b1, a1])]
    tri = np.vstack([fan, *quads])
    return xy, tri, np.concatenate([[0.0], rho])


def _ear_clip(poly: np.ndarray, where: str) -> np.ndarray:
    """Triangles (k, 3) of vertex indices covering a simple polygon, counter-clockwise."""
    idx = list(range(len(poly)))
    if signed_area(poly) < 0:
        idx.reverse()
    out = []
    guard = 0
    while len(idx) > 3:
        guard += 1
        if guard > 4 * len(poly) ** 2:
            raise DataError(f"{where}: key 'base': the polygon cannot be cut into triangles (is it simple?)")
        n = len(idx)
        for k in range(n):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % n]
            a, b, c = poly[i0], poly[i1], poly[i2]
            if _cross(a, b, c) <= 0:  # reflex or flat corner: no ear
                continue
            others = [poly[m] for m in idx if m not in (i0, i1, i2)]
            if any(_in_triangle(q, a, b, c) for q in others):
                continue
            out.append((i0, i1, i2))
            del idx[k]
            break
        else:
            raise DataError(f"{where}: key 'base': the polygon cannot be cut into triangles (is it simple?)")
    out.append((idx[0], idx[1], idx[2]))
    return np.array(out, dtype=np.int64)


def polygon_mesh(polygon, size: float, *, where: str = "base") -> tuple[np.ndarray, np.ndarray]:
    """Nodes (n, 2) and counter-clockwise triangles (m, 3) covering a simple polygon.

    Each ear-clipping triangle is divided into k² similar ones, k = ceil(longest
    edge / ``size``); nodes on shared edges are merged, so the mesh is conforming.
    """
    poly = np.asarray(polygon, float)
    pts, tris = [], []
    count = 0
    for t in _ear_clip(poly, where):
        a, b, c = poly[t[0]], poly[t[1]], poly[t[2]]
        longest = max(np.hypot(*(b - a)), np.hypot(*(c - b)), np.hypot(*(a - c)))
        k = max(1, int(np.ceil(longest / size)))
        ii, jj = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = (ii + jj) <= k
        ii, jj = ii[keep], jj[keep]
        local = np.full((k + 1, k + 1), -1, dtype=np.int64)
        local[ii, jj] = np.arange(ii.size)
        pts.append(a + np.outer(ii / k, b - a) + np.outer(jj / k, c - a))
        up = [(local[i, j], local[i + 1, j], local[i, j + 1]) for i in range(k) for j in range(k - i)]
        down = [
            (local[i + 1, j], local[i + 1, j + 1], local[i, j + 1])
            for i in range(k)
            for j in range(k - i - 1)
        ]
        tris.append(np.array(up + down, dtype=np.int64) + count)
        count += ii.size
    xy = np.vstack(pts)
    tri = np.vstack(tris)
    scale = float(np.max(np.ptp(poly, axis=0)))
    key = np.round(xy / (1e-9 * scale)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return xy[first], inverse.reshape(-1)[tri]


def _cross(o, a, b) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _in_triangle(q, a, b, c) -> bool:
    return _cross(a, b, q) >= 0 and _cross(b, c, q) >= 0 and _cross(c, a, q) >= 0
