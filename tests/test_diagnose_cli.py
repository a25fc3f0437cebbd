"""``fepost diagnose`` in-process: outputs and their keys, example data, bad input, atomic folders."""

from __future__ import annotations

import json
from importlib import import_module
from pathlib import Path

import pytest

from fepost.analysis import analyse
from fepost.cli import main
from fepost.diagnose.measured import write_csv
from fepost.diagnose.synthetic import synthesize
from fepost.synthetic import write_map

CAUSES = {
    "none", "friction_level", "pressure_dependent_friction", "speed_dependent_friction",
    "elliptic_patch", "anisotropic_friction", "pressure_shift", "sensor_offset", "sensor_crosstalk",
    "load_transfer", "pressure_shape",
}  # fmt: skip


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A Hertz map and 120 rows measured on it with a pressure shift, written once for the
    module (no test changes them)."""
    folder = tmp_path_factory.mktemp("inputs")
    static = write_map(folder / "static.vtu", "hertz", radius=0.1, peak=3e5)
    a = analyse(static, friction=0.3)
    syn = synthesize(a.static_map, "pressure_shift", {"dx": 0.004, "dy": 0.0}, n=120, seed=3)
    csv = folder / "meas.csv"
    write_csv(syn.data, csv, comment="synthetic: pressure shift dx = 4 mm")
    return static, csv


@pytest.fixture
def setup(inputs, tmp_path):
    """``(static map, measured CSV, a folder of the test's own for what it writes)``."""
    return (*inputs, tmp_path)


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
    assert d["causes"] == ["pressure_shift"]
    lof = d["lack_of_fit"]
    assert {"detected", "p_value", "test", "message"} <= set(lof)
    assert lof["detected"] is False and 0.0 <= lof["p_value"] <= 1.0 and lof["message"]
    assert d["outliers"] == [] and isinstance(d["outliers"], list)
    assert {d["noise_model"][c]["model"] for c in ("Fx", "Fy", "Mz")} <= {
        "constant",
        "proportional",
        "combined",
    }
    summary = (out / "summary.txt").read_text()
    assert summary.startswith("cause: pressure_shift\n")
    assert "lack of fit: none: no structure left beyond the noise" in summary
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
    csv = tmp / "meas.csv"  # the module's CSV stays as it is
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


def test_outliers_and_two_causes_reach_the_json(tmp_path, analytic_mesh):
    static = analytic_mesh("static.vtu", "hertz", radius=0.1, peak=3e5)
    a = analyse(static, friction=0.3)
    syn = synthesize(
        a.static_map, ("anisotropic_friction", "sensor_offset"),
        {"alpha": 1.2, "offset_Fx": 150.0, "offset_Fy": -100.0, "offset_Mz": 5.0}, n=200, seed=4, outliers=3,
    )  # fmt: skip
    csv = tmp_path / "meas.csv"
    write_csv(syn.data, csv)
    out = tmp_path / "out"
    assert main(["diagnose", "--simulation", str(static), "--measured", str(csv), "--out", str(out)]) == 0
    d = json.loads((out / "diagnosis.json").read_text())
    assert sorted(d["causes"]) == ["anisotropic_friction", "sensor_offset"] and d["cause"] == d["causes"][0]
    assert set(d["parameters"]) == {"f", "alpha", "offset_Fx", "offset_Fy", "offset_Mz"}
    assert {p["cause"] for p in d["parameters"].values()} == {"friction_level", *d["causes"]}
    assert d["outliers"] == list(syn.outliers) and d["outlier_lines"] == [i + 2 for i in syn.outliers]
    assert d["gain"]["model"] == "+".join(d["causes"])
    assert "causes: " + ", ".join(d["causes"]) in (out / "summary.txt").read_text()


def test_make_example_writes_documented_data_that_diagnose_explains(tmp_path, analytic_mesh, capsys):
    """The example command's plumbing: file, header, a diagnosis that finds the hidden cause.

    Seed 2, not 3: at seed 3 the anisotropy candidate passes its nesting test by
    chance on these data (p = 0.0069 against the 0.05/7 = 0.0071 level; 1 in 140
    per candidate, measured by benchmarks/bench_false_positive.py for the rule
    as a whole), which is the rule working as designed, not what this test is about.
    """
    static = analytic_mesh("static.vtu", "hertz", radius=0.1, peak=3e5)
    csv = tmp_path / "example.csv"
    args = ["diagnose", "--make-example", str(csv), "--simulation", str(static), "--cause", "friction_level"]
    assert main([*args, "--seed", "2"]) == 0
    assert f"written: {csv} (300 test points, hidden cause friction_level, seed 2" in capsys.readouterr().out
    text = csv.read_text()
    assert "# Hidden cause: friction_level (f = 0.255)." in text
    assert f"--simulation {static} --cause friction_level --seed 2" in text
    assert (
        main(["diagnose", "--simulation", str(static), "--measured", str(csv), "--out", str(tmp_path / "o")])
        == 0
    )
    d = json.loads((tmp_path / "o" / "diagnosis.json").read_text())
    assert d["cause"] == "friction_level"
    lo, hi = d["parameters"]["f"]["ci95"]
    assert lo <= 0.255 <= hi
    capsys.readouterr()
    # an existing file needs --force; --make-example does not mix with --measured
    assert main([*args, "--seed", "2"]) == 2
    assert capsys.readouterr().err.strip() == f"fepost: error: {csv}: file exists (use --force to replace it)"
    assert main([*args, "--measured", str(csv), "--force"]) == 2
    assert "--make-example writes data and stops" in capsys.readouterr().err


def test_cli_cause_names_are_the_vocabulary():
    import fepost.diagnose
    from fepost.cli.diagnose import CAUSES as offered
    from fepost.diagnose.causes import CAUSES, MEANING

    assert offered is CAUSES is fepost.diagnose.CAUSES and set(MEANING) == set(CAUSES)
    assert fepost.diagnose.diagnose is import_module("fepost.diagnose.pipeline").diagnose
    assert {"diagnose", "read_measured", "Diagnosis"} <= set(dir(fepost.diagnose))
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        fepost.diagnose.nope  # noqa: B018


ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
@pytest.mark.skipif(
    not (ROOT / "meshes" / "static.vtu").is_file(), reason="sample mesh meshes/static.vtu absent"
)
def test_shipped_example_is_reproducible_and_diagnosed(tmp_path, documented_page):
    """examples/measured_example.csv is what its header says: the documented command remakes it,
    and diagnose finds the documented cause, its parameter and the three gross errors (the
    diagnosis docs/diagnose.md shows, made once per session for the page and this test)."""
    import numpy as np

    from fepost.diagnose.example import EXAMPLE_SEED
    from fepost.diagnose.measured import read_measured

    shipped = ROOT / "examples" / "measured_example.csv"
    head = [line for line in shipped.read_text().splitlines() if line.startswith("#")]
    assert "# Hidden cause: pressure_dependent_friction (c_p = 0.25)." in head
    assert any(f"--cause pressure_dependent_friction --seed {EXAMPLE_SEED}" in line for line in head)
    again = tmp_path / "again.csv"
    static = ROOT / "meshes" / "static.vtu"
    assert main(["diagnose", "--make-example", str(again), "--simulation", str(static)]) == 0
    a, b = read_measured(shipped), read_measured(again)
    for col in ("vx", "vy", "wz", "Fx", "Fy", "Mz", "N"):
        np.testing.assert_allclose(getattr(a, col), getattr(b, col), rtol=1e-8, atol=1e-9)
    rows = next(line for line in head if "gross errors" in line)
    planted = [int(x) for x in rows.split("data rows ")[1].split(" (")[0].split(", ")]
    page = documented_page("docs/diagnose.md")
    page.stderr_of(SHIPPED_DIAGNOSIS)  # the page ran this very command (KeyError if not)
    d = json.loads((page.folder / "out" / "diagnosis" / "diagnosis.json").read_text())
    assert d["causes"] == ["pressure_dependent_friction"]
    lo, hi = d["parameters"]["c_p"]["ci95"]
    assert lo <= 0.25 <= hi
    assert d["outliers"] == planted
    assert d["lack_of_fit"]["detected"] is False


#: The command of docs/diagnose.md that diagnoses the shipped example.
SHIPPED_DIAGNOSIS = (
    "fepost diagnose --simulation meshes/static.vtu --measured examples/measured_example.csv"
    " --out out/diagnosis"
)


def _table(rows, header="vx,vy,wz,Fx,Fy,Mz"):
    return header + "\n" + "".join(rows)


def _programme(n=40, **over):
    """n distinct plausible rows (for checks that come after parsing)."""
    import numpy as np

    ang = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    cols = {"vx": np.cos(ang), "vy": np.sin(ang), "wz": np.linspace(-3, 3, n), "Fx": -200 * np.cos(ang),
            "Fy": -200 * np.sin(ang), "Mz": np.linspace(-5, 5, n)}  # fmt: skip
    cols.update(over)
    names = list(cols)
    return (
        ",".join(names)
        + "\n"
        + "".join(",".join(f"{cols[k][i]:.6g}" for k in names) + "\n" for i in range(n))
    )


BAD = [
    ("", "no header row: the file is empty or only comments", None),
    ("vx,vy,wz,Fx,Fy\n" + "1,0,0,-1,0\n" * 30, "missing column(s) Mz in the header", None),
    (_table(["0.1,0,0,-900,1,nan\n"]), "line 2, column Mz: not a finite number: 'nan'", None),
    (_table(["0.1,0,0,-900,1,-inf\n"]), "line 2, column Mz: not a finite number: '-inf'", None),
    (_table(["0.1,0,0,-900,one,0\n"]), "line 2, column Fy: not a number: 'one'", None),
    (
        _table(["0.1,0,0,-900,1," + "7" * 140_000 + "\n"]),
        "line 2: a cell is longer than 131072 characters",
        None,
    ),
    (_table(["0.1,0,0,-900,1,0,x\n"], "vx,vy,wz,Fx,Fy,Mz,note"), None, "ok-ignored"),
    (
        _table(["0.1,0,0,-900,1,0,soon\n"], "vx,vy,wz,Fx,Fy,Mz,time"),
        "line 2, column time: not a number: 'soon'",
        None,
    ),
    (_table(["0.3,0.1,2,-900,10,5\n"] * 40), "every row is the same test point", None),
    (
        _table(["0,0,0,-900,10,5\n"] * 40),
        "columns vx, vy, wz are zero in every row: nothing slides or spins",
        None,
    ),
    (_programme(Mz=[3.0] * 40), "column Mz has the same value in every row", None),
    (_programme(n=5001), "5001 data rows: diagnose takes at most 5000 test points", None),
    (
        "vx,vy,wz,Fx,Fy,Mz\n" + "0.1,0,1,-900,1,2\n" * 1_000_000,
        "1000000 data rows: diagnose takes at most",
        None,
    ),
]


@pytest.mark.parametrize(("text", "message", "note"), BAD, ids=lambda v: None)
def test_every_bad_csv_is_a_one_line_error_naming_the_file(setup, capsys, text, message, note):
    static, _, tmp = setup
    if note == "ok-ignored":
        return  # other columns are ignored (a parsing case, covered in test_diagnose_measured)
    bad = tmp / "bad.csv"
    bad.write_text(text)
    rc = main(["diagnose", "--simulation", str(static), "--measured", str(bad), "--out", str(tmp / "o")])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.count("\n") == 1 and err.startswith(f"fepost: error: {bad}: "), err[:300]
    assert message in err
    assert "Traceback" not in err and not (tmp / "o").exists()


def test_bad_options_and_paths_are_one_line_errors(setup, capsys):
    static, csv, tmp = setup
    base = ["diagnose", "--simulation", str(static)]
    cases = [
        (
            [*base, "--measured", str(csv), "--out", str(tmp / "o"), "--seed", "-1"],
            "argument --seed: must be an integer >= 0",
        ),
        (
            [*base, "--measured", str(csv), "--out", str(tmp / "o"), "--folds", "1"],
            "argument --folds",
        ),
        ([*base, "--measured", str(tmp)], "--out required"),
        ([*base, "--out", str(tmp / "o")], "--measured required"),
        (
            [*base, "--measured", str(tmp), "--out", str(tmp / "o")],
            "is a folder, not a measured-data CSV file",
        ),
        ([*base, "--measured", str(tmp / "none.csv"), "--out", str(tmp / "o")], "none.csv: no such file"),
    ]
    for args, message in cases:
        assert main(args) == 2, args
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and message in err, err
        assert not (tmp / "o").exists()
