"""The paper's closed-form friction approximations (paper eqs. 1.3, 1.7, 1.8; docs/theory.md).

With u = ω_z R (m/s) and v = |v| (m/s):

    F∥ = F0 v / √(v² + a u²)                   (N, along −v on the tire)
    M_C = M0 u / √(u² + m v²)                  (N·m, opposing ω_z)
    F⊥ = k_x (M0 / 2R) u / √(u² + (m/4) v²)    (N, lateral)

Magnitudes are returned; the signs of the components on the tire follow from
the exact integrals (`fepost.friction.exact`) and are applied by
`components`. `asymptotic_coefficients` derives a and m of any
pressure map from the asymptotes of the exact integrals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..friction_coefficient import DEFAULT_FRICTION, check_friction
from .quadrature import PressureQuadrature


def f_parallel(v, u, F0: float, a: float) -> np.ndarray:
    """|F∥| in N for sliding speed ``v`` and spin speed ``u = ω_z R`` (both m/s)."""
    v = np.abs(np.asarray(v, float))
    u = np.asarray(u, float)
    den = np.sqrt(v**2 + a * u**2)
    return np.where(den > 0, F0 * v / np.where(den > 0, den, 1.0), 0.0)


def torque(v, u, M0: float, m: float) -> np.ndarray:
    """|M_C| in N·m."""
    v = np.asarray(v, float)
    u = np.abs(np.asarray(u, float))
    den = np.sqrt(u**2 + m * v**2)
    return np.where(den > 0, M0 * u / np.where(den > 0, den, 1.0), 0.0)


def f_perpendicular(v, u, M0: float, m: float, k_x: float, radius: float) -> np.ndarray:
    """|F⊥| in N (with the 1/R the paper omits)."""
    v = np.asarray(v, float)
    u = np.abs(np.asarray(u, float))
    den = np.sqrt(u**2 + 0.25 * m * v**2)
    return np.where(den > 0, abs(k_x) * M0 / (2.0 * radius) * u / np.where(den > 0, den, 1.0), 0.0)


def f_parallel_ratio(psi, a: float) -> np.ndarray:
    """F∥/F0 = 1/√(1 + aψ²), ψ = u/v."""
    return 1.0 / np.sqrt(1.0 + a * np.asarray(psi, float) ** 2)


def torque_ratio(upsilon, m: float) -> np.ndarray:
    """M_C/M0 = 1/√(1 + mυ²), υ = v/u."""
    return 1.0 / np.sqrt(1.0 + m * np.asarray(upsilon, float) ** 2)


def f_perpendicular_ratio(upsilon, m: float) -> np.ndarray:
    """F⊥/(k_x M0/2R) = 1/√(1 + mυ²/4), υ = v/u."""
    return 1.0 / np.sqrt(1.0 + 0.25 * m * np.asarray(upsilon, float) ** 2)


def components(vx, vy, wz, *, F0: float, M0: float, a: float, m: float, k_x: float, radius: float):
    """Closed-form force (N) and torque (N·m) components on the tire: (Fx, Fy, Mz).

    ``vx``, ``vy``: sliding velocity of the patch origin (m/s); ``wz``: spin (rad/s);
    ``radius``: R (m), so u = |ω_z| R. Signs, derived from the Coulomb integrals and tested
    against `fepost.friction.exact.friction_resultants`:

    - F∥ acts along −v̂ (Coulomb friction opposes sliding);
    - M_z = −sgn(ω_z)·M_C (the torque opposes the spin);
    - F⊥ acts along y with sign −sgn(ω_z)·sgn(k_x): at pure spin the traction is
      −fσ ê_φ, and a forward pressure shift σ0(1 + k_x x/R) loads the front
      (x > 0), where ê_φ points to +y for ω_z > 0, so F_y = −k_x M0/(2R).

    Examples
    --------
    Pure sliding along x gives −F0 along x, pure spin gives −M0:

    >>> from fepost.friction.closed_form import components
    >>> Fx, Fy, Mz = components([1.0, 0.0], [0.0, 0.0], [0.0, 2.0],
    ...                         F0=3870.0, M0=277.3, a=0.94, m=9.5, k_x=0.0, radius=0.12)
    >>> float(Fx[0]), float(Mz[1])
    (-3870.0, -277.3)
    """
    vx, vy, wz = np.broadcast_arrays(*(np.asarray(q, float) for q in (vx, vy, wz)))
    v = np.hypot(vx, vy)
    u = np.abs(wz) * radius
    fpar = f_parallel(v, u, F0, a)
    safe = np.where(v > 0, v, 1.0)
    fx = -fpar * np.where(v > 0, vx / safe, 0.0)
    fy = -fpar * np.where(v > 0, vy / safe, 0.0)
    spin = np.sign(wz)
    fy = fy - spin * np.sign(k_x) * f_perpendicular(v, u, M0, m, k_x, radius)
    mz = -spin * torque(v, u, M0, m)
    return fx, fy, mz


@dataclass(frozen=True)
class AsymptoticCoefficients:
    """F0 = fN (N), M0 = f∬σ r dA (N·m), a, m (dimensionless) for ``radius`` R (m),
    matched to the exact integrals' asymptotes for sliding along ``direction`` (rad)."""

    F0: float
    M0: float
    a: float
    m: float
    radius: float
    f: float
    direction: float

    def to_dict(self) -> dict:
        return {k: float(getattr(self, k)) for k in ("F0", "M0", "a", "m", "radius", "f", "direction")}


def asymptotic_coefficients(
    quad: PressureQuadrature,
    f: float = DEFAULT_FRICTION,
    *,
    radius: float | None = None,
    direction: float = 0.0,
) -> AsymptoticCoefficients:
    """a and m matched to the asymptotes of the exact integrals.

    Sliding at speed v along v̂ = (cos β, sin β) (β = ``direction``), spinning at ω,
    u = |ω| R; σ-weighted integrals about the patch origin, n̂ = v̂ rotated by +90°:

    - u ≫ v: the ICR sits at p0 = J v/ω, close to the origin, and to first order
      F = −(f/|ω|) S v with S = ∬ σ ê_r ê_rᵀ/r dA, so F∥ = f v/|ω| · T with
      T = v̂ᵀS v̂ = ∬ σ (v̂·ê_r)²/r dA. Matching F0 v/(√a u) gives √a = N / (R T).
      (A patch long along x slides along x with little drag near pure spin: the
      weight is (v̂·ê_r)², along the sliding direction.)
    - v ≫ u: ŵ = v̂ + (ω/v)(v̂·p) n̂ + O(ω²), so M_z = −f(ω/v) ∬ σ (v̂·p)² dA
      (plus −fN x_c × v̂, zero when the origin is the centre of pressure).
      Matching M0 u/(√m v) gives √m = M0 R / (f ∬ σ (v̂·p)² dA).

    For an axisymmetric map, T = π R A⁰ and ∬σ x² dA = π R⁴ A³ while N = 2πR²A¹
    and M0 = 2π f R³ A², so √a = 2A¹/A⁰ and √m = 2A²/A³, the paper's (1.5).
    ``radius`` defaults to ``quad.radius``.
    """
    if not isinstance(quad, PressureQuadrature):
        raise ArgumentError(f"quad must be a PressureQuadrature, got {type(quad).__name__}")
    f = check_friction(f, name="f")
    R = quad.radius if radius is None else radius
    if not (np.isfinite(R) and R > 0):
        raise ArgumentError(f"radius must be a positive finite length in m, got {radius!r}")
    if not np.isfinite(direction):
        raise ArgumentError(f"direction must be a finite angle in rad, got {direction!r}")
    ex, ey = np.cos(direction), np.sin(direction)
    x, y, s, da = quad.x, quad.y, quad.sigma, quad.dA
    r = np.hypot(x, y)
    N = float(s @ da)
    M0 = f * float(s @ (r * da))
    T = _inverse_r_moment(quad, ex, ey)
    second = float(s @ ((ex * x + ey * y) ** 2 * da))
    a = (N / (R * T)) ** 2
    m = (M0 * R / (f * second)) ** 2
    return AsymptoticCoefficients(f * N, M0, float(a), float(m), float(R), float(f), float(direction))


def _inverse_r_moment(quad: PressureQuadrature, nx: float, ny: float) -> float:
    """T = ∬ σ (n̂·ê_r)²/r dA about the origin (N/m), n̂ = (nx, ny).

    The integrand is singular like 1/r at the origin; when the origin lies in the
    domain, σ(0) + ∇σ(0)·p is subtracted and integrated exactly along rays
    (∬ (n̂·ê)²/r dA = ∫ (n̂·ê_θ)² ρ_max dθ; ∬ (G·p)(n̂·ê)²/r dA = ∫ (G·ê)(n̂·ê)² ρ_max²/2 dθ),
    leaving a bounded remainder for the nodes.
    """
    x, y, s, da = quad.x, quad.y, quad.sigma, quad.dA
    r = np.hypot(x, y)
    inv = np.divide(1.0, r, out=np.zeros_like(r), where=r > 0)
    proj2 = (nx * x * inv + ny * y * inv) ** 2
    d = quad.domain
    if d.level(0.0, 0.0) >= 1.0:
        return float(s @ (proj2 * inv * da))
    h = 1e-4 * max(d.ax, d.ay)
    s0 = float(quad.sigma_at(np.array([0.0]), np.array([0.0]))[0])
    gx = float(np.diff(quad.sigma_at(np.array([-h, h]), np.zeros(2)))[0]) / (2 * h)
    gy = float(np.diff(quad.sigma_at(np.zeros(2), np.array([-h, h])))[0]) / (2 * h)
    rem = s - s0 - gx * x - gy * y
    n = 4096
    theta = np.arange(n) * (2.0 * np.pi / n)
    c, sn = np.cos(theta), np.sin(theta)
    rho = d.ray_length(0.0, 0.0, theta)
    pr2 = (nx * c + ny * sn) ** 2
    exact = (2.0 * np.pi / n) * np.sum(pr2 * (s0 * rho + (gx * c + gy * sn) * rho**2 / 2.0))
    return float(rem @ (proj2 * inv * da)) + float(exact)


def paper_coefficients(tensors, f: float, k_x: float = 0.0) -> dict[str, float]:
    """F0, M0, a, m of the paper's definitions for a map's pressure integrals.

    ``tensors``: `MapTensors` (R = ``tensors.radius``).
    With A⁰ = tr S/(2πR), A¹ = N/(2πR²), A² = ∬σ r dA/(2πR³), A³ = tr Q/(2πR⁴)
    (the angular means of the same integrals), √a = 2A¹/A⁰ and √m = 2A²/A³:
    a = (2N/(R tr S))², m = (2R ∬σ r dA/tr Q)². ``k_x`` is passed through.
    """
    R = tensors.radius
    a = (2.0 * tensors.N / (R * float(np.trace(tensors.inverse)))) ** 2
    m = (2.0 * R * tensors.polar / float(np.trace(tensors.second))) ** 2
    return {"F0": f * tensors.N, "M0": f * tensors.polar, "a": a, "m": m, "k_x": float(k_x), "radius": R}


def paper_model(F0: float, M0: float, a: float, m: float, k_x: float, radius: float):
    """The closed forms as a callable (vx, vy, wz) → (Fx, Fy, Mz), like the generalised model."""

    def predict(vx, vy, wz):
        return components(vx, vy, wz, F0=F0, M0=M0, a=a, m=m, k_x=k_x, radius=radius)

    return predict
