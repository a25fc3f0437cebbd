"""Error map: where over the kinematic sphere the friction models miss the exact integrals.

Four panels: rows force (|ΔF|/F0) and torque (|ΔM_z|/M0), columns the models
of an `ErrorMap` (by default the paper's closed
forms and the generalised model); x the sliding direction β (0–180°), y the
meridian coordinate t = (2/π)·atan ε, labelled in ε = |v|/(|ω_z| R) from pure
spin (ε = 0) to pure sliding (ε = ∞). One logarithmic colour scale for all
panels, so the panels compare honestly; a contour marks the 3 % goal and each
panel's title gives its largest error. The module computes nothing physical:
the data come from `fepost.friction.sphere.error_map`
(`fepost.friction.summary.model_error_map` for an FE map).
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import PurePath

import numpy as np

from ..errors import ArgumentError
from ..friction.sphere import ErrorMap
from . import theme
from .curves import mathtext

#: ε values labelled on the y axis.
EPS_TICKS = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0, np.inf)
#: The accuracy goal drawn as a contour (fraction of F0 or M0).
GOAL = 0.03
#: Lower end of the colour scale (errors below it share its colour).
FLOOR = 1e-3
#: Longest line of the heading (characters): the narrowest map, one panel wide, holds it.
TITLE_WIDTH = 48
#: Panel titles of the usual model names.
TITLES = {"paper": "paper's closed forms (1.8)", "model": "generalised model", "base": "generalised base"}


def plot_error_map(data: ErrorMap, names: Sequence[str] = ("paper", "model"), fig=None):
    """Draw ``data`` for the models ``names``; return the figure (module docstring).

    Axes carry ``gid`` = ``"<quantity>:<name>"`` (quantity ``force`` or ``torque``)
    so tests can find them.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    if not isinstance(data, ErrorMap):
        raise ArgumentError(f"data must be an ErrorMap, got {type(data).__name__}")
    names = tuple(names)
    missing = [n for n in names if n not in data.force]
    if not names or missing:
        raise ArgumentError(f"names must be models of the map ({', '.join(data.names)}), got {list(names)!r}")
    top = max(float(np.max(getattr(data, q)[n])) for q in ("force", "torque") for n in names)
    norm = LogNorm(vmin=FLOOR, vmax=max(top, 10 * FLOOR))
    with theme.mpl_style():
        if fig is None:
            fig = plt.figure(figsize=(3.4 * len(names) + 1.2, 6.2), layout="constrained")
        axes = fig.subplots(2, len(names), squeeze=False, sharex=True, sharey=True)
        mesh = None
        for i, (q, label) in enumerate((("force", "|ΔF| / F_0"), ("torque", "|ΔM_z| / M_0"))):
            for j, name in enumerate(names):
                ax = axes[i, j]
                err = np.clip(getattr(data, q)[name], FLOOR, None)
                mesh = ax.pcolormesh(
                    data.beta, data.t, err.T, norm=norm, cmap=theme.CMAP, shading="nearest", rasterized=True
                )
                if np.nanmax(err) > GOAL:
                    ax.contour(data.beta, data.t, err.T, levels=[GOAL], colors="white", linewidths=1.0)
                worst = data.worst(name)
                ax.set_title(mathtext(f"{TITLES.get(name, name)}: {label} ≤ {worst[q]:.3f}"), fontsize=9)
                ax.set_gid(f"{q}:{name}")
                ax.grid(False)
                if i == 1:
                    ax.set_xlabel("sliding direction β (deg)")
                if j == 0:
                    ax.set_ylabel(mathtext("ε = |v| / (|ω_z| R)"))
        for ax in axes.ravel():
            ax.set_xticks([0, 45, 90, 135, 180])
            ticks = [1.0 if not np.isfinite(e) else (2.0 / np.pi) * np.arctan(e) for e in EPS_TICKS]
            ax.set_yticks(ticks)
            ax.set_yticklabels(["∞" if not np.isfinite(e) else f"{e:g}" for e in EPS_TICKS])
            ax.set_ylim(0.0, 1.0)
            ax.set_xlim(float(data.beta[0]), float(data.beta[-1]))
        cbar = fig.colorbar(mesh, ax=axes, shrink=0.9)
        cbar.set_label(f"error (fraction of F0 or M0); white line: {GOAL:.0%}")
        fig.suptitle(error_map_title(data.source), fontsize=10)
    return fig


def error_map_title(source: str) -> str:
    """The error map's heading: what it shows, then the map's file name (not its whole path,
    which would not fit), wrapped to lines of at most `TITLE_WIDTH` characters."""
    head = "Error over the kinematic sphere, both spin signs"
    name = PurePath(source).name if source else ""
    if not name:
        return head
    return head + "\n" + "\n".join(textwrap.wrap(name, TITLE_WIDTH, break_on_hyphens=False))
