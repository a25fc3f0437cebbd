"""The patch in plan: FE faces coloured by pressure, the contact edge, circles and ellipse."""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..patch import Patch
from . import theme
from .outline import circle_points, ellipse_points
from .render import EDGE_FRACTION, contact_edge
from .scene import nice_top


def pressure_colour_range(*patches: Patch) -> tuple[float, float]:
    """(0, top) in kPa: the colour range of the pressure in Figures 1, 2 and the patch plan,
    the peak of ``patches`` rounded up to the colour bar's round top (`nice_top`)."""
    peak = max(float(np.max(p.values)) for p in patches) / 1e3
    return 0.0, nice_top(peak, 7)[0]


def circularity_verdict(patch: Patch) -> str:
    """One line of plain text: circular or not, with the numbers the rule looks at."""
    word = "circular" if patch.circular else "NOT circular"
    return f"{word}: aspect {patch.aspect:.3f}, r_max/r_equiv {patch.r_max / patch.r_equiv:.3f}"


def verdict_title(patch: Patch) -> str:
    """The figure's title: `circularity_verdict` with the radii set as subscripts."""
    word = "circular" if patch.circular else "NOT circular"
    return (
        f"Loaded region — {word}: aspect {patch.aspect:.3f}, "
        rf"$r_{{\max}}/r_{{\mathrm{{equiv}}}}$ {patch.r_max / patch.r_equiv:.3f}"
    )


def plot_patch_plan(patch: Patch, ax=None, *, clim: tuple[float, float] | None = None, symbol: str = "σ₀"):
    """Plot the loaded region in plan (m, pressure in kPa); return the figure.

    ``clim``: the colour range in kPa (default 0 … the round top of the colour bar of
    Figure 1, `pressure_colour_range`), so the same pressure has the same colour in both;
    ``symbol``: the pressure's symbol in the colour bar and legend.

    Draws the FE triangles coloured by the FE pressure (Gouraud for nodal data,
    flat for face data), the contact edge (the contour where the pressure is
    `EDGE_FRACTION` of its peak), the r_max circle
    about the origin, the r_equiv circle (√(area/π)) about the area centroid,
    the fitted ellipse, the centre of pressure, and the circularity verdict in
    the title. The legend sits below the axes, clear of the data.
    """
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    if not isinstance(patch, Patch):
        raise ArgumentError(f"patch must be a Patch, got {type(patch).__name__}")
    with theme.mpl_style():
        if ax is None:
            fig, ax = plt.subplots(figsize=(6.4, 6.0), layout="constrained")
        else:
            fig = ax.figure
        xy = np.asarray(patch.xy)
        kpa = np.asarray(patch.values) / 1e3
        shading = "gouraud" if patch.location == "point" else "flat"
        vmin, vmax = clim or pressure_colour_range(patch)
        tpc = ax.tripcolor(
            xy[:, 0],
            xy[:, 1],
            patch.triangles,
            kpa,
            shading=shading,
            cmap=theme.CMAP,
            gid="pressure",
            rasterized=True,
            vmin=vmin,
            vmax=vmax,
        )
        fig.colorbar(tpc, ax=ax, label=f"contact pressure {symbol} (kPa)", shrink=0.8)
        edge = contact_edge(patch)
        ax.add_collection(
            LineCollection(
                list(edge),
                colors=theme.EDGE_COLOUR,
                linewidths=1.2,
                label=f"contact edge ({symbol} = {EDGE_FRACTION:.0%} of peak)",
                gid="edge",
            )
        )
        r = patch.r_max
        c = circle_points(r)
        ax.plot(
            c[:, 0],
            c[:, 1],
            color=theme.RMAX_COLOUR,
            lw=1.5,
            label=rf"$r_{{\max}}$ = R = {r:.4g} m",
            gid="r_max",
        )
        ce = patch.ellipse_centre
        c = circle_points(patch.r_equiv, ce)
        ax.plot(
            c[:, 0],
            c[:, 1],
            color=theme.REQUIV_COLOUR,
            lw=1.5,
            ls="--",
            label=rf"$r_{{\mathrm{{equiv}}}}$ = {patch.r_equiv:.4g} m",
            gid="r_equiv",
        )
        e = ellipse_points(patch.ellipse_axes, patch.ellipse_angle, ce)
        ax.plot(
            e[:, 0],
            e[:, 1],
            color=theme.ELLIPSE_COLOUR,
            lw=1.5,
            label=f"fitted ellipse (aspect {patch.aspect:.3f})",
            gid="ellipse",
        )
        cp = patch.centre_of_pressure
        ax.plot([cp[0]], [cp[1]], "+", color="black", ms=10, mew=1.5, label="centre of pressure", gid="cop")
        ax.annotate(
            "",
            xy=(0.5 * r, -1.12 * r),
            xytext=(-0.5 * r, -1.12 * r),
            arrowprops={"arrowstyle": "-|>", "color": theme.ROLLING_COLOUR, "lw": 1.5},
        )
        ax.text(
            0.0,
            -1.19 * r,
            "rolling direction +x",
            ha="center",
            va="top",
            color=theme.ROLLING_COLOUR,
            fontsize=9,
            gid="rolling",
        )
        lim = 1.3 * r
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(verdict_title(patch), fontsize=10)
        ax.grid(False)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8.5)
    return fig
