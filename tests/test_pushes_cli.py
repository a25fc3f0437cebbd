"""``fepost pushes`` end to end on an excerpt of a real log (written at test time: the logs stay in
../shared), and its refusals: one line, exit 2, nothing written."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from test_pushes import excerpt

from fepost.body import load_body
from fepost.cli import main
from fepost.diagnose.measured import read_measured

REAL = Path(__file__).resolve().parents[1].parent / "shared" / "real" / "planar-sliding"
LAYOUT = "patch"
COLUMNS = ["vx", "vy", "wz", "Fx", "Fy", "Mz", "N", "time", "push", "source"]

pytestmark = pytest.mark.skipif(
    not REAL.is_dir(), reason=f"{REAL} is absent: the real push logs live in ../shared/real/planar-sliding"
)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pushes_cli")
    log = excerpt(REAL / f"hardboard_{LAYOUT}.txt", 5, folder / "excerpt.txt")
    out = folder / "pushes.csv"
    return log, out, folder


def test_pushes_writes_the_measured_csv(run, capsys):
    log, out, _ = run
    body = REAL / "bodies" / f"{LAYOUT}.json"
    code = main(["pushes", str(log), "--body", str(body), "--out", str(out)])
    said = capsys.readouterr().out
    assert code == 0
    with out.open() as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == COLUMNS and len(rows) == 6
    assert [r[8] for r in rows[1:]] == ["1", "2", "3", "4", "5"] and {r[9] for r in rows[1:]} == {str(log)}
    weight = load_body(body).weight
    assert all(float(r[6]) == pytest.approx(weight, rel=1e-9) for r in rows[1:])
    # diagnose's reader takes it as it is
    data = read_measured(out)
    assert len(data) == 5 and data.time is not None and list(data.time) == [1, 2, 3, 4, 5]
    level = np.hypot(data.Fx, data.Fy) / weight
    assert np.all((level > 0.1) & (level < 0.35))
    assert f"{log}: 5 pushes, 5 kept, 0 left out" in said
    assert f"5 pushes -> {out} (0 left out) from 1 log" in said
    for word in ("zero:", "impact:", "outliers (kept):", "signs:", "u = |w| R/|v|"):
        assert word in said


def test_pushes_to_standard_output(run, capsys):
    log, _, _ = run
    body = REAL / "bodies" / f"{LAYOUT}.json"
    assert main(["pushes", str(log), "--body", str(body), "--out", "-"]) == 0
    out, err = capsys.readouterr()
    assert out.splitlines()[0] == ",".join(COLUMNS) and len(out.splitlines()) == 6
    assert "5 pushes -> standard output" in err


def test_damaged_log_refused_in_one_line_nothing_written(run, capsys):
    """A log cut in the middle of a force sample of its last push: exit 2, one line naming push and line."""
    log, _, folder = run
    lines = log.read_text().splitlines()
    at = len(lines) - 300  # a force sample of push 5 (its ~220 finger poses and the count follow it)
    assert len(lines[at].split()) == 3
    bad = folder / "truncated.txt"
    bad.write_text("\n".join([*lines[:at], lines[at][:12]]) + "\n")
    out = folder / "never.csv"
    body = REAL / "bodies" / f"{LAYOUT}.json"
    code = main(["pushes", str(log), str(bad), "--body", str(body), "--out", str(out)])
    _, err = capsys.readouterr()
    assert code == 2 and not out.exists()
    assert err.strip().splitlines() == [
        f"fepost: error: {bad}: push 5, line {at + 1}: expected 3 numbers (force sample: t fx fy), got 1"
    ]


def test_body_refused_in_one_line(run, capsys, tmp_path):
    log, _, _ = run
    body = tmp_path / "body.json"
    body.write_text((REAL / "bodies" / f"{LAYOUT}.json").read_text().replace('"mass": 1.518', '"mass": -1'))
    code = main(["pushes", str(log), "--body", str(body), "--out", str(tmp_path / "x.csv")])
    _, err = capsys.readouterr()
    assert code == 2 and err.strip().splitlines() == [
        f"fepost: error: {body}: key 'mass' must be positive, got -1"
    ]
