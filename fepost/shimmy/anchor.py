"""The outside anchor: Somieski's simple nose landing gear with a stretched-string tire.

G. Somieski, "Shimmy analysis of a simple aircraft nose landing gear model using
different mathematical methods", Aerospace Science and Technology 1(8):545–555
(1997); the same model and parameter table are the starting point of Thota,
Krauskopf and Lowenberg, "Interaction of torsion and lateral bending in aircraft
nose landing gear shimmy", Nonlinear Dynamics 57:455–467 (2009). One torsional
degree of freedom ψ (yaw of the wheel about the strut) and the lateral
deflection y of the tire's leading contact point (von Schlippe's stretched
string, relaxation length σ, straight-tangent approximation):

    I_z ψ̈ = c ψ + k ψ̇ + M_α(α) − e F_y(α) + (κ/V) ψ̇
    ẏ = V ψ + (e − a) ψ̇ − (V/σ) y,      α = y/σ,

with Somieski's sign convention (c, k, κ negative: restoring and dissipative).
Linear tire: F_y = c_Fα F_z α, M_α = c_Mα F_z α. The nonlinear model saturates
F_y at |α| = δ and lets M_α follow F_z c_Mα (α_g/π) sin(πα/α_g) up to α_g, zero beyond.

The linear characteristic polynomial, with D = −k − κ/V, C = −c and
Q = F_z (e c_Fα − c_Mα)/σ:

    I_z s³ + (I_z V/σ + D) s² + (D V/σ + C + Q (e − a)) s + (C/σ + Q) V = 0.

Routh–Hurwitz: the straight rolling is stable iff the coefficients are positive
and a₂ a₁ > a₃ a₀; multiplied by V, a₂a₁ − a₃a₀ is a cubic in V whose positive
roots are the critical speeds (`routh_hurwitz_speeds`), a closed form
independent of the eigenvalues of the state matrix (`eigen_critical_speeds`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

#: Reference of the anchor.
REFERENCE = (
    "G. Somieski, Shimmy analysis of a simple aircraft nose landing gear model using different "
    "mathematical methods, Aerospace Science and Technology 1(8):545-555, 1997 (parameter table as "
    "reproduced by Thota, Krauskopf and Lowenberg, Nonlinear Dynamics 57:455-467, 2009)"
)


@dataclass(frozen=True)
class SomieskiGear:
    """Somieski's parameter table (SI; c, k, κ negative in his convention)."""

    a: float = 0.1  # half contact length, m
    e: float = 0.1  # caster length, m
    Iz: float = 1.0  # moment of inertia about the strut, kg m^2
    Fz: float = 9000.0  # vertical force, N
    c: float = -100000.0  # torsional spring rate, N m/rad
    cFa: float = 20.0  # side-force derivative, 1/rad
    cMa: float = -2.0  # aligning-moment derivative, m/rad
    k: float = -50.0  # torsional damping, N m s/rad (his range 0 ... -50)
    kappa: float = -270.0  # tread-width moment constant, N m^2/rad
    sigma: float = 0.3  # relaxation length, m
    delta: float = np.radians(5.0)  # side-force saturation angle, rad
    alpha_g: float = np.radians(10.0)  # sliding limit of the aligning moment, rad

    def with_damping(self, k: float) -> SomieskiGear:
        return replace(self, k=k)

    def to_dict(self) -> dict:
        return {key: float(v) for key, v in asdict(self).items()}


def state_matrix(p: SomieskiGear, V: float) -> np.ndarray:
    """The linear model's matrix for the state (ψ, ψ̇, y) at speed V."""
    q = p.Fz * (p.cMa - p.e * p.cFa) / p.sigma  # tire torque per metre of y
    return np.array(
        [
            [0.0, 1.0, 0.0],
            [p.c / p.Iz, (p.k + p.kappa / V) / p.Iz, q / p.Iz],
            [V, p.e - p.a, -V / p.sigma],
        ]
    )


def _hurwitz_cubic(p: SomieskiGear) -> np.ndarray:
    """Coefficients (highest power first) of V (a₂a₁ − a₃a₀) as a cubic in V."""
    Q = p.Fz * (p.e * p.cFa - p.cMa) / p.sigma
    d0, d1, C = -p.k, -p.kappa, -p.c
    # V a2 = Iz V²/σ + d0 V + d1 ;  a1 = d0 V/σ + (d1/σ + C + Q (e − a)) ;  V a0 = (C/σ + Q) V²
    va2 = np.array([p.Iz / p.sigma, d0, d1])
    a1 = np.array([d0 / p.sigma, d1 / p.sigma + C + Q * (p.e - p.a)])
    return np.polysub(np.polymul(va2, a1), [p.Iz * (C / p.sigma + Q), 0.0, 0.0])


def routh_hurwitz_speeds(p: SomieskiGear) -> tuple[float, ...]:
    """Critical speeds (m/s) by the Routh–Hurwitz closed form: positive real roots of the cubic."""
    roots = np.roots(_hurwitz_cubic(p))
    real = roots[np.abs(roots.imag) <= 1e-9 * np.maximum(1.0, np.abs(roots.real))].real
    return tuple(sorted(float(r) for r in real if r > 0))


def growth(p: SomieskiGear, V: float) -> tuple[float, float]:
    """(largest real part of the eigenvalues in 1/s, its frequency in Hz) at speed V."""
    ev = np.linalg.eigvals(state_matrix(p, V))
    i = int(np.argmax(ev.real))
    return float(ev[i].real), float(abs(ev[i].imag) / (2 * np.pi))


def eigen_critical_speeds(p: SomieskiGear, lo: float = 0.5, hi: float = 300.0, n: int = 600):
    """Critical speeds (m/s) and frequencies (Hz) where the largest real part changes sign."""
    from scipy.optimize import brentq

    speeds = np.linspace(lo, hi, n)
    g = np.array([growth(p, V)[0] for V in speeds])
    out = []
    for i in np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]:
        v = brentq(lambda s: growth(p, s)[0], speeds[i], speeds[i + 1], xtol=1e-12)
        out.append((float(v), growth(p, v)[1]))
    return tuple(out)


def nonlinear_rhs(p: SomieskiGear, V: float):
    """The nonlinear model's f(t, x), x = (ψ, ψ̇, y) (module docstring)."""

    def f(t, x):
        psi, dpsi, y = x
        alpha = np.arctan(y / p.sigma)
        fy = p.cFa * p.Fz * (alpha if abs(alpha) <= p.delta else p.delta * np.sign(alpha))
        if abs(alpha) <= p.alpha_g:
            ma = p.Fz * p.cMa * p.alpha_g / np.pi * np.sin(np.pi * alpha / p.alpha_g)
        else:
            ma = 0.0
        ddpsi = (p.c * psi + p.k * dpsi + ma - p.e * fy + p.kappa / V * dpsi) / p.Iz
        dy = V * np.sin(psi) + (p.e - p.a) * dpsi * np.cos(psi) - V / p.sigma * y * np.cos(psi)
        return [dpsi, ddpsi, dy]

    return f


def anchor_record(p: SomieskiGear | None = None) -> dict:
    """The ``anchor`` entry of shimmy.json: reference, published inputs, computed critical speeds."""
    p = SomieskiGear() if p is None else p
    cases = []
    for k in (0.0, -20.0, -50.0):
        q = p.with_damping(k)
        eig = eigen_critical_speeds(q)
        cases.append(
            {
                "k": k,
                "critical_speed_eigenvalues": [v for v, _ in eig],
                "frequency_hz": [f for _, f in eig],
                "critical_speed_routh_hurwitz": list(routh_hurwitz_speeds(q)),
            }
        )
    return {
        "reference": REFERENCE,
        "published": {
            "parameters": p.to_dict(),
            "critical_speed": None,
            "note": (
                "Somieski gives the stability boundary as a curve in the speed x torsional-damping "
                "plane; no printed critical value was available to fepost, so the computed values are "
                "checked against the independent Routh-Hurwitz closed form instead"
            ),
        },
        "computed": {"cases": cases},
    }
