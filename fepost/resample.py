"""Resample a patch's FE pressure onto a polar grid by FE interpolation.

The FE field is interpolated with its own elements: linear on each triangle
for nodal data, constant per face for face data. Two implementations give the
same numbers (the tests hold them to round-off): ``method="bins"`` (default,
`fepost.locate`, a few times faster on million-node patches) and
``method="vtk"`` (VTK's probe filter through pyvista's ``sample``). Grid nodes
that fall on no loaded face (outside the patch, in a groove, in a hole of the
mesh) get zero pressure; the valid-point mask is kept on the map. Whether the
resampled map still carries the FE load is checked by `fepost.analysis.analyse` (N against N_fe).
"""

from __future__ import annotations

import numpy as np

from .errors import ArgumentError
from .locate import interpolate
from .patch import Patch
from .polar import PolarGrid, PolarMap

#: Interpolation back-ends (same results): numpy binning, VTK probe filter.
METHODS = ("bins", "vtk")


def _surface(patch: Patch):
    import pyvista as pv

    pts = np.column_stack([patch.xy, np.zeros(len(patch.xy))])
    mesh = pv.PolyData.from_regular_faces(pts, patch.triangles)
    if patch.location == "point":
        mesh.point_data["p"] = patch.values
    else:
        mesh.cell_data["p"] = patch.values
    return mesh


def _probe(patch: Patch, x: np.ndarray, y: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    import pyvista as pv

    probe = pv.PolyData(np.column_stack([x, y, np.zeros(x.size)]))
    # vtkCellLocator: builds faster than the static locator for one query batch
    out = probe.sample(_surface(patch), tolerance=1e-9 * radius, snap_to_closest_point=False, locator="cell")
    sigma = np.asarray(out.point_data["p"], float)
    valid = np.asarray(out.point_data["vtkValidPointMask"], bool)
    return sigma, valid


def resample(
    patch: Patch,
    grid: PolarGrid | None = None,
    radius: float | None = None,
    centre: tuple[float, float] = (0.0, 0.0),
    method: str = "bins",
) -> PolarMap:
    """Sample ``patch``'s pressure on ``grid`` about ``centre`` (patch frame, m).

    ``radius`` defaults to the largest distance from ``centre`` of a patch node,
    so the disc holds the whole loaded region. ``method``: ``"bins"`` or ``"vtk"``.
    """
    if method not in METHODS:
        raise ArgumentError(f"resample: method must be one of {METHODS}, got {method!r}")
    grid = grid or PolarGrid.make()
    cx, cy = float(centre[0]), float(centre[1])
    if radius is None:
        radius = float(np.max(np.hypot(patch.xy[:, 0] - cx, patch.xy[:, 1] - cy)))
    x, y = grid.xy(radius)
    if method == "bins":
        query = np.column_stack([x.ravel() + cx, y.ravel() + cy])
        flat, ok = interpolate(patch.xy, patch.triangles, patch.values, patch.location, query)
        sigma, valid = flat.reshape(grid.shape), ok.reshape(grid.shape)
    else:
        sigma, valid = _probe(patch, x.ravel() + cx, y.ravel() + cy, radius)
        sigma, valid = sigma.reshape(grid.shape), valid.reshape(grid.shape)
    sigma = np.where(valid, sigma, 0.0)
    return PolarMap(grid=grid, radius=radius, sigma=sigma, centre=(cx, cy), valid=valid, source=patch.source)
