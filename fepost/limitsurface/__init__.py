"""Limit surfaces of planar sliding: the ellipsoid and the convex quartic, fitted to pushes.

The robotics community's description of the same physics as fepost's friction
models: the set of wrenches that make a planar contact slide, with the twist
normal to it (`fepost.limitsurface.polynomial`), fitted to measured wrench and
twist directions (`fepost.limitsurface.fit`).
"""

from .fit import LimitSurface, fit_limit_surface, support_points, wrench_errors
from .polynomial import HomogeneousPolynomial

__all__ = ["HomogeneousPolynomial", "LimitSurface", "fit_limit_surface", "support_points", "wrench_errors"]
