"""VTK files as solvers and converters write them: element orderings, vector components, pieces, bodies."""

import json

import meshio
import numpy as np
import pytest
import pyvista as pv

from fepost import analyse
from fepost.errors import InputFileError, PatchError
from fepost.reader import read_contact
from fepost.reader.cells import SPECS, VTK_TYPES

P = 1.0e5


@pytest.mark.parametrize("vtk_type", sorted(t for t, (name, _) in VTK_TYPES.items() if SPECS[name].dim >= 2))
def test_vtk_node_orderings_match_the_face_tables(vtk_type):
    """VTK's own cell definitions (vtkCell.GetEdge / GetFace point ids), mapped through the
    permutation to the canonical (Exodus) order, name the same mid-edge and face-centre nodes
    as fepost's tables."""
    from vtkmodules.vtkCommonDataModel import vtkGenericCell

    name, perm = VTK_TYPES[vtk_type]
    spec = SPECS[name]
    cell = vtkGenericCell()
    cell.SetCellType(vtk_type)
    n = cell.GetNumberOfPoints()
    assert n == spec.n_nodes
    for i in range(n):
        cell.GetPointIds().SetId(i, i)
    canon = np.arange(n) if perm is None else np.argsort(perm)  # VTK node v is canonical node canon[v]
    mid = {frozenset(e): spec.n_corners + k for k, e in enumerate(spec.edges)}
    if spec.quadratic:
        for k in range(cell.GetNumberOfEdges()):
            ids = [canon[cell.GetEdge(k).GetPointId(i)] for i in range(3)]
            assert mid[frozenset(ids[:2])] == ids[2], (name, k, ids)
    if spec.dim == 3:
        faces = {frozenset(f) for _, f in spec.face_nodes()}
        vtk_faces = set()
        for k in range(cell.GetNumberOfFaces()):
            f = cell.GetFace(k)
            vtk_faces.add(frozenset(int(canon[f.GetPointId(i)]) for i in range(f.GetNumberOfPoints())))
        assert vtk_faces == faces


def _contact_vtu(path, names=True):
    p2 = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float) * 0.2
    pts = np.column_stack([p2, np.zeros(4)])
    contact = np.zeros((4, 6), np.float32)
    contact[:, 3] = P
    contact[:, 0] = -1e-5
    grid = pv.UnstructuredGrid(np.r_[4, 0, 1, 2, 3], np.array([pv.CellType.QUAD]), pts)
    grid.point_data["CONTACT"] = contact
    if names:
        arr = grid.GetPointData().GetArray("CONTACT")
        for k, c in enumerate(("COPEN", "CSLIP1", "CSLIP2", "CPRESS", "CSHEAR1", "CSHEAR2")):
            arr.SetComponentName(k, c)
    grid.save(path)
    return path


def test_pressure_as_a_named_component_of_a_vector_array(tmp_path):
    path = _contact_vtu(tmp_path / "ccx.vtu")
    fld = read_contact(path)
    assert fld.field == "CONTACT:CPRESS" and not fld.notes
    assert analyse(fld).static_patch.N_fe == pytest.approx(P * 0.04, rel=1e-6)
    assert read_contact(path, field="CPRESS").field == "CONTACT:CPRESS"
    assert read_contact(path, field="CONTACT:3").field == "CONTACT:CPRESS"


def test_legacy_vtk_without_component_names_uses_the_ccx2paraview_layout(tmp_path):
    """A legacy file as ccx2paraview writes it (version 3.0, FIELD arrays, no component names)."""
    rows = "\n".join("\t".join(f"{v:.6E}" for v in (-1e-5, 0, 0, P, 0, 0)) for _ in range(4))
    legacy = tmp_path / "ccx.vtk"
    legacy.write_text(
        "# vtk DataFile Version 3.0\n\nASCII\nDATASET UNSTRUCTURED_GRID\n\n"
        "POINTS 4 double\n0 0 0\n0.2 0 0\n0.2 0.2 0\n0 0.2 0\n\n"
        "CELLS 1 5\n4 0 1 2 3\n\nCELL_TYPES 1\n9\n\n"
        f"POINT_DATA 4\nFIELD CONTACT 1\nCONTACT 6 4 double\n{rows}\n"
    )
    fld = read_contact(legacy)
    assert fld.field == "CONTACT:CPRESS"
    assert any("by ccx2paraview's layout" in n and "the file names no components" in n for n in fld.notes)
    assert analyse(fld).static_patch.N_fe == pytest.approx(P * 0.04, rel=1e-12)


def _disc_piece(offset, peak, n_rings=8, radius=0.1, z=0.0):
    from fepost import analytic
    from fepost.synthetic import disc_mesh

    p2, tri = disc_mesh(n_rings)
    p2 = radius * p2
    val = analytic.pressure_function("uniform", radius, peak)(p2[:, 0], p2[:, 1])
    pts = np.column_stack([p2 + offset, np.full(len(p2), z)])
    g = pv.PolyData.from_regular_faces(pts, tri)
    g.point_data["CPRESS"] = val
    return g


def test_multiblock_pieces_are_never_merged(tmp_path):
    """Two bodies whose faces coincide (both sides of one contact, nodes at the same positions):
    merging their nodes would double the load; one side is taken and the note says so."""
    one = _disc_piece((0, 0), P)
    one.save(tmp_path / "one.vtp")
    mb = pv.MultiBlock([_disc_piece((0, 0), 0.9 * P), one])
    path = tmp_path / "both.vtm"
    mb.save(path)
    fld = read_contact(path)
    assert any("both sides of the contact carry pressure" in n for n in fld.notes)
    alone = analyse(tmp_path / "one.vtp").static_patch.N_fe
    both = analyse(fld).static_patch.N_fe
    assert both == pytest.approx(alone, rel=1e-12) or both == pytest.approx(0.9 * alone, rel=1e-12)


def test_pieces_side_by_side_are_one_surface(tmp_path):
    """Two pieces of one surface (a partitioned export), apart: both kept; the patch step decides."""
    mb = pv.MultiBlock([_disc_piece((0, 0), P), _disc_piece((0.5, 0), P)])
    path = tmp_path / "two.vtm"
    mb.save(path)
    with pytest.raises(PatchError, match=r"two\.vtm: 2 separate contact patches \(load shares 50%, 50%\)"):
        analyse(path)


def _box(path, top_pressure=True, both=False):
    """A 1 × 1 × 0.25 block of 4 × 4 × 1 hexahedra, pressure P on its top (and bottom) nodes."""
    grid = pv.ImageData(dimensions=(5, 5, 2), spacing=(0.25, 0.25, 0.25)).cast_to_unstructured_grid()
    z = np.asarray(grid.points)[:, 2]
    grid.point_data["CPRESS"] = np.where(np.isclose(z, 0.25) | (both & np.isclose(z, 0.0)), P, 0.0)
    grid.save(path)
    return path


def test_a_volume_mesh_keeps_its_contact_face_not_its_sides(tmp_path):
    a = analyse(_box(tmp_path / "box.vtu"))
    assert a.static_patch.N_fe == pytest.approx(P, rel=1e-12)
    assert a.static_patch.dropped_edge_faces == 16  # 4 sides × 4 faces along the top edge
    assert a.static_patch.area == pytest.approx(1.0, rel=1e-12)


def test_two_parallel_loaded_surfaces_are_two_patches(tmp_path):
    with pytest.raises(
        PatchError,
        match=r"box2\.vtu: 2 separate contact patches \(load shares 50%, 50%\) on different surfaces",
    ):
        analyse(_box(tmp_path / "box2.vtu", both=True))


def test_nan_coordinates_and_wild_connectivity_are_refused(tmp_path):
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [np.nan, 0, 0]], float)
    m = meshio.Mesh(pts, [("triangle", np.array([[0, 1, 2]]))], point_data={"CPRESS": np.ones(4)})
    meshio.write(tmp_path / "nan.vtu", m)
    with pytest.raises(InputFileError, match=r"nan\.vtu: 1 node coordinates are NaN or infinite"):
        read_contact(tmp_path / "nan.vtu")
    m = meshio.Mesh(pts[:3], [("triangle", np.array([[0, 1, 7]]))], point_data={"CPRESS": np.ones(3)})
    meshio.write(tmp_path / "wild.vtu", m)
    with pytest.raises(
        InputFileError, match=r"wild\.vtu: connectivity refers to node 7 but the file has 3 nodes"
    ):
        read_contact(tmp_path / "wild.vtu")


def test_string_arrays_are_ignored(tmp_path):
    from vtkmodules.vtkCommonCore import vtkStringArray

    g = _disc_piece((0, 0), P).cast_to_unstructured_grid()
    s = vtkStringArray()
    s.SetName("label")
    s.SetNumberOfValues(g.n_points)
    for i in range(g.n_points):
        s.SetValue(i, "x")
    g.GetPointData().AddArray(s)
    g.save(tmp_path / "s.vtu")
    fld = read_contact(tmp_path / "s.vtu")
    assert "label" not in fld.arrays and fld.field == "CPRESS"


def test_point_and_cell_arrays_are_counted_and_named_alike():
    """One reader of a data object's arrays for points and cells: values per node or cell,
    component names kept, string arrays passed over, a wrong count named in one line."""
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkStringArray

    from fepost.reader.vtkfile import _data_arrays

    g = pv.Plane(i_resolution=2, j_resolution=1).cast_to_unstructured_grid()  # 6 nodes, 2 cells
    g.clear_data()
    vec = vtkDoubleArray()
    vec.SetName("CSTRESS")
    vec.SetNumberOfComponents(2)
    vec.SetComponentName(0, "CPRESS")
    vec.SetComponentName(1, "CSHEAR1")
    vec.SetNumberOfTuples(g.n_cells)
    label = vtkStringArray()
    label.SetName("label")
    label.SetNumberOfValues(g.n_cells)
    g.GetCellData().AddArray(vec)
    g.GetCellData().AddArray(label)
    g.point_data["CPRESS"] = np.arange(6.0)
    components: dict = {}
    points = _data_arrays("p.vtu", g.GetPointData(), 6, "point", components)
    cells = _data_arrays("p.vtu", g.GetCellData(), 2, "cell", components)
    assert list(points) == ["CPRESS"] and points["CPRESS"].tolist() == list(range(6))
    assert list(cells) == ["CSTRESS"]
    assert cells["CSTRESS"].shape == (2, 2) and components == {"CSTRESS": ("CPRESS", "CSHEAR1")}
    with pytest.raises(InputFileError, match=r"^p\.vtu: point array 'CPRESS' has 6 values for 7 nodes$"):
        _data_arrays("p.vtu", g.GetPointData(), 7, "point", {})
    with pytest.raises(InputFileError, match=r"^p\.vtu: cell array 'CSTRESS' has 2 values for 3 cells$"):
        _data_arrays("p.vtu", g.GetCellData(), 3, "cell", {})


def test_sidecar_is_validated(tmp_path):
    path = _box(tmp_path / "box.vtu")
    side = tmp_path / "box.json"
    side.write_text(json.dumps({"reaction_z": P}))
    assert read_contact(path).reaction_z == P
    for text, pattern in (
        ('{"reaction_z": NaN}', r"box\.json: unreadable sidecar JSON \(non-finite number NaN"),
        (
            '{"reaction_z": "12 kN"}',
            r"box\.json: sidecar key 'reaction_z' must be a finite number, got '12 kN'",
        ),
        ('{"reaction_z": true}', r"box\.json: sidecar key 'reaction_z' must be a finite number, got True"),
        ("[1, 2]", r"box\.json: sidecar JSON must be an object, got list"),
        ("[" * 100000, r"box\.json: unreadable sidecar JSON"),
    ):
        side.write_text(text)
        with pytest.raises(InputFileError, match=pattern):
            read_contact(path)
