"""A sweep counts each case once (issue 17, item 4): one row per case whatever the formats
it is written in, a rolling map is never a static load point, and an input that names
nothing is a usage error with nothing written."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from fepost.cli import main
from fepost.errors import ArgumentError
from fepost.report.sweeppage import write_trends
from fepost.sweep import run_sweep
from fepost.sweep.inputs import PREFERENCE, expand_inputs
from fepost.sweep.pairs import ROLLING, STATIC, pair_sources, parse_rolling_pairs
from fepost.sweep.table import read_table
from fepost.sweep.trends import groups

ROOT = Path(__file__).resolve().parents[1]
AIR = ROOT / "meshes" / "aircraft"
LOADS = ("025", "050", "075", "100", "125", "150")


def test_one_source_per_case_in_the_documented_preference():
    sources = expand_inputs([str(AIR)])
    stems = [Path(s.path).stem for s in sources]
    assert sorted(stems) == sorted([f"static_{k}" for k in LOADS] + ["rolling_100"])
    for s in sources:
        assert Path(s.path).suffix == PREFERENCE[0]  # .e before .vtu
        assert [Path(a).name for a in s.also] == [Path(s.path).with_suffix(".vtu").name]


def test_a_case_given_twice_in_two_formats_explicitly_is_one_source():
    vtu, exo = AIR / "static_050.vtu", AIR / "static_050.e"
    sources = expand_inputs([str(vtu), str(exo)])
    assert len(sources) == 1 and sources[0].path == str(exo) and sources[0].also == (str(vtu),)


def test_the_rolling_map_pairs_with_its_static_map_of_the_same_load():
    pairings = pair_sources(expand_inputs([str(AIR)]), None)
    assert len(pairings) == 6
    assert all(p.role == STATIC for p in pairings)
    paired = [p for p in pairings if p.rolling is not None]
    assert [(Path(p.static.path).stem, Path(p.rolling).stem) for p in paired] == [
        ("static_100", "rolling_100")
    ]
    assert [Path(a).name for a in paired[0].rolling_also] == ["rolling_100.vtu"]
    # an explicit rule pairs the same way
    ruled = pair_sources(expand_inputs([str(AIR)]), parse_rolling_pairs("static=rolling"))
    assert [(p.static.path, p.rolling) for p in ruled] == [(p.static.path, p.rolling) for p in pairings]


def test_a_rolling_map_without_its_static_map_is_listed_apart(tmp_path):
    for name in ("rolling_100.vtu", "static_050.vtu"):
        shutil.copy(AIR / name, tmp_path / name)
    shutil.copy(AIR / "rolling_100.json", tmp_path / "other_case.json")
    shutil.copy(AIR / "rolling_100.vtu", tmp_path / "other_case.vtu")  # recognised by its sidecar
    pairings = pair_sources(expand_inputs([str(tmp_path)]), None)
    roles = {Path(p.static.path).name: p.role for p in pairings}
    assert roles == {"rolling_100.vtu": ROLLING, "other_case.vtu": ROLLING, "static_050.vtu": STATIC}
    assert all(p.rolling is None for p in pairings)
    rows = [
        {"status": "ok", "role": STATIC, "N": 1.0},
        {"status": "ok", "role": ROLLING, "N": 2.0},
    ]
    assert groups(rows) == {"all": [rows[0]]}


@pytest.mark.parametrize(
    "given", ["no/such/file.vtu", "meshes/aircraft/nothing_*.vtu", "docs"], ids=["missing", "glob", "folder"]
)
def test_an_input_naming_nothing_is_a_usage_error_with_nothing_written(capsys, tmp_path, given):
    out = tmp_path / "out"
    code = main(
        ["sweep", str(ROOT / given) if given == "docs" else given, "--out", str(out), "--no-progress"]
    )
    _, err = capsys.readouterr()
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("fepost: error: ") and given.split("/")[-1] in lines[0]
    assert not out.exists()
    with pytest.raises(ArgumentError):
        run_sweep([given], out)
    assert not out.exists()


def test_the_aircraft_folder_gives_six_load_points_and_the_pair(tmp_path):
    old = os.umask(0o027)  # the outputs must follow the umask, as docs/cli-exit-codes.md says
    try:
        res = run_sweep(
            [str(AIR)], tmp_path / "out", workers=1, processes=False, progress=False, trends=write_trends
        )
    finally:
        os.umask(old)
    assert res.ok
    out = tmp_path / "out"
    for p in [out / "coefficients.parquet", out / "coefficients.csv", out / "trends.html", out / "trends"]:
        assert p.stat().st_mode & 0o777 == (0o750 if p.is_dir() else 0o640), p
    assert all(p.stat().st_mode & 0o777 == 0o640 for p in (out / "trends").iterdir())
    rows = read_table(res.csv)
    assert [Path(r["source"]).stem for r in rows] == [f"static_{k}" for k in LOADS]
    assert all(r["role"] == STATIC and r["also_as"] for r in rows)
    pair = next(r for r in rows if r["rolling"])
    assert Path(pair["source"]).stem == "static_100" and Path(pair["rolling"]).stem == "rolling_100"
    side = json.loads((AIR / "rolling_100.json").read_text())
    assert pair["N_rolling"] == pytest.approx(side["cpress_integral"], rel=1e-2)
    assert pair["load_mismatch_allowed"] is False
    fits = json.loads((tmp_path / "out" / "trends.json").read_text())["fits"]
    assert {f["n"] for f in fits if f["quantity"] != "k_x"} == {6}
    assert rows == read_table(res.parquet)
