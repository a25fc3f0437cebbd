"""Rough edges of issue 30, one test each: rig globs with the static reference, ``-`` as
standard output, the sweep's trend exponents and its rolling-partner note, the diagnose
lack-of-fit sentence, and the report's provenance, grid phrase and curve figures."""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import fepost.sweep as sweep_pkg
from fepost.cli import main
from fepost.diagnose.summary import summary_text
from fepost.figures.curves import BELOW_ZERO, SPEED_DEFINITIONS, CurveData, plot_curve
from fepost.report.assemble import HASH_DIGITS, shown_input
from fepost.rig import rig_table
from fepost.sweep.trends import fit_power_law, load_trends, trend_lines
from fepost.synthetic import write_map

REPO = Path(__file__).resolve().parents[1]
RIG = REPO / "meshes" / "rig"


def _rig_exports() -> list[Path]:
    return sorted(RIG.glob("*.vtu"))


needs_rig = pytest.mark.skipif(
    not (RIG / "static.vtu").is_file() or len(_rig_exports()) < 3, reason="no rig runs in meshes/rig/"
)


@pytest.fixture
def small_map(tmp_path) -> Path:
    return write_map(tmp_path / "static.vtu", "hertz", radius=0.05, peak=3e5, n_rings=12)


# ---------------------------------------------------------------- rig


@needs_rig
def test_rig_glob_skips_the_static_reference_with_a_note(tmp_path, capsys):
    """``fepost rig meshes/rig/*.vtu`` caught static.vtu (its sidecar has no kinematics): it is
    skipped with a note, every run is a row."""
    runs = [p for p in _rig_exports() if p.name != "static.vtu"][:2]
    given = [str(RIG / "static.vtu"), *map(str, runs)]
    out = tmp_path / "rig.csv"
    assert main(["rig", *given, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"note: {RIG / 'static.vtu'} skipped: its sidecar static.json" in printed
    assert "no kinematics" in printed and "2 runs ->" in printed
    rows = out.read_text().splitlines()
    assert len(rows) == 3 and not any("static.vtu" in r for r in rows)
    table = rig_table(given, shear=False)
    assert [p for p, _ in table.skipped] == [str(RIG / "static.vtu")]
    assert table.to_dict()["skipped"][0]["source"] == str(RIG / "static.vtu")


@needs_rig
def test_rig_of_the_static_reference_alone_is_a_one_line_error(tmp_path, capsys):
    out = tmp_path / "rig.csv"
    assert main(["rig", str(RIG / "static.vtu"), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no slide/spin run among the 1 exports given" in err[0]
    assert not out.exists()


def test_a_run_with_a_faulty_sidecar_is_still_an_error(tmp_path, small_map, capsys):
    """Only a sidecar with neither kinematics nor reaction is skipped; a run missing one of
    them is refused as before."""
    small_map.with_suffix(".json").write_text(json.dumps({"reaction": {"force": [0, 0, 1]}}))
    assert main(["rig", str(small_map), "--out", str(tmp_path / "rig.csv")]) == 2
    assert "missing key 'kinematics'" in capsys.readouterr().err


# ---------------------------------------------------------------- "-" is standard output


def test_coefficients_json_dash_is_standard_output(small_map, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["coefficients", str(small_map), "--json", "-"]) == 0
    cap = capsys.readouterr()
    doc = json.loads(cap.out)  # stdout holds the JSON alone
    assert doc["N"] > 0 and "F0" in doc
    assert "F0" in cap.err  # the human summary went to stderr
    assert not (tmp_path / "-").exists()


@needs_rig
def test_rig_out_dash_is_standard_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    run = next(p for p in _rig_exports() if p.name != "static.vtu")
    assert main(["rig", str(run), "--out", "-"]) == 0
    cap = capsys.readouterr()
    lines = cap.out.splitlines()
    assert lines[0].startswith("vx,vy,wz,Fx,Fy,Mz,N,source") and len(lines) == 2
    assert "1 runs -> standard output" in cap.err
    assert not (tmp_path / "-").exists()


def test_predict_out_dash_is_standard_output(small_map, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    kin = tmp_path / "kin.csv"
    kin.write_text("vx,vy,wz\n0.1,0,0\n0,0,1\n")
    assert main(["predict", str(small_map), "--kinematics", str(kin), "--out", "-"]) == 0
    cap = capsys.readouterr()
    rows = cap.out.splitlines()
    assert len(rows) == 3 and "Fx" in rows[0]
    assert "2 rows -> standard output" in cap.err
    assert not (tmp_path / "-").exists()
    # both data outputs cannot share standard output
    args = ["predict", str(small_map), "--kinematics", str(kin), "--out", "-", "--model-json", "-"]
    assert main(args) == 2
    assert "only one of them can be standard output" in capsys.readouterr().err


def test_a_file_named_dash_is_dot_slash_dash(small_map, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["coefficients", str(small_map), "--json", "./-"]) == 0
    assert json.loads((tmp_path / "-").read_text())["N"] > 0
    assert "F0" in capsys.readouterr().out


@pytest.mark.parametrize("command", ["report", "sweep"])
def test_folders_are_never_standard_output(command, small_map, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main([command, str(small_map), "--out", "-"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot be standard output" in err[0]
    assert not (tmp_path / "-").exists()


# ---------------------------------------------------------------- sweep


def test_trend_lines_state_the_fitted_exponents():
    loads = [1e4, 2e4, 4e4, 8e4]
    fit = fit_power_law(loads, [0.05 * (n / 1e4) ** 0.4 for n in loads], quantity="R", label="R", hertz=1 / 3)
    (line,) = trend_lines([fit])
    assert line.startswith("trend: R ~ N^0.400  (95 % 0.400 to 0.400") and "Hertz 1/3" in line
    (short,) = trend_lines([fit_power_law(loads[:2], [1.0, 2.0], quantity="k_x")])
    assert short == "trend: k_x: no fit, 2 loads: a fit needs 3"


@pytest.mark.slow
def test_sweep_prints_its_trend_exponents_and_names_the_rolling_partner(tmp_path, capsys, monkeypatch):
    """Three Hertz loads and a rolling map written in two formats: the console states the
    exponents the trends page fits, and the rolling map's other format is noted as that (not
    as another file of the static case)."""
    n0, r0 = 1.0e4, 0.05
    for i, load in enumerate((1e4, 2e4, 4e4)):
        radius = r0 * (load / n0) ** (1.0 / 3.0)
        peak = 3 * load / (2 * math.pi * radius**2)
        write_map(tmp_path / f"static_{i}.vtu", "hertz", radius=radius, peak=peak, n_rings=10)
        if i == 1:
            for suffix in (".vtu", ".vtp"):
                write_map(
                    tmp_path / f"rolling_{i}{suffix}", "hertz", radius=radius, peak=peak, k_x=0.1, n_rings=10
                )
    run_sweep = sweep_pkg.run_sweep
    monkeypatch.setattr(sweep_pkg, "run_sweep", lambda *a, **k: run_sweep(*a, processes=False, **k))
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "*.vt?"), "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    rolling = tmp_path / "rolling_1"
    assert f"note: {rolling}.vtu read as the rolling map of {tmp_path / 'static_1.vtu'}" in printed
    assert f"also as {rolling}.vtp (not read)" in printed
    assert "rolling_1.vtu (not read)" not in printed
    fits = {f["quantity"]: f for f in json.loads((out / "trends.json").read_text())["fits"]}
    assert fits["R"]["exponent"] == pytest.approx(1 / 3, abs=0.02)
    for q, label in (("R", "R"), ("M0", "M0"), ("aR2", "a R^2"), ("m_over_R2", "m / R^2")):
        assert f"trend: {label} ~ N^{fits[q]['exponent']:.3f}  (95 % {fits[q]['ci95'][0]:.3f}" in printed
    rows = sweep_pkg.read_table(out / "coefficients.csv")
    assert trend_lines(load_trends(rows))[0] in printed
    row = next(r for r in rows if r["rolling"])
    assert row["also_as"] == "" and row["rolling_also_as"] == f"{rolling}.vtp"


# ---------------------------------------------------------------- diagnose sentence


def _diagnosis(lack_of_fit: dict) -> SimpleNamespace:
    """The parts of a diagnosis that `summary_text` reads, for the simulation's own fit."""
    stats = {"verdict": "ok", "rmse": 1.0, "strongest": "none", "p_adjusted": 0.5}
    return SimpleNamespace(
        cause="none",
        causes=["none"],
        gain={"rmse_before": 1.0, "rmse_after": 1.0, "delta_bic": 0.0},
        info={},
        holds=None,
        lack_of_fit=lack_of_fit,
        robust={},
        outliers=[],
        noise={},
        pairs=None,
        separation=[],
        indistinguishable=[],
        design_notes=[],
        residuals={k: dict.fromkeys(("Fx", "Fy", "Mz"), stats) for k in ("before", "after")},
        closed_form={"rmse_vs_data": 1.0, "rmse_vs_exact": 0.1, "exact_rmse_vs_data": 1.0},
        candidates=[],
    )


def test_lack_of_fit_p_value_is_not_attached_to_the_drift_clause():
    """The strongest test's p-value (here Fy's residual structure) is stated with its test in a
    sentence of its own, not in parentheses after "do not drift with run order"."""
    lof = {
        "detected": False,
        "message": "no structure left beyond the noise: the residuals do not drift with run order",
        "test": "residual structure of Fy (F-test on the predicted Fx, Fy, Mz)",
        "p_value": 0.31,
    }
    (line,) = [s for s in summary_text(_diagnosis(lof)).splitlines() if s.startswith("lack of fit")]
    assert line == (
        "lack of fit: none: no structure left beyond the noise: the residuals do not drift with run "
        "order. Strongest test: residual structure of Fy (F-test on the predicted Fx, Fy, Mz), Holm p = 0.31"
    )


# ---------------------------------------------------------------- Figures 4-6


def _curve(**kw) -> CurveData:
    x = np.linspace(0.0, 5.0, 11)
    base = dict(
        name="M_C",
        title="Figure 5: friction torque M_C against υ = v/u",
        x_name="upsilon",
        x_label="υ = v / (ω_z R)",
        y_label="M_C (N·m)",
        unit="N·m",
        x=x,
        closed_form=1 / np.sqrt(1 + x**2),
        exact=1 / np.sqrt(1 + 1.1 * x**2),
        fit=1 / np.sqrt(1 + x**2),
        band_lo=1 / np.sqrt(1 + x**2) - 0.1,
        band_hi=1 / np.sqrt(1 + x**2) + 0.1,
        test_x=np.linspace(0, 5, 7),
        test_y=np.linspace(1.0, -0.05, 7),
    )
    base.update(kw)
    return CurveData(**base)


def _legend(fig) -> dict[str, str]:
    """Legend texts of the test points and the band, by series."""
    texts = [t.get_text() for t in fig.legends[0].get_texts()]  # the figure's legend, below the axes
    return {
        "test": next(t for t in texts if "test points" in t),
        "band": next(t for t in texts if "prediction band" in t),
    }


def test_curve_figures_define_u_and_v_under_the_speed_ratio_axis():
    import matplotlib.pyplot as plt

    for x_name in ("psi", "upsilon"):
        fig = plot_curve(_curve(x_name=x_name))
        label = fig.axes[0].xaxis.label.get_text()
        assert label.endswith("\n" + SPEED_DEFINITIONS)
        assert r"u = \omega_z R" in label and "sliding speed" in label
        plt.close(fig)
    fig = plot_curve(_curve(x_name="t"))  # another abscissa: no speed definitions
    assert SPEED_DEFINITIONS not in fig.axes[0].xaxis.label.get_text()
    plt.close(fig)


def test_curve_figures_say_the_points_are_synthetic_and_why_they_cross_zero():
    """Points and band reaching below zero while the noise-free curves do not: the legend says
    the additive noise takes them there; the band is drawn as computed (not clipped)."""
    import matplotlib.pyplot as plt

    c = _curve()
    fig = plot_curve(c)
    legend = _legend(fig)
    assert legend["test"].startswith("synthetic test points (the paper's 20 % noise)")
    assert legend["test"].endswith(BELOW_ZERO) and legend["band"].endswith(BELOW_ZERO)
    band = next(col for col in fig.axes[0].collections if col.get_gid() == "band")
    assert band.get_paths()[0].vertices[:, 1].min() == pytest.approx(float(c.band_lo.min()))
    plt.close(fig)
    # all above zero: no such words
    fig = plot_curve(_curve(test_y=np.linspace(1.0, 0.05, 7), band_lo=np.full(11, 0.01)))
    assert not any(BELOW_ZERO in t for t in _legend(fig).values())
    plt.close(fig)
    # a curve that itself goes below zero: the noise is not the reason, nothing is said
    fig = plot_curve(_curve(closed_form=np.linspace(1.0, -0.5, 11)))
    assert not any(BELOW_ZERO in t for t in _legend(fig).values())
    plt.close(fig)


# ---------------------------------------------------------------- report


def test_provenance_names_inputs_relative_or_by_name_with_a_hash(tmp_path, monkeypatch):
    inside = tmp_path / "work" / "maps"
    inside.mkdir(parents=True)
    data = inside / "a.vtu"
    data.write_bytes(b"fepost provenance")
    digest = hashlib.sha256(b"fepost provenance").hexdigest()[:HASH_DIGITS]
    monkeypatch.chdir(tmp_path / "work")
    assert shown_input(data) == (str(Path("maps") / "a.vtu"), digest)  # absolute, inside the cwd
    assert shown_input("maps/a.vtu") == (str(Path("maps") / "a.vtu"), digest)
    monkeypatch.chdir(inside)
    assert shown_input(tmp_path / "work" / "maps" / "a.vtu")[0] == "a.vtu"
    other = tmp_path / "elsewhere"
    other.mkdir()
    monkeypatch.chdir(other)
    assert shown_input(data) == ("a.vtu", digest)  # outside the cwd: the file name only
    assert shown_input(other / "missing.vtu") == ("missing.vtu", "")


@pytest.mark.slow
def test_report_provenance_and_grid_phrase(analytic_report):
    """A report on maps outside the working folder: the provenance table names them by file name
    and hash, never by their absolute path; the model rows' grid is said once."""
    static, rolling, out = analytic_report
    html = (out / "report.html").read_text(encoding="utf-8")
    table = html.split('<h2 id="inputs">', 1)[1].split("</table>", 1)[0]
    for path in (static, rolling):
        sha = hashlib.sha256(path.read_bytes()).hexdigest()[:HASH_DIGITS]
        assert f"<code>{path.name}</code> (SHA-256 {sha}…)" in table
    assert str(static.parent) not in table
    assert html.count("the densest evaluated") == 1
    assert "; the largest errors over the error map&#39;s grid, the densest evaluated" in html


def test_table1_json_dash_is_standard_output(small_map, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["table1", "--static", str(small_map), "--json", "-", "--n-points", "20"]) == 0
    cap = capsys.readouterr()
    doc = json.loads(cap.out)
    assert doc["inputs"]["static"] == str(small_map)
    assert "static map:" in cap.err and not (tmp_path / "-").exists()
