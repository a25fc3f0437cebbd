"""Reference pressure maps for the friction models, with their pressure integrals in closed form.

Used by the tests and ``benchmarks/bench_model.py`` to check the generalised model
on patches of known shape (ellipses of any aspect, a tire-like rounded rectangle,
an asymmetric rolling-like map).

An elliptic map σ = σ0 p(s), s = r/ρ_b(φ), on the ellipse with semi-axes (A, B)
(ρ_b(φ) = 1/√(cos²φ/A² + sin²φ/B²)) has

    ∬ σ K(φ) r^k dA = σ0 m_k ∫₀^{2π} K(φ) ρ_b(φ)^{k+2} dφ,   m_k = ∫₀¹ p(s) s^{k+1} ds,

one-dimensional integrals that scipy's quad evaluates independently of fepost's
quadratures. m_k: uniform 1/(k+2); Hertz (p = √(1 − s²)) m_{−1} = π/4, m_0 = 1/3,
m_1 = π/16, m_2 = 2/15.
"""

from __future__ import annotations

import numpy as np
from scipy import integrate

from ..analytic import pressure_function
from ..polar import PolarMap
from .quadrature import PressureQuadrature, edge_grid

#: Radius (m) of the equal-area disc of every reference map, and its peak pressure (Pa).
RADIUS = 0.1
PEAK = 2.0e5
MK = {
    "uniform": {-1: 1.0, 0: 1.0 / 2.0, 1: 1.0 / 3.0, 2: 1.0 / 4.0},
    "hertz": {-1: np.pi / 4.0, 0: 1.0 / 3.0, 1: np.pi / 16.0, 2: 2.0 / 15.0},
}


def ellipse_quad(
    profile: str = "hertz", aspect: float = 1.0, nr: int = 64, nphi: int = 128, k_x: float = 0.0
):
    """A map on the ellipse of semi-axes (R√aspect, R/√aspect) (equal area), as a quadrature."""
    fn = pressure_function(profile, RADIUS, peak=PEAK, k_x=k_x)
    quad = PressureQuadrature.from_polar(PolarMap.from_function(fn, RADIUS, edge_grid(nr, nphi)))
    return quad.stretched(np.sqrt(aspect)) if aspect != 1.0 else quad


def semi_axes(aspect: float) -> tuple[float, float]:
    s = np.sqrt(aspect)
    return RADIUS * s, RADIUS / s


def ellipse_integral(profile: str, aspect: float, kernel, k: int) -> float:
    """∬ σ K(φ) r^k dA (closed-form radial part, scipy quad in φ)."""
    A, B = semi_axes(aspect)

    def rho_b(phi):
        return 1.0 / np.sqrt((np.cos(phi) / A) ** 2 + (np.sin(phi) / B) ** 2)

    val, _ = integrate.quad(
        lambda p: kernel(p) * rho_b(p) ** (k + 2), 0.0, 2.0 * np.pi, limit=200, epsabs=0, epsrel=1e-12
    )
    return PEAK * MK[profile][k] * val


def reference_tensors(profile: str, aspect: float) -> dict:
    """N, polar, Q = ∬σ p pᵀ, S = ∬σ ê_r ê_rᵀ/r of a centred elliptic map (SI)."""
    c, s = np.cos, np.sin
    return {
        "N": ellipse_integral(profile, aspect, lambda p: 1.0, 0),
        "polar": ellipse_integral(profile, aspect, lambda p: 1.0, 1),
        "Q": np.array(
            [
                [ellipse_integral(profile, aspect, lambda p: c(p) ** 2, 2), 0.0],
                [0.0, ellipse_integral(profile, aspect, lambda p: s(p) ** 2, 2)],
            ]
        ),
        "S": np.array(
            [
                [ellipse_integral(profile, aspect, lambda p: c(p) ** 2, -1), 0.0],
                [0.0, ellipse_integral(profile, aspect, lambda p: s(p) ** 2, -1)],
            ]
        ),
    }


def tire_like(aspect: float = 1.6, nr: int = 64, nphi: int = 128) -> PressureQuadrature:
    """A tire-like patch: rounded-rectangle outline (superellipse, exponent 4), pressure
    low in the middle and raised on the lateral shoulders, falling to zero at the edge."""
    a, b = RADIUS * np.sqrt(aspect), RADIUS / np.sqrt(aspect)

    def sigma(x, y):
        s4 = (np.abs(x) / a) ** 4 + (np.abs(y) / b) ** 4
        inside = np.clip(1.0 - s4, 0.0, None)
        return PEAK * np.sqrt(inside) * (0.55 + 0.9 * (y / b) ** 2)

    tt = np.linspace(0.0, 0.5 * np.pi, 4001)
    R = float(np.max(np.hypot(a * np.sqrt(np.cos(tt)), b * np.sqrt(np.sin(tt))))) * 1.0001
    return PressureQuadrature.from_polar(PolarMap.from_function(sigma, R, edge_grid(nr, nphi)))


def asymmetric(aspect: float = 1.5, k: float = 0.15, shift=(0.006, -0.004)) -> PressureQuadrature:
    """A rolling-like map: Hertz ellipse with a forward pressure gradient σ(1 + k x/R), moved
    off the origin by ``shift`` (m): force at pure spin and torque at pure sliding both non-zero."""
    return ellipse_quad("hertz", aspect, k_x=k).shifted(*shift)
