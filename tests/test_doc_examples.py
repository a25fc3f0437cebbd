"""The commands README.md and docs/ show with their output print that output.

Each page's marked blocks run once, in order, in one scratch folder (``page_run``); every
checked block is then compared with what its commands printed (`tests.docexamples`, where
the markers, the options and the tolerances are explained). After a change of output, run
``python -m tests.docexamples --update`` and review the diff of the pages.
"""

from __future__ import annotations

import re

import docexamples as dx  # tests/docexamples.py (the folder is on sys.path, as for the other helpers)
import pytest

CHECKED = [
    (page, b.name) for page in dx.pages_with_examples() for b in dx.blocks(page) if b.kind == "checked"
]


@pytest.fixture(scope="module")
def page_run(documented_page):
    """page -> its `PageRun`, each page run once per test session (conftest's
    ``documented_page``: the tutorial's run is shared with tests/test_docs.py)."""
    return documented_page


@pytest.mark.slow
@pytest.mark.parametrize(("page", "name"), CHECKED, ids=[name for _, name in CHECKED])
def test_documented_output_is_what_the_command_prints(page, name, page_run):
    block = next(b for b in dx.blocks(page) if b.name == name)
    problems = dx.check_block(block, page_run(page))
    assert not problems, "\n".join(problems) + "\n(regenerate: python -m tests.docexamples --update)"


def test_every_command_shown_with_output_is_checked():
    """A ``$`` line followed by output lines, in any fenced block of the README or docs/, is
    in a block marked ``checked``."""
    unchecked = []
    for page in dx.pages():
        lines = (dx.REPO / page).read_text(encoding="utf-8").splitlines()
        marked = {b.start for b in dx.blocks(page) if b.kind == "checked"}
        start = None
        for i, text in enumerate(lines):
            if text.startswith("```"):
                start = i + 1 if start is None else None
                continue
            if start is not None and text.startswith("$ ") and start not in marked:
                following = lines[i + 1] if i + 1 < len(lines) else "```"
                if not following.startswith(("```", "$ ")):
                    unchecked.append(f"{page}:{i + 1}: {text}")
    assert not unchecked, "\n".join(unchecked)
    assert len(CHECKED) >= 6  # the tutorial's, diagnose's, rig's and the README's


@pytest.mark.slow
@pytest.mark.parametrize("page", dx.pages_with_examples())
def test_the_documented_commands_write_only_into_an_ignored_folder(page, page_run):
    """Run from the clone's root, a page's examples leave nothing untracked there: all they
    write is under out/, which .gitignore lists."""
    folder = page_run(page).folder
    made = sorted(p.name for p in folder.iterdir() if not p.is_symlink())
    assert made in ([], ["out"]), made
    assert "/out/" in (dx.REPO / ".gitignore").read_text(encoding="utf-8").splitlines()


# ---------------------------------------------------------------- the comparison itself
PAGE = """Intro.

<!-- doc-example: checked rtol=1e-3 until="held" -->
```console
$ fepost diagnose x
cause: friction_level
  f = 0.269724  (95 % CI 0.268577 .. 0.270872)
held-out RMSE: before 0.0542, after 0.02353; delta BIC -1014.4
...
```

<!-- doc-example: setup -->
```python
print("made")
```
"""
OUTPUT = (
    "cause: friction_level\n  f = 0.269724  (95 % CI 0.268577 .. 0.270872)\n"
    "held-out RMSE: before 0.0542, after 0.02353; delta BIC -1014.4\nlack of fit: none\n"
)


def _check(output: str, page: str = PAGE) -> list[str]:
    block = dx.blocks("x.md", page)[0]
    return dx.differences(list(block.commands()[0].expected), output, block.options, block.rtol, block.width)


def test_the_blocks_of_a_page_are_found_with_their_options():
    checked, setup = dx.blocks("x.md", PAGE)
    assert (checked.kind, checked.lang, checked.rtol, checked.options["until"]) == (
        "checked",
        "console",
        1e-3,
        "held",
    )
    assert [c.line for c in checked.commands()] == ["fepost diagnose x"]
    assert (setup.kind, setup.lang, setup.body) == ("setup", "python", ('print("made")',))


def test_the_same_output_agrees_and_a_changed_number_or_word_does_not():
    assert _check(OUTPUT) == []
    # within rtol 1e-3 (plus the print's rounding): agrees
    assert _check(OUTPUT.replace("0.269724", "0.269800")) == []
    assert _check(OUTPUT.replace("-1014.4", "-1014.9")) == []
    # beyond it: the line is named
    (problem,) = _check(OUTPUT.replace("0.269724", "0.271"))
    assert problem.startswith("line 2:") and "0.271" in problem
    assert _check(OUTPUT.replace("-1014.4", "-1016.5"))
    assert _check(OUTPUT.replace("friction_level", "pressure_shift"))
    # a line more before the cut, or the cut gone
    assert _check(OUTPUT.replace("cause: friction_level\n", "cause: friction_level\n  new line\n"))
    assert _check(OUTPUT.replace("lack of fit: none\n", ""))


def test_without_a_tolerance_the_text_must_be_exact():
    page = PAGE.replace("rtol=1e-3 ", "")
    assert _check(OUTPUT, page) == []
    assert _check(OUTPUT.replace("0.269724", "0.269725"), page)


def test_integers_get_no_rounding_allowance():
    assert dx.numbers_agree("0.0445", "0.045", 0.0) is False
    assert dx.numbers_agree("0.044", "0.0445", 1e-3)  # the page rounds the printed value
    assert dx.numbers_agree("0.0446", "0.045", 1e-3)
    # one unit in the last digit is a change, not a rounding, whatever the rtol
    assert not dx.numbers_agree("0.8", "0.9", 1e-9)
    assert not dx.numbers_agree("0.044", "0.045", 1e-3)
    assert not dx.numbers_agree("1014.4", "1014.5", 1e-9)
    assert dx.numbers_agree("1014.4", "1014.5", 1e-4)  # within rtol itself
    assert not dx.numbers_agree("82", "83", 1e-3)  # row numbers are not rounded values
    assert dx.numbers_agree("1e-18", "1.0000001e-18", 1e-3)


def test_keep_and_width_shape_the_shown_lines():
    out = "a 1\nb 2\nc 3\nd " + "x " * 80 + "\ne 5\n"
    shown = [t for t, _ in dx.render(out, {"keep": "^(a|d|e)"}, width=40)]
    assert shown[0] == "a 1" and shown[1] == "..." and shown[3] == "e 5"
    assert shown[2].endswith(" ...") and len(shown[2]) <= 40
    # a cut line states a prefix of the full line: its numbers and words are still compared
    assert dx.line_agrees("d x x ...", "d x x x x", 0.0)
    assert not dx.line_agrees("d y x ...", "d x x x x", 0.0)
    assert dx.line_agrees("f = 0.3 and ...", "f = 0.3 and more", 0.0)
    assert not dx.line_agrees("f = 0.4 and ...", "f = 0.3 and more", 0.0)


def test_update_rewrites_only_the_output_lines(tmp_path):
    block = dx.blocks("x.md", PAGE)[0]
    new = OUTPUT.replace("0.269724", "0.2801")
    run = dx.PageRun(tmp_path, {block.name: [new], dx.blocks("x.md", PAGE)[1].name: ["made\n"]})
    text = dx.updated_page("x.md", run, PAGE)
    assert text == PAGE.replace("0.269724", "0.2801")
    # and the rewritten page agrees with the run
    assert (
        dx.differences(list(dx.blocks("x.md", text)[0].commands()[0].expected), new, block.options, 1e-3, 110)
        == []
    )


# ---------------------------------------------------------------- one accuracy figure per map
PERCENT = re.compile(
    r"within ([\d.]+)% of the exact integrals \(largest \|dF\|/F0 ([\d.]+)%, \|dMz\|/M0 ([\d.]+)%"
)


def _stated(text: str) -> set[tuple[float, ...]]:
    return {tuple(float(v) for v in m) for m in PERCENT.findall(text)}


@pytest.fixture(scope="module")
def small_analysis():
    import fepost

    return fepost.analyse(str(dx.REPO / "meshes" / "static.vtu"), str(dx.REPO / "meshes" / "rolling.vtu"))


def test_the_stated_accuracy_is_the_direct_error_map_on_the_same_grid(small_analysis):
    """The turned sums of the stated accuracy give the direct `model_error_map`'s numbers."""
    import numpy as np

    from fepost.friction.law import FrictionLaw
    from fepost.friction.summary import ACCURACY_GRID, model_error_map

    a = small_analysis
    turned = a.model_summary.rolling_errors
    direct = model_error_map(
        a.rolling_map,
        a.coefficients,
        FrictionLaw(f=a.coefficients.f),
        model=a.model_summary.rolling,
        rolling=True,
        **ACCURACY_GRID,
    )
    assert turned.beta.shape == direct.beta.shape and np.allclose(
        turned.beta, direct.beta, rtol=0, atol=1e-12
    )
    for name in direct.names:
        assert np.allclose(turned.force[name], direct.force[name], rtol=0, atol=1e-12), name
        assert np.allclose(turned.torque[name], direct.torque[name], rtol=0, atol=1e-12), name
    # denser than the model's own check grid, so never below its largest errors by more than a grid step
    acc = a.model_summary.accuracy
    assert acc.model >= 0.9 * max(
        a.model_summary.static.accuracy["model_force"], a.model_summary.static.accuracy["model_torque"]
    )


@pytest.mark.slow
def test_coefficients_predict_and_report_state_one_figure_per_map(small_analysis, tmp_path, capsys):
    """`fepost coefficients`, `fepost predict` (static and rolling) and the report state the same
    figure for the same maps, all from the model summary's error maps."""
    from fepost.cli import main
    from fepost.report.build import _error_maps, quote_error_maps

    static, rolling = (str(dx.REPO / "meshes" / f) for f in ("static.vtu", "rolling.vtu"))
    summary = small_analysis.model_summary
    kin = tmp_path / "kin.csv"
    kin.write_text("vx,vy,wz\n0.1,0,1\n0,0.2,2\n")

    def printed(*argv: str) -> str:
        assert main(list(argv)) == 0
        return capsys.readouterr().out

    coef = printed("coefficients", static, "--rolling", rolling)
    pred_static = printed("predict", static, "--kinematics", str(kin), "--out", str(tmp_path / "p.csv"))
    pred_rolling = printed(
        "predict", static, "--rolling", rolling, "--kinematics", str(kin), "--out", str(tmp_path / "q.csv")
    )

    def figures(acc) -> tuple[float, ...]:
        return tuple(round(100 * v, 1) for v in (acc.model, acc.model_force, acc.model_torque))

    both, alone, roll = summary.accuracy, summary.map_accuracy(), summary.map_accuracy(True)
    assert _stated(coef) == {figures(both)}
    assert _stated(pred_static) == {figures(alone)} and "over the static map on" in pred_static
    assert _stated(pred_rolling) == {figures(roll)} and "over the rolling map on" in pred_rolling
    assert f"{alone.model_force:.3f}, |dMz|/M0 {alone.model_torque:.3f}" in coef
    assert f"{roll.model_force:.3f}, |dMz|/M0 {roll.model_torque:.3f}" in coef
    # the report: its error maps are these, its recommendation the same sentence
    _, docs = _error_maps(small_analysis, tmp_path)
    assert docs["error_map"]["worst"]["model"]["force"] == alone.model_force
    assert docs["error_map_rolling"]["worst"]["model"]["torque"] == roll.model_torque
    ctx = {"model_rows": [], "model_recommendation": "placeholder"}
    quote_error_maps(ctx, docs, summary)
    assert _stated(ctx["model_recommendation"]) == {figures(both)}


def test_the_pages_quote_the_figure_their_checked_output_states():
    """Prose "within X %" and "miss by up to Y %" on a page equal the stated figure in the
    page's checked `fepost coefficients` output (which the slow tests compare with a real run)."""
    for page in ("docs/tutorial.md",):
        text = (dx.REPO / page).read_text(encoding="utf-8")
        block = next(b for b in dx.blocks(page) if "fepost coefficients" in "\n".join(b.body))
        use = "\n".join(block.body)
        (within,) = re.findall(r"within ([\d.]+)% of the exact integrals", use)
        (paper,) = re.findall(r"miss by up to (\d+)%", use)
        prose = text.replace("\n".join(block.body), "")
        assert re.findall(r"within ([\d.]+) % of the exact", prose) == [within], page
        assert re.findall(r"miss by up to (\d+) %", prose) == [paper], page
