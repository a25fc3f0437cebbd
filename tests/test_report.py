"""``fepost report``: every promised file, an HTML that matches the JSON, clean failures."""

from __future__ import annotations

import base64
import csv
import json
import re
import shutil
import subprocess
import sys
import warnings
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
    "error_map.json",
    "error_map_rolling.json",
    "curves.csv",
    "fig1_static.png",
    "fig2_rolling.png",
    "patch_plan.png",
    "patch_plan.svg",
    "patch_plan.pdf",
    *(
        f"{stem}.{ext}"
        for stem in (
            "fig3_sections",
            "fig4_f_parallel",
            "fig5_torque",
            "fig6_f_perp",
            "error_map",
            "error_map_rolling",
        )
        for ext in ("png", "svg", "pdf")
    ),
    *(f"{m}_{part}" for m in ("static", "rolling") for part in ("map.vtu", "patch.vtp", "outline.vtp")),
)
#: Written by the sample load sweep's section (the report of the sample tire only).
SWEEP_FILES = ("sweep/coefficients.csv", "sweep/coefficients.parquet", "sweep/load_trends.png")
#: JSON documents the page's tagged numbers come from (data-key prefix = file stem).
JSON_SOURCES = ("coefficients", "table1", "closed_form_vs_exact", "error_map", "error_map_rolling")
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


#: The tutorial's report step (docs/tutorial.md), which the `report` fixture takes as it is.
TUTORIAL_REPORT = "fepost report --out out/report --force"


@pytest.fixture(scope="module")
def report(tmp_path_factory, request):
    """``(exit status, report folder, what it printed on stderr, inputs)`` of the default
    report: the sample tire's, with the default seed. With the sample meshes shipped that is
    the report the tutorial makes (`documented_page`: run once per session, for its printed
    outputs, its files and these tests); else one of analytic stand-ins, made here."""
    inputs = _inputs(tmp_path_factory.mktemp("report"))
    if not inputs:
        page = request.getfixturevalue("documented_page")("docs/tutorial.md")
        return 0, page.folder / "out" / "report", page.stderr_of(TUTORIAL_REPORT), inputs
    import io
    from contextlib import redirect_stderr

    out = Path(inputs[0]).parent / "rep"
    err = io.StringIO()
    with redirect_stderr(err):
        code = main(["report", *inputs, "--out", str(out)])
    return code, out, err.getvalue(), inputs


@pytest.mark.slow
def test_report_writes_every_promised_file(report):
    code, out, _, inputs = report
    assert code == 0
    for name in PROMISED + (() if inputs else SWEEP_FILES):
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
    html = (out / "report.html").read_text(encoding="utf-8")
    for ref in page.refs:
        assert not re.match(r"^[a-z]+:", ref), f"external reference {ref}"
        if ref.startswith("#"):  # a link inside the page: to an element that exists
            assert f'id="{ref[1:]}"' in html, ref
            continue
        assert (out / ref).is_file(), ref


@pytest.mark.slow
def test_report_html_is_self_contained(report):
    """Every image is embedded (a data: URI holding exactly the PNG written beside the
    page), so report.html shows everything on its own; alt texts are plain text."""
    _, out, _, _ = report
    page = _page(out)
    pngs = sorted(str(p.relative_to(out)) for p in out.rglob("*.png"))
    assert len(page.images) == len(pngs) >= 9
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
    sources = {name: json.loads((out / f"{name}.json").read_text()) for name in JSON_SOURCES}
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
        assert f"closed_form_vs_exact.{curve}.model_max_abs_relative" in page.values
    for i in range(6):
        assert f"table1.generalised.rows.{i}.fitted" in page.values
    for key in ("direction_coefficients.a.0", "direction_coefficients.m.1", "static.Q.0.0", "static.S.1.1"):
        assert f"coefficients.model.{key}" in page.values
    assert checked >= 90


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
        assert series == {"exact", "closed_form", "model", "fit", "band_lo", "band_hi", "test"}
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
    static, rolling = inputs or [str(p) for p in sample_paths()]
    sample = ["--static", static, "--rolling", rolling]
    cli_json = tmp_path / "t1.json"
    assert main(["table1", *sample, "--json", str(cli_json)]) == 0
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
def test_report_and_table1_agree_on_analytic_maps(analytic_report, tmp_path):
    """Task: `fepost report` and `fepost table1 --json`, both with their default seed,
    give identical Table 1 rows on the same analytic meshes."""
    import io
    from contextlib import redirect_stderr, redirect_stdout

    s, r, out = analytic_report
    cli_json = tmp_path / "t1.json"
    with redirect_stderr(io.StringIO()), redirect_stdout(io.StringIO()):
        assert main(["table1", "--static", str(s), "--rolling", str(r), "--json", str(cli_json)]) == 0
    from_report = json.loads((out / "table1.json").read_text())
    from_table1 = json.loads(cli_json.read_text())
    assert from_report["settings"]["seed"] == from_table1["settings"]["seed"] == DEFAULT_SEED
    assert [row["name"] for row in from_report["rows"]] == TABLE1_NAMES
    assert from_report["rows"] == from_table1["rows"]
    # a report of other files than the sample tire's has no sample sweep
    assert not (out / "sweep").exists() and 'id="sweep"' not in (out / "report.html").read_text()


@pytest.fixture
def small_map(tmp_path):
    return str(write_map(tmp_path / "small.vtu", "hertz", n_rings=8))


def test_report_unwritable_folder(small_map, capsys):
    code = main(["report", small_map, "--out", "/proc/fepost-report-test"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("fepost: error: /proc/fepost-report-test: cannot write in /proc (")
    assert err.count("\n") == 1


def test_build_report_force_never_deletes_its_inputs(tmp_path, monkeypatch):
    """The Python API guards its inputs and the sample meshes as the command line does: refused
    before any work. The sample folder is a scratch one here (a failing guard must not cost the
    repository its meshes), looked up when the report is built, as in use."""
    import fepost.report.samples as samples
    from fepost.errors import OutputError
    from fepost.report import build_report

    (tmp_path / "data").mkdir()
    static = write_map(tmp_path / "data" / "small.vtu", "hertz", n_rings=8)
    before = static.read_bytes()
    with pytest.raises(OutputError, match=r"refusing to replace this folder: it contains the input"):
        build_report(static, out=static.parent, force=True)
    scratch = tmp_path / "meshes"
    scratch.mkdir()
    (scratch / "kept.vtu").write_bytes(before)
    monkeypatch.setattr(samples, "meshes_folder", lambda: scratch)
    with pytest.raises(OutputError, match=r"refusing to replace this folder: it is the input"):
        build_report(static, out=scratch, force=True)
    assert static.read_bytes() == before and sorted(p.name for p in static.parent.iterdir()) == ["small.vtu"]
    assert sorted(p.name for p in scratch.iterdir()) == ["kept.vtu"]


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
        == "fepost: error: argument --inflation-pressure: must be a positive pressure up to 1 GPa, got '0' "
        "(see 'fepost report --help')\n"
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
    if shutil.which("chromium") is None and shutil.which("chromium-browser") is None:
        pytest.skip("chromium is not installed (make test CHROMIUM=no, or APT=no without it)")
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
    res = build_report(small_map, out=out, seed=1, sections=(nothing, extra), inflation_pressure=200e3)
    html = (out / "report.html").read_text(encoding="utf-8")
    assert html.count("<h2") == 10  # the 9 core sections (the appendix among them) and the extra one
    assert '<h2 id="extra-section">Extra section &lt;demo&gt;</h2>' in html
    assert "<p>N is shown &amp; checked.</p>" in html and "The extra caption." in html
    page = _page(out)
    assert ("An extra figure" in [alt for _, alt in page.images]) and "extra.csv" in page.refs
    assert {"extra_fig.png", "extra_fig.svg", "extra.csv"} <= set(res.files)
    # the provider that returned None left no trace: 8 core sections and the extra one, no files
    assert sorted(p.name for p in out.iterdir() if p.name.startswith("extra")) == [
        "extra.csv",
        "extra_fig.pdf",
        "extra_fig.png",
        "extra_fig.svg",
    ]


# ------------------------------------ the demo's case, the generalised model and the sample sweep
def test_default_inputs_are_the_aircraft_tire():
    """`fepost report` without inputs, and so `make demo`, reports on the aircraft tire at its
    rated load: the static map and the rolled map (free rolling), not the sliding stand-in."""
    from fepost.reader.sidecar import read_sidecar
    from fepost.report.samples import sample_inputs

    static, rolling = sample_inputs()
    assert static == REPO / "meshes" / "aircraft" / "static_100.vtu"
    assert rolling == REPO / "meshes" / "rig-aircraft" / "roll_free.vtu"
    side = read_sidecar(rolling)
    assert side is not None and side["kind"] == "rolling run" and side["longitudinal_slip"] == 0
    make = (REPO / "Makefile").read_text()
    demo = re.search(r"^demo:.*\n((?:\t.*\n)+)", make, re.M)
    assert demo is not None
    lines = [ln.strip() for ln in demo.group(1).splitlines()]
    commands = [ln for ln in lines if "fepost report" in ln and not ln.startswith("@")]
    assert commands == ["$(VENV)/bin/fepost report --out $(OUT) --force"]  # no inputs: the samples


@pytest.mark.slow
def test_report_default_case_is_the_aircraft_tire(report):
    _, out, _, inputs = report
    if inputs:
        pytest.skip("the sample meshes are absent: the report ran on analytic stand-ins")
    coef = json.loads((out / "coefficients.json").read_text())
    static, rolling = sample_paths()
    assert Path(coef["static"]["source"]).resolve() == static.resolve()
    assert Path(coef["rolling"]["source"]).resolve() == rolling.resolve()
    side = json.loads(static.with_suffix(".json").read_text())
    assert coef["reaction_z"] == side["reaction_z"]
    assert coef["N"] == pytest.approx(side["reaction_z"], rel=0.005)  # the solver's own reaction
    text = "".join(_page(out).text)
    sidecar = static.with_suffix(".json").name
    assert (
        f"{side['inflation_pressure'] / 1e3:g}{NNBSP}kPa (source: sidecar {sidecar}, key inflation_pressure)"
        in text
    )


@pytest.mark.slow
def test_report_labels_the_rolling_map(report, monkeypatch):
    """What the rolling map is, from its sidecar, said in the provenance, the k_x row and
    Figure 2 (caption and title); a rolled map's k_x with its own-mesh static map beside."""
    from dataclasses import replace

    from fepost.figures.units import normalise
    from fepost.reader.sidecar import read_sidecar
    from fepost.report.rollinglabel import rolling_label

    _, out, _, inputs = report
    coef = json.loads((out / "coefficients.json").read_text())
    rolling = Path(coef["rolling"]["source"])
    label = rolling_label(read_sidecar(rolling))
    # the page's unit style (a narrow no-break space in 0.75 m), whitespace made one space
    label = replace(label, text=" ".join(normalise(label.text).split()))
    page = _page(out)
    text = " ".join(" ".join(page.text).split())
    provenance = text.split("Inputs and provenance", 1)[1].split("friction coefficient f", 1)[0]
    assert provenance.count(label.text) == 1
    assert f"k_x {coef['k_x']:.6g} R·x_c/⟨x²⟩: the centre-of-pressure shift of the {label.text}" in text
    figure2 = text.split("Figure 2.", 1)[1].split("Figure 3.", 1)[0]
    assert figure2.count(label.text) == 1
    assert f"Figure 2: contact pressure, {label.short}" in [alt for _, alt in page.images]
    if inputs:
        assert label.kind == "unstated" and "own-mesh" not in text
        return
    assert label.kind == "rolled" and "free rolling" in label.text and "stand-in" not in provenance
    import fepost
    from fepost.report.assemble import shown_input

    partner = rolling.parent / "roll_static.vtu"
    k_own = fepost.analyse(partner, rolling, friction=coef["f"]).coefficients.k_x
    monkeypatch.chdir(out.parent.parent)  # where the report ran (`report`): inputs are named from there
    assert (
        f"k_x = {coef['k_x']:.4f} pairs the static map with the rolled map, which was solved on a mesh "
        f"of its own; with its own-mesh static partner {shown_input(partner)[0]} the same "
        f"rolled map gives k_x = {k_own:.4f}."
    ) in text
    assert page.values["coefficients.k_x"] == coef["k_x"]


@pytest.mark.slow
def test_report_error_maps_quote_their_json(report):
    """The error maps are embedded, and the largest errors the page quotes are those of
    error_map*.json, which are the largest values of the maps themselves."""
    _, out, _, _ = report
    page = _page(out)
    alts = {base64.b64decode(src.split(",", 1)[1]): alt for src, alt in page.images}
    coef = json.loads((out / "coefficients.json").read_text())
    for stem, tag in (("error_map", "static"), ("error_map_rolling", "rolling")):
        doc = json.loads((out / f"{stem}.json").read_text())
        assert alts[(out / f"{stem}.png").read_bytes()].startswith(f"Error map of the {tag} map")
        assert (len(doc["beta_deg"]), len(doc["t"])) == (33, 33)  # summary.ACCURACY_GRID
        for name in ("paper", "base", "model"):
            for q in ("force", "torque"):
                quoted = page.values[f"{stem}.worst.{name}.{q}"]
                assert quoted == doc["worst"][name][q] == max(max(row) for row in doc[q][name])
        worst = doc["worst"]
        # what the page says: the closed forms miss by more than 10 % of F0 and M0, the
        # generalised model stays inside the 3 % goal
        assert worst["paper"]["force"] > 0.10 and worst["paper"]["torque"] > 0.15
        assert worst["model"]["force"] < 0.03 and worst["model"]["torque"] < 0.03
        # a second, different grid (the model's own staggered check grid) finds the same levels
        acc = coef["model"][tag]["accuracy"]
        assert worst["paper"]["force"] == pytest.approx(acc["compare_force"], rel=0.05)
        assert worst["paper"]["torque"] == pytest.approx(acc["compare_torque"], rel=0.05)
        assert abs(worst["model"]["force"] - acc["model_force"]) < 0.005
        assert abs(worst["model"]["torque"] - acc["model_torque"]) < 0.005
    # pure sliding (t = 1) on the static map: the closed forms give F0 along -v, as the exact integral
    doc = json.loads((out / "error_map.json").read_text())
    assert doc["t"][-1] == 1.0 and max(row[-1] for row in doc["force"]["paper"]) < 1e-6


@pytest.mark.slow
def test_figures_4_6_show_the_generalised_model(report):
    """Figures 4-6 carry a third line, the generalised model, whose values are those of
    Table 1's generalised form at the FE maps' own coefficients."""
    import fepost
    from fepost.table1 import table1

    _, out, _, inputs = report
    static, rolling = inputs or [str(p) for p in sample_paths()]
    expected_table = table1(fepost.analyse(static, rolling, friction=0.3), seed=DEFAULT_SEED)
    assert expected_table.generalised is not None
    with open(out / "curves.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    errors = json.loads((out / "closed_form_vs_exact.json").read_text())
    for fig, key, stem in (
        ("F_parallel", "f_parallel", "fig4_f_parallel"),
        ("M_C", "torque", "fig5_torque"),
        ("F_perp", "f_perp", "fig6_f_perp"),
    ):

        def series(name, fig=fig):
            pts = [(r["x"], r["value"]) for r in rows if r["figure"] == fig and r["series"] == name]
            return np.array(pts, dtype=float)

        model, exact = series("model"), series("exact")
        assert len(model) == len(exact) > 100
        want = expected_table.generalised.form.curves(model[:, 0])[key]
        np.testing.assert_allclose(model[:, 1], want, rtol=1e-12, atol=0)
        # the quoted gap is the gap of these curves, and within the 3 % goal of the error maps,
        # whose force scale is F0: F⊥'s own scale |k_x| M0/(2R) vanishes in free rolling (the
        # rolled map's k_x = 0.034 makes it 0.9 % of F0), so there the goal is taken in F0
        gap = np.max(np.abs(model[:, 1] - exact[:, 1])) / errors[key]["scale"]
        assert gap == pytest.approx(errors[key]["model_max_abs_relative"], rel=1e-9)
        goal_scale = errors["f_parallel"]["scale"] if key == "f_perp" else errors[key]["scale"]
        assert gap * errors[key]["scale"] / goal_scale < 0.03
        # and on each curve's own scale, where a model drawn as zero (or with the wrong sign) fails:
        # measured 0.26 % (F∥), 0.33 % (M), 6.3 % (F⊥ of the rolled map, whose peak is 0.8 % of F0)
        own = np.max(np.abs(model[:, 1] - exact[:, 1])) / np.max(np.abs(exact[:, 1]))
        assert own < (0.10 if key == "f_perp" else 0.01), (key, own)
        assert 'id="model"' in (out / f"{stem}.svg").read_text(encoding="utf-8")  # the line is drawn


@pytest.mark.slow
def test_report_sample_sweep_section(report):
    """The report of the sample tire shows its load sweep: 6 loads, the power law of R with
    its 95 % interval (equal to an independent fit of the table), and the report's own case,
    whose row pairs it with the sweep's rolling map (the sliding stand-in, labelled so)
    rather than the report's rolled map: equal to a fresh computation of that row."""
    from scipy import stats

    from fepost.options import AnalysisOptions
    from fepost.sweep.jobs import Job, run_job
    from fepost.sweep.table import read_table

    _, out, _, inputs = report
    if inputs:
        pytest.skip("the sample meshes are absent: no sample sweep")
    html = (out / "report.html").read_text(encoding="utf-8")
    assert '<h2 id="sweep">Load sweep</h2>' in html
    section = html.split('<h2 id="sweep">', 1)[1].split("<h2", 1)[0]
    rows = read_table(out / "sweep" / "coefficients.csv")
    assert [r["case"] for r in rows] == [f"static_{p:03d}" for p in (25, 50, 75, 100, 125, 150)]
    assert all(r["status"] == "ok" for r in rows) and all(r["case"] in section for r in rows)
    loads = [r["load"] for r in rows]
    assert loads == sorted(loads) and loads[0] < 0.3 * loads[-1]
    # R ∝ N^α: the exponent and interval quoted equal a least-squares fit of log R on log N
    fit = stats.linregress(np.log([r["N"] for r in rows]), np.log([r["R"] for r in rows]))
    half = stats.t.ppf(0.975, len(rows) - 2) * fit.stderr
    number = r"([−\d.]+)"
    m = re.search(rf"R ∝ N\^{number}, 95{NNBSP}% interval \[{number}, {number}\], from 6 loads", section)
    assert m, section[:2000]
    quoted = [float(g.replace("−", "-")) for g in m.groups()]
    assert quoted == pytest.approx([fit.slope, fit.slope - half, fit.slope + half], abs=6e-4)
    assert 0.3 < fit.slope < 0.7
    # the rated-load row pairs static_100 with the sweep's rolling map, the sliding stand-in,
    # not the report's rolled map: computed by the sweep, its static coefficients the report's ...
    coef = json.loads((out / "coefficients.json").read_text())
    own = rows[3]
    assert Path(own["rolling"]).name == "rolling_100.vtu"
    assert all(r["seconds"] is not None for r in rows)
    for key in ("N", "R", "M0", "a", "m", "aR2", "m_over_R2"):
        assert own[key] == coef[key], key
    # ... and equal to the row a sweep computes for that pair, the stand-in's k_x included
    static = sample_paths()[0]
    stand_in = REPO / "meshes" / "aircraft" / "rolling_100.vtu"
    job = Job(own["source"], str(static.resolve()), None, AnalysisOptions(), friction=0.3,
              rolling=str(stand_in.resolve()), rolling_given=own["rolling"])  # fmt: skip
    fresh = run_job(job)
    assert fresh["status"] == "ok", fresh["error"]
    for key in ("N", "R", "M0", "a", "m", "k_x", "aspect", "circular", "load", "case", "deflection"):
        assert own[key] == fresh[key], key
    assert own["k_x"] != coef["k_x"]
    # the pairing is labelled for what it is, and the report's own rolling map named
    text = " ".join(" ".join(_page(out).text).split())
    assert (
        "The k_x of static_100 is from its rolling partner rolling_100.vtu, a sliding stand-in (the "
        "rim slid along x, no rotation): its k_x is the shift of a sliding patch, not of rolling."
    ) in text
    assert (
        "The report above is the case static_100 of this sweep, with another rolling map: the report "
        f"pairs it with roll_free.vtu, a rolled map (quasi-static free rolling, slip κ = 0.000, rim "
        f"turned 75.5° over 0.75 m of axle travel) (k_x = {coef['k_x']:.4f}); the sweep's row keeps "
        "the sweep's pairing."
    ) in text


@pytest.mark.slow
def test_sample_sweep_reuses_the_report_row_of_the_same_pair(tmp_path):
    """A report of static_100 with the sweep's own rolling map (the stand-in): the sweep takes
    that row from the report's analysis (no worker time) and says the report is that case."""
    from types import SimpleNamespace

    import fepost
    from fepost.options import AnalysisOptions
    from fepost.report.sweepsection import sample_sweep_section
    from fepost.sweep.table import read_table

    air = REPO / "meshes" / "aircraft"
    if not (air / "static_100.vtu").is_file():
        pytest.skip("the sample meshes are absent: no sample sweep")
    a = fepost.analyse(air / "static_100.vtu", air / "rolling_100.vtu", friction=0.3)
    data = SimpleNamespace(analysis=a, friction=0.3, options=AnalysisOptions())
    section = sample_sweep_section(data, tmp_path)
    assert section is not None
    rows = read_table(tmp_path / "sweep" / "coefficients.csv")
    own = rows[3]
    assert own["seconds"] is None and all(r["seconds"] is not None for i, r in enumerate(rows) if i != 3)
    coef = a.to_dict()
    for key in ("N", "R", "M0", "a", "m", "k_x", "x_c", "aR2", "m_over_R2"):
        assert own[key] == coef[key], key
    assert "The report above is the case static_100 of this sweep." in section.paragraphs[0]
    assert any("rolling_100.vtu, a sliding stand-in" in p for p in section.paragraphs)


@pytest.mark.slow
def test_report_main_table_is_short_and_the_internals_are_in_the_appendix(report):
    """The coefficient table an engineer reads: the coefficients and the accuracy of both
    models; the pressure moments and the generalised model's internals in the appendix."""
    _, out, _, _ = report
    html = (out / "report.html").read_text(encoding="utf-8")
    main = html.split('<h2 id="coefficients">', 1)[1].split("<h2", 1)[0]
    appendix = html.split('<h2 id="appendix">', 1)[1].split("<h2", 1)[0]
    assert main.count("<tr>") - 2 <= 26  # rows less the header and the accuracy group's heading
    for key in ("N", "R", "F0", "M0", "a", "m", "k_x"):
        assert f'data-key="coefficients.{key}"' in main, key
    for key in ("error_map.worst.paper.force", "error_map.worst.model.torque"):
        assert f'data-key="{key}"' in main, key
    internals = ("A.0", "A.3", "model.static.Q.0.0", "model.static.S.1.1", "model.direction_coefficients.a.0")
    for key in internals:
        assert f'data-key="coefficients.{key}"' in appendix and f'data-key="coefficients.{key}"' not in main


@pytest.mark.slow
def test_every_k_x_of_the_page_says_what_its_rolling_map_is(report):
    """The report's k_x (coefficients, Table 1) and the sweep's (a sliding stand-in) each
    carry the kind of rolling map they come from."""
    _, out, _, inputs = report
    text = " ".join(" ".join(_page(out).text).split())
    assert "every k_x in these tables is the centre-of-pressure shift of the " in text
    if inputs:
        return
    html = (out / "report.html").read_text(encoding="utf-8")
    section = html.split('<h2 id="sweep">', 1)[1].split("<h2", 1)[0]
    assert "<th>k_x</th><th>k_x from (its rolling map)</th>" in section
    stand_in = re.search(r'<td class="num">0\.24\d*</td><td>sliding stand-in</td>', section)
    assert stand_in, section[-3000:]


@pytest.mark.slow
def test_report_sweep_folder_follows_the_umask(report):
    """The report's sweep folder is as readable as the documented outputs (no 0600/0700)."""
    from fepost.output import _umask  # noqa: PLC2701 - the test reads the process's umask

    _, out, _, inputs = report
    if inputs:
        pytest.skip("the sample meshes are absent: no sample sweep")
    mask = _umask()
    entries = [out / "sweep", *sorted((out / "sweep").rglob("*"))]
    assert any(p.name == "coefficients.parquet" for p in entries)
    for p in entries:
        want = (0o777 if p.is_dir() else 0o666) & ~mask
        assert p.stat().st_mode & 0o777 == want, (p, oct(p.stat().st_mode))


@pytest.mark.slow
def test_report_quotes_one_model_accuracy_the_error_maps_largest(report):
    """The recommendation's "within X %" and the coefficient table's model errors are the error
    maps' largest errors (the densest grid the report evaluates), not the coarser check grid's."""
    _, out, _, _ = report
    html = (out / "report.html").read_text(encoding="utf-8")
    worst = []
    for stem in ("error_map", "error_map_rolling"):
        if (out / f"{stem}.json").is_file():
            doc = json.loads((out / f"{stem}.json").read_text())
            worst += [doc["worst"]["model"]["force"], doc["worst"]["model"]["torque"]]
    quoted = re.findall(r"within ([\d.]+)%", html.split('class="verdict">Which model to use', 1)[1][:600])
    assert quoted and float(quoted[0]) == pytest.approx(100 * max(worst), abs=0.05)
    check = json.loads((out / "coefficients.json").read_text())["model"]["static"]["accuracy"]
    assert max(check["model_force"], check["model_torque"]) < max(worst)  # the check grid is coarser


def test_a_map_without_inflation_pressure_warns_and_says_so(small_map):
    from fepost.analysis import analyse
    from fepost.errors import ReaderWarning
    from fepost.report.build import inflation_pressure_of

    a = analyse(small_map)
    with pytest.warns(ReaderWarning, match=r"the paper's P\* = 200 kPa is assumed"):
        p, source = inflation_pressure_of(None, a)
    assert p == 200e3 and source.startswith("NOT GIVEN")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert inflation_pressure_of(1.38e6, a) == (1.38e6, "option --inflation-pressure")


# ------------------------------------ what the rolling map is (fepost.report.rollinglabel)
ROLL = REPO / "meshes" / "rig-aircraft"


def test_rolling_label_of_a_rolled_map():
    from fepost.report.rollinglabel import rolling_label

    side = {
        "kind": "rolling run",
        "longitudinal_slip": 0.0,
        "rim_rotation_deg": 75.49635683320805,
        "axle_travel_m": 0.75,
    }
    label = rolling_label(side)
    assert label.kind == "rolled"
    assert label.text == (
        "rolled map (quasi-static free rolling, slip κ = 0.000, rim turned 75.5° over 0.75 m of axle travel)"
    )
    assert label.short == "rolled map, free rolling"
    braked = rolling_label({**side, "longitudinal_slip": -0.2000000130, "rim_rotation_deg": 60.3798})
    assert braked.text == (
        "rolled map (quasi-static braking, slip κ = -0.200, rim turned 60.4° over 0.75 m of axle travel)"
    )
    assert rolling_label({**side, "longitudinal_slip": 0.04}).short == "rolled map, driving κ = 0.040"
    # what the sidecar does not give is not said
    assert rolling_label({"kind": "rolling run"}).text == "rolled map (quasi-static rolling)"


def test_rolling_label_of_a_sliding_standin():
    from fepost.report.rollinglabel import rolling_label

    label = rolling_label({"rolling_standin": {"direction": "+x"}, "description": "a slide"})
    assert label.kind == "standin" and label.short == "sliding stand-in"
    assert label.text == (
        "sliding stand-in (the rim slid along x, no rotation): its k_x is the shift of a sliding "
        "patch, not of rolling"
    )


def test_rolling_label_without_a_kind():
    from fepost.report.rollinglabel import rolling_label

    for side in (None, {}, {"reaction_z": 1.0}):
        label = rolling_label(side)
        assert (label.kind, label.text, label.short) == (
            "unstated",
            "rolling map (kind not stated)",
            "rolling map",
        )
    assert rolling_label({"kind": "static map"}).text == "rolling map (its sidecar's kind: static map)"


def test_rolling_labels_of_the_shipped_maps():
    """The shipped sidecars: the rolled runs, the sliding stand-ins of both tires."""
    from fepost.reader.sidecar import read_sidecar
    from fepost.report.rollinglabel import rolling_label

    cases = {
        ROLL / "roll_free.vtu": "rolled",
        ROLL / "roll_brake20.vtu": "rolled",
        REPO / "meshes" / "aircraft" / "rolling_100.vtu": "standin",
        REPO / "meshes" / "rolling.vtu": "standin",
    }
    cases = {p: k for p, k in cases.items() if p.is_file()}
    if not cases:
        pytest.skip("no shipped rolling maps")
    for path, kind in cases.items():
        assert rolling_label(read_sidecar(path)).kind == kind, path
    if (ROLL / "roll_free.vtu").is_file():
        side = read_sidecar(ROLL / "roll_free.vtu")
        turned = f"{side['rim_rotation_deg']:.1f}°"
        assert turned in rolling_label(side).text and "free rolling" in rolling_label(side).text


def test_own_mesh_static_partner(tmp_path):
    """A rolled map's static partner: the one static map beside it on the same mesh."""
    from fepost.report.rollinglabel import own_mesh_static

    mesh = {"model_nodes": 10}
    roll = {"kind": "rolling run", "mesh": mesh}

    def put(name, side):
        (tmp_path / f"{name}.vtu").write_bytes(b"")
        (tmp_path / f"{name}.json").write_text(json.dumps(side))
        return tmp_path / f"{name}.vtu"

    r = put("roll_a", roll)
    put("other_mesh", {"kind": "static map", "mesh": {"model_nodes": 11}})
    put("slide", {"rolling_standin": {}, "mesh": mesh})
    assert own_mesh_static(r, roll) is None  # no static map on that mesh yet
    s = put("roll_static", {"kind": "static map", "mesh": mesh})
    assert own_mesh_static(r, roll) == s
    assert own_mesh_static(r, {"rolling_standin": {}, "mesh": mesh}) is None  # not a rolled map
    assert own_mesh_static(r, None) is None
    put("roll_static2", {"kind": "static map", "mesh": mesh})
    assert own_mesh_static(r, roll) is None  # two candidates: none chosen
    if (ROLL / "roll_free.vtu").is_file():
        from fepost.reader.sidecar import read_sidecar

        free = ROLL / "roll_free.vtu"
        assert own_mesh_static(free, read_sidecar(free)) == ROLL / "roll_static.vtu"


def test_own_mesh_k_x_is_the_pair_analysed_directly():
    """The report's second k_x is the rolled map with its own-mesh static map, analysed
    directly; none for a pair that already is that one, or for a stand-in."""
    import fepost
    from fepost.report.rollinglabel import own_mesh_k_x

    static, free = REPO / "meshes" / "aircraft" / "static_100.vtu", ROLL / "roll_free.vtu"
    if not (static.is_file() and free.is_file()):
        pytest.skip("the sample meshes are absent")
    a = fepost.analyse(static, free)
    got = own_mesh_k_x(a, friction=0.3)
    assert got is not None and got.static == ROLL / "roll_static.vtu"
    direct = fepost.analyse(ROLL / "roll_static.vtu", free).coefficients.k_x
    assert got.k_x == direct and abs(got.k_x - a.coefficients.k_x) < 0.02
    # the k_x of the rolling run's centre-of-pressure shift from the sidecar's face integral
    side = json.loads(free.with_suffix(".json").read_text())
    shift = side["samples"][-1]["centre_of_pressure_shift_m"]
    c = fepost.analyse(ROLL / "roll_static.vtu", free).coefficients
    assert c.x_c == pytest.approx(shift, abs=1e-3)
    assert own_mesh_k_x(fepost.analyse(ROLL / "roll_static.vtu", free), friction=0.3) is None
    stand_in = REPO / "meshes" / "aircraft" / "rolling_100.vtu"
    assert own_mesh_k_x(fepost.analyse(static, stand_in), friction=0.3) is None
