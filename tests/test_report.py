"""``fepost report``: every promised file, an HTML that matches the JSON, clean failures."""

from __future__ import annotations

import base64
import csv
import json
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from fepost.cli import main
from fepost.report.samples import SAMPLE_ROLLING, SAMPLE_STATIC, meshes_folder
from fepost.synthetic import write_map
from fepost.table1 import DEFAULT_SEED

REPO = Path(__file__).resolve().parents[1]


def sample_paths():
    """The report's default inputs (named in one place: fepost.report.samples)."""
    return (
        meshes_folder() / SAMPLE_STATIC,
        None if SAMPLE_ROLLING is None else meshes_folder() / SAMPLE_ROLLING,
    )


SAMPLES = tuple(p for p in sample_paths() if p is not None)
PROMISED = (
    "report.html",
    "coefficients.json",
    "table1.json",
    "closed_form_vs_exact.json",
    "curves.csv",
    "fig1_static.png",
    "fig2_rolling.png",
    "patch_plan.png",
    "patch_plan.svg",
    "patch_plan.pdf",
    *(
        f"{stem}.{ext}"
        for stem in ("fig3_sections", "fig4_f_parallel", "fig5_torque", "fig6_f_perp")
        for ext in ("png", "svg", "pdf")
    ),
    *(f"{m}_{part}" for m in ("static", "rolling") for part in ("map.vtu", "patch.vtp", "outline.vtp")),
)
NNBSP = "\u202f"
TABLE1_NAMES = ["f", "F0", "M0", "a", "m", "k_x"]


class _Page(HTMLParser):
    """Links, images (src, alt) and the numbers tagged with data-key / data-value."""

    def __init__(self):
        super().__init__()
        self.refs: list[str] = []
        self.images: list[tuple[str, str]] = []
        self.values: dict[str, float] = {}
        self.text: list[str] = []
        self._skip = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("style", "script"):
            self._skip += 1
        if tag == "img":
            self.images.append((a.get("src", ""), a.get("alt", "")))
        elif a.get("href"):
            self.refs.append(a["href"])
        if "data-key" in a:
            self.values[a["data-key"]] = float(a["data-value"])

    def handle_endtag(self, tag):
        if tag in ("style", "script"):
            self._skip -= 1

    def handle_data(self, data):
        if not self._skip:
            self.text.append(data)


def _page(out: Path) -> _Page:
    page = _Page()
    page.feed((out / "report.html").read_text(encoding="utf-8"))
    return page


def _lookup(data, dotted: str):
    for part in dotted.split("."):
        data = data[int(part)] if isinstance(data, list) else data[part]
    return data


def _inputs(tmp_path) -> list[str]:
    """The shipped sample meshes when they exist, else analytic stand-ins."""
    if all(p.is_file() for p in SAMPLES):
        return []
    s = write_map(tmp_path / "static.vtu", "tire", radius=0.15, peak=6e5, n_rings=24)
    r = write_map(tmp_path / "rolling.vtu", "tire", radius=0.15, peak=6e5, k_x=0.13, n_rings=24)
    return [str(s), str(r)]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    out = tmp / "rep"
    import io
    from contextlib import redirect_stderr

    err = io.StringIO()
    inputs = _inputs(tmp)
    with redirect_stderr(err):
        code = main(["report", *inputs, "--out", str(out), "--seed", "3"])
    return code, out, err.getvalue(), inputs


@pytest.mark.slow
def test_report_writes_every_promised_file(report):
    code, out, _, _ = report
    assert code == 0
    for name in PROMISED:
        assert (out / name).is_file(), name
        assert (out / name).stat().st_size > 0, name
    assert not [p.name for p in out.parent.iterdir() if p.name.startswith(".")], (
        "temporary folder left behind"
    )


@pytest.mark.slow
def test_report_progress_lines(report):
    _, _, err, _ = report
    lines = err.strip().splitlines()
    steps = [ln for ln in lines if ln.startswith("[")]
    assert steps and all(re.fullmatch(r"\[\d+/\d+\] .+ \.\.\. done in \d+\.\d s", ln) for ln in steps)
    assert steps[-1].startswith(f"[{len(steps)}/{len(steps)}]")


@pytest.mark.slow
def test_report_html_references_only_existing_files(report):
    _, out, _, _ = report
    page = _page(out)
    assert page.refs
    for ref in page.refs:
        assert not re.match(r"^[a-z]+:", ref), f"external reference {ref}"
        assert (out / ref).is_file(), ref


@pytest.mark.slow
def test_report_html_is_self_contained(report):
    """Every image is embedded (a data: URI holding exactly the PNG written beside the
    page), so report.html shows everything on its own; alt texts are plain text."""
    _, out, _, _ = report
    page = _page(out)
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert len(page.images) == len(pngs) == 7
    embedded = {}
    for src, alt in page.images:
        assert src.startswith("data:image/png;base64,"), src[:40]
        embedded[base64.b64decode(src.split(",", 1)[1])] = alt
        assert alt and "<" not in alt and "&" not in alt and "$" not in alt, alt
    assert set(embedded) == {(out / name).read_bytes() for name in pngs}
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "<link" not in html and "<script" not in html


@pytest.mark.slow
def test_report_units_one_style(report):
    """SI units with N·m (never "N m"), lengths in m (no mm), a narrow no-break space
    between every number and its unit, and the R line reads R = r_max = <value> m."""
    _, out, _, _ = report
    page = _page(out)
    text = "".join(page.text)
    assert "N m" not in text and "Nm" not in text
    assert not re.search(r"\dmm|\d mm|\(mm\)", text)
    loose = re.findall(r"\d (?:N·m|kPa|MPa|Pa|m²|m|N|s)(?![\w²])", text)
    assert not loose, loose[:5]
    coef = json.loads((out / "coefficients.json").read_text())
    r_line = re.search(r"R used\s*R = r_max = ([0-9.]+)" + NNBSP + r"m: smallest circle", text)
    assert r_line and float(r_line.group(1)) == pytest.approx(coef["R"], rel=1e-3)
    assert "THEORY.md" not in text and "INTERFACE.md" not in text and "shared/" not in text


@pytest.mark.slow
def test_report_vtk_files(report):
    """The VTK files hold the polar maps and the patches: read back with pyvista and,
    independently, meshio, they integrate to N and draw R, r_equiv and the ellipse."""
    import meshio
    import pyvista as pv

    _, out, _, _ = report
    coef = json.loads((out / "coefficients.json").read_text())
    grid = pv.read(out / "static_map.vtu")
    n = float(np.sum(grid.point_data["sigma"] * grid.point_data["dA"]))
    assert n == pytest.approx(coef["N"], rel=1e-12)
    m = meshio.read(out / "static_map.vtu")
    assert float(np.sum(m.point_data["sigma"] * m.point_data["dA"])) == pytest.approx(coef["N"], rel=1e-12)
    assert float(grid.field_data["R"][0]) == coef["R"]
    np.testing.assert_allclose(grid.field_data["frame_origin"], coef["patch"]["centre"], rtol=1e-12)
    rolling = pv.read(out / "rolling_map.vtu")
    n_roll = float(np.sum(rolling.point_data["sigma"] * rolling.point_data["dA"]))
    assert n_roll == pytest.approx(coef["N_rolling"], rel=1e-12)
    lines = pv.read(out / "static_outline.vtp")
    names = list(lines.field_data["part_names"])
    part = np.asarray(lines.cell_data["part"])

    def radii(name, centre=(0.0, 0.0)):
        cells = lines.extract_cells(np.flatnonzero(part == names.index(name)))
        return np.hypot(cells.points[:, 0] - centre[0], cells.points[:, 1] - centre[1])

    np.testing.assert_allclose(radii("circle_R"), coef["R"], rtol=1e-12)
    np.testing.assert_allclose(
        radii("circle_r_equiv", coef["patch"]["ellipse_centre"]), coef["patch"]["r_equiv"]
    )
    ell = radii("ellipse", coef["patch"]["ellipse_centre"])
    assert ell.max() == pytest.approx(coef["patch"]["ellipse_semi_axes"][0], rel=1e-4)
    assert ell.min() == pytest.approx(coef["patch"]["ellipse_semi_axes"][1], rel=1e-4)
    assert radii("outline").max() == pytest.approx(coef["R"], rel=1e-12)
    patch = pv.read(out / "static_patch.vtp")
    assert patch.n_cells == coef["patch"]["n_faces"]
    assert float(np.max(patch.point_data["pressure"])) > 0


@pytest.mark.slow
def test_report_numbers_equal_the_json(report):
    _, out, _, _ = report
    page = _page(out)
    sources = {
        name: json.loads((out / f"{name}.json").read_text())
        for name in ("coefficients", "table1", "closed_form_vs_exact")
    }
    checked = 0
    for key, value in page.values.items():
        src, path = key.split(".", 1)
        assert value == _lookup(sources[src], path), key
        checked += 1
    coef = sources["coefficients"]
    for key in ("N", "R", "F0", "M0", "a", "m", "k_x"):
        assert page.values[f"coefficients.{key}"] == coef[key]
    for i in range(6):
        for part in ("theory", "fitted", "ci95.0", "ci95.1"):
            assert f"table1.rows.{i}.{part}" in page.values
    for curve in ("f_parallel", "torque", "f_perp"):
        assert f"closed_form_vs_exact.{curve}.max_abs_relative" in page.values
    assert checked >= 40


@pytest.mark.slow
def test_report_json_contract(report):
    _, out, _, _ = report
    coef = json.loads((out / "coefficients.json").read_text())
    for key in ("N", "R", "A", "F0", "M0", "a", "m", "b", "b1", "f", "k_x", "x_c", "N_fe", "patch"):
        assert key in coef, key
    t1 = json.loads((out / "table1.json").read_text())
    assert [r["name"] for r in t1["rows"]] == TABLE1_NAMES
    for r in t1["rows"]:
        lo, hi = r["ci95"]
        assert lo <= r["fitted"] <= hi
    assert t1["rows"][1]["theory"] == coef["F0"]
    assert t1["rows"][5]["theory"] == coef["k_x"]


@pytest.mark.slow
def test_report_curves_csv_matches_the_fit(report):
    _, out, _, _ = report
    with open(out / "curves.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    figures = {r["figure"] for r in rows}
    assert figures == {"F_parallel", "M_C", "F_perp"}
    for fig in figures:
        series = {r["series"] for r in rows if r["figure"] == fig}
        assert series == {"exact", "closed_form", "fit", "band_lo", "band_hi", "test"}
    # The closed form at υ = 0 is M0 exactly.
    coef = json.loads((out / "coefficients.json").read_text())
    m0 = [float(r["value"]) for r in rows if r["figure"] == "M_C" and r["series"] == "closed_form"][0]
    assert m0 == pytest.approx(coef["M0"], rel=1e-12)


@pytest.mark.slow
def test_report_refuses_non_empty_folder_without_force(report, capsys):
    _, out, _, inputs = report
    before = sorted(p.name for p in out.iterdir())
    code = main(["report", *inputs, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err == f"fepost: error: {out}: folder exists and is not empty (use --force to replace it)\n"
    assert sorted(p.name for p in out.iterdir()) == before


@pytest.mark.slow
def test_report_table1_json_is_fepost_table1(report, tmp_path):
    """The report's table1.json is Table1.to_dict() (what fepost table1 --json writes,
    less its "inputs"), for the same inputs and seed."""
    _, out, _, inputs = report
    sample = ["--static", inputs[0], "--rolling", inputs[1]] if inputs else []
    cli_json = tmp_path / "t1.json"
    assert main(["table1", *sample, "--seed", "3", "--json", str(cli_json)]) == 0
    expected = json.loads(cli_json.read_text())
    assert expected.pop("inputs")
    assert json.loads((out / "table1.json").read_text()) == expected


@pytest.mark.slow
def test_report_figures_show_the_table1_fit(report):
    """Figures 4-6 plot Table 1's own fit (no second fit): at psi = upsilon = 0 each
    fitted closed form equals its fitted amplitude in table1.json, inside its band."""
    _, out, _, _ = report
    t1 = json.loads((out / "table1.json").read_text())
    with open(out / "curves.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    p = {k: v["value"] for k, v in t1["fit"]["parameters"].items()}
    amplitude = {
        "F_parallel": p["F0"],
        "M_C": p["M0"],
        "F_perp": p["k_x"] * p["M0"] / (2 * t1["settings"]["R"]),
    }
    for fig, expected in amplitude.items():

        def series(name, fig=fig):
            return [
                (float(r["x"]), float(r["value"])) for r in rows if r["figure"] == fig and r["series"] == name
            ]

        fit, lo, hi = series("fit"), series("band_lo"), series("band_hi")
        assert fit[0] == (0.0, pytest.approx(expected, rel=1e-12)), fig
        assert all(a[1] < b[1] < c[1] for a, b, c in zip(lo, fit, hi, strict=True)), fig
        assert len(series("test")) == t1["settings"]["n_points_per_curve"], fig


@pytest.mark.slow
def test_report_and_table1_agree_on_analytic_maps(tmp_path):
    """Task: `fepost report` and `fepost table1 --json`, both with their default seed,
    give identical Table 1 rows on the same analytic meshes."""
    import io
    from contextlib import redirect_stderr, redirect_stdout

    s = write_map(tmp_path / "static.vtu", "tire", radius=0.15, peak=6e5, n_rings=12)
    r = write_map(tmp_path / "rolling.vtu", "tire", radius=0.15, peak=6e5, k_x=0.13, n_rings=12)
    out, cli_json = tmp_path / "rep", tmp_path / "t1.json"
    with redirect_stderr(io.StringIO()), redirect_stdout(io.StringIO()):
        assert main(["report", str(s), str(r), "--out", str(out)]) == 0
        assert main(["table1", "--static", str(s), "--rolling", str(r), "--json", str(cli_json)]) == 0
    from_report = json.loads((out / "table1.json").read_text())
    from_table1 = json.loads(cli_json.read_text())
    assert from_report["settings"]["seed"] == from_table1["settings"]["seed"] == DEFAULT_SEED
    assert [row["name"] for row in from_report["rows"]] == TABLE1_NAMES
    assert from_report["rows"] == from_table1["rows"]


@pytest.fixture
def small_map(tmp_path):
    return str(write_map(tmp_path / "small.vtu", "hertz", n_rings=8))


def test_report_unwritable_folder(small_map, capsys):
    code = main(["report", small_map, "--out", "/proc/fepost-report-test"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("fepost: error: /proc/fepost-report-test: cannot write in /proc (")
    assert err.count("\n") == 1


def test_report_parent_is_a_file(tmp_path, small_map, capsys):
    (tmp_path / "afile").write_text("x")
    out = tmp_path / "afile" / "rep"
    code = main(["report", small_map, "--out", str(out)])
    assert code == 2
    assert capsys.readouterr().err == f"fepost: error: {out}: parent folder {out.parent} does not exist\n"


def test_report_bad_mesh_leaves_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.vtu"
    bad.write_text("this is not a VTK file\n")
    out = tmp_path / "rep"
    code = main(["report", str(bad), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith(f"fepost: error: {bad}") and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.vtu"]


def test_report_bad_inflation_pressure(tmp_path, small_map, capsys):
    out = tmp_path / "rep"
    code = main(["report", small_map, "--out", str(out), "--inflation-pressure", "0"])
    assert code == 2
    assert (
        capsys.readouterr().err
        == "fepost: error: --inflation-pressure must be a positive pressure in Pa, got 0.0\n"
    )
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.vtu"]


@pytest.mark.browser
@pytest.mark.slow
@pytest.mark.skipif(
    shutil.which("chromium") is None and not Path("/usr/bin/chromium").is_file(),
    reason="chromium not installed",
)
def test_report_screenshot(report, tmp_path):
    _, out, _, _ = report
    png = tmp_path / "shot.png"
    proc = subprocess.run(
        [
            sys.executable,
            str(REPO / "scripts" / "screenshot_report.py"),
            str(out / "report.html"),
            str(png),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    head = png.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    width = int.from_bytes(head[16:20], "big")
    height = int.from_bytes(head[20:24], "big")
    assert (width, height) == (1280, 4000)


@pytest.mark.slow
def test_report_optional_sections(tmp_path, small_map):
    """A section provider's section appears (title, text, table, figure embedded, files
    listed); one that returns None leaves no trace."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fepost.report import Section, build_report
    from fepost.report.figures import save_matplotlib

    def extra(data, folder):
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, data.analysis.coefficients.N])
        f = save_matplotlib(fig, folder, "extra_fig", "extra-fig", "An extra figure")
        (folder / "extra.csv").write_text("a,b\n1,2\n")
        return Section(
            key="extra-section",
            title="Extra section <demo>",
            paragraphs=("N is shown & checked.",),
            table=(("name", "value"), ("N", data.analysis.coefficients.N)),
            figures=(f,),
            captions={"extra-fig": "The extra caption."},
            files=("extra.csv",),
        )

    def nothing(data, folder):
        return None

    out = tmp_path / "rep"
    res = build_report(small_map, out=out, seed=1, sections=(nothing, extra))
    html = (out / "report.html").read_text(encoding="utf-8")
    assert html.count("<h2") == 9  # the 8 core sections and the extra one
    assert '<h2 id="extra-section">Extra section &lt;demo&gt;</h2>' in html
    assert "<p>N is shown &amp; checked.</p>" in html and "The extra caption." in html
    page = _page(out)
    assert ("An extra figure" in [alt for _, alt in page.images]) and "extra.csv" in page.refs
    assert {"extra_fig.png", "extra_fig.svg", "extra.csv"} <= set(res.files)
    base = build_report(small_map, out=tmp_path / "plain", seed=1, sections=(nothing,))
    plain = (tmp_path / "plain" / "report.html").read_text(encoding="utf-8")
    assert plain.count("<h2") == 8 and "extra" not in plain and "extra.csv" not in base.files
