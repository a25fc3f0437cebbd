"""Closed-form reference pressure maps and their integrals (docs/theory.md,
"Reference values").

Every profile is a function of ρ = r/R on the unit disc, scaled by a peak
pressure ``p`` (Pa). The closed forms below are checked in the tests against
``scipy.integrate.quad`` of the defining integrals.

========== ============================ =====================================
name       σ(ρ)/p                        A⁰, A¹, A², A³ (×p)
========== ============================ =====================================
uniform    1                             1, 1/2, 1/3, 1/4
hertz      √(1−ρ²)                       π/4, 1/3, π/16, 2/15
paraboloid 1−ρ²                          2/3, 1/4, 2/15, 1/12
========== ============================ =====================================

``tire`` is a profile with raised shoulders, σ/p = (1−ρ²)^{1/2}·(0.6 + 0.8ρ²)...
no closed form is claimed for it; its moments are computed by quadrature.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .errors import ArgumentError
from .friction_coefficient import DEFAULT_FRICTION

_PROFILES: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "uniform": lambda rho: np.ones_like(rho),
    "hertz": lambda rho: np.sqrt(np.clip(1.0 - rho**2, 0.0, None)),
    "paraboloid": lambda rho: np.clip(1.0 - rho**2, 0.0, None),
    # A tire-like map: low centre, raised shoulders, zero at the edge.
    "tire": lambda rho: np.sqrt(np.clip(1.0 - rho**2, 0.0, None)) * (0.6 + 1.2 * rho**2),
}

#: A^k/p for k = 0..3, closed forms (docs/theory.md, "Reference values", and direct integration).
MOMENTS: dict[str, tuple[float, float, float, float]] = {
    "uniform": (1.0, 1.0 / 2.0, 1.0 / 3.0, 1.0 / 4.0),
    "hertz": (np.pi / 4.0, 1.0 / 3.0, np.pi / 16.0, 2.0 / 15.0),
    "paraboloid": (2.0 / 3.0, 1.0 / 4.0, 2.0 / 15.0, 1.0 / 12.0),
}


def profile_names() -> tuple[str, ...]:
    return tuple(_PROFILES)


def profile(name: str) -> Callable[[np.ndarray], np.ndarray]:
    """σ(ρ)/p for the named profile (vectorised, zero outside ρ = 1)."""
    try:
        base = _PROFILES[name]
    except KeyError:
        raise ArgumentError(f"profile must be one of {', '.join(_PROFILES)}, got {name!r}") from None

    def f(rho):
        rho = np.asarray(rho, float)
        return np.where(rho <= 1.0, base(rho), 0.0)

    return f


def pressure_function(
    name: str,
    radius: float,
    peak: float = 1.0,
    k_x: float = 0.0,
    centre: tuple[float, float] = (0.0, 0.0),
    aspect: float = 1.0,
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """σ(x, y) in Pa for a profile on a patch of ``radius`` m.

    ``k_x`` applies the rolling shift σ(1 + k_x x/R) (docs/theory.md, "Integrals of the pressure");
    ``aspect`` stretches the patch along x by √aspect and shrinks it along y
    by the same factor (equal area); ``centre`` offsets the patch (m).
    """
    g = profile(name)
    s = np.sqrt(aspect)

    def sigma(x, y):
        x = np.asarray(x, float) - centre[0]
        y = np.asarray(y, float) - centre[1]
        rho = np.hypot(x / s, y * s) / radius
        return peak * g(rho) * (1.0 + k_x * x / radius)

    return sigma


def moments(name: str, peak: float = 1.0) -> np.ndarray:
    """A⁰…A³ (Pa) of a profile with a closed form (``uniform``, ``hertz``, ``paraboloid``)."""
    if name not in MOMENTS:
        raise ArgumentError(f"no closed-form moments for profile {name!r}; known: {', '.join(MOMENTS)}")
    return peak * np.array(MOMENTS[name])


def load(name: str, radius: float, peak: float = 1.0) -> float:
    """N = 2π R² A¹ (N) of a circular profile."""
    return 2.0 * np.pi * radius**2 * moments(name, peak)[1]


def coefficients(name: str, radius: float, peak: float = 1.0, friction: float = DEFAULT_FRICTION) -> dict:
    """F0, M0, a, m, b, b1 (SI) of a circular profile (docs/theory.md, "Integrals of the pressure")."""
    A = moments(name, peak)
    F0 = 2.0 * np.pi * friction * radius**2 * A[1]
    M0 = 2.0 * np.pi * friction * radius**3 * A[2]
    a = (2.0 * A[1] / A[0]) ** 2
    m = (2.0 * A[2] / A[3]) ** 2
    return {"F0": F0, "M0": M0, "a": a, "m": m, "b": m / 4.0, "b1": M0 / 2.0}
