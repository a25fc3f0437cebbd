"""The tire-model generators (scripts/tiremodel) without the solver: both tires'
coarse meshes and CalculiX decks, read back with meshio's Abaqus reader and
checked with VTK's cell volumes (a few seconds, no ``ccx`` needed)."""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:  # scripts/ is a plain folder (namespace package) at the repo root
    sys.path.insert(0, str(REPO))

pytest.importorskip("gmsh")

from scripts.tiremodel import aircraft_deck as ad  # noqa: E402
from scripts.tiremodel import deck as dk  # noqa: E402
from scripts.tiremodel import meshing as mg  # noqa: E402
from scripts.tiremodel.aircraft_geometry import (  # noqa: E402
    AircraftParams,
    build_aircraft_mesh,
    coarse_aircraft_params,
)
from scripts.tiremodel.geometry import TireParams, build_mesh, coarse_params  # noqa: E402


@pytest.fixture(scope="module")
def small():
    return build_mesh(coarse_params())


@pytest.fixture(scope="module")
def aircraft():
    return build_aircraft_mesh(coarse_aircraft_params())


def _profile_point(arc, b, depth=0.0):
    yc, rc, rr, _, _ = arc
    return np.array([yc + (rr - depth) * math.sin(b), rc + (rr - depth) * math.cos(b)])


@pytest.mark.parametrize("params", [TireParams(), AircraftParams()], ids=["small", "aircraft"])
def test_profile_arcs_join_tangentially(params):
    """Each arc starts where the previous one ends, with the same normal angle; the crown
    top lies at the outer radius, the crown arc ends at the tread half-width, the widest
    point is at +-section_width/2, the bead at the end of the sidewall arc."""
    arcs = params.arcs()
    for a, b in zip(arcs, arcs[1:], strict=False):
        assert a[4] == b[3]
        np.testing.assert_allclose(_profile_point(a, a[4]), _profile_point(b, b[3]), atol=1e-12)
    np.testing.assert_allclose(_profile_point(arcs[0], 0.0), [0.0, params.outer_radius], atol=1e-12)
    assert _profile_point(arcs[0], arcs[0][4])[0] == pytest.approx(params.tread_half_width, rel=1e-12)
    ys = [_profile_point(arc, b)[0] for arc in arcs for b in np.linspace(arc[3], arc[4], 201)]
    assert max(ys) == pytest.approx(params.section_width() / 2, rel=1e-9)
    np.testing.assert_allclose(params.bead(), _profile_point(arcs[2], arcs[2][4]), atol=1e-12)
    assert params.axle_z == pytest.approx(params.outer_radius + params.gap0)


@pytest.mark.parametrize("which", ["small", "aircraft"])
def test_mesh_volumes_positive_and_faces_outward(which, request):
    """VTK's cell volumes (same corner order as C3D8) are all positive; every boundary
    quad's right-hand normal points away from the centroid of the element it bounds."""
    import pyvista as pv

    mesh = request.getfixturevalue(which)
    grid = pv.UnstructuredGrid({pv.CellType.HEXAHEDRON: mesh.hexes}, mesh.nodes)
    assert grid.compute_cell_sizes()["Volume"].min() > 0
    for quads in (mesh.outer_quads, mesh.contact_quads, mesh.inner_quads):
        x = mesh.nodes[quads]
        normal = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
        elems = [e for e, _ in mg.quads_to_faces(mesh.hexes, quads)]
        away = x.mean(axis=1) - mesh.nodes[mesh.hexes[elems]].mean(axis=1)
        assert (np.einsum("ij,ij->i", normal, away) > 0).all()
    # no two nodes coincide (the aircraft tire's two revolutions are merged at 180 deg)
    assert np.unique(np.round(mesh.nodes / 1e-7), axis=0).shape[0] == mesh.nodes.shape[0]
    assert set(np.unique(mesh.hexes)) == set(range(mesh.nodes.shape[0]))


def _read_deck(path):
    import meshio

    return meshio.read(path, file_format="abaqus")


def _element_cards(path, ending):
    """{element number: node numbers} of the ``*ELEMENT`` cards whose line ends in ``ending``."""
    out, inside = {}, False
    for line in Path(path).read_text().splitlines():
        if line.startswith("*"):
            inside = line.startswith("*ELEMENT") and line.endswith(ending)
        elif inside:
            number, *nodes = (int(v) for v in line.split(","))
            out[number] = nodes
    return out


def test_small_deck_reads_back(small, tmp_path):
    """The sample-tire deck read by meshio: the tire's nodes and elements, then the road's;
    node sets; one contact face per contact quad, one pressure face per cavity quad."""
    nt, et = small.nodes.shape[0], small.hexes.shape[0]
    case = dk.CASES["rolling"]
    info = dk.write_deck(tmp_path / "rolling.inp", small, case, 0.04)
    m = _read_deck(tmp_path / "rolling.inp")
    np.testing.assert_allclose(m.points[:nt], small.nodes, rtol=1e-9, atol=1e-12)
    assert m.points.shape[0] == nt + info["road_nodes"]
    assert np.abs(m.points[nt:, 2]).max() <= 0.02 + 1e-12 and m.points[nt:, 2].max() == 0.0
    tire, road = m.cells
    np.testing.assert_array_equal(tire.data, small.hexes)
    assert road.data.shape[0] == info["road_elements"] and road.data.min() == nt
    np.testing.assert_array_equal(m.point_sets["BEAD"], small.bead_nodes)
    np.testing.assert_array_equal(m.point_sets["TIREN"], np.arange(nt))
    np.testing.assert_array_equal(m.point_sets["ROADN"], np.arange(nt, m.points.shape[0]))
    lines = (tmp_path / "rolling.inp").read_text().splitlines()
    surface = lines.index("*SURFACE, NAME=STIRE, TYPE=ELEMENT")
    stire = lines[surface + 1 : surface + 1 + small.contact_quads.shape[0] + 1]
    assert stire[-1] == "*SURFACE, NAME=SROAD, TYPE=ELEMENT"
    assert all(1 <= int(ln.split(",")[0]) <= et for ln in stire[:-1])
    assert len(re.findall(r"^\d+, P[1-6], 2\.000000e\+05$", "\n".join(lines), re.M)) == len(small.inner_quads)
    assert lines.count("4") == info["equations"] > 0  # one 4-term equation per cut-face node
    assert lines.count("*STEP, NLGEOM, INC=400") == 3  # inflation, vertical travel, roll
    assert f"BEAD, 1, 1, {case.roll_dx:.9e}" in lines
    dk.write_deck(tmp_path / "inflate.inp", small, case, 0.0, inflation_only=True)
    assert (tmp_path / "inflate.inp").read_text().count("*STEP") == 1


def test_aircraft_deck_reads_back(aircraft, tmp_path):
    """The aircraft deck read by meshio: C3D8I and C3D8 blocks together hold every tire
    element once, numbered as in the mesh; the road block follows; node sets."""
    nt = aircraft.nodes.shape[0]
    info = ad.write_aircraft_deck(tmp_path / "a.inp", aircraft, [ad.Stage(0.1, 0.02, (("end", 1.0),))])
    m = _read_deck(tmp_path / "a.inp")
    np.testing.assert_allclose(m.points[:nt], aircraft.nodes, rtol=1e-9, atol=1e-12)
    assert m.points.shape[0] == nt + info.road_nodes
    assert m.points[nt:, 1].min() == pytest.approx(0.0, abs=1e-12)  # half road, y >= 0
    road = m.cells[-1]
    numbered = _element_cards(tmp_path / "a.inp", "ELSET=TIRE")
    assert sorted(numbered) == list(range(1, aircraft.hexes.shape[0] + 1))
    np.testing.assert_array_equal([numbered[e + 1] for e in range(len(numbered))], aircraft.hexes + 1)
    incompatible = _element_cards(tmp_path / "a.inp", "TYPE=C3D8I, ELSET=TIRE")
    assert 0 < len(incompatible) < len(numbered)
    assert aircraft.fine[np.array(list(incompatible)) - 1].all()  # C3D8I only around the patch
    assert road.data.shape[0] == info.road_elements and road.data.min() == nt
    for name, nodes in (("BEAD", aircraft.bead_nodes), ("SYMN", aircraft.symmetry_nodes)):
        np.testing.assert_array_equal(m.point_sets[name], nodes)
    np.testing.assert_array_equal(m.point_sets["ROADREF"], [nt])
    text = (tmp_path / "a.inp").read_text()
    assert len(re.findall(r"^\d+, P[1-6], 1\.380000e\+06$", text, re.M)) == len(aircraft.inner_quads)
    assert "*CONTACT PAIR, INTERACTION=SI, TYPE=NODE TO SURFACE\nSTIRE, SROAD" in text


def test_volume_mesh_merges_coincident_nodes_and_orients_hexes():
    """Two unit cubes side by side, each with its own tags for the shared face's nodes and the
    second one listed upside down (negative volume), plus a node no element uses."""
    import pyvista as pv

    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    corners = np.vstack([corners, corners + [0, 0, 1]])
    coords = np.vstack([corners, corners + [1, 0, 0], [[5, 5, 5]]]).astype(float)
    tag = 101 + np.arange(coords.shape[0])  # tag of coords[i]
    hex_tags = np.array([tag[0:8], np.r_[tag[12:16], tag[8:12]]])  # second cube upside down
    tags, coords = tag[::-1].copy(), coords[::-1].copy()  # gmsh's node order need not follow the tags
    for merge_tol, n_nodes in ((None, 16), (1e-7, 12)):
        nodes, hexes, remap = mg.volume_mesh(tags, coords, hex_tags, merge_tol)
        assert nodes.shape == (n_nodes, 3)
        np.testing.assert_allclose(nodes[hexes[:, 0]], [[0, 0, 0], [1, 0, 0]])
        grid = pv.UnstructuredGrid({pv.CellType.HEXAHEDRON: hexes}, nodes)
        np.testing.assert_allclose(grid.compute_cell_sizes()["Volume"], 1.0)
        np.testing.assert_array_equal(remap(hex_tags[:1]), hexes[:1])
        with pytest.raises(RuntimeError, match="not in volume mesh"):
            remap(np.array([tag[-1]]))
