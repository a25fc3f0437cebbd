"""The study's figures: curves over u, limit-surface slices, held-out errors, the diagnosis."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .layouts import NAMES, RHO, SHORT, SURFACES, Layout, predict_on
from .physics import edge_loaded


def _psi(lay: Layout) -> np.ndarray:
    v = np.hypot(lay.kin[:, 0], lay.kin[:, 1])
    return np.abs(lay.kin[:, 2]) * lay.R / np.where(v > 0, v, np.nan)


def figure_curves(layouts: list[Layout], fits: dict, path: Path) -> None:
    """Measured against predicted |F|/N and |M|/(N R) over ψ = ωR/|v| (the paper's Figures 4–6)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(layouts), figsize=(3.2 * len(layouts), 6.0), sharex=True)
    axes = np.atleast_2d(axes).reshape(2, len(layouts))
    style = {
        "exact": ("tab:blue", "o"), "paper": ("tab:green", "^"), "ellipsoid": ("tab:orange", "s"),
        "quartic": ("tab:purple", "D"), "edge": ("tab:red", "v"),
    }  # fmt: skip
    for j, lay in enumerate(layouts):
        psi = _psi(lay)
        preds = {k: fits[lay.name]["f"][k] * lay.pred[k] for k in ("exact", "paper")}
        preds.update({k: fits[lay.name]["surface"][k].wrench(lay.kin) for k in SURFACES})
        if "edge" in fits[lay.name]:
            lam, f = fits[lay.name]["edge"]
            preds["edge"] = f * edge_loaded(lay, lam)
        for i, (quantity, unit) in enumerate(((_force, lay.N), (_torque, lay.N * lay.R))):
            ax = axes[i, j]
            for key, P in preds.items():
                color, marker = style[key]
                ax.plot(psi, quantity(P) / unit, marker, ms=3.5, mfc="none", color=color, label=NAMES[key])
            ax.plot(psi, quantity(lay.W) / unit, "k.", ms=5, label="measured")
            ax.set_xscale("log")
            ax.grid(alpha=0.3)
            if j == 0:
                ax.set_ylabel("|F| / N" if i == 0 else "|M| / (N R)")
            if i == 1:
                ax.set_xlabel("ψ = |ω| R / |v|")
        axes[0, j].set_title(f"{SHORT[lay.name]} (R = {1000 * lay.R:.0f} mm)", fontsize=10)
    axes[0, 0].legend(fontsize=7, loc="lower left")
    fig.suptitle("Hardboard pushes: measured and predicted (f and surfaces fitted on 70 % of each log)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _force(W: np.ndarray) -> np.ndarray:
    return np.hypot(W[:, 0], W[:, 1])


def _torque(W: np.ndarray) -> np.ndarray:
    return np.abs(W[:, 2])


SLICE_COLOURS = (
    ("exact", "tab:blue"),
    ("ellipsoid", "tab:orange"),
    ("quartic", "tab:purple"),
    ("edge", "tab:red"),
)


def figure_surfaces(layouts: list[Layout], fits: dict, path: Path) -> None:
    """Slices of the limit surfaces (twists in the planes vy = 0 and vx = 0), pushes near them."""
    import matplotlib.pyplot as plt

    chosen = [x for x in layouts if x.name in ("patch", "30_90_30_30_30_90")]
    fig, axes = plt.subplots(len(chosen), 2, figsize=(9.0, 4.2 * len(chosen)), squeeze=False)
    th = np.linspace(0.0, 2.0 * np.pi, 181)
    for i, lay in enumerate(chosen):
        for j, (c, label) in enumerate(((0, "F_x"), (1, "F_y"))):
            ax = axes[i, j]
            t = np.zeros((th.size, 3))
            t[:, c] = np.cos(th)
            t[:, 2] = np.sin(th) / RHO
            curves = {
                "exact": fits[lay.name]["f"]["exact"] * predict_on(lay.pmap, lay.coefficients, t)["exact"]
            }
            curves.update({k: fits[lay.name]["surface"][k].wrench(t) for k in SURFACES})
            if "edge" in fits[lay.name]:
                lam, f = fits[lay.name]["edge"]
                curves["edge"] = f * edge_loaded(lay, lam, t)
            for key, color in SLICE_COLOURS:
                if key not in curves:
                    continue
                W = curves[key]
                ax.plot(W[:, c], W[:, 2] / RHO, "-", color=color, label=NAMES[key])
            tw = np.column_stack([lay.kin[:, 0], lay.kin[:, 1], lay.kin[:, 2] * RHO])
            off = np.degrees(np.arcsin(np.abs(tw[:, 1 - c]) / np.linalg.norm(tw, axis=1)))
            near = off < 25.0
            ax.plot(lay.W[near, c], lay.W[near, 2] / RHO, "k.", label="pushes within 25° of the slice")
            ax.set_xlabel(f"{label} (N)")
            ax.set_ylabel("M_z / ρ (N), ρ = 50 mm")
            ax.set_title(f"{SHORT[lay.name]}: twists with v_{'yx'[c]} = 0", fontsize=10)
            ax.set_aspect("equal")
            ax.grid(alpha=0.3)
        axes[i, 0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


BAR_COLOURS = {
    "exact": "tab:blue", "paper": "tab:green", "model": "tab:cyan", "ellipsoid": "tab:orange",
    "quartic": "tab:purple",
}  # fmt: skip


def figure_errors(held: dict, across: dict, path: Path) -> None:
    """Held-out force and torque errors per model and layout, within a log and across layouts."""
    import matplotlib.pyplot as plt

    keys = ("exact", "paper", "model", "ellipsoid", "quartic")
    names = list(held)
    fig, axes = plt.subplots(1, 3, figsize=(14.0, 4.0))
    x = np.arange(len(names))
    width = 0.8 / len(keys)
    for ax, metric, title in (
        (axes[0], "force_rel", "held-out |ΔF| / |F| (RMS), within each log"),
        (axes[1], "torque_rel", "held-out |ΔM| / |M| (RMS), within each log"),
    ):
        for k, key in enumerate(keys):
            vals = [held[n][key]["test"][metric] for n in names]
            ax.bar(x + k * width, vals, width, label=NAMES[key], color=BAR_COLOURS[key])
        ax.set_title(title, fontsize=10)
    for k, key in enumerate(("exact", "ellipsoid", "quartic")):
        vals = [across[n][key]["test"]["force_rel"] for n in names]
        axes[2].bar(x + k * 0.27, vals, 0.27, label=NAMES[key], color=BAR_COLOURS[key])
    axes[2].set_title("|ΔF| / |F| (RMS), fitted on the other four layouts", fontsize=10)
    for ax in axes:
        ax.set_xticks(x + 0.3, [SHORT[n] for n in names], rotation=20, fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_diagnosis(per_log: dict, pooled: dict, path: Path) -> None:
    """ΔBIC of every cause against the simulation per log and summed (pooled); chosen causes boxed."""
    import matplotlib.pyplot as plt

    causes = [r["name"] for r in pooled["candidates"]]
    logs = list(per_log)
    M = np.array(
        [
            [r["per_log"][g] if r["per_log"][g] is not None else np.nan for g in logs]
            for r in pooled["candidates"]
        ]
    )
    M = np.column_stack([M, [r["delta_bic_sum"] for r in pooled["candidates"]]])
    fig, ax = plt.subplots(figsize=(9.0, 0.45 * len(causes) + 1.6))
    shown = np.sign(M) * np.log10(1.0 + np.abs(M))
    lim = np.nanmax(np.abs(shown))
    ax.imshow(shown, cmap="RdBu_r", vmin=-lim, vmax=lim, aspect="auto")
    for i in range(M.shape[0]):
        for j in range(M.shape[1]):
            if np.isfinite(M[i, j]):
                ax.text(j, i, f"{M[i, j]:.0f}", ha="center", va="center", fontsize=7)
    for j, g in enumerate(logs):
        primary = per_log[g]["cause"]
        if primary in causes:
            i = causes.index(primary)
            ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=2.0, ec="k"))
    ax.set_xticks(range(len(logs) + 1), [SHORT[g] for g in logs] + ["pooled (sum)"], fontsize=8)
    ax.set_yticks(range(len(causes)), causes, fontsize=8)
    ax.set_title("ΔBIC of each cause against the simulation (blue: supported; boxed: named)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# -- tables ------------------------------------------------------------------------------------
