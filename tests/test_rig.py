"""fepost rig: rig runs -> measured-data CSV; checks on the committed slide/spin runs (meshes/rig/)."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fepost.errors import DataError, FepostError, InputFileError
from fepost.rig import reaction_resultants, read_run, rig_table

REPO = Path(__file__).resolve().parents[1]
RIG = REPO / "meshes" / "rig"
FRICTION = 0.3


def _runs() -> list[Path]:
    out = []
    for side in sorted(RIG.glob("*.json")):
        if "kinematics" in json.loads(side.read_text()):
            out.append(side.with_suffix(".vtu"))
    return out


RUNS = _runs()
# committed sample data: their absence fails (tests/test_committed_data.py), never skips
assert RUNS, "meshes/rig/ holds no solved rig runs: committed sample data are missing"

_DAT = re.compile(r"forces \(fx,fy,fz\) for set REFN and time\s+\S+\s*\n\s*\n\s*\d+\s+(\S+)\s+(\S+)\s+(\S+)")


def _dat_force(run: Path) -> np.ndarray:
    """The reference node's reaction as CalculiX printed it (the run's .dat excerpt), parsed apart."""
    text = run.with_suffix(".dat.txt").read_text()
    m = _DAT.findall(text)
    assert m, f"no REFN force record in {run.with_suffix('.dat.txt').name}"
    return np.array([float(v) for v in m[-1]])


# ---------------------------------------------------------------- frames and signs


def test_moment_is_transferred_to_the_origin():
    # a force (0, 10) N at the reference node (2, 0) m: Mz about the origin = 2 * 10 = 20 N m more
    r = reaction_resultants([0.0, 10.0, 100.0], [0.0, 0.0, 5.0], [2.0, 0.0], [0.0, 0.0])
    assert (r.Fx, r.Fy, r.N) == (0.0, 10.0, 100.0)
    assert r.Mz == pytest.approx(25.0)
    # a force (10, 0) at (0, 1): Mz = x Fy - y Fx = -10
    r = reaction_resultants([10.0, 0.0, 100.0], [0.0, 0.0, 0.0], [0.0, 1.0], [0.0, 0.0])
    assert r.Mz == pytest.approx(-10.0)


def test_force_is_turned_into_the_tire_frame():
    # the tire turned by +90 degrees: the road's -x is the tire's +y; Mz is frame-free,
    # taken about the moved origin (1, 0): the force (-1, 0) at the reference (0, 0) gives 0
    r = reaction_resultants([-1.0, 0.0, 10.0], [0.0, 0.0, 2.0], [0.0, 0.0], [1.0, 0.0], math.pi / 2)
    assert (r.Fx, r.Fy) == pytest.approx((0.0, 1.0))
    assert r.Mz == pytest.approx(2.0)
    r = reaction_resultants([0.0, -1.0, 10.0], [0.0, 0.0, 0.0], [0.0, 0.0], [1.0, 0.0], math.pi / 2)
    assert (r.Fx, r.Fy) == pytest.approx((-1.0, 0.0))
    assert r.Mz == pytest.approx(1.0)  # (0 - 1) * (-1) - 0


# ---------------------------------------------------------------- bad input


def _write_run(tmp_path: Path, side: dict | None, name: str = "run") -> Path:
    run = tmp_path / f"{name}.vtu"
    run.write_text("placeholder, never read: shear=False")
    if side is not None:
        (tmp_path / f"{name}.json").write_text(json.dumps(side))
    return run


def _good() -> dict:
    return {
        "kinematics": {"vx": 0.03, "vy": 0.0, "wz": 0.0},
        "origin": [0.0, 0.0, 0.0],
        "reaction": {
            "force": [-3000.0, 0.0, 10000.0],
            "moment": [0.0, 0.0, 0.0],
            "ref_position": [0.0, 0.0, 0.0],
            "ref_displacement": [0.0, 0.0, 0.0],
        },
        "tire_motion": {"rotation_z": 0.0, "origin_position": [0.03, 0.0]},
        "units": "SI (m, N, Pa)",
    }


def test_good_sidecar_reads(tmp_path):
    r = read_run(_write_run(tmp_path, _good()), shear=False)
    assert (r.vx, r.reaction.Fx, r.reaction.N) == (0.03, -3000.0, 10000.0)
    assert r.shear is None


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.pop("kinematics"), "missing key 'kinematics'"),
        (lambda d: d["kinematics"].pop("wz"), "kinematics.wz must be a number"),
        (lambda d: d["reaction"].pop("moment"), "missing key reaction.moment"),
        (lambda d: d.pop("origin"), "missing key 'origin'"),
        (lambda d: d["reaction"]["force"].__setitem__(0, float("nan")), "not finite"),
        (lambda d: d["kinematics"].__setitem__("vx", "fast"), "must be a number"),
        (lambda d: d["tire_motion"].pop("rotation_z"), "tire_motion.rotation_z must be a number"),
        (lambda d: d["tire_motion"].__setitem__("origin_position", [1.0]), "origin_position must be"),
        (lambda d: d.__setitem__("units", "mm-t-s"), "units 'mm-t-s' not supported"),
        (lambda d: d["reaction"]["force"].__setitem__(2, -5.0), "N > 0"),
        (lambda d: d["reaction"].__setitem__("force", [1.0, 2.0]), "must be a list of 3 numbers"),
        (lambda d: d.__setitem__("kinematics", {"vx": 0.0, "vy": 0.0, "wz": 0.0}), "all zero"),
    ],
)
def test_bad_sidecar_is_one_line_error(tmp_path, edit, message):
    side = _good()
    edit(side)
    run = _write_run(tmp_path, None)
    (tmp_path / "run.json").write_text(json.dumps(side))
    with pytest.raises(DataError) as err:
        read_run(run, shear=False)
    assert message in str(err.value)
    assert "\n" not in str(err.value) and "run.json" in str(err.value)


def test_missing_sidecar_and_run(tmp_path):
    with pytest.raises(InputFileError, match="sidecar run.json not found"):
        read_run(_write_run(tmp_path, None), shear=False)
    with pytest.raises(InputFileError, match="rig run not found"):
        read_run(tmp_path / "nothing.vtu")
    (tmp_path / "bad.vtu").write_text("x")
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(DataError, match="not valid JSON"):
        read_run(tmp_path / "bad.vtu")


def test_cli_bad_input_exit_2(tmp_path):
    run = _write_run(tmp_path, None)
    p = subprocess.run(
        [sys.executable, "-m", "fepost", "rig", str(run), "--out", str(tmp_path / "o.csv")],
        capture_output=True,
        text=True,
        cwd=REPO,
    )
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and "run.json not found" in p.stderr
    assert not (tmp_path / "o.csv").exists()


# ---------------------------------------------------------------- the committed runs


def test_reproduces_the_solver_reaction_totals():
    """|F| and N as CalculiX printed them; the direction turned by the tire's turn (sidecar)."""
    table = rig_table(RUNS, shear=False)
    for run, r in zip(RUNS, table.runs, strict=True):
        f = _dat_force(run)
        assert math.hypot(r.reaction.Fx, r.reaction.Fy) == pytest.approx(math.hypot(f[0], f[1]), rel=1e-9)
        assert r.reaction.N == f[2]
        turn = json.loads(run.with_suffix(".json").read_text())["tire_motion"]["rotation_z"]
        d = math.atan2(r.reaction.Fy, r.reaction.Fx) - math.atan2(f[1], f[0]) + turn
        assert abs(math.remainder(d, 2 * math.pi)) < 1e-9, run.name


def test_shear_integral_agrees_with_the_reactions():
    """The export's shear traction, integrated over the deformed faces, against the reactions.

    Two different computations: nodal reaction forces of the rigid road against
    bilinear nodal tractions integrated over the tire's faces. Measured: within
    6e-4 fN (|F|) and 5e-4 fNR (Mz, R = 0.1 m) on 27 of the 29 runs; the two runs
    at 45 degrees and spin angle 75 degrees, whose last steps needed up to 17
    iterations, differ by up to 5.5e-3 fN and 2.5e-2 fNR (their N by 0.85 %).
    """
    dfs = []
    for r in rig_table(RUNS).runs:
        fn = FRICTION * r.reaction.N
        assert r.shear is not None
        df = math.hypot(r.reaction.Fx - r.shear.Fx, r.reaction.Fy - r.shear.Fy) / fn
        dfs.append(df)
        assert df < 1e-2, r.source
        assert abs(r.reaction.Mz - r.shear.Mz) < 3e-2 * fn * 0.1, r.source
        assert abs(r.reaction.N - r.shear.N) < 1e-2 * r.reaction.N, r.source
    assert float(np.median(dfs)) < 1e-3


def test_pure_sliding_reaches_the_coulomb_limit_against_the_velocity():
    slides = [r for r in rig_table(RUNS, shear=False).runs if r.wz == 0.0]
    assert slides
    for r in slides:
        f = math.hypot(r.reaction.Fx, r.reaction.Fy)
        assert f == pytest.approx(FRICTION * r.reaction.N, rel=2e-3), r.source
        v = math.hypot(r.vx, r.vy)
        # opposite to the sliding velocity (THEORY section 3: vx > 0 gives Fx = -f N)
        cos = (r.reaction.Fx * r.vx + r.reaction.Fy * r.vy) / (f * v)
        assert cos < -0.999, r.source


def test_no_run_exceeds_the_coulomb_bound():
    for r in rig_table(RUNS, shear=False).runs:
        assert math.hypot(r.reaction.Fx, r.reaction.Fy) <= FRICTION * r.reaction.N * (1 + 2e-3), r.source


def test_torque_opposes_the_spin():
    for r in rig_table(RUNS, shear=False).runs:
        if r.vx == r.vy == 0.0:
            assert r.reaction.Mz * r.wz < 0.0, r.source


def test_cli_writes_the_measured_csv(tmp_path):
    from fepost.diagnose.measured import read_measured

    out = tmp_path / "rig.csv"
    p = subprocess.run(
        [sys.executable, "-m", "fepost", "rig", *map(str, RUNS[:3]), "--out", str(out)],
        capture_output=True,
        text=True,
        cwd=REPO,
    )
    assert p.returncode == 0, p.stderr
    data = read_measured(out)
    assert len(data) == len(RUNS[:3])
    first = rig_table(RUNS[:1], shear=False).runs[0].reaction
    assert (data.Fx[0], data.Fy[0], data.Mz[0]) == pytest.approx((first.Fx, first.Fy, first.Mz), rel=1e-12)


def test_errors_are_fepost_errors():
    assert issubclass(DataError, FepostError) and issubclass(InputFileError, FepostError)
