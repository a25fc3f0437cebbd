"""The trends page of a sweep (``DIR/trends.html``) and its embeddable section.

HTML comes from Jinja2 templates kept as files in ``fepost/report/templates/sweep/``:
``section.html.j2`` (figures, power-law fits, the table) is what
`sweep_section` returns for embedding in another page (the report);
``trends.html.j2`` wraps it into a standalone page.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import markupsafe

from ..figures.sweep import MAX_SERIES, plot_load_trends, plot_time_trends, transient_series
from ..figures.units import display_unit
from ..output import write_json_atomic, write_text_atomic
from ..sweep.table import normalise
from ..sweep.trends import PowerLaw, load_trends

#: Heading of the section (on the trends page, and by default when embedded).
TITLE = "Sweep: coefficients against load"
#: Most rows listed in the HTML table (the CSV and Parquet files hold them all).
MAX_TABLE_ROWS = 200
#: How the page writes a fitted quantity (HTML; subscripts as <sub>).
HTML_LABELS = {"M0": "M<sub>0</sub>", "aR2": "a R²", "m_over_R2": "m / R²", "k_x": "k<sub>x</sub>"}
#: Columns of the HTML table: column, heading (HTML).
TABLE_COLUMNS = (
    ("source", "source"),
    ("step", "step"),
    ("status", "status"),
    ("load", "load (N)"),
    ("N", "N (N)"),
    ("R", "R (m)"),
    ("M0", "M<sub>0</sub> (N·m)"),
    ("a", "a"),
    ("m", "m"),
    ("aspect", "aspect"),
    ("circular", "circular"),
    ("k_x", "k<sub>x</sub>"),
    ("error", "error"),
)


def _environment():
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("fepost.report", "templates/sweep"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["num"] = _num
    env.filters["quantity"] = _quantity
    env.filters["html"] = markupsafe.Markup
    return env


def _quantity(fit: PowerLaw):
    """A fit's quantity as the page writes it: symbol with subscripts, unit in the report's
    style in parentheses (none for a dimensionless quantity)."""
    name = markupsafe.Markup(HTML_LABELS.get(fit.quantity, markupsafe.escape(fit.label)))
    unit = display_unit(fit.unit)
    return name + markupsafe.Markup(" (") + unit + markupsafe.Markup(")") if unit else name


def _num(v, digits: int = 4) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return ""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    return str(v)


def _save(fig, folder: Path, stem: str) -> list[str]:
    import matplotlib.pyplot as plt

    from .figures import save_formats

    try:
        return save_formats(fig, folder, stem, ("png", "svg"))
    finally:
        plt.close(fig)


def draw_figures(rows: Sequence[Mapping], fits: Sequence[PowerLaw], folder: Path) -> list[dict]:
    """Draw the sweep's figures into ``folder`` (PNG and SVG); return name and caption of each."""
    folder.mkdir(parents=True, exist_ok=True)
    figures = []
    loads = {r["N"] for r in rows if r.get("status") == "ok" and r.get("N") is not None}
    if len(loads) >= 2:
        from .rollinglabel import kind_of_rolling_maps

        kind = kind_of_rolling_maps(r.get("rolling") for r in rows if r.get("k_x") is not None)
        _save(plot_load_trends(rows, fits, k_x_kind=kind), folder, "load_trends")
        figures.append(
            {
                "png": "load_trends.png",
                "svg": "load_trends.svg",
                "caption": "Coefficients against the normal load N (log-log), power-law fits with "
                "their 95 % confidence bands; exponents with 95 % intervals in the legends.",
            }
        )
    series = transient_series(rows)
    if series:
        _save(plot_time_trends(series), folder, "time_trends")
        figures.append(
            {
                "png": "time_trends.png",
                "svg": "time_trends.svg",
                "caption": "Coefficients against time for the runs with several time steps"
                + (f" (the first {MAX_SERIES} of {len(series)})" if len(series) > MAX_SERIES else "")
                + ".",
            }
        )
    return figures


def sweep_section(
    rows: Sequence[Mapping],
    figure_dir: str | os.PathLike,
    href: str = "",
    *,
    heading_level: int = 2,
    title: str | None = TITLE,
) -> str:
    """An HTML ``<section>`` with the sweep's figures, power-law fits and table.

    Parameters
    ----------
    rows : sequence of mappings
        The sweep table (`SweepResult.rows` or
        `fepost.sweep.table.read_table` of ``coefficients.parquet``).
    figure_dir : path
        Folder the figures are drawn into (created).
    href : str
        How the page holding the section reaches ``figure_dir`` (relative URL
        prefix, e.g. ``"sweep"``); images are linked as ``href/name.png``.
    heading_level : int
        Level of the section's heading (``2`` → ``<h2>``; sub-headings one below).
    title : str or None
        The section's heading; None for none (the page around it gives one).
    """
    rows = [normalise(r) for r in rows]
    return _section(rows, load_trends(rows), figure_dir, href, heading_level, title)


def _section(
    rows: Sequence[Mapping],
    fits: Sequence[PowerLaw],
    figure_dir: str | os.PathLike,
    href: str,
    heading_level: int,
    title: str | None,
) -> str:
    """`sweep_section` of normalised ``rows`` with their fits ``fits``."""
    figures = draw_figures(rows, fits, Path(figure_dir))
    prefix = href.rstrip("/") + "/" if href else ""
    listed = list(rows)[:MAX_TABLE_ROWS]
    return (
        _environment()
        .get_template("section.html.j2")
        .render(
            title=title,
            h=max(1, min(5, int(heading_level))),
            figures=[{**f, "png": prefix + f["png"], "svg": prefix + f["svg"]} for f in figures],
            fits=fits,
            rows=listed,
            n_rows=len(rows),
            n_errors=sum(r.get("status") != "ok" for r in rows),
            columns=TABLE_COLUMNS,
        )
    )


def write_trends(rows: Sequence[Mapping], out: str | os.PathLike) -> Path:
    """Write ``trends.html``, ``trends.json`` and the figures in ``trends/`` into ``out``.

    The figures are drawn into a temporary folder and moved into place whole.
    """
    out = Path(out)
    rows = [normalise(r) for r in rows]
    fits = load_trends(rows)
    tmp = Path(tempfile.mkdtemp(prefix=".trends.", suffix=".tmp", dir=out))
    try:
        section = _section(rows, fits, tmp, "trends", 2, TITLE)
        final = out / "trends"
        if final.is_dir():
            old = out / f".trends.old-{os.getpid()}"
            os.replace(final, old)
            os.replace(tmp, final)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    page = (
        _environment()
        .get_template("trends.html.j2")
        .render(
            section=markupsafe.Markup(section),
            n_rows=len(rows),
        )
    )
    write_json_atomic(out / "trends.json", {"fits": [f.to_dict() for f in fits]})
    return write_text_atomic(out / "trends.html", page)
