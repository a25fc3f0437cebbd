"""Figures of a diagnosis (matplotlib, no pyplot state; callers save or embed them).

* `plot_predicted_vs_measured` — one panel per channel: the simulation
  (grey) and the named extension's held-out predictions (colour) against the
  measurement, with the identity line.
* `plot_residuals` — residuals in % of the channel scale (f₀N, f₀NR)
  against sliding speed, speed ratio, sliding direction, spin sign and (when
  they vary) load and roll, and against the run order (or the ``time``
  column), with the group means the ANOVA test compares (± their 95 %
  interval) and its p-value per panel: structure shows as a trend or a step of
  the means, noise as a flat band around zero, drift as a trend along the run.
  A fourth row shows the force residual along the sliding direction (positive:
  less friction than simulated), where a change of friction level with speed,
  load or pressure shows as a trend of the means even when the signed Fx, Fy
  residuals only fan out. Outliers are drawn in red.
* `plot_candidates` — ΔBIC of every candidate against the simulation.
* `plot_recording` — for a rig recording: the kinematics and forces
  against time (a decimated copy, `fepost.diagnose.holds.TRACE_POINTS` samples
  at most), the steady holds shaded and each hold's mean drawn on it, the rows
  left out (transitions) in red, dropouts shaded grey, clock resets as dashed
  lines and the ends of holds cut for drifting as dotted lines; the title states
  the hold rule in seconds.

Each function takes an optional figure or axes and returns it; none calls show().
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from .measured import CHANNELS
from .residuals import binned_means
from .result import Diagnosis

UNITS = {"Fx": "N", "Fy": "N", "Mz": "N·m"}
#: Forces (moments) whose largest magnitude reaches this are drawn in kN (kN·m), so
#: that aircraft-sized tick labels (−60000, 40000) do not run into each other.
KILO_FROM = 5000.0


def display_units(values: np.ndarray, unit: str) -> tuple[float, str]:
    """(divisor, unit label) for drawing ``values`` in ``unit``: k-prefixed at or above `KILO_FROM`."""
    top = float(np.max(np.abs(values))) if np.size(values) else 0.0
    return (1e3, "k" + unit) if top >= KILO_FROM else (1.0, unit)


#: Most dropouts, resets and drift cuts drawn on the recording figure (each kind).
MAX_MARKS = 200

BEFORE = "0.55"
AFTER = "tab:blue"


def plot_predicted_vs_measured(diag: Diagnosis, axes=None):
    """Predicted against measured per channel; returns the axes (3,)."""
    if axes is None:
        fig = Figure(figsize=(12, 4.2), layout="constrained")
        axes = fig.subplots(1, 3)
    keep = np.ones(len(diag.data), bool)
    keep[list(diag.outliers)] = False
    meas = diag.data.forces
    before = diag.predictions["before"]
    after = diag.predictions["after_heldout"]
    for c, ax in enumerate(axes):
        ch = CHANNELS[c]
        div, unit = display_units(np.concatenate([meas[:, c], before[:, c]]), UNITS[ch])
        rb = np.sqrt(np.mean(((meas[keep, c] - before[keep, c]) / diag.scales[c]) ** 2))
        ra = np.sqrt(np.mean(((meas[keep, c] - after[keep, c]) / diag.scales[c]) ** 2))
        ax.scatter(
            meas[keep, c] / div, before[keep, c] / div, s=9, c=BEFORE, label=f"simulation (rmse {rb:.3g})"
        )
        if diag.cause != "none":
            ax.scatter(
                meas[keep, c] / div,
                after[keep, c] / div,
                s=9,
                c=AFTER,
                alpha=0.7,
                label=f"{'+'.join(diag.causes)}, held-out (rmse {ra:.3g})",
            )
        if not keep.all():
            ax.scatter(
                meas[~keep, c] / div, before[~keep, c] / div, s=22, c=OUTLIER, marker="x", zorder=5,
                label="outlier (left out)", gid="outliers",
            )  # fmt: skip
        lo = min(meas[:, c].min(), before[:, c].min())
        hi = max(meas[:, c].max(), before[:, c].max())
        ax.plot([lo / div, hi / div], [lo / div, hi / div], "k-", lw=0.8)
        ax.set_xlabel(f"measured {ch} ({unit})")
        ax.set_ylabel(f"predicted {ch} ({unit})")
        ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
        ax.set_title(ch)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].figure.suptitle(
        f"predicted vs measured — cause: {'+'.join(diag.causes)} (rmse in scaled units, outliers left out)"
    )
    return axes


#: Colour and marker of outliers (rows left out of every fit).
OUTLIER = "tab:red"
#: Largest number of x tick labels per panel (narrow panels: fewer, so they never touch).
XTICKS = 4


def _columns(diag: Diagnosis) -> list[str]:
    cols = []
    for name, x in diag.variables.items():
        ok = np.isfinite(x)
        if np.unique(x[ok]).size >= 2:
            cols.append(name)
    return cols


def along_sliding(data, res: np.ndarray) -> np.ndarray:
    """Force residual (rows of Fx, Fy in ``res``) along the sliding direction v/|v|; nan at |v| = 0."""
    v = np.hypot(data.vx, data.vy)
    along = res[:, 0] * data.vx + res[:, 1] * data.vy
    return np.divide(along, v, out=np.full(v.shape, np.nan), where=v > 0)


def run_order(diag: Diagnosis) -> tuple[str, np.ndarray]:
    """(label, position) of the run-order column: the ``time`` column when present, else the row."""
    if diag.data.time is not None:
        return "time (run order)", np.asarray(diag.data.time, float)
    return "run order (data row)", np.arange(len(diag.data), dtype=float)


def _limits(values: list[np.ndarray]) -> tuple[float, float]:
    """y-limits holding every kept value with a 10 % margin (outliers may fall outside)."""
    v = np.concatenate([np.asarray(x, float)[np.isfinite(x)] for x in values])
    if not v.size:
        return -1.0, 1.0
    lo, hi = float(v.min()), float(v.max())
    pad = 0.1 * (hi - lo) or 1.0
    return lo - pad, hi + pad


def _draw_outliers(ax, x, y, ylim) -> None:
    """Outliers as red crosses; those beyond ``ylim`` as red triangles on the edge."""
    ok = np.isfinite(y)
    x, y = x[ok], y[ok]
    inside = (y >= ylim[0]) & (y <= ylim[1])
    span = ylim[1] - ylim[0]
    kw = {"c": OUTLIER, "s": 22, "zorder": 5}
    ax.scatter(x[inside], y[inside], marker="x", gid="outliers", label="outlier (left out)", **kw)
    above, below = y > ylim[1], y < ylim[0]
    top, bottom = ylim[1] - 0.02 * span, ylim[0] + 0.02 * span
    ax.scatter(x[above], np.full(above.sum(), top), marker="^", gid="outliers-clipped", **kw)
    ax.scatter(x[below], np.full(below.sum(), bottom), marker="v", gid="outliers-clipped", **kw)


def plot_residuals(diag: Diagnosis, fig: Figure | None = None) -> Figure:
    """Residuals (% of scale) against the kinematic variables and the run order; returns the figure.

    Outliers (left out of every fit) are red crosses, or red triangles on the
    panel's edge when they lie beyond the kept rows' range; the group means and
    y-limits use the kept rows only. The p-value of each kinematic panel is its
    ANOVA test on the standardised residuals; the run-order column shows the
    lack-of-fit run-order test. The legend sits below the panels.
    """
    cols = _columns(diag)
    order_label, order_x = run_order(diag)
    ncol = len(cols) + 1
    fixed = fig is None
    if fig is None:
        fig = Figure(figsize=(2.9 * ncol + 1.2, 11.0))
    axes = np.atleast_2d(fig.subplots(4, ncol, sharex="col", sharey="row", squeeze=False))
    if fixed:
        _fixed_margins(fig, 4, ncol)
    meas = diag.data.forces
    rb = 100 * (meas - diag.predictions["before"]) / diag.scales
    ra = 100 * (meas - diag.predictions["after_heldout"]) / diag.scales
    rows = [
        (rb[:, c], ra[:, c], f"{CHANNELS[c]} residual (% of f0N{'R' if c == 2 else ''})") for c in range(3)
    ]
    rows.append(
        (
            along_sliding(diag.data, rb),
            along_sliding(diag.data, ra),
            "along sliding (% of f0N)\n+ = less friction than simulated",
        )
    )
    out = np.zeros(len(diag.data), bool)
    out[list(diag.outliers)] = True
    keep = ~out
    shown = "+".join(diag.causes)
    rng = np.random.default_rng(0)
    lof = diag.lack_of_fit.get("tests", {})
    trend_key = "trend_time" if diag.data.time is not None else "trend_file"
    for c, (before, after, label) in enumerate(rows):
        ylim = _limits([before[keep], after[keep]] if diag.cause != "none" else [before[keep]])
        for j, name in enumerate([*cols, order_label]):
            ax = axes[c, j]
            if name == order_label:
                x0 = order_x
                x = x0
            else:
                x0 = np.array(diag.variables[name], float)
                x = x0
                if np.unique(x0[np.isfinite(x0)]).size <= 3:  # categorical: jitter the points only
                    x = x0 + rng.uniform(-0.15, 0.15, x0.size)
            if name.startswith("load N"):
                x0, x = x0 / 1e3, x / 1e3
            ax.axhline(0.0, color="k", lw=0.6)
            ax.scatter(x[keep], before[keep], s=6, c=BEFORE, alpha=0.6, label="simulation")
            if diag.cause != "none":
                ax.scatter(x[keep], after[keep], s=6, c=AFTER, alpha=0.5, label=f"{shown}, held-out")
            if out.any():
                _draw_outliers(ax, x[out], before[out], ylim)
            ok = np.isfinite(before) & keep
            groups = binned_means(before[ok], "run order" if name == order_label else name, x0[ok])
            if groups is not None:
                bars = ax.errorbar(
                    *groups[:2], yerr=groups[2], fmt="o-", color="k", ms=3, lw=1.0, capsize=2,
                    label="simulation: group mean ± 95 %",
                )  # fmt: skip
                bars.lines[0].set_gid("group-means")
            ax.set_ylim(*ylim)
            text = None
            if c < 3 and name != order_label:
                p = diag.residuals["before"][CHANNELS[c]]["p_values"].get(name)
                if p is not None:
                    text = f"ANOVA p = {p:.2g}"
            elif c == 0 and name == order_label and trend_key in lof:
                text = f"drift test p = {lof[trend_key]['p_holm']:.2g}\n(chosen model, Holm)"
            if text:
                ax.text(0.03, 0.97, text, transform=ax.transAxes, fontsize=7, va="top", gid="p-value",
                        bbox={"fc": "white", "ec": "none", "alpha": 0.7, "pad": 1.0})  # fmt: skip
            if name in ("spin sign", "roll"):
                ax.set_xticks([-1, 0, 1])
            else:
                ax.xaxis.set_major_locator(MaxNLocator(nbins=XTICKS, min_n_ticks=2))
            ax.tick_params(labelsize=8)
            if c == len(rows) - 1:
                ax.set_xlabel("load N (kN)" if name.startswith("load N") else name, fontsize=9)
            if j == 0:
                ax.set_ylabel(label, fontsize=9)
            if j == 0 and c < 3:
                st = diag.residuals["before"][CHANNELS[c]]
                ax.set_title(
                    f"{CHANNELS[c]}: {st['verdict']} (p={st['p_adjusted']:.2g})", fontsize=8, loc="left"
                )
    handles, labels = [], []
    for ax in axes.ravel():
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    where: dict = {"loc": "outside lower center"}
    if fixed:
        where = {"loc": "lower center", "bbox_to_anchor": (0.5, 0.005)}
    fig.legend(handles, labels, ncol=min(len(labels), 4), fontsize=8, **where)
    fig.suptitle(
        "residuals (measured − predicted) vs kinematics and run order: "
        "flat band = noise, trend or step = structure",
        **({"y": 1.0 - 0.06 / fig.get_figheight(), "va": "top"} if fixed else {}),
    )
    return fig


#: Margins of the residuals figure (inches): left (y tick labels and two-line y labels),
#: right, bottom (x tick labels, x labels and the legend), top (the suptitle and the first
#: row's title), and the gaps between columns and between rows (a row title).
RESIDUAL_MARGINS = {"left": 0.85, "right": 0.1, "bottom": 0.8, "top": 0.5, "wgap": 0.14, "hgap": 0.32}


def _fixed_margins(fig: Figure, nrow: int, ncol: int) -> None:
    """Lay the residual panels out with `RESIDUAL_MARGINS`, fixed in inches.

    The panels share their axes by row and column, so only the outer panels carry
    tick labels, and the margins hold them for any data; matplotlib's constrained
    layout would measure every one of the 24 panels' ticks twice per save (half the
    time a diagnose spends on its figures). tests/test_diagnose_figures.py checks that
    no label, legend or panel overlaps another."""
    m = RESIDUAL_MARGINS
    w, h = fig.get_size_inches()
    panel_w = (w - m["left"] - m["right"] - (ncol - 1) * m["wgap"]) / ncol
    panel_h = (h - m["bottom"] - m["top"] - (nrow - 1) * m["hgap"]) / nrow
    fig.subplots_adjust(
        left=m["left"] / w,
        right=1.0 - m["right"] / w,
        bottom=m["bottom"] / h,
        top=1.0 - m["top"] / h,
        wspace=m["wgap"] / panel_w,
        hspace=m["hgap"] / panel_h,
    )


def plot_candidates(diag: Diagnosis, ax=None):
    """ΔBIC of every candidate against the simulation (negative is better); returns the axes."""
    if ax is None:
        ax = Figure(figsize=(7, 3.6), layout="constrained").subplots()
    names = [s.name for s in diag.candidates]
    vals = [s.delta_bic for s in diag.candidates]
    colours = ["tab:green" if s.admissible else "0.7" for s in diag.candidates]
    y = np.arange(len(names))[::-1]
    ax.barh(y, vals, color=colours)
    ax.set_yticks(y, names, fontsize=8)
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_xlabel("ΔBIC vs the simulation (green: admissible; negative = better)")
    ax.set_title(f"candidates — cause: {diag.cause}")
    return ax


def plot_recording(diag: Diagnosis, fig: Figure | None = None) -> Figure:
    """The recording with its holds shaded and the left-out rows in red; returns the figure."""
    holds = diag.holds
    if holds is None:
        raise ValueError("plot_recording needs a diagnosis of a recording (diag.holds is None)")
    tr = holds.trace
    if fig is None:
        fig = Figure(figsize=(12, 9), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    t = tr["time"]
    inside = np.zeros(t.size, bool)
    for a, b in holds.spans:
        inside[np.searchsorted(t, a) : np.searchsorted(t, b, side="right")] = True
    panels = [(("vx", "vy"), "m/s"), (("wz",), "rad/s"), (("Fx", "Fy"), "N"), (("Mz",), "N·m")]
    for ax, (names, unit) in zip(axes, panels, strict=True):
        values = np.concatenate([tr[n] for n in names])
        div, shown = display_units(values, unit) if unit in ("N", "N·m") else (1.0, unit)
        for k, name in enumerate(names):
            y = tr[name] / div
            ax.plot(t, np.where(inside, y, np.nan), lw=0.6, color=f"C{k}", label=f"{name} (in holds)")
            ax.plot(t, np.where(inside, np.nan, y), lw=0.6, color=OUTLIER, alpha=0.7,
                    label="left out (transitions)" if k == 0 else None)  # fmt: skip
            mean = np.asarray(getattr(diag.data, name)) / div
            ax.hlines(mean, holds.spans[:, 0], holds.spans[:, 1], color="k", lw=1.2,
                      label="hold mean" if k == 0 else None)  # fmt: skip
        ax.fill_between(t, 0, 1, where=inside, transform=ax.get_xaxis_transform(), color="tab:green",
                        alpha=0.12, lw=0, label="steady hold")  # fmt: skip
        _mark_gaps(ax, holds, 0.002 * (t[-1] - t[0]) if t.size else 0.0)
        ax.set_ylabel(f"{', '.join(names)} ({shown})", fontsize=9)
        ax.yaxis.set_major_locator(MaxNLocator(nbins=5))
        ax.legend(fontsize=7, loc="upper right", ncol=4)
    axes[-1].set_xlabel("time (s)" if not holds.resets else "time (s, run clock: resets taken out)")
    d = holds.to_dict()
    gaps = holds.gaps_text()
    fig.suptitle(
        f"recording: {d['count']} steady holds, {d['rows_used']} of {d['rows']} rows used, "
        f"{d['rows_left_out']} left out\nholds: kinematics steady over {holds.window:g} s windows and over "
        f"the whole hold, {holds.settle:g} s settling left out at each end" + (f"\n{gaps}" if gaps else ""),
        fontsize=10,
    )
    return fig


def _mark_gaps(ax, holds, least: float) -> None:
    """Dropouts shaded grey (at least ``least`` s wide), clock resets dashed, the ends of drift-cut
    holds dotted; the first `MAX_MARKS` of each."""
    for k, drop in enumerate(holds.dropouts[:MAX_MARKS]):
        a, b = drop.time
        ax.axvspan(a, max(b, a + least), color="0.4", alpha=0.35, lw=0,
                   label="dropout (left out)" if k == 0 else None)  # fmt: skip
    for k, reset in enumerate(holds.resets[:MAX_MARKS]):
        ax.axvline(reset.clock, color="k", ls="--", lw=0.9, label="clock reset" if k == 0 else None)
    for k, (a, b, _) in enumerate(holds.splits[:MAX_MARKS]):
        ax.axvline(a, color="tab:purple", ls=":", lw=0.9, label="hold cut for drift" if k == 0 else None)
        ax.axvline(b, color="tab:purple", ls=":", lw=0.9)


def save_figures(diag: Diagnosis, folder) -> list[str]:
    """Write the three figures as PNG into ``folder``; returns the file names."""
    from pathlib import Path

    folder = Path(folder)
    out = []
    axes = plot_predicted_vs_measured(diag)
    axes[0].figure.savefig(folder / "predicted_vs_measured.png", dpi=110)
    out.append("predicted_vs_measured.png")
    plot_residuals(diag).savefig(folder / "residuals.png", dpi=100)
    out.append("residuals.png")
    plot_candidates(diag).figure.savefig(folder / "candidates.png", dpi=110)
    out.append("candidates.png")
    if diag.holds is not None:
        plot_recording(diag).savefig(folder / "recording.png", dpi=100)
        out.append("recording.png")
    return out
