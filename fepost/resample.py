"""Resample a patch's FE pressure onto a polar grid by FE interpolation.

The FE field is interpolated with its own elements: linear on each triangle
for nodal data, constant per face for face data (VTK's probe filter through
pyvista's ``sample``). Grid nodes that fall on no loaded face (outside the
patch, in a groove, in a hole of the mesh) get zero pressure; the valid-point
mask is kept on the map. Whether the resampled map still carries the FE load
is checked by :func:`fepost.analysis.analyse` (N against N_fe).
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

from .patch import Patch
from .polar import PolarGrid, PolarMap


def _surface(patch: Patch) -> pv.PolyData:
    pts = np.column_stack([patch.xy, np.zeros(len(patch.xy))])
    mesh = pv.PolyData.from_regular_faces(pts, patch.triangles)
    if patch.location == "point":
        mesh.point_data["p"] = patch.values
    else:
        mesh.cell_data["p"] = patch.values
    return mesh


def resample(
    patch: Patch,
    grid: PolarGrid | None = None,
    radius: float | None = None,
    centre: tuple[float, float] = (0.0, 0.0),
) -> PolarMap:
    """Sample ``patch``'s pressure on ``grid`` about ``centre`` (patch frame, m).

    ``radius`` defaults to the largest distance from ``centre`` of a patch node,
    so the disc holds the whole loaded region.
    """
    grid = grid or PolarGrid.make()
    cx, cy = float(centre[0]), float(centre[1])
    if radius is None:
        radius = float(np.max(np.hypot(patch.xy[:, 0] - cx, patch.xy[:, 1] - cy)))
    x, y = grid.xy(radius)
    probe = pv.PolyData(np.column_stack([x.ravel() + cx, y.ravel() + cy, np.zeros(x.size)]))
    mesh = _surface(patch)
    # vtkCellLocator: builds faster than the static locator for one query batch
    out = probe.sample(mesh, tolerance=1e-9 * radius, snap_to_closest_point=False, locator="cell")
    sigma = np.asarray(out.point_data["p"], float).reshape(grid.shape)
    valid = np.asarray(out.point_data["vtkValidPointMask"], bool).reshape(grid.shape)
    sigma = np.where(valid, sigma, 0.0)
    return PolarMap(grid=grid, radius=radius, sigma=sigma, centre=(cx, cy), valid=valid, source=patch.source)
