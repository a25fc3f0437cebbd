"""The fast VTK path (only the chosen point arrays decoded) gives what the general path gives.

Each file is read twice in-process: with the array selection of `fepost.reader.vtkselect`
and with it switched off (every array decoded, as before); the contact fields must be
identical, every field of them, and errors must carry the same message.
"""

import meshio
import numpy as np
import pytest
import pyvista as pv
from vtk_writers import both_ways, same_fields

from fepost.reader import contact, vtkselect
from fepost.reader.vtkfile import read_vtk

pv.OFF_SCREEN = True

CCX = ("COPEN", "CSLIP1", "CSLIP2", "CPRESS", "CSHEAR1", "CSHEAR2")


def _hertz(points: np.ndarray) -> np.ndarray:
    r2 = points[:, 0] ** 2 + points[:, 1] ** 2
    return 1e5 * np.sqrt(np.clip(1.0 - r2 / 0.3**2, 0.0, None))


def _surface_mesh() -> pv.UnstructuredGrid:
    plane = pv.Plane(i_size=1.0, j_size=1.0, i_resolution=24, j_resolution=20).triangulate()
    return plane.cast_to_unstructured_grid()


def _extras(mesh, n_arrays: int = 4) -> None:
    rng = np.random.default_rng(3)
    n = mesh.n_points
    for k in range(n_arrays):
        mesh.point_data[f"S{k}"] = rng.normal(size=(n, 1 + 2 * (k % 4)))
    mesh.point_data["V"] = rng.normal(size=(n, 3))


def _read(path, **kw):
    """(fast, general) results of `read_here`; each an exception's (type, message) when it raised."""
    return both_ways(lambda: contact.read_here(path, **kw), vtkselect, "SELECTABLE")


def _skipped(path, field=None, displacement="auto") -> set[str]:
    """The point arrays the fast path left undecoded (empty: it read the file whole)."""
    return set(read_vtk(path, field=field, displacement=displacement).ncomp)


_same = same_fields


@pytest.fixture
def solver_vtu(tmp_path):
    """A surface with CPRESS, a displacement, a 6-component CONTACT with named components and extras."""
    mesh = _surface_mesh()
    p = _hertz(np.asarray(mesh.points))
    mesh.point_data["CPRESS"] = p
    _extras(mesh)
    u = np.zeros((mesh.n_points, 3))
    u[:, 2] = -1e-3 * p / p.max()
    mesh.point_data["U"] = u
    contact6 = np.zeros((mesh.n_points, 6))
    contact6[:, 3] = 0.5 * p
    mesh.point_data["CONTACT"] = contact6
    mesh.cell_data["ELEM_ID"] = np.arange(mesh.n_cells, dtype=float)
    path = tmp_path / "solver.vtu"
    mesh.save(path)
    # component names written by hand (pyvista does not write them): the header scan must find them
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter

    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    grid = r.GetOutput()
    arr = grid.GetPointData().GetArray("CONTACT")
    for k, name in enumerate(CCX):
        arr.SetComponentName(k, name)
    w = vtkXMLUnstructuredGridWriter()
    w.SetFileName(str(path))
    w.SetInputData(grid)
    w.Write()
    return path


OPTIONS = [
    {},
    {"field": "CPRESS"},
    {"field": "CONTACT:3"},
    {"field": "CONTACT:CPRESS"},
    {"field": "CSHEAR1"},
    {"field": "cpress"},
    {"displacement": None},
    {"displacement": "U"},
    {"displacement": "V"},
    {"field": "S0"},
    {"field": "NOPE"},
    {"displacement": "NOPE"},
    {"displacement": "S0"},
    {"field": "CONTACT"},
    {"step": 0},
]


@pytest.mark.parametrize("options", OPTIONS, ids=[str(o) or "default" for o in OPTIONS])
def test_solver_vtu_fast_equals_general(solver_vtu, options):
    fast, general = _read(solver_vtu, **options)
    _same(fast, general)
    if not isinstance(general, tuple):  # a read that succeeds took the fast path
        kw = {k: v for k, v in options.items() if k != "step"}
        assert len(_skipped(solver_vtu, **kw)) >= 5


def test_the_fast_path_is_taken_and_skips_the_extra_arrays(solver_vtu):
    raw = read_vtk(solver_vtu, field="CPRESS", displacement="auto")
    everything = read_vtk(solver_vtu, select=False)
    # only CPRESS and U were decoded: the others (component counts from the header) load when asked for
    assert set(raw.ncomp) == set(everything.point_data) - {"CPRESS", "U"}
    assert not everything.ncomp
    assert list(raw.point_data) == list(everything.point_data)
    assert raw.components == everything.components
    assert raw.components["CONTACT"] == CCX
    for name in everything.point_data:  # the loaders give the same arrays as the full read
        assert np.array_equal(raw.point_data[name], everything.point_data[name]), name
        assert (
            raw.ncomp.get(name, everything.point_data[name].reshape(len(raw.points), -1).shape[1])
            == (everything.point_data[name].reshape(len(raw.points), -1).shape[1])
        )


def test_ambiguous_pressure_falls_back_with_the_same_error(tmp_path):
    mesh = _surface_mesh()
    mesh.point_data["CPRESS"] = _hertz(np.asarray(mesh.points))
    mesh.point_data["contact_pressure"] = _hertz(np.asarray(mesh.points))
    path = tmp_path / "two.vtu"
    mesh.save(path)
    fast, general = _read(path)
    assert isinstance(general, tuple) and "several candidate" in general[1]
    _same(fast, general)


def test_assumed_ccx_layout_without_component_names(tmp_path):
    mesh = _surface_mesh()
    contact6 = np.zeros((mesh.n_points, 6))
    contact6[:, 3] = _hertz(np.asarray(mesh.points))
    mesh.point_data["CONTACT"] = contact6
    _extras(mesh)
    path = tmp_path / "ccx.vtu"
    mesh.save(path)
    fast, general = _read(path)
    _same(fast, general)
    assert general.field == "CONTACT:CPRESS"
    assert {"S0", "V"} <= _skipped(path)


def test_cell_pressure_vtp(tmp_path):
    plane = pv.Plane(i_size=1.0, j_size=1.0, i_resolution=16, j_resolution=16)
    plane.cell_data["pressure"] = _hertz(np.asarray(plane.cell_centers().points))
    plane.point_data["displacement"] = np.zeros((plane.n_points, 3))
    _extras(plane)
    path = tmp_path / "cells.vtp"
    plane.save(path)
    for options in ({}, {"field": "pressure"}, {"displacement": None}):
        fast, general = _read(path, **options)
        _same(fast, general)
        assert general.location == "cell"
        assert {"S0", "V"} <= _skipped(path, **options)


def test_volume_mesh_with_point_pressure(tmp_path):
    grid = pv.ImageData(dimensions=(13, 11, 5), spacing=(1 / 12, 1 / 10, 0.05), origin=(-0.5, -0.5, -0.2))
    vol = grid.cast_to_unstructured_grid()
    pts = np.asarray(vol.points)
    p = np.where(np.isclose(pts[:, 2], 0.0), _hertz(pts), 0.0)
    vol.point_data["CPRESS"] = p
    vol.point_data["U"] = np.zeros((vol.n_points, 3))
    _extras(vol)
    vol.cell_data["S_cell"] = np.ones((vol.n_cells, 6))
    path = tmp_path / "vol.vtu"
    vol.save(path)
    for options in ({}, {"displacement": None}, {"field": "CPRESS"}):
        fast, general = _read(path, **options)
        _same(fast, general)
        assert {"S0", "V"} <= _skipped(path, **options)
    # the structured grid of the same block
    grid.point_data["CPRESS"] = p.reshape(-1)
    _extras(grid)
    sg = grid.cast_to_structured_grid()
    spath = tmp_path / "vol.vts"
    sg.save(spath)
    fast, general = _read(spath)
    _same(fast, general)
    assert not _skipped(spath)  # structured grids are read whole (see vtkselect.SELECTABLE)


@pytest.mark.parametrize("binary", [True, False], ids=["inline-binary", "ascii"])
def test_meshio_files(tmp_path, binary):
    """meshio writes inline (zlib base64) or ASCII arrays, no appended section."""
    mesh = _surface_mesh()
    points = np.asarray(mesh.points)
    tri = np.asarray(mesh.cells_dict[5])
    rng = np.random.default_rng(0)
    data = {"CPRESS": _hertz(points), "disp": np.zeros((len(points), 3)), "T": rng.normal(size=len(points))}
    path = tmp_path / "m.vtu"
    meshio.write(path, meshio.Mesh(points, [("triangle", tri)], point_data=data), binary=binary)
    fast, general = _read(path)
    _same(fast, general)
    assert general.displacement == "disp"
    assert _skipped(path) == {"T"}


def test_rectilinear_grid(tmp_path):
    """Read whole: VTK's conversion to cells puts the arrays in another order than the file's."""
    x = np.linspace(-0.5, 0.5, 13)
    grid = pv.RectilinearGrid(x, x, np.array([-0.1, 0.0]))
    pts = np.asarray(grid.points)
    grid.point_data["CPRESS"] = np.where(np.isclose(pts[:, 2], 0.0), _hertz(pts), 0.0)
    grid.point_data["U"] = np.zeros((grid.n_points, 3))
    _extras(grid)
    path = tmp_path / "r.vtr"
    grid.save(path)
    for options in ({}, {"displacement": None}):
        fast, general = _read(path, **options)
        _same(fast, general)
        assert not _skipped(path, **options)


def test_pressure_chosen_by_component_name_keeps_the_other_arrays_lazy(solver_vtu):
    """--field naming a component (CSHEAR1 of CONTACT): only CONTACT and U are decoded."""
    raw = read_vtk(solver_vtu, field="CSHEAR1", displacement="auto")
    assert "CONTACT" not in raw.ncomp and "U" not in raw.ncomp and "CPRESS" in raw.ncomp
