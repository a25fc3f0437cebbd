"""The fixed look of every fepost figure: window size, colours, fonts.

Renders must be reproducible pixel for pixel on one machine (the image
regression tests compare them with stored baselines), so the pyvista figures use
a theme built here rather than the user's global theme, a fixed window size and
a fixed camera, and the matplotlib figures use `mpl_style`.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from .._mplrc import MPL_RC

#: Window size of the 3-D renders, pixels (width, height).
WINDOW_SIZE = (1200, 900)
#: Colour map of pressure, everywhere.
CMAP = "viridis"
#: Line colours: static, rolling, outline circle r_max, r_equiv, ellipse, contact edge.
STATIC_COLOUR = "#1f4e99"
ROLLING_COLOUR = "#c0392b"
RMAX_COLOUR = "#222222"
REQUIV_COLOUR = "#7f7f7f"
ELLIPSE_COLOUR = "#e67e22"
#: The contact edge (contour of the FE pressure at a small fraction of its peak).
EDGE_COLOUR = "#555555"
EXACT_COLOUR = "#1f4e99"
CLOSED_COLOUR = "#2ca02c"
FIT_COLOUR = "#c0392b"
TEST_COLOUR = "#555555"
_MPL_RC: dict[str, Any] = {**MPL_RC, "svg.fonttype": "none", "svg.hashsalt": "fepost"}


def use_headless_vtk() -> None:
    """Prefer VTK's EGL window when there is no X display.

    Without it VTK first tries X, logs "bad X server connection" on stderr and
    then falls back to EGL; the preference only applies to windows created later.
    """
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


def pyvista_theme():
    """A fresh `pyvista.themes.DocumentTheme` with fepost's fixed settings."""
    import pyvista as pv

    theme = pv.themes.DocumentTheme()
    theme.window_size = list(WINDOW_SIZE)
    theme.background = "white"
    theme.font.color = "black"
    theme.font.family = "arial"
    theme.font.size = 14
    theme.font.title_size = 16
    theme.font.label_size = 14
    theme.cmap = CMAP
    theme.anti_aliasing = None
    theme.lighting = True
    theme.smooth_shading = False
    theme.show_scalar_bar = False
    return theme


@contextmanager
def mpl_style() -> Iterator[None]:
    """matplotlib rc settings of fepost figures (Agg backend assumed)."""
    import matplotlib as mpl

    with mpl.rc_context(_MPL_RC):  # type: ignore[arg-type]  # matplotlib types keys as Literal
        yield
