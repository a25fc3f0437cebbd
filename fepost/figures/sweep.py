"""Figures of a sweep: coefficients against load, and against time for transient runs.

Figure functions take rows (mappings of the table's columns) and fits, return
a matplotlib figure and never show it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..sweep.trends import QUANTITIES, PowerLaw, groups
from .units import display_unit

#: Panels of the time-step figure: column, label, unit.
TIME_PANELS = (
    ("N", "N", "N"),
    ("R", "R", "m"),
    ("M0", "M0", "N m"),
    ("aspect", "aspect", "1"),
    ("aR2", "a R²", "m²"),
    ("m_over_R2", "m / R²", "1/m²"),
)
#: How the figures write each quantity (matplotlib mathtext: subscripts, powers).
MATH_LABELS = {
    "N": "$N$",
    "R": "$R$",
    "M0": "$M_0$",
    "aR2": r"$a\,R^2$",
    "m_over_R2": "$m/R^2$",
    "k_x": "$k_x$",
    "aspect": "aspect",
}
#: Most transient runs drawn in one figure (the legend stays readable).
MAX_SERIES = 8
#: Panels per row of the load-trend figure: two, so the report, which shows images at most
#: 900 px wide, does not shrink the figure's text below the page's small print.
TREND_COLUMNS = 2
#: Legend text of the sweep's figures (points): the exponents and intervals must be readable.
LEGEND_FONTSIZE = 10.5
_COLOURS = ("#1f4e99", "#c0392b", "#2ca02c", "#e67e22", "#8e44ad", "#16a085", "#7f7f7f", "#b8860b")


def axis_label(quantity: str, unit: str) -> str:
    """Axis label of a column: its symbol with subscripts, the unit in the report's style
    ("N·m", "m⁻²") in parentheses, none for a dimensionless quantity."""
    shown = display_unit(unit)
    name = MATH_LABELS.get(quantity, quantity)
    return f"{name} ({shown})" if shown else name


def _values(rows: Sequence[Mapping], key: str) -> np.ndarray:
    return np.array([np.nan if r.get(key) is None else float(r[key]) for r in rows])


def plot_load_trends(rows: Sequence[Mapping], fits: Sequence[PowerLaw], *, k_x_kind: str | None = None):
    """Panels of R, M0, aR², m/R² and k_x against N (log-log), with fits and 95 % bands.

    ``k_x_kind``: what the rolling maps behind k_x are ("sliding stand-in", "rolled map,
    free rolling", ...), said in the k_x panel's title. Each panel's legend sits below it,
    clear of the points and bands."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, LogLocator, NullLocator

    from .theme import mpl_style

    quantities = [q for q in QUANTITIES if any(r.get(q[0]) is not None for r in rows)]
    with mpl_style():
        ncol = min(TREND_COLUMNS, len(quantities))
        nrow = -(-len(quantities) // ncol)
        fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 4.0 * nrow), squeeze=False)
        by_group = groups(rows)
        loads = _values([r for m in by_group.values() for r in m], "N")
        loads = loads[np.isfinite(loads) & (loads > 0)]
        xlim = (loads.min() / 1.1, loads.max() * 1.1) if loads.size else None
        for ax, (q, label, unit, hertz) in zip(axes.flat, quantities, strict=False):
            for k, (name, members) in enumerate(by_group.items()):
                colour = _COLOURS[k % len(_COLOURS)]
                N, y = _values(members, "N"), _values(members, q)
                ax.plot(N, y, "o", color=colour, ms=4, label=None if name == "all" else name)
                fit = next((f for f in fits if f.quantity == q and f.group == name and f.fitted), None)
                if fit is not None:
                    grid = np.geomspace(np.nanmin(N), np.nanmax(N), 100)
                    lo, hi = fit.band(grid)
                    ax.fill_between(grid, lo, hi, color=colour, alpha=0.18, lw=0)
                    lo_a, hi_a = fit.ci95  # type: ignore[misc]
                    ax.plot(
                        grid,
                        fit.predict(grid),
                        "-",
                        color=colour,
                        lw=1.2,
                        label=rf"$\propto N^{{{fit.exponent:.3f}}}$, 95 %: [{lo_a:.3f}, {hi_a:.3f}]".replace(
                            "-", "−"
                        ),
                    )
            finite = _values(rows, q)
            if np.all(finite[np.isfinite(finite)] > 0):
                ax.set_yscale("log")
            ax.set_xscale("log")
            if xlim is not None:
                ax.set_xlim(*xlim)  # one load axis for every panel, also for a quantity of few rows
            for axis in (ax.xaxis, ax.yaxis) if ax.get_yscale() == "log" else (ax.xaxis,):
                # ticks at 1, 2, 5 × 10^k, plainly labelled: a sweep rarely spans a decade
                axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
                axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                axis.set_minor_locator(NullLocator())
            ax.set_xlabel(axis_label("N", "N"))
            ax.set_ylabel(axis_label(q, unit))
            symbol = MATH_LABELS.get(q, label)
            title = symbol if hertz is None else rf"{symbol}   (Hertz: $\propto N^{{{hertz:.3g}}}$)"
            if q == "k_x" and k_x_kind:
                title = f"{symbol} ({k_x_kind})"
            ax.set_title(title, fontsize=10)
            if ax.get_legend_handles_labels()[0]:
                ax.legend(
                    loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=LEGEND_FONTSIZE, frameon=False
                )
        for ax in list(axes.flat)[len(quantities) :]:
            ax.set_visible(False)
        fig.tight_layout()
    return fig


def transient_series(rows: Sequence[Mapping]) -> dict[str, list[Mapping]]:
    """Ok rows by source, for sources with more than one time step, in step order."""
    series: dict[str, list[Mapping]] = {}
    for r in rows:
        if r.get("status") == "ok" and r.get("step") is not None:
            series.setdefault(str(r["source"]), []).append(r)
    return {k: sorted(v, key=lambda r: r["step"]) for k, v in series.items() if len(v) > 1}


def plot_time_trends(series: Mapping[str, Sequence[Mapping]]):
    """Panels of N, R, M0, aspect, aR², m/R² against time for each multi-step run."""
    import matplotlib.pyplot as plt

    from .theme import mpl_style

    with mpl_style():
        fig, axes = plt.subplots(2, 3, figsize=(12.6, 6.8), squeeze=False)
        for k, (source, members) in enumerate(list(series.items())[:MAX_SERIES]):
            t = _values(members, "time")
            if not np.all(np.isfinite(t)):
                t = _values(members, "step")
            for ax, (q, _label, _unit) in zip(axes.flat, TIME_PANELS, strict=True):
                ax.plot(t, _values(members, q), ".-", color=_COLOURS[k], lw=1, ms=3, label=source)
        for ax, (q, _label, unit) in zip(axes.flat, TIME_PANELS, strict=True):
            ax.set_xlabel("time (s) or step")
            ax.set_ylabel(axis_label(q, unit))
        axes[0, 0].legend(loc="best", fontsize=LEGEND_FONTSIZE)
        fig.tight_layout()
    return fig
