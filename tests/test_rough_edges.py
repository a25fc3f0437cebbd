"""The rough edges a new user met: the error map's heading, the sweep's legends,
Figure 3's r_max lines, the model builder without its extra."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from fepost.figures.errormap import plot_error_map  # noqa: E402
from fepost.figures.section import diameter_sections, plot_sections  # noqa: E402
from fepost.friction.sphere import ErrorMap  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
#: Smallest text (pixels on screen) the report may show.
READABLE_PX = 12.0


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _error_map(source: str) -> ErrorMap:
    beta, t = np.linspace(0, 180, 5), np.linspace(0, 1, 7)
    b, tt = np.meshgrid(beta, t, indexing="ij")
    paper = 0.2 * np.sin(np.pi * tt) + 0.01
    model = 0.01 * np.sin(np.pi * tt) * (1 + b / 180)
    return ErrorMap(
        beta, t, {"paper": paper, "model": model}, {"paper": paper, "model": model}, 1.0, 1.0, 0.1, source
    )


DEEP = "/home/someone/projects/landing-gear/fe-runs/2026-11-25/tire-model-B/static_rated_load_100_percent.vtu"


@pytest.mark.parametrize("names", [("paper", "model"), ("model",)])
def test_error_map_title_names_the_file_and_fits(names):
    fig = plot_error_map(_error_map(DEEP), names=names)
    title = fig._suptitle
    assert title.get_text() == (
        "Error over the kinematic sphere, both spin signs\nstatic_rated_load_100_percent.vtu"
    )
    assert "/home" not in title.get_text() and "fe-runs" not in title.get_text()
    fig.canvas.draw()
    box, page = title.get_window_extent(), fig.bbox
    assert page.x0 <= box.x0 and box.x1 <= page.x1 and box.y1 <= page.y1, (box, page)


def test_error_map_title_wraps_a_long_file_name():
    name = "a_very_long_file_name_of_a_parametric_study_case_with_many_settings_017.vtu"
    fig = plot_error_map(_error_map(f"/data/{name}"), names=("model",))
    lines = fig._suptitle.get_text().split("\n")
    assert len(lines) >= 3 and "".join(lines[1:]) == name
    fig.canvas.draw()
    assert fig.bbox.x0 <= fig._suptitle.get_window_extent().x0
    assert fig._suptitle.get_window_extent().x1 <= fig.bbox.x1


def test_error_map_without_source_has_no_file_line():
    fig = plot_error_map(_error_map(""))
    assert fig._suptitle.get_text() == "Error over the kinematic sphere, both spin signs"


def _report_image_width() -> float:
    css = (REPO / "fepost" / "report" / "templates" / "style.css").read_text()
    return float(re.search(r"figure img\{max-width:min\(100%,(\d+)px\)", css).group(1))


def test_load_trend_legends_are_readable_in_the_report(tmp_path):
    """The legend text of the load-trend figure, as the report shows the PNG (at most the
    style sheet's image width), is at least READABLE_PX pixels high."""
    from test_sweep_trends import hertz_rows

    from fepost.report.sweeppage import draw_figures
    from fepost.sweep.trends import load_trends

    rows = hertz_rows([1e4, 2e4, 4e4, 8e4])
    for k, r in enumerate(rows):
        r["k_x"] = 0.1 + 0.01 * k
    fits = load_trends(rows)
    from fepost.figures.sweep import plot_load_trends

    fig = plot_load_trends(rows, fits)
    sizes = [t.get_fontsize() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    width_in = fig.get_figwidth()
    plt.close(fig)
    assert sizes
    draw_figures(rows, fits, tmp_path)  # the PNG exactly as the page and the report embed it
    width_px = mpimg.imread(tmp_path / "load_trends.png").shape[1]
    shown = min(1.0, _report_image_width() / width_px)
    px_per_pt = width_px / width_in / 72.0
    assert min(sizes) * px_per_pt * shown >= READABLE_PX, (min(sizes), width_px)


def test_figure3_draws_the_rolling_radius_the_rolling_curve_reaches(aircraft):
    sec = diameter_sections(aircraft.static_patch, aircraft.rolling_patch)
    R, R_rolling = aircraft.static_patch.r_max, aircraft.rolling_patch.r_max
    assert sec.R == R and sec.R_rolling == R_rolling
    # the rolling map is loaded beyond the static R, in the static patch's frame
    beyond = np.abs(sec.s) > 1.01 * R
    assert np.any(sec.rolling_x[beyond] > 0)
    rolling_xy = aircraft.rolling_patch.xy
    assert R_rolling == pytest.approx(float(np.max(np.hypot(rolling_xy[:, 0], rolling_xy[:, 1]))), rel=1e-12)
    assert np.all(sec.rolling_x[np.abs(sec.s) > 1.001 * R_rolling] == 0.0)  # and not past its own r_max
    fig = plot_sections(sec)
    lines = {ln.get_gid(): ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid()}
    for axis in ("x", "y"):
        assert lines[f"rmax_{axis}_minus"].get_xdata()[0] == -R
        assert lines[f"rmax_{axis}_plus"].get_xdata()[0] == R
        assert lines[f"rmax_rolling_{axis}_minus"].get_xdata()[0] == -R_rolling
        assert lines[f"rmax_rolling_{axis}_plus"].get_xdata()[0] == R_rolling
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == [
        "static",
        "rolling",
        "±R = r_max, static (the R of the coefficients)",
        "±r_max, rolling map",
    ]
    assert sec.to_dict()["R_rolling"] == R_rolling


def test_figure3_static_only_draws_one_radius(aircraft):
    sec = diameter_sections(aircraft.static_patch)
    assert sec.R_rolling is None and "R_rolling" not in sec.to_dict()
    fig = plot_sections(sec)
    gids = {ln.get_gid() for ax in fig.axes for ln in ax.get_lines()}
    assert "rmax_x_plus" in gids and not any(g and g.startswith("rmax_rolling") for g in gids)


def test_model_builder_without_gmsh_names_the_extra(monkeypatch, capsys, tmp_path):
    """Tutorial step 1 after `make demo` (no 'model' extra): one line that says what to install."""
    import sys

    from scripts.tiremodel import __main__ as tiremodel

    monkeypatch.setitem(sys.modules, "gmsh", None)  # as if gmsh were not installed
    monkeypatch.setattr(tiremodel, "find_ccx", lambda: "ccx")  # the solver is not what is missing
    code = tiremodel.main(["build", "--case", "static", "--coarse", "--out", str(tmp_path / "tire")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and err[-1] == (
        "tiremodel: error: no Python module 'gmsh': install the model extra: pip install -e '.[model]'"
    )
    assert not (tmp_path / "tire").exists()
