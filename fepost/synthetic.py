"""Verification meshes: analytic pressure maps written as unstructured FE exports.

Used by the tests and benchmarks to check the pipeline against closed forms
(the reference values on the theory page, docs/theory.md) on meshes a solver
could have written: triangles or quads, nodal or face data, any plane
orientation, any offset, VTU / legacy VTK / VTP / Exodus II (VTK formats
written by meshio/pyvista; Exodus by pyexodus, since meshio's Exodus writer
produces files VTK's reader cannot read).
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
from scipy.spatial import Delaunay

from .analytic import pressure_function
from .errors import ArgumentError


def disc_mesh(
    n_rings: int = 40,
    kind: str = "tri",
    seed: int = 0,
    graded: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Unit-disc mesh: points (n, 2) and cells (m, 3) or (m, 4).

    ``tri``: Delaunay triangulation of concentric rings with random phase
    (unstructured); ring radii are graded towards the edge when ``graded``
    (ρ_k = sin(πk/2n)), which resolves the √ edge of a Hertz map.
    ``quad``: a structured square grid mapped onto the disc (elliptical
    mapping), all quadrilaterals, boundary nodes on the circle.
    """
    rng = np.random.default_rng(seed)
    if kind == "tri":
        k = np.arange(1, n_rings + 1)
        rho = np.sin(0.5 * np.pi * k / n_rings) if graded else k / n_rings
        pts = [np.zeros((1, 2))]
        for i, r in enumerate(rho):
            # spacing follows the local ring width so elements stay well shaped
            width = rho[i] - (rho[i - 1] if i else 0.0)
            n = max(6, int(np.ceil(2 * np.pi * r / max(width, 0.25 / n_rings))))
            t = (np.arange(n) + rng.uniform()) * 2 * np.pi / n
            pts.append(np.column_stack([r * np.cos(t), r * np.sin(t)]))
        p = np.vstack(pts)
        tri = Delaunay(p).simplices
        return p, tri.astype(np.int64)
    if kind == "quad":
        n = 2 * n_rings
        u = np.linspace(-1.0, 1.0, n + 1)
        if graded:
            u = np.sin(0.5 * np.pi * u)
        U, V = np.meshgrid(u, u, indexing="ij")
        X = U * np.sqrt(1.0 - 0.5 * V**2)
        Y = V * np.sqrt(1.0 - 0.5 * U**2)
        p = np.column_stack([X.ravel(), Y.ravel()])
        idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
        q = np.column_stack(
            [idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()]
        )
        return p, q.astype(np.int64)
    raise ArgumentError(f"kind must be 'tri' or 'quad', got {kind!r}")


def rotation(normal=(0.0, 0.0, 1.0), x_axis=(1.0, 0.0, 0.0)) -> np.ndarray:
    """Rows: the global directions of local x, y, z for a plane with ``normal``."""
    n = np.asarray(normal, float)
    n /= np.linalg.norm(n)
    x = np.asarray(x_axis, float)
    x = x - (x @ n) * n
    x /= np.linalg.norm(x)
    return np.vstack([x, np.cross(n, x), n])


def write_map(
    path: str | Path,
    profile: str = "hertz",
    *,
    radius: float = 0.1,
    peak: float = 1.0e6,
    k_x: float = 0.0,
    aspect: float = 1.0,
    shift: tuple[float, float] = (0.0, 0.0),
    origin=(0.0, 0.0, 0.0),
    normal=(0.0, 0.0, 1.0),
    x_axis=(1.0, 0.0, 0.0),
    n_rings: int = 40,
    kind: str = "tri",
    location: str = "point",
    field: str = "CPRESS",
    seed: int = 0,
    extra_point_data: dict | None = None,
    values=None,
) -> Path:
    """Write an analytic pressure map as an FE surface mesh; the format follows the suffix.

    The disc of ``radius`` (m; stretched by √aspect along x, shrunk along y) is
    placed with its centre at ``origin`` + ``shift`` (in-plane, m) in the plane
    with ``normal``. Pressure in Pa at nodes (``location="point"``) or face
    centroids (``"cell"``). ``values`` overrides the computed pressure.
    """
    path = Path(path)
    p2, cells = disc_mesh(n_rings, kind, seed)
    s = np.sqrt(aspect)
    p2 = radius * p2 * np.array([s, 1.0 / s]) + np.asarray(shift, float)
    sigma = pressure_function(
        profile, radius, peak, k_x=k_x, centre=(float(shift[0]), float(shift[1])), aspect=aspect
    )
    rot = rotation(normal, x_axis)
    pts = np.column_stack([p2, np.zeros(len(p2))]) @ rot + np.asarray(origin, float)
    if location == "point":
        val = sigma(p2[:, 0], p2[:, 1]) if values is None else np.asarray(values, float)
        point_data = {field: np.ascontiguousarray(val, dtype=np.float64)}
        cell_data = {}
    elif location == "cell":
        c = p2[cells].mean(axis=1)
        val = sigma(c[:, 0], c[:, 1]) if values is None else np.asarray(values, float)
        point_data = {}
        cell_data = {field: [np.ascontiguousarray(val, dtype=np.float64)]}
    else:
        raise ArgumentError(f"location must be 'point' or 'cell', got {location!r}")
    for k, v in (extra_point_data or {}).items():
        point_data[k] = np.ascontiguousarray(v, dtype=np.float64)
    ctype = "triangle" if cells.shape[1] == 3 else "quad"
    mesh = meshio.Mesh(
        np.ascontiguousarray(pts, dtype=np.float64),
        [(ctype, cells)],
        point_data=point_data,
        cell_data=cell_data,
    )
    suffix = path.suffix.lower()
    if suffix in (".e", ".exo"):
        write_exodus(path, pts, cells, [point_data], [{k: v[0] for k, v in cell_data.items()}])
    elif suffix == ".vtk":
        meshio.write(path, mesh, file_format="vtk", binary=True)
    elif suffix == ".vtp":
        import pyvista as pv

        pv.from_meshio(mesh).extract_surface(algorithm="dataset_surface").save(path)
    else:
        meshio.write(path, mesh)
    return path


def write_exodus(
    path: str | Path,
    points: np.ndarray,
    cells: np.ndarray,
    point_data: list[dict],
    cell_data: list[dict] | None = None,
    times: list[float] | None = None,
    title: str = "fepost verification map",
) -> Path:
    """Write a one-block Exodus II file with one time step per entry of ``point_data``.

    ``points`` (n, 3) m; ``cells`` (m, 3) triangles or (m, 4) quads (0-based);
    ``point_data``/``cell_data``: per step, {name: values}. A 3-vector is stored
    as the scalars ``<name>X``, ``<name>Y``, ``<name>Z`` (the Exodus convention,
    which VTK's reader joins back into one vector).
    """
    import pyexodus

    path = Path(path)
    if path.exists():
        path.unlink()
    points = np.asarray(points, float)
    cells = np.asarray(cells, np.int64)
    nsteps = len(point_data)
    cell_data = cell_data or [{} for _ in range(nsteps)]
    times = list(range(nsteps)) if times is None else times
    etype = {3: "TRI3", 4: "QUAD4"}[cells.shape[1]]
    e = pyexodus.exodus(
        str(path),
        mode="w",
        title=title,
        numDims=3,
        numNodes=len(points),
        numElems=len(cells),
        numBlocks=1,
        numNodeSets=0,
        numSideSets=0,
    )
    try:
        e.put_coords(points[:, 0], points[:, 1], points[:, 2])
        e.put_elem_blk_info(1, etype, len(cells), cells.shape[1], 0)
        e.put_elem_connectivity(1, cells + 1)
        nnames = list(point_data[0])
        cnames = list(cell_data[0])
        vec = {k: v for k, v in point_data[0].items() if np.ndim(v) == 2}
        scalar_n = [k for k in nnames if k not in vec]
        flat_n = scalar_n + [f"{k}{c}" for k in vec for c in "XYZ"[: np.shape(vec[k])[1]]]
        if flat_n:
            e.set_node_variable_number(len(flat_n))
            for i, k in enumerate(flat_n):
                e.put_node_variable_name(k, i + 1)
        if cnames:
            e.set_element_variable_number(len(cnames))
            for i, k in enumerate(cnames):
                e.put_element_variable_name(k, i + 1)
        for step in range(nsteps):
            e.put_time(step + 1, float(times[step]))
            for k in scalar_n:
                e.put_node_variable_values(k, step + 1, np.asarray(point_data[step][k], float))
            for k in vec:
                arr = np.asarray(point_data[step][k], float)
                for c, comp in enumerate("XYZ"[: arr.shape[1]]):
                    e.put_node_variable_values(f"{k}{comp}", step + 1, arr[:, c])
            for k in cnames:
                e.put_element_variable_values(1, k, step + 1, np.asarray(cell_data[step][k], float))
    finally:
        e.close()
    return path
