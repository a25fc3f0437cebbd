"""Figures of a shimmy study (matplotlib, Agg): each function takes the result and an
optional axes, draws, and returns the axes; `save_figures` writes them as PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._mplrc import MPL_RC
from .result import ShimmyResult

#: matplotlib settings of these figures: fepost's figure look.
STYLE = MPL_RC
#: Line colour of each friction model.
COLOURS = {"closed_forms": "#2ca02c", "generalised": "#c0392b", "exact": "#1f4e99"}
#: Line style of each model (the generalised model dashed: it lies on the exact integrals).
STYLES = {"closed_forms": "-", "generalised": "--", "exact": "-"}
LABELS = {
    "closed_forms": "paper's closed forms",
    "generalised": "generalised model",
    "exact": "exact integrals",
}


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots()[1]


def stability_figure(result: ShimmyResult, ax=None):
    """Growth rate (largest real part, 1/s) over speed, critical speeds and their 95 % intervals."""
    ax = _axes(ax)
    for m in result.models:
        s = m.stability
        col = COLOURS.get(m.name, "k")
        ax.plot(s.speeds, s.growth_rate, STYLES.get(m.name, "-"), color=col, label=LABELS.get(m.name, m.name),
                zorder=3 if m.name == "generalised" else 2)  # fmt: skip
        for v in s.critical_speeds:
            ax.axvline(v, color=col, ls=":", lw=1)
        if m.critical_speed_ci95 is not None:
            ax.axvspan(*m.critical_speed_ci95, color=col, alpha=0.12)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("forward speed V (m/s)")
    ax.set_ylabel("largest real part of the eigenvalues (1/s)")
    ax.set_title("Stability of rolling with sliding (shaded: 95 % interval of the critical speed)")
    ax.legend()
    return ax


def eigenvalue_figure(result: ShimmyResult, ax=None):
    """The eigenvalues' paths in the complex plane as the speed grows (Hz on the imaginary axis)."""
    ax = _axes(ax)
    for m in result.models:
        ev = m.stability.eigenvalues
        col = COLOURS.get(m.name, "k")
        for k in range(ev.shape[1]):
            ax.plot(
                ev[:, k].real,
                ev[:, k].imag / (2 * np.pi),
                ".",
                ms=2,
                color=col,
                label=LABELS.get(m.name, m.name) if k == 0 else None,
            )
    ax.axvline(0.0, color="k", lw=0.8)
    top = max(float(np.max(m.stability.eigenvalues.real)) for m in result.models)
    ax.set_xlim(-60.0, max(5.0, 1.3 * top))
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("real part (1/s)")
    ax.set_ylabel("imaginary part / 2π (Hz)")
    ax.set_title("Eigenvalue paths over the speed sweep")
    ax.legend()
    return ax


def time_history_figure(result: ShimmyResult, ax=None):
    """Yaw angle ψ − ψ_eq (rad) of every simulation."""
    ax = _axes(ax)
    for s in result.simulations:
        h = s.history
        col = COLOURS.get(h.friction_model, "k")
        ls = "-" if h.verdict != "decays" else "--"
        ax.plot(
            h.t,
            h.x[0] - h.equilibrium[0],
            ls,
            lw=0.7,
            color=col,
            label=f"{LABELS.get(h.friction_model, h.friction_model)}, {h.speed:.1f} m/s: {h.verdict}",
        )
    ax.set_xlabel("time (s)")
    ax.set_ylabel("yaw angle ψ − ψ_eq (rad)")
    ax.set_title("Time histories from a yaw perturbation")
    ax.legend(fontsize=7)
    return ax


def amplitude_figure(result: ShimmyResult, ax=None):
    """Final yaw amplitude of each simulation against speed (limit cycles filled)."""
    ax = _axes(ax)
    for s in result.simulations:
        h = s.history
        col = COLOURS.get(h.friction_model, "k")
        fill = col if h.verdict == "limit_cycle" else "none"
        ax.semilogy([h.speed], [max(h.final_amplitude, 1e-12)], "o", color=col, mfc=fill)
    for name, col in COLOURS.items():
        if any(m.name == name for m in result.models):
            ax.plot([], [], "o", color=col, label=LABELS[name])
    ax.set_xlabel("forward speed V (m/s)")
    ax.set_ylabel("yaw amplitude at the end (rad)")
    ax.set_title("Limit-cycle amplitude (filled) and decayed motions (open)")
    ax.legend()
    return ax


def trail_figure(result: ShimmyResult, ax=None):
    """The stability boundary over speed × trail: the critical speed at each trail, per model."""
    ax = _axes(ax)
    for m in result.models:
        if m.trail_map is None:
            continue
        tm = m.trail_map
        v = np.array([np.nan if c is None else c for c in tm.critical_speeds])
        style = "o" + STYLES.get(m.name, "-")
        ax.plot(tm.trails, v, style, ms=3, color=COLOURS.get(m.name, "k"), label=LABELS.get(m.name, m.name),
                zorder=3 if m.name == "generalised" else 2)  # fmt: skip
    ax.axvline(result.gear.trail, color="k", ls=":", lw=1, label="the gear's trail")
    ax.set_xlabel("trail e (m)")
    ax.set_ylabel("critical speed (m/s): unstable above")
    ax.set_title("Shimmy boundary over speed × trail (no point: stable over the sweep)")
    ax.legend()
    return ax


FIGURES = {
    "stability_map": stability_figure,
    "eigenvalue_paths": eigenvalue_figure,
    "time_histories": time_history_figure,
    "limit_cycle_amplitude": amplitude_figure,
    "stability_plane": trail_figure,
}


def save_figures(result: ShimmyResult, folder: Path) -> list[str]:
    """Write every figure of `FIGURES` as ``<name>.png`` into ``folder``; the file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = []
    with matplotlib.rc_context(STYLE):  # type: ignore[arg-type]  # matplotlib types keys as Literal
        for name, draw in FIGURES.items():
            if name in ("time_histories", "limit_cycle_amplitude") and not result.simulations:
                continue
            if name == "stability_plane" and all(m.trail_map is None for m in result.models):
                continue
            fig, ax = plt.subplots()
            draw(result, ax)
            fig.tight_layout()
            fig.savefig(Path(folder) / f"{name}.png")
            plt.close(fig)
            names.append(f"{name}.png")
    return names
