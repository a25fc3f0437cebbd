"""The whole path on real data: an excerpt of a hardboard log -> pushes -> map -> predict, diagnose.

The excerpt (the first pushes of the flat-base log, its header count rewritten) is written
to tmp_path at test time: the GPL logs stay in ../shared and are never copied into the repo.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from fepost.cli import main

SHARED = Path(__file__).resolve().parents[2] / "shared" / "real" / "planar-sliding"
LOG = SHARED / "hardboard_patch.txt"
BODY = SHARED / "bodies" / "patch.json"
#: Pushes in the excerpt: diagnose needs at least 20 rows.
PUSHES = 22
#: The map's exact integrals against plain point sums over a 1 mm grid of the base: the polar
#: grid carries 99.93 % of the load and smears the triangle's edges over a node spacing.
GRID = 0.01

pytestmark = pytest.mark.skipif(
    not (LOG.is_file() and BODY.is_file()), reason=f"the planar-sliding logs are not in {SHARED}"
)


def _excerpt(src: Path, dst: Path, pushes: int) -> None:
    """The first ``pushes`` pushes of a planar-push log, as the logger wrote them."""
    lines = src.read_text().splitlines()
    out, i = [str(pushes)], 1
    for _ in range(pushes):
        start = i
        i += 2  # the poses before and after
        i += 1 + int(lines[i])  # the force samples
        i += 1 + int(lines[i])  # the finger's poses
        out.extend(lines[start:i])
    dst.write_text("\n".join(out) + "\n")


def _rows(path: Path) -> dict[str, np.ndarray]:
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0] if k not in ("source",)}


@pytest.fixture(scope="module")
def path_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("real")
    log = tmp / "excerpt.txt"
    _excerpt(LOG, log, PUSHES)
    files = {"log": log, "csv": tmp / "pushes.csv", "map": tmp / "base.vtu", "pred": tmp / "pred.csv"}
    assert main(["pushes", str(log), "--body", str(BODY), "--out", str(files["csv"])]) == 0
    assert main(["map", str(BODY), "--out", str(files["map"])]) == 0
    argv = ["predict", str(files["map"]), "--kinematics", str(files["csv"]), "--friction", "0.28"]
    assert main([*argv, "--out", str(files["pred"])]) == 0
    out = tmp / "diagnosis"
    argv = ["diagnose", "--simulation", str(files["map"]), "--measured", str(files["csv"])]
    assert main([*argv, "--friction", "0.28", "--out", str(out)]) == 0
    files["diagnosis"] = out / "diagnosis.json"
    return files


def _point_sums(kin: np.ndarray, f: float) -> np.ndarray:
    """Coulomb friction of the uniform triangular base by plain sums over 1 mm cells (N, N, N·m)."""
    body = json.loads(BODY.read_text())
    h = 0.001
    xs = np.arange(h / 2, 0.15, h)
    X, Y = np.meshgrid(xs, xs)
    inside = X + Y < 0.15
    p = np.column_stack([X[inside], Y[inside]]) - np.array(body["reference_point"])
    load = f * body["mass"] * body["gravity"] / len(p)
    wx = kin[:, 0, None] - kin[:, 2, None] * p[None, :, 1]
    wy = kin[:, 1, None] + kin[:, 2, None] * p[None, :, 0]
    s = np.hypot(wx, wy)
    Fx, Fy = -load * wx / s, -load * wy / s
    return np.column_stack([Fx.sum(1), Fy.sum(1), (p[None, :, 0] * Fy - p[None, :, 1] * Fx).sum(1)])


def test_excerpt_gives_one_row_per_push(path_run):
    rows = _rows(path_run["csv"])
    assert 20 <= rows["vx"].size <= PUSHES
    np.testing.assert_allclose(rows["N"], 1.518 * 9.81, rtol=1e-12)
    # every wrench opposes its motion (dissipates): F·v + M ω < 0
    assert np.all(rows["Fx"] * rows["vx"] + rows["Fy"] * rows["vy"] + rows["Mz"] * rows["wz"] < 0)


def test_predictions_match_point_sums_and_follow_the_data(path_run):
    rows, pred = _rows(path_run["csv"]), _rows(path_run["pred"])
    kin = np.column_stack([rows["vx"], rows["vy"], rows["wz"]])
    exact = np.column_stack([pred["Fx_exact"], pred["Fy_exact"], pred["Mz_exact"]])
    fn = 0.28 * 1.518 * 9.81
    scale = np.array([fn, fn, fn * 0.05])
    np.testing.assert_allclose(exact / scale, _point_sums(kin, 0.28) / scale, atol=GRID)
    measured = np.column_stack([rows["Fx"], rows["Fy"], rows["Mz"]])
    # the physics with one coefficient follows the measured torque (correlation) and level
    assert np.corrcoef(exact[:, 2], measured[:, 2])[0, 1] > 0.9
    f = 0.28 * np.sum(exact / scale * measured / scale) / np.sum((exact / scale) ** 2)
    assert 0.2 < f < 0.35, f


def test_diagnosis_names_a_cause_of_the_vocabulary(path_run):
    from fepost.diagnose.causenames import CAUSES

    d = json.loads(path_run["diagnosis"].read_text())
    assert d["cause"] in CAUSES and set(d["causes"]) <= set(CAUSES)
    assert {"rmse_before", "rmse_after", "delta_bic"} <= set(d["gain"])
    assert any(c["name"] == "pressure_shape" for c in d["candidates"])
    assert d["n_points"] == len(_rows(path_run["csv"])["vx"])


def test_limit_surface_on_the_excerpt(path_run):
    from fepost.limitsurface import fit_limit_surface, wrench_errors

    rows = _rows(path_run["csv"])
    kin = np.column_stack([rows["vx"], rows["vy"], rows["wz"]])
    W = np.column_stack([rows["Fx"], rows["Fy"], rows["Mz"]])
    surf = fit_limit_surface(W, kin, degree=2, rho=0.05)
    assert np.all(np.linalg.eigvalsh(surf.polynomial.matrix()) > 0)
    err = wrench_errors(surf.wrench(kin), W, 0.05)
    # the fitted pushes themselves: within the scatter of the rig (|F| about 3.6 N)
    assert np.sqrt(np.mean(err["force"] ** 2)) < 0.2 * np.sqrt(np.mean(W[:, 0] ** 2 + W[:, 1] ** 2))
