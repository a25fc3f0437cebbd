"""Run the commands that README.md and docs/ show with their output, and compare the output.

A fenced ``console`` block preceded by the HTML comment ``<!-- doc-example: checked ... -->``
is *checked*: each ``$ COMMAND`` line in it is run and the lines after it, up to the next
``$`` line or the end of the block, must be what the command prints on stdout (exit status
0). ``<!-- doc-example: setup -->`` before a ``python`` or ``console`` block runs it without
comparing anything (it makes an input of a later block). A page's marked blocks run in the
page's order in one scratch folder (``run_page``; the tests run each page once for all its
blocks) holding links to the repository's top-level folders (``meshes/``,
``examples/``, ``docs/`` ...); ``fepost`` and ``python`` are this interpreter with the
repository on ``PYTHONPATH``.

Options of ``checked`` (``key=value``, values without spaces or in double quotes):

``rtol``
    Relative tolerance of the numbers (default 0: the text exactly). The words, and every
    number's position in the text, must always be the same. With ``rtol`` > 0 two numbers
    agree when ``|a - b| <= rtol * max(|a|, |b|)`` plus, for a printed decimal, half a unit
    of its last printed digit on each side (a value on a rounding edge may print either way).
    The value used is justified by the computation in the comment's ``why`` text:

    * ``1e-9`` — ``fepost coefficients``/``predict``: sums over the FE map and a linear
      least-squares fit, the same operations on every machine but not in the same order
      (numpy's SIMD blocking, BLAS threads): ~1e-13 relative, times the fit's condition;
    * ``1e-3`` — ``fepost diagnose``: its iterative fits stop when the noise scale changes
      by under 1e-4 relative (``fepost.diagnose.fitting.SIGMA_RTOL``), and the intervals,
      RMSEs and BICs it prints scale with it: 10 times that margin.
``until``
    Show the output up to the first line that starts with this text, then ``...``.
``keep``
    A regular expression: show only the lines it matches (``re.search``); each run of left
    out lines is one ``...`` line.
``width``
    Lines longer than this (default 110) are cut at a space and end in `` ...``; such a line
    is compared as a prefix of the full line.
``copy``
    ``FILE:DOCFILE``: the file the command wrote into the scratch folder must match the
    repository's ``DOCFILE`` (same comparison, whole file).

``python -m tests.docexamples --update [PAGE ...]`` rewrites the output of every checked
block (and the ``copy`` files) from real runs; ``--check`` only reports the differences.

Why not a library: pytest-examples, phmdoctest and mktestdocs check Python examples, cram
and prysk shell sessions in their own ``.t`` files, and sybil's document parsers would need
a custom shell-session parser and still neither compare numbers with a tolerance nor rewrite
the blocks from the runs; the runner here is those three things and nothing else.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: Top-level entries not linked into the scratch folder (outputs, tooling, hidden).
NOT_LINKED = {"out", "report", "site", "build", "diag", "diagnosis"}
MARKER = re.compile(r"^<!-- doc-example: (checked|setup)(.*?)-->\s*$")
FENCE = re.compile(r"^```(\w*)\s*$")
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
OPTION = re.compile(r'(\w+)=("[^"]*"|\S+)')
ELLIPSIS = "..."
CUT = " ..."
DEFAULT_WIDTH = 110
#: Longest time one documented command may take (s).
TIMEOUT = 600


@dataclass(frozen=True)
class Command:
    """One ``$`` line of a checked block and the output the page shows for it."""

    line: str
    expected: tuple[str, ...]


@dataclass(frozen=True)
class Block:
    """A marked fenced block of a page: where it is, what it runs, how it is compared."""

    page: str
    kind: str  # "checked" or "setup"
    lang: str
    start: int  # index of the first line inside the fence
    end: int  # index of the closing fence
    body: tuple[str, ...]
    options: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"{self.page}:{self.start}"

    def commands(self) -> list[Command]:
        """The ``$`` lines and the output lines after each (console blocks)."""
        out: list[Command] = []
        line, expected = None, []
        for text in self.body:
            if text.startswith("$ "):
                if line is not None:
                    out.append(Command(line, tuple(expected)))
                line, expected = text[2:], []
            elif line is not None:
                expected.append(text)
        if line is not None:
            out.append(Command(line, tuple(expected)))
        return out

    @property
    def rtol(self) -> float:
        return float(self.options.get("rtol", 0.0))

    @property
    def width(self) -> int:
        return int(self.options.get("width", DEFAULT_WIDTH))


def parse_options(text: str) -> dict:
    return {k: v[1:-1] if v.startswith('"') else v for k, v in OPTION.findall(text)}


def blocks(page: str, text: str | None = None) -> list[Block]:
    """The marked blocks of ``page`` (a path relative to the repository, or its ``text``), in order."""
    lines = ((REPO / page).read_text(encoding="utf-8") if text is None else text).splitlines()
    found = []
    for i, text in enumerate(lines):
        m = MARKER.match(text)
        if not m or i + 1 >= len(lines):
            continue
        fence = FENCE.match(lines[i + 1])
        if not fence:
            raise ValueError(f"{page}:{i + 1}: a doc-example marker must stand right before a fenced block")
        end = next(j for j in range(i + 2, len(lines)) if lines[j].startswith("```"))
        body = tuple(lines[i + 2 : end])
        found.append(Block(page, m.group(1), fence.group(1), i + 2, end, body, parse_options(m.group(2))))
    return found


def pages() -> list[str]:
    """README.md and every Markdown page under docs/ (repository-relative)."""
    docs = sorted(p.relative_to(REPO).as_posix() for p in (REPO / "docs").rglob("*.md"))
    return ["README.md", *docs]


def pages_with_examples() -> list[str]:
    return [p for p in pages() if blocks(p)]


# ---------------------------------------------------------------- running
def scratch_folder(where: Path) -> Path:
    """A folder with links to the repository's top-level entries (the commands' cwd)."""
    where.mkdir(parents=True, exist_ok=True)
    for entry in REPO.iterdir():
        if entry.name.startswith(".") or entry.name in NOT_LINKED or (where / entry.name).exists():
            continue
        (where / entry.name).symlink_to(entry)
    return where


def argv_of(line: str) -> list[str]:
    argv = shlex.split(line)
    if argv[0] == "fepost":
        return [sys.executable, "-m", "fepost", *argv[1:]]
    if argv[0] == "python":
        return [sys.executable, *argv[1:]]
    return argv


def run(argv: list[str], cwd: Path, errors: dict | None = None) -> str:
    """stdout of ``argv`` run in ``cwd``; a failure raises with the command's stderr. The
    stderr of a command that succeeds goes to ``errors[shlex.join(argv)]`` when given."""
    env = {**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "200"}
    proc = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=TIMEOUT)
    if proc.returncode != 0:
        raise RuntimeError(f"{shlex.join(argv)} exited with {proc.returncode}: {proc.stderr[-2000:]}")
    if errors is not None:
        errors[shlex.join(argv)] = proc.stderr
    return proc.stdout


@dataclass(frozen=True)
class PageRun:
    """The outputs of a page's marked blocks: block name -> [stdout per command]; and what
    each command wrote to stderr, by its command line as the page shows it (`stderr_of`)."""

    folder: Path
    outputs: dict
    errors: dict = field(default_factory=dict)

    def stderr_of(self, line: str) -> str:
        """The stderr of the page's command ``line`` (e.g. ``"fepost report --out out/report"``)."""
        return self.errors[shlex.join(argv_of(line))]


def saved_page_run(page: str, folder: Path) -> PageRun:
    """`run_page` in ``folder/work``, its outputs also saved to ``folder/outputs.json`` so
    that another process can take the run as it is (`load_page_run`)."""
    run = run_page(page, folder / "work")
    (folder / "outputs.json").write_text(json.dumps(run.outputs), encoding="utf-8")
    (folder / "errors.json").write_text(json.dumps(run.errors), encoding="utf-8")
    return run


def load_page_run(folder: Path) -> PageRun:
    """The `PageRun` that `saved_page_run` left in ``folder``."""
    outputs = json.loads((folder / "outputs.json").read_text(encoding="utf-8"))
    errors = json.loads((folder / "errors.json").read_text(encoding="utf-8"))
    return PageRun(folder / "work", outputs, errors)


def run_page(page: str, folder: Path) -> PageRun:
    """Run the marked blocks of ``page`` in order in ``folder``."""
    work = scratch_folder(folder)
    outputs: dict = {}
    errors: dict = {}
    for block in blocks(page):
        if block.lang == "python":
            outputs[block.name] = [run([sys.executable, "-c", "\n".join(block.body)], work)]
        else:
            outputs[block.name] = [run(argv_of(c.line), work, errors) for c in block.commands()]
    return PageRun(work, outputs, errors)


# ---------------------------------------------------------------- showing and comparing
def shorten(line: str, width: int) -> str:
    if len(line) <= width:
        return line
    cut = line.rfind(" ", 0, width - len(CUT) + 1)
    return line[: cut if cut > 0 else width - len(CUT)] + CUT


def render(stdout: str, options: dict, width: int = DEFAULT_WIDTH) -> list[tuple[str, str]]:
    """(shown line, full line) of ``stdout`` as the block shows it (``until``, ``keep``, ``width``)."""
    lines = stdout.rstrip("\n").splitlines() if stdout.strip() else []
    shown: list[tuple[str, str]] = []
    if "keep" in options:
        pattern = re.compile(options["keep"])
        gap = False
        for text in lines:
            if pattern.search(text):
                shown.append((text, text))
                gap = False
            elif not gap:
                shown.append((ELLIPSIS, ELLIPSIS))
                gap = True
    else:
        shown = [(t, t) for t in lines]
    if "until" in options:
        stop = next((i for i, (t, _) in enumerate(shown) if t.startswith(options["until"])), None)
        if stop is not None and stop + 1 < len(shown):
            shown = [*shown[: stop + 1], (ELLIPSIS, ELLIPSIS)]
    return [(t if t == ELLIPSIS else shorten(t, width), full) for t, full in shown]


def tokens(text: str) -> list[tuple[str, str]]:
    """("num", text) and ("text", text) pieces of a line."""
    out, pos = [], 0
    for m in NUMBER.finditer(text):
        if m.start() > pos:
            out.append(("text", text[pos : m.start()]))
        out.append(("num", m.group()))
        pos = m.end()
    if pos < len(text):
        out.append(("text", text[pos:]))
    return out


def _half_unit(s: str) -> float:
    """Half a unit of the last printed digit of a decimal (0 for an integer)."""
    mantissa, _, exp = s.lower().partition("e")
    if "." not in mantissa and not exp:
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (-decimals + (int(exp) if exp else 0))


def numbers_agree(a: str, b: str, rtol: float) -> bool:
    """Do the page's number and the printed one agree within ``rtol``?

    The coarser of the two may be the other rounded: half a unit of its last
    digit is allowed on top of ``rtol``, and no more. Two numbers printed to the
    same digits that differ in the last one (0.8 and 0.9) therefore disagree
    whatever the rtol, though a value of exactly 0.85 could print as either: a
    page must not hide a change of one unit in its last digit.
    """
    if a == b:
        return True
    if rtol <= 0:
        return False
    x, y = float(a), float(b)
    return abs(x - y) <= rtol * max(abs(x), abs(y)) + max(_half_unit(a), _half_unit(b))


def line_agrees(expected: str, full: str, rtol: float) -> bool:
    """Does the shown line ``expected`` state the printed line ``full``? A line ending in
    `` ...`` states a prefix of it."""
    prefix = expected.endswith(CUT)
    if not prefix and expected == full:
        return True
    want = tokens(expected[: -len(CUT)] if prefix else expected)
    have = tokens(full)
    if len(have) < len(want) or (not prefix and len(have) != len(want)):
        return False
    for i, ((kw, w), (kh, h)) in enumerate(zip(want, have, strict=False)):
        last = prefix and i == len(want) - 1
        if kw != kh:
            return False
        if kw == "num" and not numbers_agree(w, h, rtol):
            return False
        if kw == "text" and not (h.startswith(w) if last else h == w):
            return False
    return True


def differences(expected: list[str], stdout: str, options: dict, rtol: float, width: int) -> list[str]:
    """What differs between the lines a block shows and the output, as readable lines (none: agree)."""
    shown = render(stdout, options, width)
    out = []
    for i in range(max(len(expected), len(shown))):
        want = expected[i] if i < len(expected) else "<nothing>"
        have, full = shown[i] if i < len(shown) else ("<nothing>", "<nothing>")
        if want == ELLIPSIS or have == ELLIPSIS:
            if want != have:
                out.append(f"line {i + 1}: the page shows {want!r}, the command prints {have!r}")
            continue
        if not line_agrees(want, full, rtol):
            out.append(f"line {i + 1}: the page shows {want!r}\n        the command prints {have!r}")
    return out


def check_block(block: Block, run: PageRun) -> list[str]:
    """Every difference between ``block`` and its run (empty: the page is right)."""
    problems = []
    for command, stdout in zip(block.commands(), run.outputs[block.name], strict=True):
        for d in differences(list(command.expected), stdout, block.options, block.rtol, block.width):
            problems.append(f"{block.name}: $ {command.line}\n    {d}")
    if "copy" in block.options:
        written, docfile = block.options["copy"].split(":")
        text = (run.folder / written).read_text(encoding="utf-8")
        want = (REPO / docfile).read_text(encoding="utf-8").splitlines()
        for d in differences(want, text, {"width": "100000"}, block.rtol, 100000):
            problems.append(f"{docfile} (written by {block.name} as {written})\n    {d}")
    return problems


# ---------------------------------------------------------------- rewriting
def updated_page(page: str, run: PageRun, text: str | None = None) -> str:
    """The page's text (or ``text``) with every checked block's output as the run printed it."""
    lines = ((REPO / page).read_text(encoding="utf-8") if text is None else text).splitlines()
    for block in reversed(blocks(page, text)):
        if block.kind != "checked":
            continue
        body = []
        for command, stdout in zip(block.commands(), run.outputs[block.name], strict=True):
            body += [f"$ {command.line}", *(t for t, _ in render(stdout, block.options, block.width))]
        lines[block.start : block.end] = body
    return "\n".join(lines) + "\n"


def update(page: str, folder: Path, write: bool) -> list[str]:
    """Rewrite (``write``) or check ``page``; returns the differences found."""
    result = run_page(page, folder)
    problems = [p for b in blocks(page) if b.kind == "checked" for p in check_block(b, result)]
    if write:
        (REPO / page).write_text(updated_page(page, result), encoding="utf-8")
        for b in blocks(page):
            if "copy" in b.options:
                written, docfile = b.options["copy"].split(":")
                (REPO / docfile).write_text((result.folder / written).read_text(encoding="utf-8"))
    return problems


def main(argv: list[str] | None = None) -> int:
    import tempfile

    parser = argparse.ArgumentParser(prog="python -m tests.docexamples", description=__doc__.split("\n")[0])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--update", action="store_true", help="rewrite the output blocks from real runs")
    mode.add_argument("--check", action="store_true", help="only report differences (the default)")
    parser.add_argument("pages", nargs="*", help="pages to run (default: every page with examples)")
    args = parser.parse_args(argv)
    chosen = args.pages or pages_with_examples()
    unknown = [p for p in chosen if not (REPO / p).is_file()]
    if unknown:
        parser.error(f"no such page: {', '.join(unknown)}")
    changed = 0
    with tempfile.TemporaryDirectory(prefix="fepost-docexamples-") as tmp:
        for i, page in enumerate(chosen):
            try:
                problems = update(page, Path(tmp) / str(i), args.update)
            except (RuntimeError, subprocess.TimeoutExpired) as exc:  # a documented command failed
                print(f"{page}: not updated: {str(exc).splitlines()[0]}", file=sys.stderr)
                return 2
            changed += bool(problems)
            verb = "rewritten" if args.update and problems else "differs" if problems else "up to date"
            print(f"{page}: {verb}")
            for p in problems:
                print(f"  {p}")
    return 0 if args.update or not changed else 1


if __name__ == "__main__":
    sys.exit(main())
