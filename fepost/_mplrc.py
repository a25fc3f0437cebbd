"""fepost's matplotlib look, as rc settings: one definition for every layer that draws.

The figures layer (`fepost.figures.theme`) adds its SVG settings to these; the studies
that draw their own figures (`fepost.shimmy.figures`) use them as they are. Kept in the
foundations, importing nothing, so that a study need not import the figures layer above it.
"""

from __future__ import annotations

from typing import Any

#: matplotlib figure size (inches) and resolution of the PNGs (dpi).
MPL_FIGSIZE = (7.0, 4.6)
MPL_DPI = 130

#: Size, resolution, grid, no top/right spines, legend without a frame.
MPL_RC: dict[str, Any] = {
    "figure.figsize": MPL_FIGSIZE,
    "figure.dpi": 100,
    "savefig.dpi": MPL_DPI,
    "font.size": 10,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.fontsize": 8.5,
    "legend.frameon": False,
}
