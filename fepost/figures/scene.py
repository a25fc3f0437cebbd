"""Round ticks, text and axes for the 3-D pyvista figures (Figures 1 and 2).

The axes are drawn here rather than with VTK's cube axes, so that every label
is a ``vtkTextActor`` anchored at a known point: `text_box` gives its box on
screen, and `thin_axis` reduces the tick count until no two labels of an axis
overlap, nor a label and what is already placed.
"""

from __future__ import annotations

import numpy as np

#: Most intervals between ticks on an axis before thinning for overlaps.
MAX_INTERVALS = 4
#: Least gap between two labels, pixels.
LABEL_GAP = 4.0
_NICE = (1.0, 2.0, 2.5, 5.0)


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
    """Round tick values in [lo, hi] (multiples of `nice_step`)."""
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
    for decimals in range(7):
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


def font_file() -> str:
    """The TrueType font of the 3-D figures' text: matplotlib's DejaVu Sans, the font of the
    other figures, which has the Greek letters and subscripts (σ₀, σᵥ) VTK's own Arial lacks."""
    import os

    import matplotlib

    return os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf")


def use_font(prop) -> None:
    """Set a ``vtkTextProperty`` to `font_file`."""
    from vtkmodules.vtkCommonCore import VTK_FONT_FILE

    prop.SetFontFamily(VTK_FONT_FILE)
    prop.SetFontFile(font_file())


def add_text(
    plotter, text: str, xyz, size: int, h: str = "center", v: str = "center", color="black", name=None
):
    """A 2-D text actor anchored at the 3-D point ``xyz`` (world coordinates)."""
    from vtkmodules.vtkRenderingCore import vtkTextActor

    actor = vtkTextActor()
    actor.SetInput(text)
    prop = actor.GetTextProperty()
    prop.SetFontSize(size)
    use_font(prop)
    prop.SetColor(*rgb(color))
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


def rgb(color) -> tuple[float, float, float]:
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


def draw_axis(plotter, ticks, labels, *, start, direction, outward, tick_len, label_off, h, v, font):
    """Tick marks and labels along an axis: returns the label actors.

    ``start`` + t·``direction`` is the point of tick t; marks of ``tick_len`` and
    labels at ``label_off`` go along ``outward``; ``h``, ``v`` justify the labels
    (font size ``font``)."""
    import pyvista as pv

    start, direction, outward = (np.asarray(u, float) for u in (start, direction, outward))
    actors = []
    pts = []
    for t, text in zip(ticks, labels, strict=True):
        p = start + t * direction
        pts += [p, p + tick_len * outward]
        actors.append(add_text(plotter, text, p + label_off * outward, font, h, v))
    if pts:
        marks = pv.PolyData(np.array(pts))
        marks.lines = np.column_stack(
            [np.full(len(ticks), 2), np.arange(2 * len(ticks)).reshape(-1, 2)]
        ).ravel()
        plotter.add_mesh(marks, color="black", line_width=2, pickable=False)
    return actors


def thin_axis(ticks: np.ndarray, make, renderer, occupied: tuple) -> tuple[list, tuple]:
    """Draw an axis with ``make(ticks)``, legibly: while two of its labels overlap, keep every
    other tick (0 kept); then drop single labels that overlap ``occupied`` boxes (labels
    already placed). Returns the label actors kept and ``occupied`` with their boxes added."""
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
    kept, placed = [], list(occupied)
    for a, b in zip(actors, boxes, strict=True):
        if any(boxes_overlap(b, o, pad=-LABEL_GAP) for o in placed):
            renderer.RemoveActor(a)
            continue
        placed.append(b)
        kept.append(a)
    return kept, tuple(placed)
