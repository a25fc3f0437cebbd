"""The documentation: builds strictly, documents every command and output, and its tutorial runs.

The strict MkDocs build (warnings are errors: broken links, anchors, docstrings)
needs the docs extra (``pip install -e '.[docs]'``). Without it these tests skip,
except under ``make test`` (``FEPOST_REQUIRE_DOCS=1``), where they fail instead.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"
#: The core pages of the site; the other pages (reading, diagnose, model, sweep, rig,
#: cli-exit-codes) join the nav when their files exist.
CORE_PAGES = ("index.md", "tutorial.md", "theory.md", "formats.md", "cli.md", "api.md")


def _need_mkdocs():
    if importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None:
        if os.environ.get("FEPOST_REQUIRE_DOCS"):
            pytest.fail("the docs tooling is missing: pip install -e '.[docs]'")
        pytest.skip("docs extra not installed (pip install -e '.[docs]'; make test installs it)")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    _need_mkdocs()
    out = tmp_path_factory.mktemp("site")
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "WARNING" not in proc.stderr, proc.stderr[-3000:]
    return out


@pytest.mark.slow
def test_docs_build_strictly_with_every_core_page(site):
    for page in CORE_PAGES:
        assert (DOCS / page).is_file(), page
        html = site / page.replace(".md", ".html")
        assert html.is_file(), html
    index = (site / "index.html").read_text(encoding="utf-8")
    for page in CORE_PAGES[1:]:
        assert f'href="{page.replace(".md", ".html")}"' in index, page
    api = (site / "api.html").read_text(encoding="utf-8")
    for name in ("fepost.analysis.analyse", "fepost.patch.build_patch", "fepost.report.build.build_report"):
        assert f'id="{name}"' in api, name


@pytest.mark.slow
def test_docs_nav_lists_only_pages_that_exist(site):
    """Pages named in mkdocs.yml but not written yet are left out, the others are in."""
    nav = re.findall(r"^\s+- [^:]+: (\S+\.md)$", (REPO / "mkdocs.yml").read_text(), re.M)
    assert set(CORE_PAGES) <= set(nav)
    index = (site / "index.html").read_text(encoding="utf-8")
    for page in nav:
        href = f'href="{page.replace(".md", ".html")}"'
        assert (href in index) == (DOCS / page).is_file(), page


@pytest.mark.slow
def test_cli_reference_lists_every_command_and_option(site):
    """Generated from fepost.cli.build_parser(): a new subcommand appears by itself."""
    import argparse

    from fepost.cli import build_parser

    html = (site / "cli.html").read_text(encoding="utf-8")
    parser = build_parser()
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    names = [name for s in subs for name in s.choices]
    assert {"coefficients", "table1", "report", "diagnose"} <= set(names)
    for s in subs:
        for name, p in s.choices.items():
            assert f'<h2 id="fepost-{name}">fepost {name}' in html, name
            for action in p._actions:
                for opt in action.option_strings:
                    if opt not in ("-h", "--help"):
                        assert f"<code>{opt}" in html, (name, opt)


def test_no_references_to_files_outside_the_repository():
    """README, docs and the package stand alone: no ../shared anywhere, and no THEORY.md or
    INTERFACE.md in the README, the docs or the package (help texts, docstrings, templates)."""
    package = [p for p in (REPO / "fepost").rglob("*") if p.is_file() and p.suffix in (".py", ".j2", ".css")]
    texts = {p: p.read_text(encoding="utf-8") for p in [REPO / "README.md", *DOCS.rglob("*.md"), *package]}
    assert len(package) > 100
    for path, text in texts.items():
        assert "shared/" not in text, path
        assert "THEORY.md" not in text and "INTERFACE.md" not in text, path.relative_to(REPO).as_posix()


# ---------------------------------------------------------------- the tutorial runs
def tutorial_steps() -> list[tuple[str, str]]:
    """("console", command) and ("python", code) in the tutorial's order."""
    text = (DOCS / "tutorial.md").read_text(encoding="utf-8")
    steps = []
    for lang, body in re.findall(r"^```(console|python)\n(.*?)^```", text, re.M | re.S):
        if lang == "python":
            steps.append(("python", body))
        else:
            steps += [("console", line[2:]) for line in body.splitlines() if line.startswith("$ ")]
    return steps


#: Where the tutorial writes everything (git-ignored): the repository root stays clean.
TUTORIAL_OUT = "out"


@pytest.fixture(scope="module")
def tutorial(documented_page):
    """The tutorial's commands run in a scratch folder linking the repository's top-level
    folders (its marked blocks, which are all its steps: `test_every_tutorial_step_runs`;
    run once per session and shared with tests/test_doc_examples.py, which compares what
    they print); returns the folder the tutorial writes into."""
    return documented_page("docs/tutorial.md").folder / TUTORIAL_OUT


def test_every_tutorial_step_runs():
    """Each console or python block of the tutorial is marked as a documentation example,
    so the page's run (`tests.docexamples.run_page`) is the whole tutorial, in order."""
    import docexamples as dx

    text = (DOCS / "tutorial.md").read_text(encoding="utf-8").splitlines()
    fences = [i + 1 for i, line in enumerate(text) if re.match(r"^```(console|python)\s*$", line)]
    marked = {b.start for b in dx.blocks("docs/tutorial.md")}
    assert fences and [f for f in fences if f not in marked] == []
    ran = [(b.lang, line) for b in dx.blocks("docs/tutorial.md") for line in b.body]
    for kind, step in tutorial_steps():
        if kind == "console":
            assert ("console", f"$ {step}") in ran, step


def test_tutorial_has_the_steps_it_promises():
    steps = tutorial_steps()
    commands = [s.split()[1] for k, s in steps if k == "console" and s.startswith("fepost ")]
    assert commands == ["coefficients", "report", "predict", "sweep", "diagnose"]
    assert steps[0] == ("console", f"mkdir -p {TUTORIAL_OUT}")
    assert [k for k, _ in steps].count("python") == 2
    report = next(s for k, s in steps if k == "console" and s.split()[1] == "report")
    # the demo's case: no inputs
    assert shlex.split(report)[2:] == ["--out", f"{TUTORIAL_OUT}/report", "--force"]


@pytest.mark.slow
def test_tutorial_writes_only_into_an_ignored_folder(tutorial):
    """Run from the repository's root, the tutorial leaves nothing untracked there: every
    file goes into out/, which .gitignore lists."""
    work = tutorial.parent  # the scratch folder: links to the repository's entries, and out/
    assert sorted(p.name for p in work.iterdir() if not p.is_symlink()) == [TUTORIAL_OUT]
    assert any(p.is_file() for p in tutorial.rglob("*"))
    ignored = (REPO / ".gitignore").read_text(encoding="utf-8").splitlines()
    assert f"/{TUTORIAL_OUT}/" in ignored


@pytest.mark.slow
def test_tutorial_runs_and_says_what_happens(tutorial):
    import csv

    coef = json.loads((tutorial / "coefficients.json").read_text())
    text = (DOCS / "tutorial.md").read_text(encoding="utf-8")
    # the numbers quoted in the tutorial are the ones the commands give
    assert f"{coef['N']:.6g} N" in text and f"{coef['M0']:.6g} N m" in text
    assert f"{coef['k_x']:.6g}" in text and f"aspect {coef['patch']['aspect']:.4f}" in text
    assert f"agree to {100 * abs(coef['N'] / coef['reaction_z'] - 1):.2f} %" in text
    # ... the generalised model's lines and the accuracy claimed for it
    d = coef["model"]["direction_coefficients"]
    assert f"a along x, y                {d['a'][0]:.6g}, {d['a'][1]:.6g}" in text
    assert f"m along x, y                {d['m'][0]:.6g}, {d['m'][1]:.6g}" in text
    acc = coef["model"]["stated_accuracy"]["all_maps"]  # the one stated figure (friction.summary)
    assert f"within {100 * max(acc['model_force'], acc['model_torque']):.1f} %" in text
    assert f"miss by up to {100 * max(acc['paper_force'], acc['paper_torque']):.0f} %" in text
    # the report of the demo's case, with its error maps and the sample sweep
    report = tutorial / "report"
    assert (report / "report.html").is_file() and (report / "error_map.json").is_file()
    assert json.loads((report / "coefficients.json").read_text())["N"] == coef["N"]
    assert (report / "sweep" / "coefficients.csv").is_file()
    # predict: the torques quoted, and what the text says about them
    with open(tutorial / "predicted.csv", newline="") as fh:
        rows = {float(r["wz"]): r for r in csv.DictReader(fh)}
    assert len(rows) == 9
    assert json.loads((tutorial / "model.json").read_text())["F0"] == pytest.approx(coef["F0"], rel=1e-12)
    for wz in (0.5, 1.5, 4.0):
        mz = [float(rows[wz][f"Mz_{m}"]) for m in ("exact", "paper", "model")]
        assert f"{wz:g}   {mz[0]:.1f}   {mz[1]:.1f}   {mz[2]:.1f}" in text, wz
        if wz < 2:
            assert 0.2 <= abs(mz[1] / mz[0] - 1) <= 0.31 and abs(mz[2] / mz[0] - 1) < 0.01
    # the sweep's trends as quoted
    fits = {f["quantity"]: f for f in json.loads((tutorial / "sweep" / "trends.json").read_text())["fits"]}
    for q in ("R", "M0"):  # as fepost sweep prints them (all its output: tests/test_doc_examples.py)
        assert f"trend: {q} ~ N^{fits[q]['exponent']:.3f}" in text, q
    assert fits["R"]["n"] == 6
    diag = json.loads((tutorial / "diagnosis" / "diagnosis.json").read_text())
    assert diag["cause"] == "friction_level"
    lo, hi = diag["parameters"]["f"]["ci95"]
    assert lo < 0.27 < hi
    assert f"f = {diag['parameters']['f']['value']:.6g}" in text


@pytest.mark.slow
def test_formats_page_documents_every_report_file(tutorial):
    """Every file `fepost report` writes is named on the formats page, and every report
    file named there is written."""
    text = (DOCS / "formats.md").read_text(encoding="utf-8")
    section = text.split("### `fepost report --out DIR`", 1)[1].split("\n### ", 1)[0]
    section = section.split("\n#### ", 1)[0]  # the file table, not the subsections' key tables
    documented = set()
    for cell in re.findall(r"^\| ([^|]+) \|", section, re.M):
        for name in re.findall(r"`([^`]+)`", cell):
            stems = re.sub(r"\{([a-z,]+)\}", lambda m: "|".join(m.group(1).split(",")), name)
            if "|" in stems:
                base, exts = stems.split(".", 1)
                documented |= {f"{base}.{e}" for e in exts.split("|")}
            else:
                documented.add(name)
    report = tutorial / "report"
    written = {p.relative_to(report).as_posix() for p in report.rglob("*") if p.is_file()}
    assert any(name.startswith("sweep/") for name in written)  # the demo's case has the sweep
    for name in written:
        stem = name.rsplit(".", 1)[0]
        assert name in documented or f"{stem}.*" in documented, name
    for name in documented:
        if "*" not in name:
            assert name in written, name


# ---------------------------------------------------------------- one source per headline number
def _headline() -> dict:
    """The numbers docs/numbers.md shows (the output of scripts/headline_numbers.py, which the
    doc-example tests run and compare), parsed."""
    text = (DOCS / "numbers.md").read_text(encoding="utf-8")
    out: dict = {"families": {}, "meshes": {}, "k_x": {}}
    for name, f1, t1, flo, fhi, tlo, thi in re.findall(
        r"^  (\S.*?\S) +aspect 1: ([\d.]+), ([\d.]+); aspects 1-3: ([\d.]+)-([\d.]+), ([\d.]+)-([\d.]+)$",
        text,
        re.M,
    ):
        out["families"][name] = [float(v) for v in (f1, t1, flo, fhi, tlo, thi)]
    for mesh, r, force, torque in re.findall(
        r"^  (\S+\.vtu) +\d+ +([\d.]+) +[\d.]+ +[\d.]+ +([\d.]+), ([\d.]+)", text, re.M
    ):
        out["meshes"][mesh] = (float(r), float(force), float(torque))
    for partner, k in re.findall(r"^  .*?(\S+\.vtu).*k_x = ([\d.]+)$", text, re.M):
        out["k_x"][partner] = float(k)
    return out


def _pct(lo: float, hi: float) -> str:
    return f"{round(100 * lo)}–{round(100 * hi)} %"


def test_pages_quote_the_headline_numbers_of_their_one_source():
    """The closed forms' error, k_x of free rolling and R by mesh, as README.md, docs/model.md
    and docs/tutorial.md state them, are those of docs/numbers.md (rounded as quoted)."""
    h = _headline()
    fam = h["families"]
    assert set(fam) == {"uniform", "Hertz", "tire-like", "asymmetric rolling-like"}
    axisym = [fam[k] for k in ("uniform", "Hertz", "tire-like")]
    circle_f = _pct(min(v[0] for v in axisym), max(v[0] for v in axisym))
    circle_t = _pct(min(v[1] for v in axisym), max(v[1] for v in axisym))
    every_f = _pct(min(v[2] for v in fam.values()), max(v[3] for v in fam.values()))
    every_t = _pct(min(v[4] for v in fam.values()), max(v[5] for v in fam.values()))
    readme = " ".join((REPO / "README.md").read_text(encoding="utf-8").split())
    model = " ".join((DOCS / "model.md").read_text(encoding="utf-8").split())
    assert f"by {circle_f[:-2]} % of F0 and {circle_t[:-2]} % of M0 even there" in readme
    assert f"{round(100 * fam['asymmetric rolling-like'][0])} % of F0 for an asymmetric" in readme
    assert f"{every_f[:-2]} % and {every_t[:-2]} % over ellipses up to aspect 3" in readme
    assert f"{circle_f} of F0 in the force and {circle_t} of M0 in the torque" in model
    assert f"{every_f} force, {every_t} torque over the reference maps" in model
    fine, rolled = h["k_x"]["aircraft/static_100.vtu"], h["k_x"]["rig-aircraft/roll_static.vtu"]
    whole = h["k_x"]["rig-tire360/roll/roll_static.vtu"]
    r_fine, r_roll = h["meshes"]["aircraft/static_100.vtu"][0], h["meshes"]["rig-aircraft/roll_static.vtu"][0]
    assert f"k_x = {fine:.3f} ({rolled:.3f} with that mesh's own static map" in readme
    assert f"whose R is {r_roll:.3f} m against {r_fine:.3f} m" in readme
    assert f"torque-free, gives k_x = {whole:.4f}" in readme
    tutorial = " ".join((DOCS / "tutorial.md").read_text(encoding="utf-8").split())
    assert f"{rolled:.3f} against this pair's {fine:.3f}" in tutorial
    stand_in = h["k_x"]["aircraft/rolling_100.vtu"]
    assert f"the sliding stand-in `rolling_100.vtu` would give {stand_in:.2f}" in tutorial
    static = h["meshes"]["aircraft/static_100.vtu"]
    assert f"where the closed forms miss by up to {round(100 * static[2])} %" in tutorial
