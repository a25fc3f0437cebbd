"""Figure 3: contact pressure along the diameters through the static centre of pressure.

The values are the FE field itself, interpolated with the FE elements (linear
triangles for nodal data, constant per face for face data) by VTK's probe
filter on the flat patch mesh — not the resampled polar map. Points that fall
outside the loaded faces carry no contact pressure (0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError
from ..patch import Patch
from . import theme
from .render import DEFAULT_INFLATION_PRESSURE, check_pressure, patch_mesh

#: Points per diameter.
N_SECTION = 401


def fe_pressure_at(patch: Patch, x, y) -> np.ndarray:
    """FE contact pressure (Pa) at in-plane points (m, patch frame); 0 off the patch."""
    import pyvista as pv

    x = np.asarray(x, float)
    y = np.asarray(y, float)
    mesh = patch_mesh(patch, 1.0, 0.0)  # m, flat; "sigma_over_P" = σ in Pa when P* = 1
    probe = pv.PolyData(np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]))
    out = probe.sample(mesh, tolerance=1e-6 * max(patch.r_max, 1e-12))
    valid = np.asarray(out.point_data["vtkValidPointMask"], bool)
    vals = np.asarray(out.point_data["sigma_over_P"], float)
    return np.where(valid, vals, 0.0).reshape(x.shape)


@dataclass(frozen=True)
class SectionData:
    """Pressure along the x and y diameters, dimensionless σ/P*.

    ``s`` (m) is the position along each diameter; ``static_x``, ``static_y``
    (and ``rolling_x``, ``rolling_y`` when a rolling map is given) are σ/P* along
    y = 0 and x = 0 respectively. ``inflation_pressure`` P* in Pa; ``R`` (m) the
    static r_max (the R of the coefficients); ``R_rolling`` (m) the rolling map's
    r_max about the same origin, the static centre of pressure (None without a
    rolling map): the rolling map reaches further forward.
    """

    s: np.ndarray
    static_x: np.ndarray
    static_y: np.ndarray
    rolling_x: np.ndarray | None
    rolling_y: np.ndarray | None
    inflation_pressure: float
    R: float
    R_rolling: float | None = None

    def __post_init__(self) -> None:
        for name in ("s", "static_x", "static_y", "rolling_x", "rolling_y"):
            v = getattr(self, name)
            if v is not None:
                object.__setattr__(self, name, frozen(v))

    def to_dict(self) -> dict:
        d = {
            "s": self.s.tolist(),
            "static_x": self.static_x.tolist(),
            "static_y": self.static_y.tolist(),
        }
        if self.rolling_x is not None and self.rolling_y is not None:
            d.update({"rolling_x": self.rolling_x.tolist(), "rolling_y": self.rolling_y.tolist()})
        d.update({"inflation_pressure": self.inflation_pressure, "R": self.R})
        if self.R_rolling is not None:
            d["R_rolling"] = self.R_rolling
        return d


def diameter_sections(
    static: Patch,
    rolling: Patch | None = None,
    *,
    inflation_pressure: float = DEFAULT_INFLATION_PRESSURE,
    n: int = N_SECTION,
    half_length: float | None = None,
) -> SectionData:
    """σ/P* along the x and y diameters through the static centre of pressure.

    ``half_length`` (m) of the diameters (default 1.1 × the largest distance of a
    patch node from the origin, so the curves reach zero).
    """
    p_star = check_pressure(inflation_pressure)
    if int(n) != n or n < 3:
        raise ArgumentError(f"n must be an integer >= 3, got {n!r}")
    patches = [static] + ([rolling] if rolling is not None else [])
    if half_length is None:
        half_length = 1.1 * max(float(np.max(np.hypot(p.xy[:, 0], p.xy[:, 1]))) for p in patches)
    s = np.linspace(-half_length, half_length, int(n))
    zero = np.zeros_like(s)

    def along(p: Patch) -> tuple[np.ndarray, np.ndarray]:
        vals = fe_pressure_at(p, np.r_[s, zero], np.r_[zero, s]) / p_star
        return vals[: s.size], vals[s.size :]

    sx, sy = along(static)
    rx = ry = None
    if rolling is not None:
        rx, ry = along(rolling)
    r_rolling = None if rolling is None else rolling.r_max
    return SectionData(s, sx, sy, rx, ry, p_star, static.r_max, r_rolling)


def plotted_values(data: SectionData) -> np.ndarray:
    """Every σ/P* value Figure 3 plots (the y-limits must hold all of them)."""
    series = [data.static_x, data.static_y, data.rolling_x, data.rolling_y]
    return np.concatenate([np.asarray(v) for v in series if v is not None])


def _radius_lines(ax, axis: str, data: SectionData) -> None:
    """Dotted lines at ±R (the static r_max) and, with a rolling map, at ± its own r_max
    about the same origin, which the rolling curve reaches."""
    radii = [("static", data.R, theme.RMAX_COLOUR, "±R = r_max, static (the R of the coefficients)")]
    if data.R_rolling is not None:
        radii.append(("rolling", data.R_rolling, theme.ROLLING_COLOUR, "±r_max, rolling map"))
    for which, radius, colour, label in radii:
        for sgn in (-1, 1):
            side = "minus" if sgn < 0 else "plus"
            gid = f"rmax_{axis}_{side}" if which == "static" else f"rmax_rolling_{axis}_{side}"
            ax.axvline(sgn * radius, color=colour, lw=0.8, ls=":", label=label if sgn < 0 else None, gid=gid)


def plot_sections(data: SectionData, axes=None):
    """Plot the x and y diameters (static solid, rolling dashed); return the figure.

    ``axes``: a pair of matplotlib axes (x section, y section); default a new
    figure with two side-by-side panels sharing the σ/P* axis. The y-limits are
    set once, after both panels are drawn, from every plotted value (0 … 5 %
    above the highest peak), so no peak is clipped; the legend sits above the
    panels, clear of the data.
    """
    import matplotlib.pyplot as plt

    with theme.mpl_style():
        if axes is None:
            fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.4), sharey=True, layout="constrained")
        else:
            fig = axes[0].figure
        for ax, axis, st, ro in (
            (axes[0], "x", data.static_x, data.rolling_x),
            (axes[1], "y", data.static_y, data.rolling_y),
        ):
            ax.plot(data.s, st, color=theme.STATIC_COLOUR, lw=1.8, label="static", gid=f"static_{axis}")
            if ro is not None:
                ax.plot(
                    data.s,
                    ro,
                    color=theme.ROLLING_COLOUR,
                    lw=1.8,
                    ls="--",
                    label="rolling",
                    gid=f"rolling_{axis}",
                )
            _radius_lines(ax, axis, data)
            other = "y" if axis == "x" else "x"
            ax.set_xlabel(f"{axis} (m), along {other} = 0")
            ax.set_title(f"{axis} diameter" + (" (rolling direction)" if axis == "x" else " (lateral)"))
            ax.set_xlim(float(data.s[0]), float(data.s[-1]))
        top = float(np.max(plotted_values(data)))
        for ax in axes:
            ax.set_ylim(0.0, 1.05 * top if top > 0 else 1.0)
        axes[0].set_ylabel(f"σ/P* (P* = {data.inflation_pressure / 1e3:.0f} kPa)")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside upper center", ncol=min(len(labels), 2))
    return fig
