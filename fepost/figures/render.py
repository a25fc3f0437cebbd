"""Figures 1 and 2: the contact pressure over the patch as a 3-D surface (pyvista).

The surface is the FE patch itself (its triangles and its nodal or face values,
not a re-gridded map), in the patch frame of THEORY.md §1 with lengths in mm.
Height = σ/P* (dimensionless, P* the inflation pressure) times a fixed scale;
colour = σ in kPa (dimensional colour bar). The patch outline (the r_max circle
about the static centre of pressure and the fitted ellipse) is drawn at z = 0,
and an arrow marks the rolling direction +x.
"""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..patch import Patch
from . import theme

#: Default inflation pressure P* (Pa): the paper's 200 kPa.
DEFAULT_INFLATION_PRESSURE = 200e3
#: Height of the tallest point of the surface as a fraction of r_max.
HEIGHT_FRACTION = 0.4
#: Zoom applied after fitting the axes box in the window.
CAMERA_ZOOM = 1.25


def _check_pressure(inflation_pressure: float) -> float:
    p = float(inflation_pressure)
    if not (np.isfinite(p) and p > 0):
        raise ArgumentError(
            f"inflation_pressure must be a positive pressure in Pa, got {inflation_pressure!r}"
        )
    return p


def patch_mesh(
    patch: Patch, inflation_pressure: float = DEFAULT_INFLATION_PRESSURE, height_scale: float = 0.0
):
    """The patch as :class:`pyvista.PolyData` in mm.

    Points are (x, y, height_scale·σ/P*) in mm (flat when ``height_scale`` = 0);
    arrays ``pressure_kPa`` and ``sigma_over_P`` live where the FE values live
    (point or cell data, exactly the FE values), and the point array
    ``sigma_over_P_nodes`` carries the nodal values used for the height.
    """
    import pyvista as pv

    p_star = _check_pressure(inflation_pressure)
    xy_mm = np.asarray(patch.xy, float) * 1e3
    nodes = np.asarray(patch.node_values(), float) / p_star
    pts = np.column_stack([xy_mm, height_scale * nodes])
    tri = np.asarray(patch.triangles, np.int64)
    faces = np.column_stack([np.full(len(tri), 3, np.int64), tri]).ravel()
    mesh = pv.PolyData(pts, faces)
    data = mesh.point_data if patch.location == "point" else mesh.cell_data
    data["pressure_kPa"] = np.asarray(patch.values, float) / 1e3
    data["sigma_over_P"] = np.asarray(patch.values, float) / p_star
    mesh.point_data["sigma_over_P_nodes"] = nodes
    return mesh


def circle_points(radius: float, centre=(0.0, 0.0), n: int = 181) -> np.ndarray:
    """(n, 2) points of a closed circle (same units as ``radius``)."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    return np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])


def ellipse_points(axes, angle: float, centre, n: int = 181) -> np.ndarray:
    """(n, 2) points of a closed ellipse with semi-axes ``axes`` = (major, minor),
    major axis at ``angle`` (rad) from x, about ``centre``."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    a, b = axes
    c, s = np.cos(angle), np.sin(angle)
    u = a * np.cos(t)
    v = b * np.sin(t)
    return np.column_stack([centre[0] + c * u - s * v, centre[1] + s * u + c * v])


def _polyline(xy: np.ndarray, z: float = 0.0):
    import pyvista as pv

    pts = np.column_stack([xy, np.full(len(xy), z)])
    return pv.lines_from_points(pts)


def nice_ceil(x: float) -> float:
    """The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k that is >= x (x > 0)."""
    if not x > 0:
        return 1.0
    k = np.floor(np.log10(x))
    for m in (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0):
        if m * 10**k >= x * (1 - 1e-12):
            return float(m * 10**k)
    return float(10 ** (k + 1))


def _nice_range(peak: float) -> tuple[float, int]:
    """(top, n_labels): a round top >= peak with at most 6 round intervals."""
    if not peak > 0:
        return 1.0, 2
    k = np.floor(np.log10(peak))
    for step in (0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 2.5, 5.0, 10.0):
        st = step * 10**k
        n = int(np.ceil(peak / st - 1e-9))
        if n <= 6:
            return float(n * st), n + 1
    return float(10 ** (k + 1)), 2


def default_height_scale(*patches: Patch, inflation_pressure: float = DEFAULT_INFLATION_PRESSURE) -> float:
    """mm of height per unit σ/P* so that the tallest of ``patches`` rises to
    :data:`HEIGHT_FRACTION` × its r_max."""
    p_star = _check_pressure(inflation_pressure)
    peak = max(float(np.max(p.node_values())) for p in patches) / p_star
    r_mm = max(p.r_max for p in patches) * 1e3
    return HEIGHT_FRACTION * r_mm / peak if peak > 0 else 1.0


def pressure_surface(
    patch: Patch,
    *,
    inflation_pressure: float = DEFAULT_INFLATION_PRESSURE,
    title: str | None = None,
    plotter=None,
    height_scale: float | None = None,
    clim: tuple[float, float] | None = None,
    extent: float | None = None,
):
    """Render the patch pressure as a 3-D surface; return the (off-screen) plotter.

    ``inflation_pressure`` P* (Pa) scales the height σ/P*; ``height_scale`` is the
    mm of height per unit σ/P* (default :func:`default_height_scale`; give the
    same value to Figures 1 and 2 so they compare); ``clim`` the colour range in
    kPa (default 0 … peak); ``extent`` (m) the half-width the camera frames
    (default 1.35 r_max). The caller saves it with ``plotter.screenshot(path)``.
    """
    import pyvista as pv

    p_star = _check_pressure(inflation_pressure)
    if not isinstance(patch, Patch):
        raise ArgumentError(f"patch must be a Patch, got {type(patch).__name__}")
    hs = (
        default_height_scale(patch, inflation_pressure=p_star)
        if height_scale is None
        else float(height_scale)
    )
    mesh = patch_mesh(patch, p_star, hs)
    peak_kpa = float(np.max(patch.values)) / 1e3
    clim = (0.0, peak_kpa) if clim is None else (float(clim[0]), float(clim[1]))
    r_mm = patch.r_max * 1e3
    ext = nice_ceil(1.3 * r_mm if extent is None else float(extent) * 1e3)

    if plotter is None:
        theme.use_headless_vtk()
        plotter = pv.Plotter(
            off_screen=True, window_size=list(theme.WINDOW_SIZE), theme=theme.pyvista_theme()
        )
    plotter.add_mesh(
        mesh,
        scalars="pressure_kPa",
        preference="point" if patch.location == "point" else "cell",
        cmap=theme.CMAP,
        clim=clim,
        show_edges=False,
        lighting=True,
        scalar_bar_args={
            "title": "p (kPa)",
            "vertical": True,
            "position_x": 0.9,
            "position_y": 0.42,
            "height": 0.42,
            "width": 0.05,
            "n_labels": 6,
            "fmt": "%.0f",
            "title_font_size": 16,
            "label_font_size": 14,
        },
        show_scalar_bar=True,
    )
    # Outline at z = 0: r_max circle about the static centre of pressure, fitted ellipse.
    plotter.add_mesh(
        _polyline(circle_points(r_mm)),
        color=theme.RMAX_COLOUR,
        line_width=6,
        render_lines_as_tubes=True,
    )
    ell = ellipse_points(
        (patch.ellipse_axes[0] * 1e3, patch.ellipse_axes[1] * 1e3),
        patch.ellipse_angle,
        (patch.ellipse_centre[0] * 1e3, patch.ellipse_centre[1] * 1e3),
    )
    plotter.add_mesh(_polyline(ell), color=theme.ELLIPSE_COLOUR, line_width=5, render_lines_as_tubes=True)
    # Rolling direction +x: an arrow in front of the patch.
    y_arrow = -1.2 * r_mm
    arrow = pv.Arrow(
        start=(-0.45 * r_mm, y_arrow, 0.0),
        direction=(1.0, 0.0, 0.0),
        scale=0.9 * r_mm,
        tip_length=0.25,
        tip_radius=0.08,
        shaft_radius=0.03,
    )
    plotter.add_mesh(arrow, color=theme.ROLLING_COLOUR)
    plotter.add_point_labels(
        np.array([[0.55 * r_mm, y_arrow, 0.0]]),
        ["rolling direction +x"],
        font_size=16,
        text_color=theme.ROLLING_COLOUR,
        shape=None,
        show_points=False,
        always_visible=True,
    )
    # Axes in mm; z labelled in σ/P* (the height is σ/P* × height_scale).
    peak_dimless = float(np.max(mesh.point_data["sigma_over_P_nodes"])) if mesh.n_points else 0.0
    z_range, n_z = _nice_range(peak_dimless)
    z_top = z_range * hs
    plotter.show_bounds(
        bounds=(-ext, ext, -ext, ext, 0.0, max(z_top, 1e-9)),
        axes_ranges=(-ext, ext, -ext, ext, 0.0, z_range),
        xtitle="x (mm)",
        ytitle="y (mm)",
        ztitle="p / P*",
        n_xlabels=5,
        n_ylabels=5,
        n_zlabels=n_z,
        fmt="%.3g",
        font_size=12,
        color="black",
        location="outer",
        grid=False,
        ticks="outside",
    )
    legend = [
        [f"r_max = {r_mm:.1f} mm (R)", theme.RMAX_COLOUR],
        [f"fitted ellipse, aspect {patch.aspect:.3f}", theme.ELLIPSE_COLOUR],
    ]
    plotter.add_legend(legend, bcolor="white", border=False, loc="lower left", size=(0.3, 0.08), face="line")
    subtitle = f"height: p/P* (P* = {p_star / 1e3:.0f} kPa), colour: p (kPa)"
    plotter.add_text(
        f"{title}\n{subtitle}" if title else subtitle,
        position="upper_edge",
        font_size=12,
        color="black",
    )
    # Fixed camera: from the front-left, above the patch.
    plotter.camera_position = [
        (-1.5 * ext, -3.3 * ext, 2.4 * ext),
        (0.0, 0.0, 0.0),
        (0.0, 0.0, 1.0),
    ]
    plotter.camera.view_angle = 30.0
    plotter.reset_camera(bounds=(-ext, ext, -ext, ext, 0.0, max(z_top, 1e-9)))
    plotter.camera.zoom(CAMERA_ZOOM)
    return plotter
