"""A sweep as an optional section of ``fepost report`` (a report section provider).

`sample_sweep_section` is the provider for the sample load sweep shipped
in ``meshes/aircraft/`` (``static_*.vtu``, ``rolling_*.vtu`` paired by
``static=rolling``), registered in ``fepost.report.providers.DEFAULT_SECTIONS``:
when the report's static map is one of those files (the report of the sample
tire, as ``fepost report`` without inputs and ``make demo`` write it) it runs
the sweep, draws the load trends and returns a `fepost.report.Section`;
otherwise (a report of other inputs, or the files are absent) it returns None
and the report has no trace of it. `sweep_provider` makes a provider for
any other inputs.

The sweep runs on one worker thread of an in-process Dask cluster (it starts
in well under a second; the sample is a handful of files), with the report's
friction coefficient and reading options, and writes into ``sweep/`` beside
``report.html``: ``coefficients.csv``, ``coefficients.parquet`` and the
figures (PNG, SVG). The row of the report's own case (same static and rolling
file, same options) is not analysed again: it is made from the report's
analysis (`fepost.sweep.jobs.analysis_row`) and handed to the sweep as a
finished row.

The sweep only computes; this module is its presentation in the report (it
imports the sweep, never the other way round).
"""

from __future__ import annotations

import glob
import math
import shutil
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .sections import ReportData, Section

#: Sub-folder of the report that holds the sweep's files.
FOLDER = "sweep"
#: The sample sweep, relative to the repository's ``meshes/`` folder, and its pairing rule.
SAMPLE_INPUTS = ("aircraft/static_*.vtu", "aircraft/rolling_*.vtu")
SAMPLE_PAIRS = "static=rolling"
#: Columns of the section's table: column, heading.
TABLE = (
    ("case", "case"),
    ("load", "load (N)"),
    ("N", "N (N)"),
    ("R", "R (m)"),
    ("M0", "M0 (N·m)"),
    ("a", "a"),
    ("m", "m"),
    ("aR2", "a·R² (m²)"),
    ("m_over_R2", "m/R² (m⁻²)"),
    ("aspect", "aspect"),
    ("k_x", "k_x"),
    ("rolling_kind", "k_x from (its rolling map)"),
    ("status", "status"),
)


def _cell(row, key: str, kinds: dict | None = None):
    if key == "rolling_kind":  # a k_x is never shown without what its rolling map is
        if not row.get("rolling"):
            return "—"
        return (kinds or {}).get(_resolved(row.get("rolling"))) or "rolling map of unstated kind"
    v = row.get(key)
    if key == "case" and not v:
        return Path(str(row.get("source", ""))).stem
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return v


def _resolved(path) -> str:
    try:
        return str(Path(str(path)).resolve()) if path else ""
    except OSError:
        return str(path)


def _rolling_kinds(pairings) -> dict[str, str]:
    """The short label (`fepost.report.rollinglabel.RollingLabel.short`) of each rolling map
    the sweep pairs, by its resolved path."""
    from .rollinglabel import rolling_kind

    return {_resolved(pr.rolling): rolling_kind(pr.rolling) for pr in pairings if pr.rolling is not None}


def _signed(v: float, fmt: str) -> str:
    return fmt.format(v).replace("-", "−")


def _exponent_text(fit) -> str:
    if not fit.fitted:
        return f"{fit.label}: no power law ({fit.note})."
    lo, hi = fit.ci95
    hertz = "" if fit.hertz is None else f"; Hertz contact: {_signed(fit.hertz, '{:.3g}')}"
    group = "" if fit.group == "all" else f" ({fit.group})"
    return (
        f"{fit.label} ∝ N^{_signed(fit.exponent, '{:.3f}')}{group}, 95\u202f% interval "
        f"[{_signed(lo, '{:.3f}')}, {_signed(hi, '{:.3f}')}], from {fit.n} loads{hertz}."
    )


def _same_file(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    try:
        return Path(str(a)).resolve() == Path(str(b)).resolve()
    except OSError:
        return False


def _options(data):
    from ..options import AnalysisOptions

    return getattr(data, "options", None) or AnalysisOptions()


def _report_case(data: ReportData, pairings) -> tuple[int | None, bool]:
    """(index of the pairing that is the report's static map, or None; whether its row
    is the report's own computation: same rolling map and no other time step)."""
    a = getattr(data, "analysis", None)
    if a is None:
        return None, False
    for i, pr in enumerate(pairings):
        if pr.static.path is not None and _same_file(a.static_field.source, pr.static.path):
            rolling = None if a.rolling_field is None else a.rolling_field.source
            same = _same_file(rolling, pr.rolling) and _options(data).step is None
            return i, same
    return None, False


def _rolling_pairs_text(pairings) -> list[str]:
    """One sentence per static map the sweep pairs with a rolling map: what that map is
    (`fepost.report.rollinglabel.rolling_label`, from its sidecar), as the k_x column
    shows its centre-of-pressure shift."""
    from ..errors import InputFileError
    from ..figures.units import normalise
    from ..reader.sidecar import read_sidecar
    from .rollinglabel import rolling_label

    out = []
    for pr in pairings:
        if pr.rolling is None or pr.static.path is None:
            continue
        try:
            side = read_sidecar(Path(pr.rolling))
        except InputFileError:
            side = None  # the sweep's row says why the file cannot be read
        label = rolling_label(side).text
        out.append(
            normalise(
                f"The k_x of {Path(str(pr.static.given)).stem} is from its rolling partner "
                f"{Path(str(pr.rolling)).name}, a {label}."
            )
        )
    return out


def _other_rolling_map(data: ReportData, pairing) -> str:
    """The end of the intro's sentence: "." when the report pairs its static map with the
    sweep's rolling map, else which rolling map the report uses and what it is."""
    from ..figures.units import normalise
    from .rollinglabel import rolling_label

    rf = data.analysis.rolling_field
    if _same_file(None if rf is None else rf.source, pairing.rolling):
        return "."
    if rf is None:
        return ", without a rolling map (its k_x column is the sweep's pairing)."
    return normalise(
        f", with another rolling map: the report pairs it with {Path(str(rf.source)).name}, a "
        f"{rolling_label(rf.sidecar).text} (k_x = {data.analysis.coefficients.k_x:.4f}); the "
        "sweep's row keeps the sweep's pairing."
    )


def sweep_provider(
    inputs: Sequence[str],
    rolling_pairs: str | None = None,
    *,
    key: str = "sweep",
    title: str = "Load sweep",
    only_with_report_case: bool = False,
) -> Callable[[ReportData, Path], Section | None]:
    """A report section provider sweeping ``inputs`` (paths or glob patterns).

    The provider returns None when no input exists, so a report built where the
    sweep's files are missing shows no empty section; with
    ``only_with_report_case`` also when the report's static map is not one of the
    inputs (a report of other files). The report's own case, when it is a row, is
    taken from the report's analysis (module docstring). ``data`` needs
    ``friction``; ``analysis`` and ``options`` are used when present.
    """

    def provider(data: ReportData, folder: Path) -> Section | None:
        present = [i for i in inputs if glob.glob(str(i), recursive=True)]
        if not present:
            return None
        from ..errors import ArgumentError
        from ..sweep.inputs import expand_inputs
        from ..sweep.pairs import pair_sources, parse_rolling_pairs

        pairs = None if rolling_pairs is None else parse_rolling_pairs(rolling_pairs)
        sources = expand_inputs(present)
        try:
            pairings = pair_sources(sources, pairs)
        except ArgumentError:  # no rolling map among the files: a static-only sweep
            pairs = None
            pairings = pair_sources(sources, None)
        own, same = _report_case(data, pairings)
        if only_with_report_case and own is None:
            return None  # decided before the sweep's heavier imports (Dask, pyarrow)
        from ..sweep.jobs import Job, analysis_row
        from ..sweep.run import run_sweep
        from ..sweep.store import WORK, WorkFolder
        from ..sweep.trends import load_trends
        from .figures import Figure, png_data_uri
        from .sections import Section
        from .sweeppage import draw_figures

        options, friction = _options(data), float(data.friction)
        out = Path(folder) / FOLDER
        if own is not None and same:
            pr = pairings[own]
            job = Job(pr.static.given, pr.static.path, None, options, rolling=pr.rolling,
                      rolling_given=pr.rolling_given, role=pr.role, also=pr.static.also,
                      rolling_also=pr.rolling_also, friction=friction)  # fmt: skip
            with WorkFolder(out, force=True) as work:
                work.save_row(job.key(), analysis_row(job, data.analysis))
        result = run_sweep(
            present,
            out,
            rolling_pairs=pairs,
            options=options,
            friction=friction,
            workers=1,
            processes=False,
            progress=False,
            force=True,
        )
        shutil.rmtree(out / WORK, ignore_errors=True)
        rows = list(result.rows)
        fits = load_trends(rows)
        figures, captions = [], {}
        for fig in draw_figures(rows, fits, out):
            stem = fig["png"].rsplit(".", 1)[0]
            fkey = f"{key}-{stem.replace('_', '-')}"
            files = (f"{FOLDER}/{fig['png']}", f"{FOLDER}/{fig['svg']}")
            figures.append(Figure(fkey, files, fig["caption"], png_data_uri(out / fig["png"])))
            captions[fkey] = fig["caption"]
        ok = sum(r["status"] == "ok" for r in rows)
        intro = (
            f"The same analysis on each of {len(rows)} FE exports of a load sweep "
            f"({ok} analysed{'' if ok == len(rows) else f', {len(rows) - ok} failed'}), run by "
            "fepost sweep. Power laws y = c·N^α are fitted by least squares of log y on log N; "
            "the intervals use Student's t with n − 2 degrees of freedom."
        )
        if own is not None:
            name = _cell(rows[own], "case") if own < len(rows) else pairings[own].static.given
            ending = _other_rolling_map(data, pairings[own])  # "." when the report's pair is the sweep's
            intro += f" The report above is the case {name} of this sweep{ending}"
        kinds = _rolling_kinds(pairings)
        table = (tuple(h for _, h in TABLE), *(tuple(_cell(r, k, kinds) for k, _ in TABLE) for r in rows))
        return Section(
            key=key,
            title=title,
            paragraphs=(intro, *_rolling_pairs_text(pairings), *(_exponent_text(f) for f in fits)),
            table=table,
            figures=tuple(figures),
            captions=captions,
            files=(f"{FOLDER}/coefficients.csv", f"{FOLDER}/coefficients.parquet"),
        )

    return provider


def sample_sweep_section(data: ReportData, folder: Path) -> Section | None:
    """The section of the sample load sweep in ``meshes/aircraft/`` in the report of one of
    its cases; None for a report of other files, or when the sample is not there."""
    from .samples import meshes_folder

    inputs = [str(meshes_folder() / p) for p in SAMPLE_INPUTS]
    return sweep_provider(inputs, SAMPLE_PAIRS, only_with_report_case=True)(data, folder)
