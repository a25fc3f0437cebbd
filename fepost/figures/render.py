"""Figures 1 and 2: the contact pressure over the patch as a 3-D surface (pyvista).

The surface is the FE patch itself (its triangles and its nodal or face values,
not a re-gridded map), in the patch frame (origin at the static centre of
pressure, x the rolling direction, z the road normal) with lengths in m.
Height = σ/P* (dimensionless, P* the inflation pressure) times a fixed scale;
colour = σ in kPa, on a colour bar with round ticks.

The surface is drawn where the pressure is at least `EDGE_FRACTION` of
its peak, cut along that contour of the FE field (linear on each triangle), and
the contour is drawn at z = 0 as the edge of the contact: the FE faces' own
outline is a staircase of element edges, and the faces beyond the contour carry
a negligible share of the load. The r_max circle about the static centre of
pressure and the fitted ellipse are drawn at z = 0, and an arrow marks the
rolling direction +x.

The axes are drawn with `fepost.figures.scene` rather than with VTK's cube
axes, so that every label is a ``vtkTextActor`` anchored at a known point: its
box on screen is known, the tick count is reduced until no two tick labels
overlap, and the tests check that no text overlaps other text or the data.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..patch import Patch
from . import theme
from .outline import circle_points, ellipse_points, level_segments
from .scene import add_text, draw_axis, nice_ceil, nice_ticks, nice_top, rgb, thin_axis, tick_labels, use_font
from .scene import boxes_overlap as boxes_overlap  # re-exported: the figure tests check overlaps
from .scene import text_box as text_box
from .scene import viewport_box as viewport_box

#: Default inflation pressure P* (Pa): the paper's 200 kPa.
DEFAULT_INFLATION_PRESSURE = 200e3
#: Half-width of the framed square as a multiple of r_max (before rounding up to a round value).
EXTENT_FACTOR = 1.15
#: Height of the tallest point of the surface as a fraction of r_max.
HEIGHT_FRACTION = 0.4
#: The surface stops where the pressure falls below this fraction of its peak (the contact edge).
EDGE_FRACTION = 0.02
#: Zoom applied after fitting the axes box in the window.
CAMERA_ZOOM = 1.1
#: Camera shift to the right (scene moves left), in units of the framed half-width.
SHIFT_RIGHT = 0.2
#: Font sizes (points at the 1200 × 900 window): tick labels, axis titles, title.
TICK_FONT = 20
AXIS_TITLE_FONT = 22
TITLE_FONT = 24
#: Legend box (lower-left corner, size) in window fractions: top right, under the heading,
#: above the colour bar, where the camera leaves no data. Each entry is a line sample of
#: `LEGEND_SAMPLE` (window fraction) in the outline's colour and width, then its text.
LEGEND_ORIGIN = (0.62, 0.76)
LEGEND_SIZE = (0.36, 0.13)
LEGEND_SAMPLE = 0.05
#: The contact edge's line width (px); the circle's and the ellipse's.
EDGE_WIDTH, RMAX_WIDTH, ELLIPSE_WIDTH = 4.0, 6.0, 5.0


def check_pressure(inflation_pressure: float) -> float:
    """The inflation pressure P* (Pa) of a figure's p/P* axis, as a float.

    Raises
    ------
    ArgumentError
        ``inflation_pressure`` is not a finite positive number.
    """
    p = float(inflation_pressure)
    if not (np.isfinite(p) and p > 0):
        raise ArgumentError(
            f"inflation_pressure must be a positive pressure in Pa, got {inflation_pressure!r}"
        )
    return p


def patch_mesh(
    patch: Patch, inflation_pressure: float = DEFAULT_INFLATION_PRESSURE, height_scale: float = 0.0
):
    """The patch as `pyvista.PolyData` in m.

    Points are (x, y, height_scale·σ/P*) in m (flat when ``height_scale`` = 0);
    arrays ``pressure_kPa`` and ``sigma_over_P`` live where the FE values live
    (point or cell data, exactly the FE values), and the point array
    ``sigma_over_P_nodes`` carries the nodal values used for the height.
    """
    import pyvista as pv

    p_star = check_pressure(inflation_pressure)
    xy = np.asarray(patch.xy, float)
    nodes = np.asarray(patch.node_values(), float) / p_star
    pts = np.column_stack([xy, height_scale * nodes])
    tri = np.asarray(patch.triangles, np.int64)
    faces = np.column_stack([np.full(len(tri), 3, np.int64), tri]).ravel()
    mesh = pv.PolyData(pts, faces)
    data = mesh.point_data if patch.location == "point" else mesh.cell_data
    data["pressure_kPa"] = np.asarray(patch.values, float) / 1e3
    data["sigma_over_P"] = np.asarray(patch.values, float) / p_star
    mesh.point_data["sigma_over_P_nodes"] = nodes
    return mesh


def default_height_scale(*patches: Patch, inflation_pressure: float = DEFAULT_INFLATION_PRESSURE) -> float:
    """m of height per unit σ/P* so that the tallest of ``patches`` rises to
    `HEIGHT_FRACTION` × its r_max."""
    p_star = check_pressure(inflation_pressure)
    peak = max(float(np.max(p.node_values())) for p in patches) / p_star
    r = max(p.r_max for p in patches)
    return HEIGHT_FRACTION * r / peak if peak > 0 else 1.0


def contact_edge(patch: Patch, fraction: float = EDGE_FRACTION) -> np.ndarray:
    """(k, 2, 2) segments (m) of the contour where the FE pressure is ``fraction`` × its peak."""
    nodes = np.asarray(patch.node_values(), float)
    return level_segments(patch.xy, patch.triangles, nodes, fraction * float(np.max(nodes)))


def _polyline(xy: np.ndarray, z: float = 0.0):
    import pyvista as pv

    return pv.lines_from_points(np.column_stack([xy, np.full(len(xy), z)]))


def _segments(seg: np.ndarray, z: float = 0.0):
    import pyvista as pv

    pts = np.column_stack([seg.reshape(-1, 2), np.full(2 * len(seg), z)])
    idx = np.arange(2 * len(seg)).reshape(-1, 2)
    return pv.PolyData(pts, lines=np.column_stack([np.full(len(seg), 2), idx]).ravel())


def pressure_surface(
    patch: Patch,
    *,
    inflation_pressure: float = DEFAULT_INFLATION_PRESSURE,
    title: str | None = None,
    plotter=None,
    height_scale: float | None = None,
    clim: tuple[float, float] | None = None,
    extent: float | None = None,
    symbol: str = "σ",
):
    """Render the patch pressure as a 3-D surface; return the (off-screen) plotter.

    Parameters
    ----------
    patch : Patch
        The contact patch (FE faces and values in the patch frame).
    inflation_pressure : float
        P* in Pa: the height shows σ/P*.
    title : str, optional
        First line of the figure's heading.
    plotter : pyvista.Plotter, optional
        Draw into this plotter (default: a new off-screen one with fepost's theme).
    height_scale : float, optional
        m of height per unit σ/P* (default `default_height_scale`; give the
        same value to Figures 1 and 2 so they compare).
    clim : (float, float), optional
        Colour range in kPa (default 0 … peak); the top is rounded up to a round
        tick of the colour bar.
    extent : float, optional
        Half-width in m of the square the axes frame, rounded up to a round value
        (default `EXTENT_FACTOR` × r_max; give Figures 1 and 2 the same value
        so they compare).
    symbol : str
        The pressure's symbol in the heading, the height axis and the colour bar
        (the report: σ₀ for the static map, σᵥ for the rolling one, as docs/theory.md).

    The circle, the ellipse and the contact edge are drawn on a layer above the
    surface (`overlay_renderer`), so the pressure never hides them.
    The caller saves it with ``plotter.screenshot(path)``; `layout`
    gives the text actors, legend and surface it placed.
    """
    p_star = check_pressure(inflation_pressure)
    if not isinstance(patch, Patch):
        raise ArgumentError(f"patch must be a Patch, got {type(patch).__name__}")
    hs = (
        default_height_scale(patch, inflation_pressure=p_star)
        if height_scale is None
        else float(height_scale)
    )
    mesh = patch_mesh(patch, p_star, hs)
    nodes = mesh.point_data["sigma_over_P_nodes"]
    level = EDGE_FRACTION * float(np.max(nodes))
    surface = mesh.clip_scalar(scalars="sigma_over_P_nodes", value=level, invert=False)
    peak_kpa = float(np.max(patch.values)) / 1e3
    lo, hi = (0.0, peak_kpa) if clim is None else (float(clim[0]), float(clim[1]))
    ext = nice_ceil(EXTENT_FACTOR * patch.r_max if extent is None else float(extent))
    if plotter is None:
        theme.use_headless_vtk()
        plotter = _new_plotter()
    _add_surface(plotter, surface, location=patch.location, clim=(lo, hi), symbol=symbol)
    texts = [_add_outlines(plotter, patch)]
    peak_dimless = float(np.max(nodes)) if len(nodes) else 0.0
    z_range, z_step = nice_top(peak_dimless, 4)
    _place_camera(plotter, ext=ext, z_top=z_range * hs)
    heading = f"height {symbol}/P* (P* = {p_star / 1e3:.0f} kPa), colour {symbol} (kPa)"
    head = add_text(
        plotter, f"{title}\n{heading}" if title else heading, (0.5, 0.985, 0.0), TITLE_FONT, "center", "top"
    )
    head.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    legend = _add_legend(plotter, patch, symbol)
    texts += _add_axes(
        plotter,
        ext=ext,
        z_range=z_range,
        z_step=z_step,
        hs=hs,
        placed=(texts[0], head, legend),
        symbol=symbol,
    )
    plotter._fepost_layout = SurfaceLayout(tuple(texts), head, legend, surface)
    return plotter


def _new_plotter():
    import pyvista as pv

    return pv.Plotter(off_screen=True, window_size=list(theme.WINDOW_SIZE), theme=theme.pyvista_theme())


def _add_surface(plotter, surface, *, location: str, clim: tuple[float, float], symbol: str = "σ") -> None:
    """The pressure surface, coloured in kPa, with its colour bar (round ticks from ``clim[0]``)."""
    lo, hi = clim
    top, cstep = nice_top(hi - lo, 7)
    plotter.add_mesh(
        surface,
        scalars="pressure_kPa",
        preference="point" if location == "point" else "cell",
        cmap=theme.CMAP,
        clim=(lo, lo + top),
        show_edges=False,
        lighting=True,
        scalar_bar_args={
            "title": f"{symbol} (kPa)",
            "vertical": True,
            "position_x": 0.86,
            "position_y": 0.20,
            "height": 0.45,
            "width": 0.06,
            "n_labels": int(round(top / cstep)) + 1,
            "fmt": "%.0f" if cstep >= 1 else "%.2g",
            "title_font_size": AXIS_TITLE_FONT,
            "label_font_size": TICK_FONT,
        },
        show_scalar_bar=True,
    )
    bar = plotter.scalar_bar
    use_font(bar.GetTitleTextProperty())
    use_font(bar.GetLabelTextProperty())


def _add_outlines(plotter, patch: Patch):
    """The contact edge, the r_max circle and the ellipse at z = 0, and the rolling-direction
    arrow in front of the patch; returns the arrow's label."""
    import pyvista as pv

    r = patch.r_max
    top = overlay_renderer(plotter)
    edge = contact_edge(patch)
    lines = []
    if len(edge):
        lines.append(plotter.add_mesh(_segments(edge), color=theme.EDGE_COLOUR, line_width=EDGE_WIDTH))
    lines.append(
        plotter.add_mesh(
            _polyline(circle_points(r)),
            color=theme.RMAX_COLOUR,
            line_width=RMAX_WIDTH,
            render_lines_as_tubes=True,
        )
    )
    ell = ellipse_points(patch.ellipse_axes, patch.ellipse_angle, patch.ellipse_centre)
    lines.append(
        plotter.add_mesh(
            _polyline(ell), color=theme.ELLIPSE_COLOUR, line_width=ELLIPSE_WIDTH, render_lines_as_tubes=True
        )
    )
    for actor in lines:  # drawn over the surface, never hidden under the pressure
        plotter.renderer.RemoveActor(actor)
        top.AddActor(actor)
    # Rolling direction +x: an arrow in front of the patch, its label before the tail.
    y_arrow = -1.2 * r
    arrow = pv.Arrow(
        start=(-0.5 * r, y_arrow, 0.0),
        direction=(1.0, 0.0, 0.0),
        scale=0.8 * r,
        tip_length=0.25,
        tip_radius=0.08,
        shaft_radius=0.03,
    )
    plotter.add_mesh(arrow, color=theme.ROLLING_COLOUR)
    label = (-0.6 * r, y_arrow, 0.0)
    return add_text(
        plotter, "rolling direction +x", label, TICK_FONT, "right", "center", theme.ROLLING_COLOUR
    )


def _place_camera(plotter, *, ext: float, z_top: float) -> None:
    """Fixed camera: from the front-left, above the patch, the scene left of centre (clear of
    the colour bar)."""
    box = (-ext, ext, -ext, ext, 0.0, max(z_top, 1e-9))
    plotter.camera_position = [(-1.5 * ext, -3.3 * ext, 2.4 * ext), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    plotter.camera.view_angle = 30.0
    plotter.reset_camera(bounds=box)
    plotter.camera.zoom(CAMERA_ZOOM)
    cam = plotter.camera
    direction = np.subtract(cam.focal_point, cam.position)
    right = np.cross(direction, cam.up)
    shift = SHIFT_RIGHT * ext * right / np.linalg.norm(right)
    cam.position = tuple(np.add(cam.position, shift))
    cam.focal_point = tuple(np.add(cam.focal_point, shift))


def overlay_renderer(plotter):
    """A renderer on the layer above the plotter's, sharing its camera: what it draws is
    drawn over the surface (its depth buffer starts empty). Made once per plotter."""
    top = getattr(plotter, "_fepost_overlay", None)
    if top is not None:
        return top
    from vtkmodules.vtkRenderingCore import vtkRenderer

    win = plotter.render_window
    win.SetNumberOfLayers(max(2, win.GetNumberOfLayers()))
    top = vtkRenderer()
    top.SetLayer(1)
    top.SetViewport(*plotter.renderer.GetViewport())
    top.SetActiveCamera(plotter.renderer.GetActiveCamera())
    top.InteractiveOff()
    win.AddRenderer(top)
    plotter._fepost_overlay = top
    return top


def _add_legend(plotter, patch: Patch, symbol: str = "σ"):
    """The legend of the outlines, top right under the heading: for each, a line sample in
    its colour and width, then its text. Returns the legend's frame, a 2-D actor whose
    position and size (normalised viewport) hold every sample and text."""
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkRenderingCore import vtkActor2D, vtkCoordinate, vtkPolyDataMapper2D, vtkTextActor

    entries = [
        (f"circle of radius R = {patch.r_max:.4g} m", theme.RMAX_COLOUR, RMAX_WIDTH),
        (f"fitted ellipse, aspect {patch.aspect:.3f}", theme.ELLIPSE_COLOUR, ELLIPSE_WIDTH),
        (f"contact edge, {symbol} = {EDGE_FRACTION:.0%} of peak", theme.EDGE_COLOUR, EDGE_WIDTH),
    ]
    x0, y0 = LEGEND_ORIGIN
    w, h = LEGEND_SIZE
    row = h / len(entries)
    right = x0 + w
    renderer = plotter.renderer
    win_w, _ = renderer.GetSize()
    for i, (text, colour, width) in enumerate(entries):
        yc = y0 + h - (i + 0.5) * row
        sample = vtkPolyData()
        sp, sc = vtkPoints(), vtkCellArray()
        sp.InsertNextPoint(x0 + 0.005, yc, 0.0)
        sp.InsertNextPoint(x0 + 0.005 + LEGEND_SAMPLE, yc, 0.0)
        sc.InsertNextCell(2)
        sc.InsertCellPoint(0)
        sc.InsertCellPoint(1)
        sample.SetPoints(sp)
        sample.SetLines(sc)
        coord = vtkCoordinate()
        coord.SetCoordinateSystemToNormalizedViewport()
        mapper = vtkPolyDataMapper2D()
        mapper.SetInputData(sample)
        mapper.SetTransformCoordinate(coord)
        line = vtkActor2D()
        line.SetMapper(mapper)
        line.GetProperty().SetColor(*rgb(colour))
        line.GetProperty().SetLineWidth(width)
        plotter.add_actor(line, reset_camera=False, pickable=False)
        label = vtkTextActor()
        label.SetInput(text)
        prop = label.GetTextProperty()
        prop.SetFontSize(TICK_FONT)
        use_font(prop)
        prop.SetColor(*rgb("black"))
        prop.SetJustificationToLeft()
        prop.SetVerticalJustificationToCentered()
        label.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        label.GetPositionCoordinate().SetValue(x0 + 0.015 + LEGEND_SAMPLE, yc)
        plotter.add_actor(label, reset_camera=False, pickable=False)
        box = text_box(label, renderer)
        right = max(right, box[1] / max(win_w, 1))
    frame = vtkActor2D()
    frame.SetPosition(x0, y0)
    frame.SetPosition2(right - x0, h)
    return frame


def _add_axes(
    plotter, *, ext: float, z_range: float, z_step: float, hs: float, placed, symbol: str = "σ"
) -> list:
    """Axes: x along the front edge, y along the left edge (z = 0), height at the back-left
    corner; labels thinned clear of each other and of the ``placed`` (label, heading, legend)."""
    import pyvista as pv

    renderer = plotter.renderer
    z_top = z_range * hs
    frame = np.array([[-ext, -ext, 0], [ext, -ext, 0], [ext, ext, 0], [-ext, ext, 0], [-ext, -ext, 0]], float)
    plotter.add_mesh(pv.lines_from_points(frame), color="#555555", line_width=1.5, pickable=False)
    zline = np.array([[-ext, ext, 0.0], [-ext, ext, z_top]])
    plotter.add_mesh(pv.lines_from_points(zline), color="black", line_width=2, pickable=False)
    tick = 0.04 * ext
    xy_ticks = nice_ticks(-ext, ext)
    label, head, legend = placed
    occupied: tuple = (text_box(label, renderer), text_box(head, renderer))
    occupied += (viewport_box(legend, renderer), viewport_box(plotter.scalar_bar, renderer))

    def axis(ticks, occupied, start, direction, outward, offset, h, v, scale=1.0):
        def make(tk):
            where = {"start": start, "direction": direction, "outward": outward, "h": h, "v": v}
            return draw_axis(
                plotter, tk, tick_labels(tk / scale), **where, tick_len=tick, label_off=offset, font=TICK_FONT
            )

        return thin_axis(ticks * scale, make, renderer, occupied)

    xs, occupied = axis(xy_ticks, occupied, (0, -ext, 0), (1, 0, 0), (0, -1, 0), 0.12 * ext, "center", "top")
    # The back-left corner (y = +ext) carries the height axis and its 0: no y tick there.
    y_ticks = xy_ticks[xy_ticks < ext * (1.0 - 1e-9)]
    ys, occupied = axis(y_ticks, occupied, (-ext, 0, 0), (0, 1, 0), (-1, 0, 0), 0.12 * ext, "right", "center")
    z_ticks = np.arange(0.0, z_range + 0.5 * z_step, z_step)
    zs, _ = axis(z_ticks, occupied, (-ext, ext, 0), (0, 0, 1), (-1, 0, 0), 0.08 * ext, "right", "center", hs)
    return [
        *xs,
        *ys,
        *zs,
        add_text(plotter, "x (m)", (0.55 * ext, -1.5 * ext, 0.0), AXIS_TITLE_FONT, "left", "top"),
        add_text(plotter, "y (m)", (-1.45 * ext, -0.55 * ext, 0.0), AXIS_TITLE_FONT, "right", "top"),
        add_text(
            plotter,
            f"{symbol}/P*",
            (-ext, ext, z_top * 1.12 + 0.02 * ext),
            AXIS_TITLE_FONT,
            "center",
            "bottom",
        ),
    ]


@dataclass(frozen=True)
class SurfaceLayout:
    """What `pressure_surface` placed, for checking the figure: the text actors
    of the axes and labels, the heading, the legend and the drawn surface (m)."""

    texts: tuple
    heading: object
    legend: object
    surface: object


def layout(plotter) -> SurfaceLayout:
    """The `SurfaceLayout` of a plotter made by `pressure_surface`."""
    found = getattr(plotter, "_fepost_layout", None)
    if found is None:
        raise ArgumentError("layout: the plotter was not made by pressure_surface")
    return found
