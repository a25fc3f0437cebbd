"""Curves drawn around a contact patch: circles, ellipses, the loaded region's edge.

Pure numpy (no plotting): the figures and the report's VTK files share them.
All coordinates are in the units given (the callers use m).
"""

from __future__ import annotations

import numpy as np

#: Points per circle or ellipse (closed: the last point repeats the first).
CURVE_POINTS = 241


def circle_points(radius: float, centre=(0.0, 0.0), n: int = CURVE_POINTS) -> np.ndarray:
    """(n, 2) points of a closed circle of ``radius`` about ``centre``."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    return np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])


def ellipse_points(axes, angle: float, centre=(0.0, 0.0), n: int = CURVE_POINTS) -> np.ndarray:
    """(n, 2) points of a closed ellipse of semi-axes ``axes`` = (major, minor), the
    major axis at ``angle`` (rad) from x, about ``centre``."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    a, b = axes
    c, s = np.cos(angle), np.sin(angle)
    u, v = a * np.cos(t), b * np.sin(t)
    return np.column_stack([centre[0] + c * u - s * v, centre[1] + s * u + c * v])


def boundary_edges(triangles) -> np.ndarray:
    """(k, 2) node pairs of the edges that belong to one triangle only: the region's boundary."""
    tri = np.asarray(triangles, np.int64)
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    return uniq[counts == 1]


def level_segments(xy, triangles, values, level: float) -> np.ndarray:
    """(k, 2, 2) segments of the contour ``values == level`` of a field linear on each triangle.

    ``values`` are nodal. Each triangle whose corners straddle ``level`` contributes
    the segment between the two edge points where the linear interpolant equals
    ``level`` (marching triangles). A node exactly at ``level`` counts as above.
    """
    xy = np.asarray(xy, float)
    tri = np.asarray(triangles, np.int64)
    v = np.asarray(values, float)[tri]  # (m, 3)
    above = v >= level
    n_above = above.sum(axis=1)
    cut = (n_above == 1) | (n_above == 2)
    tri, v, above = tri[cut], v[cut], above[cut]
    # the odd corner out: the one above when one is, the one below when two are
    lone = np.where(above.sum(axis=1) == 1, np.argmax(above, axis=1), np.argmin(above, axis=1))
    rows = np.arange(len(tri))
    k0 = lone
    k1 = (lone + 1) % 3
    k2 = (lone + 2) % 3

    def crossing(ka, kb):
        va, vb = v[rows, ka], v[rows, kb]
        t = (level - va) / (vb - va)
        pa, pb = xy[tri[rows, ka]], xy[tri[rows, kb]]
        return pa + t[:, None] * (pb - pa)

    return np.stack([crossing(k0, k1), crossing(k0, k2)], axis=1)
