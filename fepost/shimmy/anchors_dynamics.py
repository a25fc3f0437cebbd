"""Outside anchors of the dynamics with dry friction and of shimmy (docs/dynamics-anchors.md), reproduced.

* `disc_epsilon`: a flat disc sliding and spinning on a plane under coupled Coulomb
  friction stops sliding and spinning together, with ε = v/(Rω) tending to the
  root of F(ε) R / M(ε) = ε m R² / I (Farkas, Bartels, Unger and Wolf, PRL 90,
  248302, 2003; Weidman and Malhotra, PRL 95, 264303, 2005: 0.653 for a homogeneous
  disc, 1 for a ring). Two ways, for any contact (exact integrals, closed forms,
  generalised model, FE map): the root, and the time integration of m v̇ = −F,
  I ω̇ = −M read near the stop (`disc_stop`). On an FE map the body's mass is
  spread as its pressure (`pressure_inertia_ratio`), as the homogeneous disc's and
  the ring's are, and it slides along the rolling direction x.
* `towed_wheel_*`: Schwab and Meijaard's towed rigid body on a rigid non-holonomic
  wheel (Multibody System Dynamics 10, 2003, 107–123): the published characteristic
  polynomial, and the eigenvalues of the constrained equations written out here
  (Newton–Euler with the wheel's side force as the multiplier): stable iff ab > r²,
  the band 0.3 < a/l < 0.7 for r² = 0.21 l².
* `somieski_*`: the values computed independently for Somieski's nose gear
  (cross-checks, not published numbers) from `fepost.shimmy.anchor`'s model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from .brush import sliding_point_forces

#: The published terminal ratios ε (homogeneous disc, ring).
PUBLISHED_EPSILON = {"homogeneous": 0.653, "ring": 1.0}


def ring_forces(vx, vy, wz, *, R: float = 1.0, f: float = 0.3, N: float = 1.0, nodes: int = 4096):
    """Exact Coulomb resultants of a ring of radius R (all pressure on the rim), by the midpoint rule."""
    phi = (np.arange(nodes) + 0.5) * 2 * np.pi / nodes
    x, y = R * np.cos(phi), R * np.sin(phi)
    return sliding_point_forces(x, y, np.full(nodes, f * N / nodes), vx, vy, wz)


def closed_form_disc(profile: str, *, R: float = 1.0, f: float = 0.3, N: float = 1.0):
    """The paper's closed forms for a uniform disc (a = 1, m = 64/9, M0 = 2/3 f N R) or a ring
    (√a = 2A¹/A⁰ = 2, √m = 2A²/A³ = 2, M0 = f N R): a contact function (vx, vy, wz) -> forces."""
    from .contact import closed_form_forces

    coef = {"uniform": (1.0, 64.0 / 9.0, 2.0 / 3.0), "ring": (4.0, 4.0, 1.0)}
    if profile not in coef:
        raise ArgumentError(f"profile must be 'uniform' or 'ring', got {profile!r}")
    a, m, m0 = coef[profile]

    def forces(vx, vy, wz):
        return closed_form_forces(vx, vy, wz, F0=f * N, M0=m0 * f * N * R, a=a, m=m, k_x=0.0, R=R)

    return forces


def disc_epsilon(forces, R: float, inertia_ratio: float, lo: float = 1e-3, hi: float = 20.0) -> float:
    """The root ε of F(ε) R / M(ε) = ε m R² / I (``inertia_ratio`` = I/(m R²)), sliding along x."""
    from scipy.optimize import brentq

    def g(eps):
        fx, _, mz = forces(np.array([eps * R]), np.array([0.0]), np.array([1.0]))
        return float(-fx[0]) * R - eps / inertia_ratio * float(-mz[0])

    return float(brentq(g, lo, hi, xtol=1e-12))


def pressure_inertia_ratio(quad) -> float:
    """I/(m R²) of a flat body whose mass is spread as its contact pressure (R: the patch radius):
    ⟨r²⟩/R² = ∬σ r² dA / (N R²); 1/2 for the homogeneous disc, 1 for the ring."""
    r2 = float(np.sum(quad.sigma * quad.dA * (quad.x**2 + quad.y**2)) / quad.load)
    return r2 / quad.radius**2


@dataclass(frozen=True)
class DiscStop:
    """A time integration of the sliding, spinning disc to (near) its stop."""

    epsilon: float  # v/(Rω) at the end
    t_stop: float  # s, the extrapolated stop of both motions
    v_left: float  # v at the end over v at the start
    w_left: float


def disc_stop(forces, R: float, inertia_ratio: float, *, eps0: float = 0.2, f: float = 0.3, g: float = 9.81):
    """Integrate m v̇ = −F, I ω̇ = −M (unit mass, load m g, from v = ε0 R ω0, R ω0 = 1 m/s) until
    the motion is 1e-6 of its start; ``forces`` at the load N = 1 (scaled by m g)."""
    from scipy.integrate import solve_ivp

    def rhs(t, s):
        v, w = s
        if v <= 0 and w <= 0:
            return [0.0, 0.0]
        fx, _, mz = forces(np.array([max(v, 0.0)]), np.array([0.0]), np.array([max(w, 0.0)]))
        return [float(fx[0]) * g, float(mz[0]) * g / (inertia_ratio * R * R)]

    def small(t, s):
        return math.hypot(s[0], R * s[1]) - 1e-6 * math.hypot(eps0, 1.0)

    small.terminal = True  # type: ignore[attr-defined]
    s0 = [eps0, 1.0 / R]
    sol = solve_ivp(rhs, (0.0, 10.0), s0, method="DOP853", rtol=1e-11, atol=1e-15, events=small)
    v, w = sol.y[:, -1]
    return DiscStop(float(v / (R * w)), float(sol.t[-1]), float(v / s0[0]), float(w / s0[1]))


# -- the towed rigid wheel ---------------------------------------------------------------


def towed_wheel_polynomial(a: float, b: float, r2: float, u: float, k: float, m: float) -> np.ndarray:
    """The published characteristic polynomial's coefficients (λ³ first)."""
    l_ = a + b
    mu = (a * b - r2) / (a * a + r2)
    wn2 = k * l_ * l_ / (m * (a * a + r2))
    return np.array([1.0, (1 + mu) * u / l_, wn2, u / l_ * wn2])


def towed_wheel_matrix(a: float, b: float, r2: float, u: float, k: float, m: float) -> np.ndarray:
    """State matrix of the constrained towed body, state (Y, θ, θ̇).

    Body: lateral position Y of the centre of mass, yaw θ, forward speed u. The spring
    k acts at b ahead: −k (Y + b θ). The wheel, a behind, has no side slip:
    Ẏ − a θ̇ − u θ = 0, its side force λ the multiplier. m Ÿ = −k (Y + bθ) + λ and
    m r² θ̈ = −k b (Y + bθ) − a λ, with Ÿ = a θ̈ + u θ̇, give
    m (r² + a²) θ̈ = −k (a + b)(Y + b θ) − a m u θ̇.
    """
    den = m * (r2 + a * a)
    return np.array(
        [
            [0.0, u, a],
            [0.0, 0.0, 1.0],
            [-k * (a + b) / den, -k * (a + b) * b / den, -a * m * u / den],
        ]
    )


def towed_wheel_band(
    r2: float = 0.21, l_: float = 1.0, u: float = 1.0, k: float = 1.5, m: float = 5.0, n: int = 2001
):
    """(lowest, highest) a/l where the constrained body's eigenvalues all have negative real parts."""
    ratios = np.linspace(0.0, 1.0, n)[1:-1]
    stable = [
        np.max(np.linalg.eigvals(towed_wheel_matrix(q * l_, (1 - q) * l_, r2 * l_**2, u, k, m)).real) < 0
        for q in ratios
    ]
    inside = ratios[np.array(stable)]
    return float(inside.min()), float(inside.max())


# -- Somieski's nose gear: the independent values (cross-checks) --------------------------


def somieski_damping_needed(V: float, lo: float = -200.0, hi: float = 0.0) -> float:
    """The torsional damping k (N m s/rad, Somieski's sign) at which the gear is neutral at speed V."""
    from scipy.optimize import brentq

    from .anchor import SomieskiGear, growth

    p = SomieskiGear()
    return float(brentq(lambda k: growth(p.with_damping(k), V)[0], lo, hi, xtol=1e-12))


def somieski_peak_damping(lo: float = 60.0, hi: float = 150.0) -> tuple[float, float]:
    """(speed m/s, damping N m s/rad) where the damping needed is largest in magnitude."""
    from scipy.optimize import minimize_scalar

    res = minimize_scalar(somieski_damping_needed, bounds=(lo, hi), method="bounded", options={"xatol": 1e-6})
    return float(res.x), float(res.fun)
