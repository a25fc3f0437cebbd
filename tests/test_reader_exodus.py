"""Exodus II as solvers write it: blocks, bodies, side sets, node sets, steps, globals, 2-D models.

The files are written with netCDF4 alone (tests/exodus_files.py), in MOOSE's
layout; the expected loads are closed forms of the fields written.
"""

import json
import re

import numpy as np
import pytest
from exodus_files import hex_grid, write

from fepost import analyse
from fepost.cli import main
from fepost.errors import DimensionError, FieldError, PressureError, ScaleWarning
from fepost.reader import read_contact, time_steps

P = 1000.0


def _two_bodies(tmp_path, name="pair.e", both_sides=False, scale=1.0, **kw):
    """A 1 × 1 × 1 cube (block 2, 3 × 3 × 3 HEX8) resting on a 2 × 2 × 1 slab (block 1, 4 × 4 × 2):
    the cube's bottom nodes carry P; the slab's top nodes sit at the same positions (not merged)."""
    slab_pts, slab = hex_grid(4, 4, 2, size=(2.0, 2.0, 1.0), origin=(-1.0, -1.0, -1.0))
    cube_pts, cube = hex_grid(3, 3, 3, size=(1.0, 1.0, 1.0), origin=(-0.5, -0.5, 0.0))
    pts = np.vstack([slab_pts, cube_pts]) * scale
    n0 = len(slab_pts)
    p = np.zeros(len(pts))
    p[n0:][np.isclose(cube_pts[:, 2], 0.0)] = P
    if both_sides:
        top = (
            np.isclose(slab_pts[:, 2], 0.0)
            & (np.abs(slab_pts[:, 0]) <= 0.5)
            & (np.abs(slab_pts[:, 1]) <= 0.5)
        )
        p[:n0][top] = 0.8 * P  # the slab side carries a little less (a penalty's asymmetry)
    # side sets on every face of both bodies (as MOOSE meshes have), and node sets
    ss = [
        (np.arange(len(slab)), np.full(len(slab), 5)),  # every slab element's top side (some interior)
        (len(slab) + np.arange(len(cube)), np.full(len(cube), 4)),  # every cube element's bottom side
    ]
    ns = [np.arange(n0), n0 + np.arange(len(cube_pts))]
    disp = np.zeros(len(pts))
    return write(
        tmp_path / name,
        pts,
        [("HEX8", slab), ("HEX8", cube + n0)],
        nodal={
            "contact_pressure": np.vstack([0 * p, p]),
            "disp_x": np.vstack([disp, disp]),
            "disp_y": np.vstack([disp, disp]),
            "disp_z": np.vstack([disp, disp]),
        },
        times=(0.0, 1.0),
        side_sets=ss,
        side_set_names=["slab_top", "cube_bottom"],
        node_sets=ns,
        **kw,
    )


def test_blocks_are_the_surface_and_nodes_of_two_bodies_are_never_merged(tmp_path):
    path = _two_bodies(tmp_path)
    fld = read_contact(path)
    assert "element block 2" in fld.body and "element block 1" not in fld.body
    assert "the loaded faces lie on side set 2 'cube_bottom' (100% of them)" in fld.notes
    a = analyse(fld)
    p = a.static_patch
    assert p.N_fe == pytest.approx(P * 1.0, rel=1e-12)  # 1000 Pa on the 1 × 1 bottom of the cube
    assert p.area == pytest.approx(1.0, rel=1e-12)
    assert p.R == pytest.approx(np.sqrt(0.5), rel=1e-12)
    assert not p.circular and p.dropped_edge_faces == 12  # the cube's side faces along the bottom edge
    # M0 = f ∬σ r dA, for a uniform square of side 1: f P (√2 + asinh 1)/6. The polar grid meets a
    # pressure that jumps along a square's edges: ~0.5 % on the default grid, converging when refined
    m0 = 0.3 * P * (np.sqrt(2) + np.arcsinh(1.0)) / 6
    assert a.coefficients.N == pytest.approx(P, rel=1e-2)
    assert a.coefficients.M0 == pytest.approx(m0, rel=1e-2)
    from fepost.polar import PolarGrid

    fine = analyse(fld, grid=PolarGrid.make(256, 512)).coefficients
    assert fine.N == pytest.approx(P, rel=5e-4) and fine.M0 == pytest.approx(m0, rel=5e-4)


def test_both_sides_of_a_contact_loaded_one_is_taken(tmp_path):
    fld = read_contact(_two_bodies(tmp_path, both_sides=True))
    assert "element block 2" in fld.body
    assert any(
        re.search(r"both sides of the contact carry pressure: loaded faces taken from element block 2", n)
        for n in fld.notes
    )
    assert analyse(fld).static_patch.N_fe == pytest.approx(P, rel=1e-12)


def test_surface_option_picks_a_side_set_or_a_block(tmp_path):
    path = _two_bodies(tmp_path, both_sides=True)
    slab = analyse(path, surface="slab_top").static_patch
    # 0.8 P on the slab's nodes within the cube's footprint, ramping to zero over one 0.5 element:
    # ∬ = 0.8 P (1 + 2 · 0.5/2)²
    assert slab.N_fe == pytest.approx(0.8 * P * 1.5**2, rel=1e-12)
    assert analyse(path, surface="2").static_patch.N_fe == pytest.approx(P, rel=1e-12)  # side set id 2
    with pytest.raises(
        FieldError,
        match=r"pair\.e: no side set or element block 'road'; side sets: 1 'slab_top', "
        r"2 'cube_bottom'; blocks: element block 1",
    ):
        read_contact(path, surface="road")


def test_time_steps_and_a_step_without_contact(tmp_path):
    path = _two_bodies(tmp_path)
    steps = time_steps(path)
    assert [(s.index, s.time) for s in steps] == [(0, 0.0), (1, 1.0)]
    with pytest.raises(
        PressureError,
        match=r"pair\.e: pressure array 'contact_pressure' is zero "
        r"everywhere at step 0 \(t = 0\) \(no contact\); contact pressure is "
        r"positive at step\(s\) 1 \(t = 1\): choose one with --step",
    ):
        read_contact(path, step=0)
    assert time_steps(path, units="mm-kg-ms")[1].time == pytest.approx(1e-3)


def test_reaction_globals_are_shown_and_checked(tmp_path, capsys):
    path = _two_bodies(tmp_path, globals_={"bot_react_z": [0.0, P], "top_react_z": [0.0, -P], "dt": [0, 1]})
    fld = read_contact(path)
    assert dict(fld.reactions) == {"bot_react_z": P, "top_react_z": -P}
    out = tmp_path / "c.json"
    assert main(["coefficients", str(path), "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert re.search(r"solver bot_react_z\s+1000 N\s+\(N_fe/\|reaction\| - 1 = \+0\.00%\)", text)
    assert json.loads(out.read_text())["reactions"] == {"bot_react_z": P, "top_react_z": -P}
    wrong = _two_bodies(tmp_path, "wrong.e", globals_={"react_z": [0.0, 1e3 * P]})
    with pytest.warns(
        ScaleWarning,
        match=r"wrong\.e: N_fe = 1000 N differs from the solver's reaction by "
        r"-99\.9% \(react_z = 1e\+06 N\) \(a factor 0\.001: wrong --units\?\)",
    ):
        analyse(wrong)


def test_two_dimensional_models_are_refused(tmp_path):
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    path = write(
        tmp_path / "plane.e",
        pts,
        [("QUAD4", np.array([[0, 1, 2, 3]]))],
        nodal={"contact_pressure": np.array([[0.0, 0.0, 5.0, 5.0]])},
    )
    with pytest.raises(
        DimensionError,
        match=r"plane\.e: 2-D model \(num_dim = 2: plane strain, plane stress or "
        r"axisymmetric\): the contact is a line, not a patch",
    ):
        read_contact(path)


def test_a_line_of_loaded_nodes_in_3d_is_a_line_contact(tmp_path):
    pts, conn = hex_grid(4, 4, 1)
    p = np.where(np.isclose(pts[:, 2], 1.0) & np.isclose(pts[:, 1], 0.5), P, 0.0)
    path = write(tmp_path / "line.e", pts, [("HEX8", conn)], nodal={"contact_pressure": p[None]})
    with pytest.raises(
        DimensionError, match=r"line\.e: the loaded nodes lie on one line: the contact is a line"
    ):
        analyse(path)


def test_element_variable_pressure(tmp_path):
    """Pressure as an element variable: every boundary face of an element carries its value; for a
    slab of HEX8 that is its top and its bottom, two parallel loaded surfaces, refused as such."""
    pts, conn = hex_grid(2, 2, 1, size=(2.0, 2.0, 0.2))
    p = np.array([1.0, 2.0, 3.0, 4.0]) * P
    path = write(tmp_path / "cells.e", pts, [("HEX8", conn)], elemental={"pressure": [p[None]]})
    fld = read_contact(path, field="pressure")
    assert fld.location == "cell" and fld.n_faces == 4 + 4 + 8
    assert sorted(fld.values) == sorted(np.repeat(p, 4))  # each element's top, bottom and two sides
    from fepost.errors import PatchError

    with pytest.raises(
        PatchError,
        match=r"cells\.e: 2 separate contact patches \(load shares 50%, 50%\) on "
        r"different surfaces",
    ):
        analyse(fld)


@pytest.mark.parametrize(
    "etype,order",
    [
        ("HEX8", "hex8"),
        ("HEX20", "hex20"),
        ("HEX27", "hex27"),
        ("TETRA", "tet4"),
        ("TETRA10", "tet10"),
        ("WEDGE", "wedge6"),
        ("WEDGE15", "wedge15"),
        ("PYRAMID", "pyramid5"),
        ("PYRAMID13", "pyramid13"),
        ("SHELL4", "quad4"),
        ("SHELL8", "quad8"),
        ("SHELL9", "quad9"),
        ("TRISHELL3", "tri3"),
        ("TRI6", "tri6"),
        ("TRISHELL7", "tri7"),
    ],
)
def test_element_faces_carry_their_element_load(tmp_path, etype, order):
    """One element of each type, its nodes placed on the unit cube, tetrahedron, wedge, pyramid,
    square or triangle; a field p0 (1 + x − y²/2) on the nodes of z = 0: N_fe equals the closed
    form of the face's own interpolant (exact for quadratic faces, which hold y²)."""
    from fepost.reader.cells import SPECS

    square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    triangle = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    ref = {
        "hex": square + [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
        "tet": triangle + [[0, 0, 1]],
        "wedge": triangle + [[0, 0, 1], [1, 0, 1], [0, 1, 1]],
        "pyramid": square + [[0.5, 0.5, 1]],
        "quad": square,
        "tri": triangle,
    }
    spec = SPECS[order]
    fam = order.rstrip("0123456789")
    corners = np.array(ref[fam], float)
    nodes = list(corners)
    for a, b in spec.edges if spec.quadratic else ():
        nodes.append(0.5 * (corners[a] + corners[b]))
    extra = [None] * (spec.n_nodes - len(nodes))  # volume centre and face centres
    if extra:
        first = len(nodes)
        for k, face in enumerate(spec.faces):
            extra[spec.face_centres[k] - first] = corners[list(face)].mean(axis=0)
        if order == "hex27":
            extra[20 - first] = corners.mean(axis=0)
        nodes += extra
    pts = np.array(nodes)
    p = P * (1 + pts[:, 0] - 0.5 * pts[:, 1] ** 2) * np.isclose(pts[:, 2], 0.0)
    path = write(
        tmp_path / f"{order}.e",
        pts,
        [(etype, np.arange(len(pts))[None])],
        nodal={"contact_pressure": p[None]},
    )
    patch = analyse(path).static_patch
    on_square = fam in ("hex", "pyramid", "quad")
    face = {
        "hex": "quad",
        "pyramid": "quad",
        "quad": "quad",
        "tet": "tri",
        "wedge": "tri",
        "tri": "tri",
    }[fam]
    if spec.quadratic:  # ∬ (1 + x − y²/2) over the unit square, over the unit right triangle
        exact = P * ((1 + 0.5 - 1 / 6) if on_square else (0.5 + 1 / 6 - 1 / 24))
    elif face == "quad":  # the bilinear interpolant of the corner values: their mean
        exact = P * (1 + 2 + 1.5 + 0.5) / 4
    else:  # the linear interpolant over the triangle: area × mean of the corners
        exact = P * 0.5 * (1 + 2 + 0.5) / 3
    assert patch.N_fe == pytest.approx(exact, rel=1e-12)


def _whole(monkeypatch):
    """Make the reader read every element whatever ``surface`` names (the reference)."""
    from fepost.reader import contact, exodus

    monkeypatch.setattr(
        contact, "read_exodus", lambda path, step, surface=None: exodus.read_exodus(path, step)
    )


def _block_on_ground(tmp_path, *, elemental=False):
    """A 4 × 4 × 3 HEX8 block whose bottom carries a Hertz-like pressure; side set 1 'ground'
    names the bottom sides of the bottom layer (16 of 48 elements; k runs fastest in the file,
    so every third element), side set 2 'top' the top sides. Returns (path, bottom layer)."""
    pts, conn = hex_grid(4, 4, 3, size=(1.0, 1.0, 0.3), origin=(-0.5, -0.5, 0.0))
    r2 = pts[:, 0] ** 2 + pts[:, 1] ** 2
    p = np.where(np.isclose(pts[:, 2], 0.0), P * np.clip(1.0 - r2 / 0.6**2, 0.0, None), 0.0)
    layer = np.flatnonzero(np.isclose(pts[conn[:, 0], 2], 0.0))  # elements of the bottom layer
    top = np.flatnonzero(np.isclose(pts[conn[:, 4], 2], 0.3))
    kw = {}
    if elemental:
        pe = np.zeros(len(conn))
        pe[layer] = P
        kw["elemental"] = {"pressure": [pe[None]]}
    return write(
        tmp_path / "block.e",
        pts,
        [("HEX8", conn)],
        nodal={
            "contact_pressure": p[None],
            "disp_x": 0 * p[None],
            "disp_y": 0 * p[None],
            "disp_z": 0 * p[None],
        },
        side_sets=[(layer, np.full(len(layer), 4)), (top, np.full(len(top), 5))],
        side_set_names=["ground", "top"],
        **kw,
    ), layer


@pytest.mark.parametrize("surface", ["ground", "GROUND ", "1"])
def test_a_named_side_set_reads_only_its_elements_and_gives_the_same_field(tmp_path, monkeypatch, surface):
    from vtk_writers import same_fields

    from fepost.reader.contact import read_here, read_raw

    path, layer = _block_on_ground(tmp_path)
    raw = read_raw(path, None, surface=surface)
    try:
        assert raw.partial
        assert [len(b.conn) for b in raw.blocks] == [len(layer)]  # 16 of 48 elements read
        np.testing.assert_array_equal(raw.blocks[0].conn, write_conn(path)[layer])
        assert [ss.name for ss in raw.side_sets] == ["ground"]
        np.testing.assert_array_equal(raw.side_sets[0].elements, np.arange(len(layer)))
    finally:
        raw.close()
    part = read_here(path, surface=surface)
    _whole(monkeypatch)
    whole = read_here(path, surface=surface)
    reference = read_raw(path, None, surface=surface)
    assert not reference.partial
    reference.close()
    same_fields(part, whole)
    assert part.body == "side set 1 'ground'" and part.n_faces == 16


def write_conn(path):
    """The connectivity as written (0-based), read back with netCDF4."""
    import netCDF4

    with netCDF4.Dataset(str(path)) as ds:
        return np.asarray(ds.variables["connect1"][:], np.int64) - 1


def test_side_sets_of_two_bodies_read_apart(tmp_path, monkeypatch):
    """Side set 1 names every slab element, side set 2 every cube element: each reads its body's
    block alone and gives the field of the whole file's reading."""
    from vtk_writers import same_fields

    from fepost.reader.contact import read_here, read_raw

    path = _two_bodies(tmp_path, both_sides=True)
    for surface, rows in (("slab_top", [32, 0]), ("2", [0, 27])):
        raw = read_raw(path, None, surface=surface)
        assert raw.partial and [len(b.conn) for b in raw.blocks] == rows
        raw.close()
    parts = [read_here(path, surface=s) for s in ("slab_top", "2")]
    _whole(monkeypatch)
    for got, s in zip(parts, ("slab_top", "2"), strict=True):
        same_fields(got, read_here(path, surface=s))


def test_a_refusal_of_a_named_side_set_is_worded_from_the_whole_mesh(tmp_path, monkeypatch):
    """The slab carries no pressure: the refusal names where it is (a block among them), as a
    reading of every element does."""
    from fepost.reader.contact import read_here

    path = _two_bodies(tmp_path)
    with pytest.raises(PressureError) as part:
        read_here(path, surface="slab_top")
    assert "element block 2" in str(part.value) and "--surface" in str(part.value)
    _whole(monkeypatch)
    with pytest.raises(PressureError) as whole:
        read_here(path, surface="slab_top")
    assert str(part.value) == str(whole.value)


def test_element_values_on_a_named_side_set_are_read_from_the_whole_mesh(tmp_path, monkeypatch):
    from vtk_writers import same_fields

    from fepost.reader.contact import read_here

    path, layer = _block_on_ground(tmp_path, elemental=True)
    part = read_here(path, field="pressure", surface="ground")
    assert part.location == "cell" and part.n_faces == len(layer)
    _whole(monkeypatch)
    same_fields(part, read_here(path, field="pressure", surface="ground"))


def test_an_element_block_named_as_surface_is_read_whole(tmp_path):
    from fepost.reader.contact import read_raw

    path = _two_bodies(tmp_path, both_sides=True)
    raw = read_raw(path, None, surface="element block 2")
    assert not raw.partial and [len(b.conn) for b in raw.blocks] == [32, 27]
    raw.close()


def test_warnings_of_a_side_set_reading_arrive_once(tmp_path):
    """A sentinel value on a node of the other body: the side set's reading warns about it once,
    through the reading child, as a reading of every element does."""
    import warnings

    import netCDF4

    from fepost.errors import SentinelWarning

    path = _two_bodies(tmp_path, both_sides=True)
    with netCDF4.Dataset(str(path), "a") as ds:
        v = ds.variables["vals_nod_var1"]
        row = np.asarray(v[1, :])
        row[0] = -99999.0  # a slab corner, far from the cube
        v[1, :] = row
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        fld = read_contact(path, surface="cube_bottom")
    sentinel = [w for w in seen if issubclass(w.category, SentinelWarning)]
    assert len(sentinel) == 1 and "1 values equal to sentinel -99999" in str(sentinel[0].message)
    assert fld.body == "side set 2 'cube_bottom'"
