"""Figures of a shimmy study (matplotlib, Agg), drawn for a design review.

Each function takes the result and a matplotlib figure, draws into it (one or
several axes), and returns the figure; `save_figures` writes those that have
something to show as PNG. Every run and every verdict is readable: the time
histories are small multiples (one panel per run, its verdict in the title and
colour), the limit-cycle figure marks settled, still growing and decaying runs
apart, and the stability maps shade the unstable region with the boundary drawn.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
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
#: Colour and marker of each verdict of a time simulation.
VERDICT_STYLE = {
    "decays": ("#1f77b4", "o", "none"),  # open circle
    "limit_cycle": ("#d62728", "o", "full"),  # filled circle
    "grows": ("#ff7f0e", "^", "full"),  # triangle up
}
VERDICT_TEXT = {
    "decays": "decays",
    "limit_cycle": "limit cycle (settled)",
    "grows": "still growing",
}
#: Unstable region's shade on the stability maps.
UNSTABLE = "#f4c7c3"
#: Axis label of each mapped gear parameter (value shown times the factor).
PARAMETER_AXES = {
    "trail": ("trail e (m)", 1.0),
    "torsional_damping": ("torsional damping c_ψ (kN m s/rad)", 1e-3),
    "torsional_stiffness": ("torsional stiffness k_ψ (MN m/rad)", 1e-6),
}


def _label(name: str) -> str:
    return LABELS.get(name, name)


def stability_figure(result: ShimmyResult, fig):
    """Growth rate (largest real part, 1/s) over speed; unstable ranges shaded, boundaries marked
    (▲ onset, ▼ end of an unstable range), the critical speed's 95 % interval as a bar."""
    ax = fig.subplots()
    for m in result.models:
        s = m.stability
        col = COLOURS.get(m.name, "k")
        ax.plot(s.speeds, s.growth_rate, STYLES.get(m.name, "-"), color=col, label=_label(m.name),
                zorder=3 if m.name == "generalised" else 2)  # fmt: skip
        for b in s.boundaries:
            ax.plot([b.speed], [0.0], "^" if b.direction == "onset" else "v", color=col, ms=7, zorder=4)
        if m.critical_speed_ci95 is not None:
            ax.axvspan(*m.critical_speed_ci95, color=col, alpha=0.10)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.plot([], [], "k^", label="onset of instability")
    ax.plot([], [], "kv", label="end of an unstable range")
    low = min(float(np.min(m.stability.growth_rate)) for m in result.models)
    high = max(float(np.max(m.stability.growth_rate)) for m in result.models)
    floor = -max(5.0, 4.0 * abs(high))  # the crossing readable: the deep low-speed dip clipped
    clipped = low < floor
    if clipped:
        ax.set_ylim(floor, max(high, 0.0) + 0.15 * (max(high, 0.0) - floor))
    ax.set_xlabel("forward speed V (m/s)")
    ax.set_ylabel("growth rate: largest real part (1/s)")
    note = f"; clipped below {floor:.1f}" if clipped else ""
    title = "Stability of rolling with sliding: above 0 unstable"
    ax.set_title(f"{title}\n(shaded: 95 % interval of the critical speed{note})", fontsize=9.5)
    ax.legend()
    return fig


def eigenvalue_figure(result: ShimmyResult, fig):
    """The eigenvalues' paths in the complex plane as the speed grows (Hz on the imaginary axis)."""
    ax = fig.subplots()
    for m in result.models:
        ev = m.stability.eigenvalues
        col = COLOURS.get(m.name, "k")
        for k in range(ev.shape[1]):
            ax.plot(ev[:, k].real, ev[:, k].imag / (2 * np.pi), ".", ms=2, color=col,
                    label=_label(m.name) if k == 0 else None)  # fmt: skip
    ax.axvline(0.0, color="k", lw=0.8)
    top = max(float(np.max(m.stability.eigenvalues.real)) for m in result.models)
    ax.set_xlim(-60.0, max(5.0, 1.3 * top))
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("real part (1/s)")
    ax.set_ylabel("imaginary part / 2π (Hz)")
    ax.set_title("Eigenvalue paths over the speed sweep")
    ax.legend()
    return fig


def damping_figure(result: ShimmyResult, fig):
    """Damping ratio ζ = −Re λ/|λ| and frequency |Im λ|/2π of every oscillating mode over speed."""
    ax_z, ax_f = fig.subplots(2, 1, sharex=True)
    for m in result.models:
        s = m.stability
        col = COLOURS.get(m.name, "k")
        ev = s.eigenvalues
        V = np.repeat(s.speeds[:, None], ev.shape[1], axis=1)
        osc = ev.imag > 1e-9  # one of each complex pair
        zeta = -ev.real / np.maximum(np.abs(ev), 1e-300)
        ax_z.plot(V[osc], zeta[osc], ".", ms=2.5, color=col, label=_label(m.name))
        ax_f.plot(V[osc], ev.imag[osc] / (2 * np.pi), ".", ms=2.5, color=col)
        for b in s.boundaries:
            for ax in (ax_z, ax_f):
                ax.axvline(b.speed, color=col, ls=":", lw=1)
    ax_z.axhline(0.0, color="k", lw=0.8)
    ax_z.set_ylabel("damping ratio ζ")
    ax_z.set_ylim(max(-0.05, ax_z.get_ylim()[0]), min(0.3, ax_z.get_ylim()[1]))
    ax_f.set_ylabel("frequency (Hz)")
    ax_f.set_xlabel("forward speed V (m/s)")
    ax_z.set_title("Damping ratio and frequency of the gear's modes (dotted: boundaries)")
    ax_z.legend(markerscale=3)
    return fig


def mode_figure(result: ShimmyResult, fig):
    """The mode that crosses at each model's first boundary, over one period, for a yaw
    amplitude of 1 mrad: the axle's lateral deflection y and the contact centre's lateral
    motion y − e ψ (mm), the yaw ψ (mrad)."""
    models = [m for m in result.models if m.stability.boundaries]
    axes = np.atleast_1d(fig.subplots(1, max(len(models), 1), sharey=True, squeeze=False)[0])
    phase = np.linspace(0.0, 2 * np.pi, 200)
    e = result.gear.trail
    for ax, m in zip(axes, models, strict=False):
        b = m.stability.boundaries[0]
        rot = np.exp(1j * phase)
        psi = 1e-3 * np.real(b.mode[0] * rot)
        y = 1e-3 * np.real(b.mode[2] * rot)
        deg = np.degrees(phase)
        ax.plot(deg, 1e3 * psi, color="k", label="yaw ψ (mrad)")
        ax.plot(deg, 1e3 * y, color=COLOURS.get(m.name, "C0"), label="axle y (mm)")
        ax.plot(deg, 1e3 * (y - e * psi), "--", color=COLOURS.get(m.name, "C0"), label="contact y − eψ (mm)")
        ratio = abs(b.mode[2]) / max(abs(b.mode[0]), 1e-300)
        lag = np.degrees(np.angle(b.mode[2] / b.mode[0])) if abs(b.mode[0]) > 0 else float("nan")
        title = f"{_label(m.name)}\n{b.direction} at {b.speed:.1f} m/s, {b.frequency_hz:.1f} Hz\n"
        phase_text = f"leads ψ by {lag:.0f}°" if lag >= 0 else f"lags ψ by {-lag:.0f}°"
        ax.set_title(title + f"|y|/|ψ| = {1e3 * ratio:.0f} mm/rad, y {phase_text}", fontsize=8.5)
        ax.set_xlabel("phase (°)")
        ax.set_xticks([0, 90, 180, 270, 360])
    axes[0].set_ylabel("amplitude for ψ = 1 mrad")
    axes[0].legend(fontsize=7.5)
    if not models:
        axes[0].text(0.5, 0.5, "no boundary in the sweep", ha="center", transform=axes[0].transAxes)
    return fig


def time_history_figure(result: ShimmyResult, fig):
    """Yaw angle ψ − ψ_eq (mrad) of every simulation, one panel per run: model, speed and verdict
    in the panel's title, the trace coloured by its verdict."""
    sims = list(result.simulations)
    ncol = 2 if len(sims) > 1 else 1
    nrow = max(1, (len(sims) + ncol - 1) // ncol)
    fig.set_size_inches(7.5, 1.2 + 1.9 * nrow)
    axes = np.ravel(fig.subplots(nrow, ncol, sharex=True, squeeze=False))
    for ax, s in zip(axes, sims, strict=False):
        h = s.history
        col = VERDICT_STYLE.get(h.verdict, ("k", "o", "full"))[0]
        ax.plot(h.t, 1e3 * (h.x[0] - h.equilibrium[0]), lw=0.5, color=col)
        amp = "" if h.amplitude is None else f", {1e3 * h.amplitude:.2f} mrad"
        verdict = VERDICT_TEXT.get(h.verdict, h.verdict)
        title = f"{_label(h.friction_model)}, {h.speed:.1f} m/s\n{verdict}{amp}"
        ax.set_title(f"{title} (linear growth {s.linear_growth_rate:+.2f} 1/s)", fontsize=8)
        ax.set_ylabel("ψ − ψ_eq (mrad)", fontsize=8)
    for ax in axes[len(sims) :]:
        ax.set_visible(False)
    for ax in axes[-ncol:]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Time histories from a yaw perturbation (blue: decays, red: limit cycle, orange: grows)",
                 fontsize=9.5)  # fmt: skip
    return fig


def amplitude_figure(result: ShimmyResult, fig):
    """Amplitude at the end of each run of the limit-cycle sweep against speed, per model: filled
    circles settled (limit cycle), triangles still growing, open circles decaying; the linear
    critical speed dotted, where the branch should start."""
    ax = fig.subplots()
    for m in result.models:
        if not m.branch:
            continue
        col = COLOURS.get(m.name, "k")
        v = np.array([p.speed for p in m.branch])
        a = np.array([p.amplitude for p in m.branch])
        ax.plot(v, 1e3 * a, STYLES.get(m.name, "-"), color=col, lw=0.8, label=_label(m.name))
        for p in m.branch:
            _, marker, fill = VERDICT_STYLE.get(p.verdict, ("k", "o", "full"))
            ax.plot([p.speed], [1e3 * p.amplitude], marker, color=col, mfc=col if fill == "full" else "white")
        if m.stability.critical_speed is not None:
            ax.axvline(m.stability.critical_speed, color=col, ls=":", lw=1)
    legend = {**VERDICT_TEXT, "decays": "died away or still falling"}
    for verdict, (_, marker, fill) in VERDICT_STYLE.items():
        ax.plot([], [], marker, color="k", mfc="k" if fill == "full" else "white", label=legend[verdict])
    ax.set_xlabel("forward speed V (m/s)")
    ax.set_ylabel("yaw amplitude at the end of the run (mrad)")
    ax.set_ylim(bottom=0.0)
    ax.set_title("Limit-cycle amplitude over speed (sweep of simulations down in speed;\n"
                 "dotted: linear critical speed, where the branch starts)", fontsize=9.5)  # fmt: skip
    ax.legend(fontsize=7.5)
    return fig


def parameter_figure(result: ShimmyResult, fig, parameter: str = "trail"):
    """Stability over speed × one gear parameter, one panel per model: unstable region shaded,
    the boundary (growth rate 0) drawn, the gear's own value dashed."""
    models = [m for m in result.models if parameter in m.maps]
    axes = np.ravel(fig.subplots(1, max(len(models), 1), sharey=True, squeeze=False))
    label, scale = PARAMETER_AXES.get(parameter, (parameter, 1.0))
    for ax, m in zip(axes, models, strict=False):
        pm = m.maps[parameter]
        V, P = np.meshgrid(pm.speeds, scale * pm.values)
        g = pm.growth_rate
        if np.max(g) > m.stability.tolerance:
            ax.contourf(V, P, g, levels=[m.stability.tolerance, np.max(g)], colors=[UNSTABLE], extend="max")
        if np.any(g > 0) and np.any(g < 0):
            ax.contour(V, P, g, levels=[0.0], colors=[COLOURS.get(m.name, "k")], linewidths=1.5)
        ax.axhline(scale * getattr(result.gear, parameter), color="k", ls="--", lw=0.8)
        ax.set_title(_label(m.name), fontsize=9)
        ax.set_xlabel("forward speed V (m/s)")
    axes[0].set_ylabel(label)
    what = label.split(" (")[0]
    fig.suptitle(f"Stability over speed × {what} (shaded: unstable; dashed: the gear's value)", fontsize=9.5)
    return fig


#: The parameter each stability map's figure shows.
MAP_FIGURES = {
    "stability_plane": "trail",
    "stability_damping": "torsional_damping",
    "stability_stiffness": "torsional_stiffness",
}
FIGURES: dict[str, Callable[..., object]] = {
    "stability_map": stability_figure,
    "eigenvalue_paths": eigenvalue_figure,
    "damping_frequency": damping_figure,
    "mode_shapes": mode_figure,
    "time_histories": time_history_figure,
    "limit_cycle_amplitude": amplitude_figure,
    **{name: partial(parameter_figure, parameter=p) for name, p in MAP_FIGURES.items()},
}


def _has_content(result: ShimmyResult, name: str) -> bool:
    if name == "time_histories":
        return bool(result.simulations)
    if name == "limit_cycle_amplitude":
        return any(m.branch for m in result.models)
    if name == "mode_shapes":
        return any(m.stability.boundaries for m in result.models)
    if name in MAP_FIGURES:
        return any(MAP_FIGURES[name] in m.maps for m in result.models)
    return True


def save_figures(result: ShimmyResult, folder: Path) -> list[str]:
    """Write every figure of `FIGURES` that has something to show as ``<name>.png`` into
    ``folder``; the file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = []
    with matplotlib.rc_context(STYLE):  # type: ignore[arg-type]  # matplotlib types keys as Literal
        for name, draw in FIGURES.items():
            if not _has_content(result, name):
                continue
            fig = plt.figure()
            if name == "damping_frequency":
                fig.set_size_inches(7.0, 6.0)
            if name in MAP_FIGURES or name == "mode_shapes":
                fig.set_size_inches(9.0, 3.8)
            draw(result, fig)
            fig.tight_layout()
            fig.savefig(Path(folder) / f"{name}.png")
            plt.close(fig)
            names.append(f"{name}.png")
    return names
