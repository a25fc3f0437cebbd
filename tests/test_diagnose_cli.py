"""``fepost diagnose`` in-process: outputs, INTERFACE keys, bad input, atomic folders."""

from __future__ import annotations

import json

import pytest

from fepost.analysis import analyse
from fepost.cli import main
from fepost.diagnose.measured import write_csv
from fepost.diagnose.synthetic import synthesize

CAUSES = {
    "none", "friction_level", "pressure_dependent_friction", "speed_dependent_friction",
    "elliptic_patch", "anisotropic_friction", "pressure_shift", "sensor_offset",
}  # fmt: skip


@pytest.fixture
def setup(tmp_path, analytic_mesh):
    static = analytic_mesh("static.vtu", "hertz", radius=0.1, peak=3e5)
    a = analyse(static, friction=0.3)
    syn = synthesize(a.static_map, "pressure_shift", {"dx": 0.004, "dy": 0.0}, n=120, seed=3)
    csv = tmp_path / "meas.csv"
    write_csv(syn.data, csv, comment="synthetic: pressure shift dx = 4 mm")
    return static, csv, tmp_path


def test_diagnose_writes_the_interface_json_summary_and_figures(setup, capsys):
    static, csv, tmp = setup
    out = tmp / "out"
    rc = main(["diagnose", "--simulation", str(static), "--measured", str(csv), "--out", str(out)])
    assert rc == 0
    d = json.loads((out / "diagnosis.json").read_text())
    assert d["cause"] == "pressure_shift"
    assert set(d["parameters"]) == {"f", "dx", "dy"}
    for p in d["parameters"].values():
        assert p["ci95"][0] <= p["value"] <= p["ci95"][1]
    assert d["parameters"]["dx"]["ci95"][0] <= 0.004 <= d["parameters"]["dx"]["ci95"][1]
    assert {"rmse_before", "rmse_after", "delta_bic"} <= set(d["gain"])
    assert d["gain"]["rmse_after"] < d["gain"]["rmse_before"]
    assert d["criterion"] == "BIC"
    names = [c["name"] for c in d["candidates"]]
    assert set(names) == CAUSES and names[0] == d["cause"]
    assert all("score" in c for c in d["candidates"])
    assert {"rmse_vs_data", "rmse_vs_exact"} <= set(d["closed_form"])
    for png in ("predicted_vs_measured.png", "residuals.png", "candidates.png"):
        assert (out / png).stat().st_size > 1000
    summary = (out / "summary.txt").read_text()
    assert summary.startswith("cause: pressure_shift\n")
    assert "cause: pressure_shift" in capsys.readouterr().out
    assert not [p for p in tmp.iterdir() if p.name.startswith(".out")], "no temporary folders left"


def test_existing_folder_needs_force(setup, capsys):
    static, csv, tmp = setup
    out = tmp / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    args = ["diagnose", "--simulation", str(static), "--measured", str(csv), "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"fepost: error: {out}: folder exists and is not empty (use --force to replace it)"
    assert (out / "keep.txt").read_text() == "mine"
    assert main([*args, "--force"]) == 0
    assert not (out / "keep.txt").exists() and (out / "diagnosis.json").is_file()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "vx,vy,Fx,Fy\n1,2,3,4\n",
            "missing column(s) wz, Mz in the header (found 'vx', 'vy', 'Fx', 'Fy')",
        ),
        ("vx,vy,wz,Fx,Fy,Mz\n0.1,0,0,x,0,0\n", "line 2, column Fx: not a number: 'x'"),
        ("vx,vy,wz,Fx,Fy,Mz\n" + "0.1,0,0,-900,1,0\n" * 5, "5 test points are too few"),
    ],
    ids=["missing-columns", "non-numeric", "too-few-rows"],
)
def test_bad_csv_is_a_one_line_error_and_writes_nothing(setup, capsys, text, message):
    static, _, tmp = setup
    bad = tmp / "bad.csv"
    bad.write_text(text)
    rc = main(["diagnose", "--simulation", str(static), "--measured", str(bad), "--out", str(tmp / "o")])
    assert rc == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"fepost: error: {bad}: ")
    assert message in err
    assert not (tmp / "o").exists()
    assert not [p for p in tmp.iterdir() if p.name.startswith(".o.")]


def _rewrite(csv, tmp, column, func, extra=None):
    import numpy as np

    from fepost.diagnose.measured import read_measured

    d = read_measured(csv)
    fields = {k: np.array(getattr(d, k)) for k in ("vx", "vy", "wz", "Fx", "Fy", "Mz")}
    fields[column] = func(fields[column])
    from fepost.diagnose.measured import MeasuredData

    out = tmp / f"{column}.csv"
    write_csv(MeasuredData(**fields, **(extra or {})), out)
    return out


def test_dead_channel_and_wrong_units_and_roll_without_rolling(setup, capsys):
    import numpy as np

    static, csv, tmp = setup
    cases = [
        (_rewrite(csv, tmp, "Fy", lambda a: 0 * a), "column Fy is zero in every row"),
        (_rewrite(csv, tmp, "Fx", lambda a: 1000 * a), "column Fx: |Fx| is"),
        (
            _rewrite(csv, tmp, "Mz", lambda a: a, {"roll": np.resize([0, 1], 120)}),
            "60 rows have roll = ±1",
        ),
    ]
    for path, message in cases:
        rc = main(
            [
                "diagnose",
                "--simulation",
                str(static),
                "--measured",
                str(path),
                "--out",
                str(tmp / "o"),
            ]
        )
        err = capsys.readouterr().err
        assert rc == 2 and message in err and err.count("\n") == 1
        assert not (tmp / "o").exists()


def test_blank_lines_and_comments_are_allowed(setup):
    static, csv, tmp = setup
    lines = csv.read_text().splitlines()
    text = "\n".join(lines[:3] + ["", "# mid-file comment", ""] + lines[3:]) + "\n"
    csv.write_text(text)
    assert (
        main(
            [
                "diagnose",
                "--simulation",
                str(static),
                "--measured",
                str(csv),
                "--out",
                str(tmp / "o"),
            ]
        )
        == 0
    )
