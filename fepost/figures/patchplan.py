"""The patch in plan: FE faces coloured by pressure, outline circles, fitted ellipse."""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..patch import Patch
from . import theme
from .render import circle_points, ellipse_points


def circularity_verdict(patch: Patch) -> str:
    """One line: circular or not, with the numbers the rule looks at."""
    word = "circular" if patch.circular else "NOT circular"
    return f"{word}: aspect {patch.aspect:.3f}, r_max/r_equiv {patch.r_max / patch.r_equiv:.3f}"


def plot_patch_plan(patch: Patch, ax=None):
    """Plot the loaded region in plan (mm, pressure in kPa); return the figure.

    Draws the FE triangles coloured by the FE pressure (Gouraud for nodal data,
    flat for face data), the r_max circle about the origin, the r_equiv circle
    (√(area/π)) about the area centroid, the fitted ellipse, the centre of
    pressure, and the circularity verdict in the title.
    """
    import matplotlib.pyplot as plt

    if not isinstance(patch, Patch):
        raise ArgumentError(f"patch must be a Patch, got {type(patch).__name__}")
    with theme.mpl_style():
        if ax is None:
            fig, ax = plt.subplots(figsize=(6.4, 5.6), layout="constrained")
        else:
            fig = ax.figure
        xy = np.asarray(patch.xy) * 1e3
        kpa = np.asarray(patch.values) / 1e3
        shading = "gouraud" if patch.location == "point" else "flat"
        tpc = ax.tripcolor(
            xy[:, 0],
            xy[:, 1],
            patch.triangles,
            kpa,
            shading=shading,
            cmap=theme.CMAP,
            gid="pressure",
            rasterized=True,
        )
        ax.triplot(xy[:, 0], xy[:, 1], patch.triangles, color="white", lw=0.15, alpha=0.5, rasterized=True)
        fig.colorbar(tpc, ax=ax, label="contact pressure (kPa)", shrink=0.85)
        c = circle_points(patch.r_max * 1e3)
        ax.plot(
            c[:, 0],
            c[:, 1],
            color=theme.RMAX_COLOUR,
            lw=1.5,
            label=f"r_max = {patch.r_max * 1e3:.1f} mm (R)",
            gid="r_max",
        )
        ce = patch.ellipse_centre
        c = circle_points(patch.r_equiv * 1e3, (ce[0] * 1e3, ce[1] * 1e3))
        ax.plot(
            c[:, 0],
            c[:, 1],
            color=theme.REQUIV_COLOUR,
            lw=1.5,
            ls="--",
            label=f"r_equiv = {patch.r_equiv * 1e3:.1f} mm",
            gid="r_equiv",
        )
        e = ellipse_points(
            (patch.ellipse_axes[0] * 1e3, patch.ellipse_axes[1] * 1e3),
            patch.ellipse_angle,
            (ce[0] * 1e3, ce[1] * 1e3),
        )
        ax.plot(
            e[:, 0],
            e[:, 1],
            color=theme.ELLIPSE_COLOUR,
            lw=1.5,
            label=f"fitted ellipse (aspect {patch.aspect:.3f})",
            gid="ellipse",
        )
        cp = patch.centre_of_pressure
        ax.plot(
            [cp[0] * 1e3],
            [cp[1] * 1e3],
            "+",
            color="black",
            ms=10,
            mew=1.5,
            label="centre of pressure",
            gid="cop",
        )
        ax.annotate(
            "",
            xy=(0.5 * patch.r_max * 1e3, -1.12 * patch.r_max * 1e3),
            xytext=(-0.5 * patch.r_max * 1e3, -1.12 * patch.r_max * 1e3),
            arrowprops={"arrowstyle": "-|>", "color": theme.ROLLING_COLOUR, "lw": 1.5},
        )
        ax.text(
            0.0,
            -1.19 * patch.r_max * 1e3,
            "rolling direction +x",
            ha="center",
            va="top",
            color=theme.ROLLING_COLOUR,
            fontsize=8.5,
        )
        lim = 1.3 * patch.r_max * 1e3
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_title(f"Loaded region — {circularity_verdict(patch)}", fontsize=10)
        ax.grid(False)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8)
    return fig
