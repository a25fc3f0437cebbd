"""A static map and a rolling map must be one tire at one load (issue 17, item 3).

The loads compared are the FE integrals; the expected loads come from the sidecars'
``cpress_integral`` (the generator's own exact integral of the same field), a second
computation.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from fepost.analysis import LOAD_TOL, analyse
from fepost.cli import main
from fepost.errors import ArgumentError

ROOT = Path(__file__).resolve().parents[1]
AIR = ROOT / "meshes" / "aircraft"


def sidecar_load(path: Path) -> float:
    return float(json.loads(path.with_suffix(".json").read_text())["cpress_integral"])


def run(capsys, argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def loads_in(line: str) -> list[float]:
    return [float(x) for x in re.findall(r"N_fe = ([0-9.e+]+) N", line)]


@pytest.mark.parametrize(
    ("static", "rolling"),
    [
        (AIR / "static_050.vtu", AIR / "rolling_100.vtu"),  # another load of the same tire
        (AIR / "static_100.vtu", ROOT / "meshes" / "rolling.vtu"),  # another tire
    ],
    ids=["aircraft-50-with-100", "aircraft-with-small-tire"],
)
def test_a_rolling_map_of_another_load_is_refused_naming_both_loads(capsys, tmp_path, static, rolling):
    out_json = tmp_path / "c.json"
    code, out, err = run(capsys, ["coefficients", static, "--rolling", rolling, "--json", out_json])
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    line = lines[0]
    assert str(static) in line and str(rolling) in line
    rolling_load, static_load = loads_in(line)
    assert rolling_load == pytest.approx(sidecar_load(rolling), rel=2e-3)
    assert static_load == pytest.approx(sidecar_load(static), rel=2e-3)
    assert "--allow-load-mismatch" in line
    assert not out_json.exists()


@pytest.mark.parametrize(
    ("static", "rolling"),
    [
        (AIR / "static_100.vtu", AIR / "rolling_100.vtu"),
        (ROOT / "meshes" / "static.vtu", ROOT / "meshes" / "rolling.vtu"),
    ],
    ids=["aircraft-100", "small-tire"],
)
def test_a_matching_pair_is_accepted_and_both_loads_are_shown(capsys, tmp_path, static, rolling):
    out_json = tmp_path / "c.json"
    code, out, err = run(capsys, ["coefficients", static, "--rolling", rolling, "--json", out_json])
    assert code == 0, err
    doc = json.loads(out_json.read_text())
    expected = sidecar_load(rolling) / sidecar_load(static)
    assert abs(expected - 1) < LOAD_TOL
    assert doc["rolling"]["load_ratio"] == pytest.approx(expected, rel=2e-3)
    assert doc["rolling"]["load_tolerance"] == LOAD_TOL
    assert doc["rolling"]["load_mismatch_allowed"] is False
    assert doc["N_rolling"] == pytest.approx(sidecar_load(rolling), rel=1e-2)
    line = next(ln for ln in out.splitlines() if ln.startswith("rolling normal load N"))
    assert f"{doc['N_rolling']:.6g} N" in line and "within 3%" in line


def test_an_allowed_mismatch_goes_on_and_is_recorded(capsys, tmp_path):
    static, rolling = AIR / "static_050.vtu", AIR / "rolling_100.vtu"
    out_json = tmp_path / "c.json"
    argv = ["coefficients", static, "--rolling", rolling, "--json", out_json, "--allow-load-mismatch"]
    code, out, err = run(capsys, argv)
    assert code == 0, err
    doc = json.loads(out_json.read_text())
    assert doc["rolling"]["load_mismatch_allowed"] is True
    assert doc["rolling"]["load_ratio"] == pytest.approx(
        sidecar_load(rolling) / sidecar_load(static), rel=2e-3
    )
    assert "ALLOWED by --allow-load-mismatch" in out


def test_the_library_refuses_the_pair_too():
    with pytest.raises(ArgumentError, match="more than the 3% tolerance"):
        analyse(AIR / "static_050.vtu", AIR / "rolling_100.vtu")
