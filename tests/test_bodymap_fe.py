"""``fepost map --fe``: a rigid flat base on an elastic board, solved by CalculiX (coarse case).

Marked ``ccx`` (skipped without the solver). The coarse case (5 mm elements at the base's
edges, 2 layers through a 10 mm board) solves in about 3 s. Checked against statics and the
solver: its reaction at the table carries the weight; the centre of pressure sits at the centre
of mass; and a rigid punch on an elastic layer presses harder at its edges than inside.
"""

from __future__ import annotations

import json
import shutil

import meshio
import numpy as np
import pytest

from fepost.cli import main

HAVE_CCX = shutil.which("ccx") is not None
MASS, G = 1.518, 9.81
W = MASS * G
#: The solver's reaction against the applied weight: equilibrium to the solver's precision.
SOLVER_TOL = 1e-6
#: The raw CPRESS integral against the reaction: nodal values interpolated linearly over the faces
#: meet at the base's edges (measured +0.6 % at 5 mm elements).
CPRESS_TOL = 0.01
#: Centre of pressure from the centre of mass, as a fraction of the base's size (the discrete
#: contact's asymmetry; measured 4.7e-4 on this coarse mesh).
COP_TOL = 1e-3
SIZE = 0.15
#: A coarse model (module docstring).
COARSE = {"EDGE_SIZE": 0.005, "FAR_SIZE": 0.015, "LAYERS": 2}


def _block(board: dict) -> dict:
    """The flat-based block of these tests on ``board``."""
    return {
        "mass": MASS,
        "gravity": G,
        "centre_of_mass": [0.05, 0.05],
        "reference_point": [0.05, 0.05],
        "base": [[0.0, 0.0], [SIZE, 0.0], [0.0, SIZE]],
        "board": board,
    }


@pytest.fixture(scope="module")
def fe_map(tmp_path_factory):
    if not HAVE_CCX:
        pytest.skip("CalculiX 'ccx' is not on PATH")
    from fepost.bodymap import board

    d = tmp_path_factory.mktemp("bodymap_fe")
    body = d / "block.json"
    body.write_text(json.dumps(_block({"thickness": 0.01})))
    with pytest.MonkeyPatch.context() as mp:
        for name, value in COARSE.items():
            mp.setattr(board, name, value)
        assert main(["map", str(body), "--out", str(d / "fe.vtu"), "--fe"]) == 0
    return d / "fe.vtu"


def hand_load(xy, tri, p):
    a, b, c = (xy[tri[:, k]] for k in range(3))
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    pa, pb, pc = (p[tri[:, k]] for k in range(3))
    mids = [((a + b) / 2, (pa + pb) / 2), ((b + c) / 2, (pb + pc) / 2), ((c + a) / 2, (pc + pa) / 2)]
    n = sum(float(np.sum(area * q)) / 3 for _, q in mids)
    return n, sum((area * q) @ x for x, q in mids) / 3 / n


@pytest.mark.ccx
def test_board_model_carries_the_weight_at_the_centre_of_mass(fe_map):
    side = json.loads(fe_map.with_suffix(".json").read_text())
    assert side["reaction_z"] == pytest.approx(W, rel=SOLVER_TOL), "the table's reaction = m g"
    assert abs(side["cpress_scale"] - 1) < CPRESS_TOL, "CalculiX's CPRESS integral against its reaction"
    assert side["board"]["thickness"] == 0.01 and side["board"]["youngs_modulus"] == 4e9
    m = meshio.read(fe_map)
    n, cop = hand_load(m.points[:, :2], m.cells_dict["triangle"], m.point_data["pressure"])
    assert n == pytest.approx(side["reaction_z"], rel=1e-12)
    assert np.hypot(*cop) < COP_TOL * SIZE, f"statics: centre of pressure at the centre of mass, got {cop}"


def distance_inside(xy):
    """Distance of points of the map frame from the triangle's edges (positive inside)."""
    x, y = xy[:, 0] + 0.05, xy[:, 1] + 0.05
    return np.minimum.reduce([x, y, (SIZE - x - y) / np.sqrt(2)])


@pytest.mark.ccx
def test_rigid_punch_presses_harder_at_its_edges(fe_map):
    m = meshio.read(fe_map)
    xy, p = m.points[:, :2], m.point_data["pressure"]
    uniform = W / (0.5 * SIZE**2)
    d = distance_inside(xy)
    edge, inner = p[(d >= -1e-9) & (d < 0.006)], p[d > 0.02]
    assert p.max() > 1.1 * uniform, f"edge peak {p.max() / uniform:.3f} x uniform"
    assert edge.mean() > uniform > inner.mean(), (edge.mean() / uniform, inner.mean() / uniform)


@pytest.mark.ccx
def test_board_map_through_fepost_coefficients(fe_map, tmp_path):
    out = tmp_path / "c.json"
    assert main(["coefficients", str(fe_map), "--json", str(out)]) == 0
    c = json.loads(out.read_text())
    assert c["N_fe"] == pytest.approx(W, rel=1e-9) and c["reaction_z"] == pytest.approx(W, rel=SOLVER_TOL)
    assert np.hypot(*c["patch"]["centre"][:2]) < COP_TOL * SIZE
    assert c["N"] == pytest.approx(W, rel=0.005), "the default polar grid carries the load"


def test_fe_refuses_point_supports(tmp_path, capsys):
    body = tmp_path / "legs.json"
    body.write_text(
        json.dumps(
            {
                "mass": MASS,
                "gravity": G,
                "centre_of_mass": [0.05, 0.05],
                "reference_point": [0.05, 0.05],
                "supports": [[0.01, 0.01], [0.13, 0.01], [0.01, 0.13]],
                "support_radius": 0.002,
            }
        )
    )
    assert main(["map", str(body), "--out", str(tmp_path / "m.vtu"), "--fe"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "point supports" in err and str(body) in err, err


@pytest.mark.parametrize(
    ("board", "message"),
    [({"thickness": -1}, "must be positive"), ({"stiffness": 1e9}, "'board.stiffness' is unknown")],
)
def test_bad_board_keys(tmp_path, capsys, board, message):
    body = tmp_path / "block.json"
    body.write_text(json.dumps(_block(board)))
    assert main(["map", str(body), "--out", str(tmp_path / "m.vtu"), "--fe"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.json"]
