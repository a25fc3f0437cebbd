"""Tests of fepost.table1 and the ``fepost table1`` command (in-process through main).

The FE maps are analytic: a Hertzian disc (R = 0.1 m, 200 kPa peak) and the same
disc with the rolling shift σ0(1 + k x/R), k = 0.13, written as .vtu with a CPRESS
point array.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import pyvista

from fepost import analytic
from fepost.analysis import analyse
from fepost.cli import main
from fepost.errors import ArgumentError
from fepost.table1 import DEFAULT_SEED, PAPER_TABLE1, ROW_NAMES, format_table, table1

pyvista.OFF_SCREEN = True

R, PEAK, K = 0.1, 2.0e5, 0.13


def _write_disc(path, k_x: float) -> None:
    disc = pyvista.Disc(center=(0, 0, 0), inner=0.0, outer=R, r_res=30, c_res=120).triangulate()
    x, y = disc.points[:, 0], disc.points[:, 1]
    disc.point_data["CPRESS"] = analytic.pressure_function("hertz", R, PEAK, k_x=k_x)(x, y)
    disc.cast_to_unstructured_grid().save(path)


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    d = tmp_path_factory.mktemp("maps")
    _write_disc(d / "static.vtu", 0.0)
    _write_disc(d / "rolling.vtu", K)
    return d / "static.vtu", d / "rolling.vtu"


@pytest.fixture(scope="module")
def analysis(meshes):
    return analyse(*meshes)


@pytest.fixture(scope="module")
def committed(analysis):
    return table1(analysis)


# --- the table ---------------------------------------------------------------------------
def test_committed_seed_recovers_every_coefficient(committed, analysis):
    """Closed-form data, committed seed: each 95 % interval holds its theoretical value."""
    c = analysis.coefficients
    assert committed.seed == DEFAULT_SEED and committed.source == "closed_form"
    assert [r.name for r in committed.rows] == list(ROW_NAMES)
    theory = {"f": c.f, "F0": c.F0, "M0": c.M0, "a": c.a, "m": c.m, "k_x": c.k_x}
    for r in committed.rows:
        assert r.theory == pytest.approx(theory[r.name], rel=1e-12), r.name
        lo, hi = r.ci95
        assert lo < r.fitted < hi, r.name
        assert lo <= r.theory <= hi, r.name
        assert r.covered
    assert committed.row("f").fitted == pytest.approx(committed.row("F0").fitted / c.N, rel=1e-12)
    assert committed.row("a").profile_ci95 is not None and committed.row("F0").profile_ci95 is None


def test_table_carries_paper_values_notes_and_bias(committed):
    d = committed.to_dict()
    json.dumps(d, allow_nan=False)
    assert [r["paper"]["fitted"] for r in d["rows"]] == [PAPER_TABLE1[n][1] for n in ROW_NAMES]
    assert any("m >= 4" in n for n in d["notes"])
    assert any("7 cm" in n for n in d["notes"])
    bias = d["exact_bias"]
    # the closed forms' best fit to exact integrals is biased (a, m move by > 3 %)
    assert abs(bias["relative_bias"]["a"]) > 0.03 and abs(bias["relative_bias"]["m"]) > 0.03
    text = format_table(committed)
    for word in ("theory", "fitted", "95 % bounds", "paper bounds", "approximation bias", "m >= 4"):
        assert word in text


def test_generalised_rows_beside_the_paper_rows(committed, analysis):
    """The generalised model fitted to exact-integral curves: every interval holds the
    map's value; the contract's ``rows`` are untouched."""
    g = committed.generalised
    assert g is not None and g.curves.source == "exact"
    assert [r.name for r in g.rows] == list(ROW_NAMES)
    c = analysis.coefficients
    theory = {"f": c.f, "F0": c.F0, "M0": c.M0, "a": c.a, "m": c.m, "k_x": c.k_x}
    for r in g.rows:  # circular map: a, m along x are the paper's a, m
        assert r.theory == pytest.approx(theory[r.name], rel=1e-6), r.name
        assert r.covered, r.name
    d = committed.to_dict()
    json.dumps(d, allow_nan=False)
    assert [r["name"] for r in d["generalised"]["rows"]] == list(ROW_NAMES)
    assert {"name", "theory", "fitted", "ci95"} <= set(d["generalised"]["rows"][0])
    assert d["generalised"]["fit"]["form"] == "generalised" and d["fit"]["form"] == "paper"
    assert [r["name"] for r in d["rows"]] == list(ROW_NAMES)
    assert "generalised model fitted to the exact-integral curves" in format_table(committed)
    for table in (committed, g):  # both tables look their rows up alike
        assert [table.row(n) for n in ROW_NAMES] == list(table.rows)
        with pytest.raises(ArgumentError, match=r"^name must be one of f, F0, M0, a, m, k_x, got 'F1'$"):
            table.row("F1")


def test_generalised_table_shares_the_analysis_models(committed, analysis):
    """The generalised models are built once per analysis: Table 1 fits the models of
    ``analysis.model_summary`` (the coefficients output and the report show the same ones),
    and its JSON keeps only the models' own errors (the paper's forms' are the coefficients')."""
    form = committed.generalised.form
    summary = analysis.model_summary
    assert form.static is summary.static and form.rolling is summary.rolling
    assert "compare_force" in summary.static.accuracy
    for m in committed.to_dict()["generalised"]["models"].values():
        assert {"model_force", "model_torque", "base_force", "base_torque"} <= set(m["accuracy"])
        assert not any(k.startswith("compare_") for k in m["accuracy"])


def test_without_rolling_map_k_x_is_assumed_and_said(meshes):
    a = analyse(meshes[0])
    t = table1(a, bias=False, profile=False, generalised=False)
    assert t.row("k_x").theory == 0.130 and t.generalised is None
    assert "assumed" in t.k_x_source and any("assumed" in n for n in t.notes)
    assert table1(a, bias=False, profile=False, k_x=0.05, generalised=False).row("k_x").theory == 0.05


def test_k_x_with_a_rolling_map_is_refused(analysis):
    with pytest.raises(ArgumentError, match=r"^k_x must be None when the analysis has a rolling map"):
        table1(analysis, k_x=0.1)


def test_exact_source_runs_and_differs(analysis, committed):
    t = table1(analysis, source="exact", bias=False, generalised=False)
    assert t.source == "exact" and t.curves.source == "exact"
    assert t.row("a").fitted != committed.row("a").fitted


# --- the command -------------------------------------------------------------------------
def test_cli_writes_json_rows(meshes, tmp_path, capsys):
    out = tmp_path / "t1.json"
    code = main(["table1", "--static", str(meshes[0]), "--rolling", str(meshes[1]), "--json", str(out)])
    assert code == 0
    printed = capsys.readouterr().out
    assert "95 % bounds" in printed and "k_x" in printed
    d = json.loads(out.read_text())
    assert [r["name"] for r in d["rows"]] == ["f", "F0", "M0", "a", "m", "k_x"]
    for r in d["rows"]:
        assert {"name", "theory", "fitted", "ci95"} <= set(r)
        assert len(r["ci95"]) == 2 and r["ci95"][0] <= r["fitted"] <= r["ci95"][1]
    assert d["settings"]["seed"] == DEFAULT_SEED
    assert not [p for p in tmp_path.iterdir() if p.name != "t1.json"]  # no temporary left behind


def test_cli_seed_and_source_options(meshes, tmp_path):
    out = tmp_path / "t1.json"
    code = main(
        [
            "table1",
            "--static",
            str(meshes[0]),
            "--seed",
            "5",
            "--source",
            "exact",
            "--friction",
            "0.5",
            "--json",
            str(out),
        ]
    )
    assert code == 0
    d = json.loads(out.read_text())
    assert d["settings"]["seed"] == 5 and d["settings"]["source"] == "exact"
    assert d["rows"][0]["theory"] == pytest.approx(0.5)


def test_cli_bad_path_exits_2_one_line_no_json(tmp_path, capsys):
    out = tmp_path / "t1.json"
    missing = tmp_path / "nope.vtu"
    code = main(["table1", "--static", str(missing), "--json", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("fepost: error: ") and "nope.vtu" in err
    assert not out.exists()


def test_cli_missing_sample_meshes_names_the_path(tmp_path, capsys, monkeypatch):
    import fepost.report.samples as samples

    monkeypatch.setattr(samples, "meshes_folder", lambda: tmp_path / "meshes")
    code = main(["table1"])
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(tmp_path / "meshes" / samples.SAMPLE_STATIC) in err


def test_cli_uses_sample_meshes_by_default(meshes, capsys, monkeypatch):
    """Without inputs: the report's sample pair (static and rolling), found beside the package."""
    import fepost.report.samples as samples

    monkeypatch.setattr(samples, "meshes_folder", lambda: meshes[0].parent)
    monkeypatch.setattr(samples, "SAMPLE_STATIC", meshes[0].name)
    monkeypatch.setattr(samples, "SAMPLE_ROLLING", meshes[1].name)
    assert main(["table1"]) == 0
    out = capsys.readouterr().out
    assert "rolling map, k_x" in out and str(meshes[0]) in out and str(meshes[1]) in out
    assert f"rolling map: {meshes[1]}: rolling map (kind not stated)" in out  # no sidecar


@pytest.mark.parametrize(
    ("sidecar", "said"),
    [
        (
            {"kind": "rolling run", "longitudinal_slip": 0.0, "rim_rotation_deg": 75.5, "axle_travel_m": 1},
            "rolled map (quasi-static free rolling, slip κ = 0.000, rim turned 75.5° over 1 m of axle "
            "travel)",
        ),
        ({"rolling_standin": {"direction": "+x"}}, "sliding stand-in (the rim slid along x, no rotation)"),
    ],
)
def test_cli_says_what_the_rolling_map_is(meshes, tmp_path, capsys, sidecar, said):
    """The rolling map's line names what its sidecar says it is."""
    rolling = Path(shutil.copy(meshes[1], tmp_path / "rolling.vtu"))
    rolling.with_suffix(".json").write_text(json.dumps(sidecar))
    assert main(["table1", "--static", str(meshes[0]), "--rolling", str(rolling)]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("rolling map:")]
    assert len(lines) == 1 and lines[0].startswith(f"rolling map: {rolling}: {said}")


def test_cli_unwritable_json_exits_2(meshes, tmp_path, capsys):
    out = tmp_path / "no" / "such" / "dir" / "t1.json"
    code = main(["table1", "--static", str(meshes[0]), "--json", str(out)])
    assert code == 2
    assert capsys.readouterr().err.count("\n") == 1
    assert not out.exists()


def test_cli_is_deterministic(meshes, tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    for p in (a, b):
        assert (
            main(
                [
                    "table1",
                    "--static",
                    str(meshes[0]),
                    "--rolling",
                    str(meshes[1]),
                    "--json",
                    str(p),
                ]
            )
            == 0
        )
    ra, rb = json.loads(a.read_text())["rows"], json.loads(b.read_text())["rows"]
    assert np.allclose([r["fitted"] for r in ra], [r["fitted"] for r in rb], rtol=0, atol=0)
