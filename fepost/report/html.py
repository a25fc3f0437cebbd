"""Writing ``report.html`` from the Jinja2 templates in ``templates/``.

The page is ``templates/report.html.j2`` (layout, prose, tables) with the style
sheet ``templates/style.css`` inlined and the figures embedded as ``data:``
URIs, so the one file shows everything. Values are autoescaped; a number cell
made by `cell` carries the exact JSON value and its dotted key
(``data-key``, ``data-value``) so the page can be checked against the JSON.
Optional sections (`fepost.report.sections`) render their own template
from ``templates/sections/``.
"""

from __future__ import annotations

import math
from functools import cache

from markupsafe import Markup

from ..figures import units


def cell(value, key: str | None = None, fmt: str = "{:.6g}", scale: float = 1.0) -> Markup:
    """A right-aligned ``<td>`` showing ``value × scale``; with ``key``, tagged with
    the unscaled value (``data-value``, exact ``repr``) and its JSON path (``data-key``)."""
    if value is None:
        return Markup("<td>—</td>")
    v = float(value)
    shown = units.number(v * scale, fmt)
    if key is None or not math.isfinite(v):
        return Markup('<td class="num">{}</td>').format(shown)
    return Markup('<td class="num" data-key="{}" data-value="{}">{}</td>').format(key, repr(v), shown)


def tagged(value, key: str, fmt: str = "{:.5g}", scale: float = 1.0) -> Markup:
    """An inline ``<span>`` like `cell` (for two numbers in one cell)."""
    v = float(value)
    return Markup('<span data-key="{}" data-value="{}">{}</span>').format(
        key, repr(v), units.number(v * scale, fmt)
    )


@cache
def environment():
    """The Jinja2 environment: package templates, autoescape, undefined names are errors."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("fepost.report", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"], default=True),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.globals.update(cell=cell, tagged=tagged, NNBSP=units.NNBSP)
    env.filters.update(
        q=units.quantity,
        kpa=units.kpa,
        number=units.number,
        unit=units.display_unit,
        text=units.normalise,
        pct=lambda v, fmt="{:.1%}": units.number(v, fmt).replace("%", f"{units.NNBSP}%"),
    )
    return env


def render_report(context: dict) -> str:
    """The HTML text of the report for ``context`` (see `fepost.report.assemble.page_context`)."""
    env = environment()
    css = env.loader.get_source(env, "style.css")[0]  # type: ignore[union-attr]
    return env.get_template("report.html.j2").render(css=Markup(css), **context)
