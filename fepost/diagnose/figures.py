"""Figures of a diagnosis (matplotlib, no pyplot state; callers save or embed them).

* :func:`plot_predicted_vs_measured` — one panel per channel: the simulation
  (grey) and the named extension's held-out predictions (colour) against the
  measurement, with the identity line.
* :func:`plot_residuals` — residuals in % of the channel scale (f₀N, f₀NR)
  against sliding speed, speed ratio, sliding direction, spin sign and (when
  they vary) load and roll, with the group means the ANOVA test compares
  (± their 95 % interval) and its p-value per panel: structure shows as a
  trend or a step of the means, noise as a flat band around zero. A fourth
  row shows the force residual along the sliding direction (positive: less
  friction than simulated), where a change of friction level with speed,
  load or pressure shows as a trend of the means even when the signed Fx, Fy
  residuals only fan out.
* :func:`plot_candidates` — ΔBIC of every candidate against the simulation.

Each function takes an optional figure or axes and returns it; none calls show().
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .measured import CHANNELS
from .residuals import binned_means
from .result import Diagnosis

UNITS = {"Fx": "N", "Fy": "N", "Mz": "N·m"}
BEFORE = "0.55"
AFTER = "tab:blue"


def plot_predicted_vs_measured(diag: Diagnosis, axes=None):
    """Predicted against measured per channel; returns the axes (3,)."""
    if axes is None:
        fig = Figure(figsize=(12, 4.2), layout="constrained")
        axes = fig.subplots(1, 3)
    meas = diag.data.forces
    before = diag.predictions["before"]
    after = diag.predictions["after_heldout"]
    for c, ax in enumerate(axes):
        ch = CHANNELS[c]
        rb = np.sqrt(np.mean(((meas[:, c] - before[:, c]) / diag.scales[c]) ** 2))
        ra = np.sqrt(np.mean(((meas[:, c] - after[:, c]) / diag.scales[c]) ** 2))
        ax.scatter(meas[:, c], before[:, c], s=9, c=BEFORE, label=f"simulation (rmse {rb:.3g})")
        if diag.cause != "none":
            ax.scatter(
                meas[:, c],
                after[:, c],
                s=9,
                c=AFTER,
                alpha=0.7,
                label=f"{diag.cause}, held-out (rmse {ra:.3g})",
            )
        lo = min(meas[:, c].min(), before[:, c].min())
        hi = max(meas[:, c].max(), before[:, c].max())
        ax.plot([lo, hi], [lo, hi], "k-", lw=0.8)
        ax.set_xlabel(f"measured {ch} ({UNITS[ch]})")
        ax.set_ylabel(f"predicted {ch} ({UNITS[ch]})")
        ax.set_title(ch)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].figure.suptitle(f"predicted vs measured — cause: {diag.cause} (rmse in scaled units)")
    return axes


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


def plot_residuals(diag: Diagnosis, fig: Figure | None = None) -> Figure:
    """Residuals (% of scale) against the kinematic variables; returns the figure."""
    cols = _columns(diag)
    if fig is None:
        fig = Figure(figsize=(3.0 * len(cols) + 1, 10.5), layout="constrained")
    axes = np.atleast_2d(fig.subplots(4, len(cols), sharey="row", squeeze=False))
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
    rng = np.random.default_rng(0)
    for j, name in enumerate(cols):
        x0 = np.array(diag.variables[name], float)
        x = x0
        if np.unique(x0[np.isfinite(x0)]).size <= 3:  # categorical: jitter the points only
            x = x0 + rng.uniform(-0.15, 0.15, x0.size)
        for c, (before, after, label) in enumerate(rows):
            ax = axes[c, j]
            ax.axhline(0.0, color="k", lw=0.6)
            ax.scatter(x, before, s=6, c=BEFORE, alpha=0.6, label="simulation")
            if diag.cause != "none":
                ax.scatter(x, after, s=6, c=AFTER, alpha=0.5, label=diag.cause)
            ok = np.isfinite(before)
            groups = binned_means(before[ok], name, x0[ok])
            if groups is not None:
                bars = ax.errorbar(
                    *groups[:2],
                    yerr=groups[2],
                    fmt="o-",
                    color="k",
                    ms=3,
                    lw=1.0,
                    capsize=2,
                    label="simulation: group mean ± 95 %",
                )
                bars.lines[0].set_gid("group-means")
            if c < 3:
                p = diag.residuals["before"][CHANNELS[c]]["p_values"].get(name)
                if p is not None:
                    ax.text(0.02, 0.97, f"ANOVA p = {p:.2g}", transform=ax.transAxes, fontsize=7, va="top")
            if c == len(rows) - 1:
                ax.set_xlabel(name)
            if j == 0:
                ax.set_ylabel(label)
            if j == 0 and c < 3:
                st = diag.residuals["before"][CHANNELS[c]]
                ax.set_title(
                    f"{CHANNELS[c]}: {st['verdict']} (p={st['p_adjusted']:.2g})",
                    fontsize=8,
                    loc="left",
                )
    axes[0, -1].legend(fontsize=7, loc="upper right")
    fig.suptitle(
        "residuals (measured − predicted) vs kinematics: flat band = noise, trend or step = structure"
    )
    return fig


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
    return out
