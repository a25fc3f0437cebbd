"""Figures of the report: they only look at results, never compute the physics.

* `.render` — Figures 1 and 2: static and rolling contact pressure as a 3-D
  surface over the FE patch (pyvista, off-screen).
* `.section` — Figure 3: pressure along the x and y diameters, from the FE field.
* `.patchplan` — the loaded region in plan with its outline circles and ellipse.
* `.curves` — Figures 4–6: F∥, M_C and F⊥ against the speed ratio.
* `.errormap` — the error of the closed forms over the kinematic sphere.
* `.sweep` — a sweep's coefficients against load and against time.
* `.theme` — the fixed window size, colours and fonts.
* `.units` — how numbers and units are written (the report uses it too).

Every figure function takes data objects and an optional plotter or axes, returns
the plotter or figure and never calls ``show()``.
"""

from .curves import CurveData, curve_table, plot_curve
from .patchplan import plot_patch_plan
from .render import patch_mesh, pressure_surface
from .section import SectionData, diameter_sections, plot_sections

__all__ = [
    "CurveData",
    "SectionData",
    "curve_table",
    "diameter_sections",
    "patch_mesh",
    "plot_curve",
    "plot_patch_plan",
    "plot_sections",
    "pressure_surface",
]
