"""``scripts.tiremodel.residuals``: CalculiX's added node numbers mapped back to the deck.

A tiny deck: a C3D8I brick (three incompatible modes), a plain C3D8 brick on it and a rigid
C3D8 block of eight nodes below. CalculiX 2.20 counts 22 + (8 + 2) + 3 = 35 nodes; a run
restarted from it 22 + 8 + 3 = 33. With every real node of the C3D8I brick held, its modes are
the only free unknowns, so the nodes CalculiX names as the largest correction are modes: 33-35,
and 31-33 in the restart (the ``ccx`` test checks this on the solver itself).
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from scripts.tiremodel import residuals  # noqa: E402

_CUBE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
NODES = (
    [(x, y, z) for z in (0, 1, 2) for x, y, _ in _CUBE]
    + [(3 * x - 1, 3 * y - 1, -1.01) for x, y, _ in _CUBE]
    + [(3 * x - 1, 3 * y - 1, -2.0) for x, y, _ in _CUBE]
    + [(0, 0, -2.0), (0, 0, -2.0)]
)
DECK = "\n".join(
    ["*NODE, NSET=NALL"]
    + [f"{k}, {x}, {y}, {z}" for k, (x, y, z) in enumerate(NODES, start=1)]
    + [
        "*ELEMENT, TYPE=C3D8I, ELSET=E1",
        "1, 1, 2, 3, 4, 5, 6, 7, 8",
        "*ELEMENT, TYPE=C3D8, ELSET=E2",
        "2, 5, 6, 7, 8, 9, 10, 11, 12",
        "*ELEMENT, TYPE=C3D8, ELSET=ER",
        "3, 17, 18, 19, 20, 13, 14, 15, 16",
        "*NSET, NSET=RN",
        "13, 14, 15, 16, 17, 18, 19, 20",
        "*MATERIAL, NAME=M",
        "*ELASTIC",
        "1e6, 0.3",
        "*SOLID SECTION, ELSET=E1, MATERIAL=M",
        "*SOLID SECTION, ELSET=E2, MATERIAL=M",
        "*SOLID SECTION, ELSET=ER, MATERIAL=M",
        "*RIGID BODY, NSET=RN, REF NODE=21, ROT NODE=22",
        "*BOUNDARY",
        "21, 1, 3",
        "22, 1, 3",
        *(f"{n}, 1, 3" for n in (9, 10, 11, 12)),
        "*STEP, NLGEOM",
        "*STATIC",
        "0.5, 1.0",
        "*BOUNDARY",
        *(f"{n}, 1, 3" for n in range(1, 9)),
        *(f"{n}, 1, 1, 0.3" for n in (5, 6, 7, 8)),
        "*NODE FILE",
        "U",
        "*END STEP",
    ]
)


@pytest.fixture()
def deck(tmp_path: Path) -> Path:
    path = tmp_path / "tiny.inp"
    path.write_text(DECK + "\n")
    return path


def test_added_nodes_are_numbered_rigid_body_first_then_modes(deck):
    mesh = residuals.read_mesh(deck)
    assert max(mesh.nodes) == 22
    assert mesh.rigid_nodes == 8 + residuals.EXTRA_PER_RIGID_BODY
    assert mesh.modes_from == 33 and mesh.total_nodes == 35
    assert [mesh.extra_owner(n) for n in (1, 22, 23, 32, 33, 34, 35)] == [None] * 4 + [1, 1, 1]
    assert mesh.place(34) == ("element", 1) and mesh.place(7) == ("node", 7)
    with pytest.raises(ValueError, match="beyond the deck's nodes"):
        mesh.extra_owner(36)
    assert mesh.where(34).startswith("C3D8I element 1 (incompatible modes) in E1 at (+0.500, +0.500, +0.500)")
    assert mesh.where(25) == "node 25 (one CalculiX adds for a rigid body)"
    assert mesh.where(6) == "node 6 at (+1.000, +0.000, +1.000)"


def test_a_restart_counts_two_nodes_fewer_and_its_modes_are_again_the_last(deck):
    mesh = residuals.read_mesh(deck, restart=True)
    assert mesh.rigid_nodes == 8 and mesh.modes_from == 31 and mesh.total_nodes == 33
    assert [mesh.extra_owner(n) for n in (30, 31, 33)] == [None, 1, 1]


def test_places_count_an_element_once(deck):
    mesh = residuals.read_mesh(deck)
    ranked = residuals.places(mesh, [33, 34, 35, 7, 7, 34])
    assert [(n, mesh.place(node)) for n, node in ranked] == [(4, ("element", 1)), (2, ("node", 7))]


def _log(path: Path, nodes: list[int], total: int | None) -> Path:
    head = [f"   nodes:        {total}"] if total is not None else []
    body = [f" largest residual force= 1.5 in node {n} and dof 2" for n in nodes]
    path.write_text("\n".join(head + body) + "\n")
    return path


def test_cli_names_the_places(deck, tmp_path, capsys):
    log = _log(tmp_path / "run.log", [34, 34, 35, 6], 35)
    assert residuals.main([str(deck), str(log), "--top", "2"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith("run.log: 4 iterations")
    assert re.match(r"\s+3x\s+C3D8I element 1 ", out[1]) and re.match(r"\s+1x\s+node 6 ", out[2])


def test_cli_refuses_a_log_of_another_deck(deck, tmp_path, capsys):
    log = _log(tmp_path / "other.log", [34], 37)
    assert residuals.main([str(deck), str(log)]) == 2
    err = capsys.readouterr().err
    assert "CalculiX counted 37 nodes" in err and "gives 35: not this log's deck" in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("total", "flag", "hint"), [(33, [], "with --restart"), (35, ["--restart"], "without --restart")]
)
def test_cli_says_when_the_log_is_the_other_kind_of_run(deck, tmp_path, capsys, total, flag, hint):
    log = _log(tmp_path / "run.log", [31], total)
    assert residuals.main([str(deck), str(log), *flag]) == 2
    assert hint in capsys.readouterr().err


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("*ELEMENT, TYPE=C3D8, ELSET=E\n1, 1, 2, 3, 4, 5, 6, 7, 8\n", "no *NODE card"),
        ("*NODE\n1, 0, 0, 0\n*RIGID BODY, ELSET=E, REF NODE=1\n", "without NSET="),
        ("*NODE\n1, 0, 0, 0\n*RIGID BODY, NSET=NOPE, REF NODE=1\n", "node set NOPE is not defined"),
    ],
)
def test_bad_decks_are_named(tmp_path, capsys, text, message):
    bad = tmp_path / "bad.inp"
    bad.write_text(text)
    log = _log(tmp_path / "run.log", [1], None)
    assert residuals.main([str(bad), str(log)]) == 2
    err = capsys.readouterr().err.strip()
    assert str(bad) in err and message in err and len(err.splitlines()) == 1


def test_missing_log_is_named(deck, tmp_path, capsys):
    assert residuals.main([str(deck), str(tmp_path / "absent.log")]) == 2
    assert "absent.log: cannot read the log" in capsys.readouterr().err


def _ccx(folder: Path, name: str) -> str:
    run = subprocess.run(
        ["ccx", "-i", name], cwd=folder, capture_output=True, text=True, timeout=120, check=False
    )
    assert run.returncode == 0, run.stdout[-2000:]
    return run.stdout


@pytest.mark.ccx
@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed")
def test_calculix_numbers_its_added_nodes_as_the_script_says(tmp_path, capsys):
    """The solver's own count and the nodes it names, in the deck's run and in a restart."""
    step = DECK[DECK.index("*STEP") :]
    (tmp_path / "base.inp").write_text(
        DECK.replace("*END STEP", "*RESTART, WRITE, FREQUENCY=1\n*END STEP") + "\n"
    )
    (tmp_path / "again.inp").write_text("*RESTART, READ, STEP=1\n" + step.replace(", 0.3", ", 0.35") + "\n")
    outputs = {"base": _ccx(tmp_path, "base")}
    shutil.copy(tmp_path / "base.rout", tmp_path / "again.rin")
    outputs["again"] = _ccx(tmp_path, "again")
    for name, restart in (("base", False), ("again", True)):
        mesh = residuals.read_mesh(tmp_path / "base.inp", restart=restart)
        total = re.search(r"nodes:\s*(\d+)", outputs[name])
        assert total is not None and int(total.group(1)) == mesh.total_nodes, name
        pattern = r"largest correction to disp=\s*\S+ in node (\d+)"
        corrected = {int(n) for n in re.findall(pattern, outputs[name])}
        assert corrected and all(mesh.extra_owner(n) == 1 for n in corrected), (name, corrected)
    # the sheared brick keeps its corners' volumes (simple shear)
    argv = [str(tmp_path / "base.inp"), "--restart", "--frd", str(tmp_path / "again.frd"), "--worst", "E1"]
    assert residuals.main(argv) == 0
    out = capsys.readouterr().out
    assert "t = 2: the most distorted elements of E1" in out
    assert "C3D8I element 1 at (+0.500, +0.500, +0.500): smallest corner volume 1.00" in out


def test_corner_volume_ratio_of_simple_shapes():
    cube = np.array([(x, y, z) for z in (0, 1) for x, y, _ in _CUBE], dtype=float)
    assert residuals.corner_volume_ratio(cube, cube * [1.0, 1.0, 0.5]) == pytest.approx(0.5)
    sheared = cube + np.outer(cube[:, 2], [0.7, 0.0, 0.0])  # simple shear keeps every corner's volume
    assert residuals.corner_volume_ratio(cube, sheared) == pytest.approx(1.0)
    keystone = cube.copy()
    keystone[6] = (0.5, 1.0, 1.0)  # corner 6 halfway to corner 7: corners 6 and 7 keep half their volume
    assert residuals.corner_volume_ratio(cube, keystone) == pytest.approx(0.5)
    keystone[6] = (-0.5, 1.0, 1.0)  # past it: corner 7 turned inside out
    assert residuals.corner_volume_ratio(cube, keystone) == pytest.approx(-0.5)


def test_most_distorted_ranks_a_sets_elements(deck):
    mesh = residuals.read_mesh(deck)
    still = {n: np.zeros(3) for n in mesh.nodes}
    squeezed = dict(still)
    for n in (9, 10, 11, 12):  # the top of the C3D8 brick pressed halfway down
        squeezed[n] = np.array([0.0, 0.0, -0.5])
    assert residuals.most_distorted(mesh, still, "e2") == [(pytest.approx(1.0), 2)]
    ranked = residuals.most_distorted(mesh, squeezed, "E2")
    assert ranked[0][1] == 2 and ranked[0][0] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="no element set NOPE"):
        residuals.most_distorted(mesh, still, "NOPE")
    with pytest.raises(ValueError, match="no displacement of element set E2"):
        residuals.most_distorted(mesh, {}, "E2")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--worst", "E1"], "--worst and --at need --frd"),
        (["--at", "1.0"], "--worst and --at need --frd"),
        ([], "give a log, or --frd with --worst ELSET"),
    ],
)
def test_cli_options_that_go_together(deck, capsys, argv, message):
    assert residuals.main([str(deck), *argv]) == 2
    assert message in capsys.readouterr().err
