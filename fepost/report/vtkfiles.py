"""VTK files of the resampled polar maps and of the patch, for ParaView.

Three kinds of file, all in the **patch frame** (m): origin at the static centre
of pressure, x the rolling direction, y lateral, z the road normal. Each file
carries the frame as field data (``frame_origin``: the origin in the FE model's
global coordinates, m; ``frame_axes``: the rows x, y, z as global unit
vectors), so ParaView's *Transform* filter can put it back into the model.

``<map>_map.vtu`` (`polar_map_grid`)
    The polar map σ(ρ_i, φ_j) that every coefficient is integrated from: one
    point per grid node at (r cos φ, r sin φ, 0) about the map's centre, quads
    between neighbouring rings (closed in φ). Point data ``sigma`` (Pa),
    ``dA`` (the quadrature weight of the node, m²; Σ sigma·dA = N), ``valid``
    (1 where the node fell on a loaded FE face). Field data ``R`` (m), ``centre``
    (m, patch frame), ``N`` (N); numbers only, so that other readers (meshio)
    read it too.
``<map>_patch.vtp`` (`patch_surface`)
    The loaded FE faces (triangles) flat in the patch plane, with the FE
    pressure ``pressure`` (Pa) where the FE values live (point or cell data).
``<map>_outline.vtp`` (`patch_outline`)
    Lines: the boundary edges of the loaded faces, the frame axes (x and y,
    length R), the circle of radius r_max = R about the origin, the circle of
    radius r_equiv about the area centroid, and the best-fit ellipse. Cell data
    ``part`` (integer code, `PARTS`) tells them apart (ParaView:
    *Threshold* on ``part``); field data ``part_names`` lists the names by code.

Written with pyvista (VTK's XML writers, binary and compressed).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..figures.outline import boundary_edges, circle_points, ellipse_points
from ..patch import Patch
from ..polar import PolarMap

#: Codes of the cell array ``part`` of the outline file.
PARTS = ("outline", "x_axis", "y_axis", "circle_R", "circle_r_equiv", "ellipse")


def _frame_data(mesh, patch: Patch) -> None:
    mesh.field_data["frame_origin"] = np.asarray(patch.frame.origin, float)
    mesh.field_data["frame_axes"] = np.asarray(patch.frame.axes, float)


def polar_map_grid(pmap: PolarMap, patch: Patch):
    """The polar map as a `pyvista.UnstructuredGrid` of quads (see the module docstring).

    ``patch`` supplies the frame recorded as field data (the static patch for
    both maps: the rolling map lives in the static frame).
    """
    import pyvista as pv

    g = pmap.grid
    nr, nphi = g.shape
    x, y = pmap.xy()
    cx, cy = pmap.centre
    pts = np.column_stack([x.ravel() + cx, y.ravel() + cy, np.zeros(x.size)])
    i, j = np.meshgrid(np.arange(nr - 1), np.arange(nphi), indexing="ij")
    ii, jj = i.ravel(), j.ravel()
    jn = (jj + 1) % nphi
    quads = np.column_stack([ii * nphi + jj, (ii + 1) * nphi + jj, (ii + 1) * nphi + jn, ii * nphi + jn])
    cells = np.column_stack([np.full(len(quads), 4), quads]).ravel()
    types = np.full(len(quads), pv.CellType.QUAD, dtype=np.uint8)
    grid = pv.UnstructuredGrid(cells, types, pts)
    grid.point_data["sigma"] = np.asarray(pmap.sigma, float).ravel()
    grid.point_data["dA"] = pmap.area_weights().ravel()
    valid = np.ones(pmap.sigma.shape, bool) if pmap.valid is None else np.asarray(pmap.valid)
    grid.point_data["valid"] = valid.ravel().astype(np.uint8)
    grid.field_data["R"] = np.array([pmap.radius])
    grid.field_data["centre"] = np.array([cx, cy])
    grid.field_data["N"] = np.array([pmap.integrate()])
    _frame_data(grid, patch)
    return grid


def patch_surface(patch: Patch, frame_of: Patch | None = None):
    """The loaded FE faces as flat `pyvista.PolyData` with ``pressure`` (Pa)."""
    import pyvista as pv

    pts = np.column_stack([patch.xy, np.zeros(len(patch.xy))])
    mesh = pv.PolyData.from_regular_faces(pts, np.asarray(patch.triangles))
    data = mesh.point_data if patch.location == "point" else mesh.cell_data
    data["pressure"] = np.asarray(patch.values, float)
    _frame_data(mesh, frame_of or patch)
    return mesh


def patch_outline(patch: Patch, frame_of: Patch | None = None):
    """Outline, frame axes, circles and ellipse of ``patch`` as `pyvista.PolyData` lines."""
    import pyvista as pv

    pieces: list[tuple[str, np.ndarray, np.ndarray]] = []  # (part, points (k, 2), lines (m, 2))
    xy = np.asarray(patch.xy, float)
    edges = boundary_edges(patch.triangles)
    used, inverse = np.unique(edges, return_inverse=True)
    pieces.append(("outline", xy[used], inverse.reshape(-1, 2)))
    R = patch.r_max
    cp = np.asarray(patch.centre_of_pressure, float)
    for name, direction in (("x_axis", (1.0, 0.0)), ("y_axis", (0.0, 1.0))):
        pieces.append((name, np.array([[0.0, 0.0], direction]) * R, np.array([[0, 1]])))
    ce = patch.ellipse_centre
    curves = {
        "circle_R": circle_points(R),
        "circle_r_equiv": circle_points(patch.r_equiv, ce),
        "ellipse": ellipse_points(patch.ellipse_axes, patch.ellipse_angle, ce),
    }
    for name, pts in curves.items():
        k = len(pts)
        pieces.append((name, pts, np.column_stack([np.arange(k - 1), np.arange(1, k)])))
    points, lines, part = [], [], []
    offset = 0
    for name, pts, ln in pieces:
        points.append(pts)
        lines.append(ln + offset)
        part.append(np.full(len(ln), PARTS.index(name)))
        offset += len(pts)
    p2 = np.concatenate(points)
    seg = np.concatenate(lines)
    mesh = pv.PolyData(
        np.column_stack([p2, np.zeros(len(p2))]), lines=np.column_stack([np.full(len(seg), 2), seg]).ravel()
    )
    mesh.cell_data["part"] = np.concatenate(part).astype(np.int32)
    mesh.field_data["part_names"] = np.array(PARTS)
    mesh.field_data["centre_of_pressure"] = cp
    mesh.field_data["R"] = np.array([R])
    mesh.field_data["r_equiv"] = np.array([patch.r_equiv])
    mesh.field_data["ellipse_semi_axes"] = np.array(patch.ellipse_axes, float)
    mesh.field_data["ellipse_angle_deg"] = np.array([np.degrees(patch.ellipse_angle)])
    _frame_data(mesh, frame_of or patch)
    return mesh


def write_vtk_files(folder: Path, name: str, pmap: PolarMap, patch: Patch, frame_of: Patch) -> list[str]:
    """Write ``<name>_map.vtu``, ``<name>_patch.vtp`` and ``<name>_outline.vtp`` into ``folder``.

    ``frame_of``: the patch whose frame the files record (the static patch).
    Returns the file names.
    """
    folder = Path(folder)
    files = {
        f"{name}_map.vtu": polar_map_grid(pmap, frame_of),
        f"{name}_patch.vtp": patch_surface(patch, frame_of),
        f"{name}_outline.vtp": patch_outline(patch, frame_of),
    }
    for fname, mesh in files.items():
        mesh.save(folder / fname, binary=True)
    return list(files)
