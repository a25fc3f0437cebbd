"""Figures 1 and 2: the contact pressure over the patch as a 3-D surface (pyvista).

The surface is the FE patch itself (its triangles and its nodal or face values,
not a re-gridded map), in the patch frame (origin at the static centre of
pressure, x the rolling direction, z the road normal) with lengths in m.
Height = σ/P* (dimensionless, P* the inflation pressure) times a fixed scale;
colour = σ in kPa, on a colour bar with round ticks.

The surface is drawn where the pressure is at least :data:`EDGE_FRACTION` of
its peak, cut along that contour of the FE field (linear on each triangle), and
the contour is drawn at z = 0 as the edge of the contact: the FE faces' own
outline is a staircase of element edges, and the faces beyond the contour carry
a negligible share of the load. The r_max circle about the static centre of
pressure and the fitted ellipse are drawn at z = 0, and an arrow marks the
rolling direction +x.

The axes are drawn here rather than with VTK's cube axes, so that every label
is a :class:`vtkTextActor` anchored at a known point: :func:`text_boxes` gives
their boxes on screen, the tick count is reduced until no two tick labels
overlap, and the tests check that no text overlaps other text or the data.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..patch import Patch
from . import theme
from .outline import circle_points, ellipse_points, level_segments

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
#: Most intervals between ticks on an axis before thinning for overlaps.
MAX_INTERVALS = 4
#: Least gap between two labels, pixels.
LABEL_GAP = 4.0
#: Legend box (lower-left corner, size) in window fractions: top right, under the heading,
#: above the colour bar, where the camera leaves no data.
LEGEND_ORIGIN = (0.62, 0.76)
LEGEND_SIZE = (0.36, 0.13)
_NICE = (1.0, 2.0, 2.5, 5.0)


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
    """The patch as :class:`pyvista.PolyData` in m.

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


def nice_step(span: float, max_intervals: int = MAX_INTERVALS) -> float:
    """The smallest of 1, 2, 2.5, 5 × 10^k that divides ``span`` into at most ``max_intervals``."""
    if not span > 0:
        return 1.0
    k = np.floor(np.log10(span / max_intervals))
    for base in (*_NICE, 10.0):
        step = base * 10**k
        if span / step <= max_intervals * (1 + 1e-9):
            return float(step)
    return float(10 ** (k + 1))


def nice_ticks(lo: float, hi: float, max_intervals: int = MAX_INTERVALS) -> np.ndarray:
    """Round tick values in [lo, hi] (multiples of :func:`nice_step`)."""
    step = nice_step(hi - lo, max_intervals)
    first = np.ceil(lo / step - 1e-9)
    last = np.floor(hi / step + 1e-9)
    return np.arange(first, last + 1) * step


def nice_top(peak: float, max_intervals: int = 6) -> tuple[float, float]:
    """(top, step): a round upper limit >= ``peak`` and its round tick step."""
    if not peak > 0:
        return 1.0, 1.0
    step = nice_step(peak, max_intervals)
    top = np.ceil(peak / step - 1e-9) * step
    if top / step > max_intervals:  # ceil pushed it past the budget: the next step up
        step = nice_step(top, max_intervals)
        top = np.ceil(peak / step - 1e-9) * step
    return float(top), float(step)


def tick_labels(values) -> list[str]:
    """Labels of round tick ``values`` with the fewest decimals that tell them apart
    (``0`` for zero, a true minus sign)."""
    values = np.asarray(values, float)
    for decimals in range(0, 7):
        texts = [f"{v:.{decimals}f}" for v in values]
        if all(abs(float(t) - v) <= 1e-9 * max(1.0, abs(v)) for t, v in zip(texts, values, strict=True)):
            break
    out = []
    for t in texts:
        if float(t) == 0:
            t = "0"
        out.append(t.replace("-", "−"))
    return out


def nice_ceil(x: float) -> float:
    """The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k that is >= x (x > 0)."""
    if not x > 0:
        return 1.0
    k = np.floor(np.log10(x))
    for m in (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0):
        if m * 10**k >= x * (1 - 1e-12):
            return float(m * 10**k)
    return float(10 ** (k + 1))


def default_height_scale(*patches: Patch, inflation_pressure: float = DEFAULT_INFLATION_PRESSURE) -> float:
    """m of height per unit σ/P* so that the tallest of ``patches`` rises to
    :data:`HEIGHT_FRACTION` × its r_max."""
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


def _text(plotter, text: str, xyz, size: int, h: str = "center", v: str = "center", color="black", name=None):
    """A 2-D text actor anchored at the 3-D point ``xyz`` (world coordinates)."""
    from vtkmodules.vtkRenderingCore import vtkTextActor

    actor = vtkTextActor()
    actor.SetInput(text)
    prop = actor.GetTextProperty()
    prop.SetFontSize(size)
    prop.SetFontFamilyToArial()
    prop.SetColor(*_rgb(color))
    {
        "left": prop.SetJustificationToLeft,
        "center": prop.SetJustificationToCentered,
        "right": prop.SetJustificationToRight,
    }[h]()
    {
        "bottom": prop.SetVerticalJustificationToBottom,
        "center": prop.SetVerticalJustificationToCentered,
        "top": prop.SetVerticalJustificationToTop,
    }[v]()
    coord = actor.GetPositionCoordinate()
    coord.SetCoordinateSystemToWorld()
    coord.SetValue(*map(float, xyz))
    plotter.add_actor(actor, reset_camera=False, name=name, pickable=False)
    return actor


def _rgb(color) -> tuple[float, float, float]:
    import pyvista as pv

    return tuple(pv.Color(color).float_rgb)  # type: ignore[return-value]


def text_box(actor, renderer) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) in display pixels of a text actor (anchored anywhere) on ``renderer``."""
    bb = [0.0] * 4
    actor.GetBoundingBox(renderer, bb)
    coord = actor.GetPositionCoordinate()
    x, y = coord.GetComputedDoubleDisplayValue(renderer)
    return (x + bb[0], x + bb[1], y + bb[2], y + bb[3])


def viewport_box(actor, renderer) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) in display pixels of a 2-D actor placed in normalised viewport
    coordinates (legend, colour bar)."""
    w, h = renderer.GetSize()
    x, y = actor.GetPosition()
    dx, dy = actor.GetPosition2()
    return (x * w, (x + dx) * w, y * h, (y + dy) * h)


def boxes_overlap(a, b, pad: float = 0.0) -> bool:
    """True when the boxes (x0, x1, y0, y1) overlap by more than ``pad`` pixels."""
    return min(a[1], b[1]) - max(a[0], b[0]) > pad and min(a[3], b[3]) - max(a[2], b[2]) > pad


def _draw_axis(plotter, ticks, labels, start, direction, outward, tick_len, label_off, h, v):
    """Tick marks and labels along an axis: returns the label actors."""
    import pyvista as pv

    start, direction, outward = (np.asarray(u, float) for u in (start, direction, outward))
    actors = []
    pts = []
    for t, text in zip(ticks, labels, strict=True):
        p = start + t * direction
        pts += [p, p + tick_len * outward]
        actors.append(_text(plotter, text, p + label_off * outward, TICK_FONT, h, v))
    if pts:
        marks = pv.PolyData(np.array(pts))
        marks.lines = np.column_stack(
            [np.full(len(ticks), 2), np.arange(2 * len(ticks)).reshape(-1, 2)]
        ).ravel()
        plotter.add_mesh(marks, color="black", line_width=2, pickable=False)
    return actors


def _thin(ticks: np.ndarray, make, renderer, occupied: list) -> list:
    """Draw an axis with ``make(ticks)``, legibly: while two of its labels overlap, keep every
    other tick (0 kept); then drop single labels that overlap ``occupied`` boxes (labels
    already placed), and add the boxes of the ones kept to ``occupied``."""
    while True:
        actors = make(ticks)
        boxes = [text_box(a, renderer) for a in actors]
        clash = any(boxes_overlap(p, q, pad=-LABEL_GAP) for i, p in enumerate(boxes) for q in boxes[i + 1 :])
        if not clash or len(ticks) <= 2:
            break
        for a in actors:
            renderer.RemoveActor(a)
        ticks = (
            ticks[::2]
            if np.any(np.isclose(ticks[::2], 0.0)) or not np.any(np.isclose(ticks, 0.0))
            else ticks[1::2]
        )
    kept = []
    for a, b in zip(actors, boxes, strict=True):
        if any(boxes_overlap(b, o, pad=-LABEL_GAP) for o in occupied):
            renderer.RemoveActor(a)
            continue
        occupied.append(b)
        kept.append(a)
    return kept


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
        m of height per unit σ/P* (default :func:`default_height_scale`; give the
        same value to Figures 1 and 2 so they compare).
    clim : (float, float), optional
        Colour range in kPa (default 0 … peak); the top is rounded up to a round
        tick of the colour bar.
    extent : float, optional
        Half-width in m of the square the axes frame, rounded up to a round value
        (default :data:`EXTENT_FACTOR` × r_max; give Figures 1 and 2 the same value
        so they compare).

    The caller saves it with ``plotter.screenshot(path)``; :func:`layout`
    gives the text actors, legend and surface it placed.
    """
    import pyvista as pv

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
    top, cstep = nice_top(hi - lo, 7)
    n_colour_labels = int(round(top / cstep)) + 1
    r = patch.r_max
    ext = nice_ceil(EXTENT_FACTOR * r if extent is None else float(extent))

    if plotter is None:
        theme.use_headless_vtk()
        plotter = pv.Plotter(
            off_screen=True, window_size=list(theme.WINDOW_SIZE), theme=theme.pyvista_theme()
        )
    renderer = plotter.renderer
    plotter.add_mesh(
        surface,
        scalars="pressure_kPa",
        preference="point" if patch.location == "point" else "cell",
        cmap=theme.CMAP,
        clim=(lo, lo + top),
        show_edges=False,
        lighting=True,
        scalar_bar_args={
            "title": "p (kPa)",
            "vertical": True,
            "position_x": 0.86,
            "position_y": 0.20,
            "height": 0.45,
            "width": 0.06,
            "n_labels": n_colour_labels,
            "fmt": "%.0f" if cstep >= 1 else "%.2g",
            "title_font_size": AXIS_TITLE_FONT,
            "label_font_size": TICK_FONT,
        },
        show_scalar_bar=True,
    )
    edge = contact_edge(patch)
    if len(edge):
        plotter.add_mesh(_segments(edge), color=theme.EDGE_COLOUR, line_width=3)
    plotter.add_mesh(
        _polyline(circle_points(r)), color=theme.RMAX_COLOUR, line_width=6, render_lines_as_tubes=True
    )
    ell = ellipse_points(patch.ellipse_axes, patch.ellipse_angle, patch.ellipse_centre)
    plotter.add_mesh(_polyline(ell), color=theme.ELLIPSE_COLOUR, line_width=5, render_lines_as_tubes=True)
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
    texts = [
        _text(
            plotter,
            "rolling direction +x",
            (-0.6 * r, y_arrow, 0.0),
            TICK_FONT,
            "right",
            "center",
            theme.ROLLING_COLOUR,
        )
    ]

    # Fixed camera: from the front-left, above the patch.
    peak_dimless = float(np.max(nodes)) if len(nodes) else 0.0
    z_range, z_step = nice_top(peak_dimless, 4)
    z_top = z_range * hs
    box = (-ext, ext, -ext, ext, 0.0, max(z_top, 1e-9))
    plotter.camera_position = [(-1.5 * ext, -3.3 * ext, 2.4 * ext), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    plotter.camera.view_angle = 30.0
    plotter.reset_camera(bounds=box)
    plotter.camera.zoom(CAMERA_ZOOM)
    # Shift the view so the scene sits left of centre, clear of the colour bar.
    cam = plotter.camera
    direction = np.subtract(cam.focal_point, cam.position)
    right = np.cross(direction, cam.up)
    shift = SHIFT_RIGHT * ext * right / np.linalg.norm(right)
    cam.position = tuple(np.add(cam.position, shift))
    cam.focal_point = tuple(np.add(cam.focal_point, shift))

    heading = f"height p/P* (P* = {p_star / 1e3:.0f} kPa), colour p (kPa)"
    head = _text(
        plotter, f"{title}\n{heading}" if title else heading, (0.5, 0.985, 0.0), TITLE_FONT, "center", "top"
    )
    head.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    legend = plotter.add_legend(
        [
            [f"circle of radius R = {r:.4g} m", theme.RMAX_COLOUR],
            [f"fitted ellipse, aspect {patch.aspect:.3f}", theme.ELLIPSE_COLOUR],
            [f"contact edge, p = {EDGE_FRACTION:.0%} of peak", theme.EDGE_COLOUR],
        ],
        bcolor="white",
        border=False,
        loc="upper right",
        size=LEGEND_SIZE,
        face="line",
    )
    legend.SetPosition(*LEGEND_ORIGIN)
    legend.SetPosition2(*LEGEND_SIZE)

    # Axes: x along the front edge, y along the left edge (z = 0), height at the back-left corner.
    frame = np.array([[-ext, -ext, 0], [ext, -ext, 0], [ext, ext, 0], [-ext, ext, 0], [-ext, -ext, 0]], float)
    plotter.add_mesh(pv.lines_from_points(frame), color="#555555", line_width=1.5, pickable=False)
    zline = np.array([[-ext, ext, 0.0], [-ext, ext, z_top]])
    plotter.add_mesh(pv.lines_from_points(zline), color="black", line_width=2, pickable=False)
    tick = 0.04 * ext
    xy_ticks = nice_ticks(-ext, ext)
    occupied = [text_box(texts[0], renderer), text_box(head, renderer)]
    occupied += [viewport_box(legend, renderer), viewport_box(plotter.scalar_bar, renderer)]

    def axis(ticks, start, direction, outward, offset, h, v, scale=1.0):
        return _thin(
            ticks * scale,
            lambda tk: _draw_axis(
                plotter, tk, tick_labels(tk / scale), start, direction, outward, tick, offset, h, v
            ),
            renderer,
            occupied,
        )

    xs = axis(xy_ticks, (0, -ext, 0), (1, 0, 0), (0, -1, 0), 0.12 * ext, "center", "top")
    # The back-left corner (y = +ext) carries the height axis and its 0: no y tick there.
    y_ticks = xy_ticks[xy_ticks < ext * (1.0 - 1e-9)]
    ys = axis(y_ticks, (-ext, 0, 0), (0, 1, 0), (-1, 0, 0), 0.12 * ext, "right", "center")
    z_ticks = np.arange(0.0, z_range + 0.5 * z_step, z_step)
    zs = axis(z_ticks, (-ext, ext, 0), (0, 0, 1), (-1, 0, 0), 0.08 * ext, "right", "center", scale=hs)
    texts += xs + ys + zs
    texts.append(_text(plotter, "x (m)", (0.55 * ext, -1.5 * ext, 0.0), AXIS_TITLE_FONT, "left", "top"))
    texts.append(_text(plotter, "y (m)", (-1.45 * ext, -0.55 * ext, 0.0), AXIS_TITLE_FONT, "right", "top"))
    texts.append(
        _text(plotter, "p/P*", (-ext, ext, z_top * 1.12 + 0.02 * ext), AXIS_TITLE_FONT, "center", "bottom")
    )

    plotter._fepost_layout = SurfaceLayout(tuple(texts), head, legend, surface)
    return plotter


@dataclass(frozen=True)
class SurfaceLayout:
    """What :func:`pressure_surface` placed, for checking the figure: the text actors
    of the axes and labels, the heading, the legend and the drawn surface (m)."""

    texts: tuple
    heading: object
    legend: object
    surface: object


def layout(plotter) -> SurfaceLayout:
    """The :class:`SurfaceLayout` of a plotter made by :func:`pressure_surface`."""
    found = getattr(plotter, "_fepost_layout", None)
    if found is None:
        raise ArgumentError("layout: the plotter was not made by pressure_surface")
    return found
