"""The integrals of a pressure map that fix the friction resultants' limits exactly.

Under Coulomb's law the resultants of a map σ(x, y) near pure spin and near pure
sliding (every direction) are set by a handful of pressure integrals about the
patch origin (p = (x, y), r = |p|, ê_r = p/r, ê_φ = (−sin φ, cos φ)):

=================== ====================================== ======== =====================================
name                integral                               unit     what it fixes
=================== ====================================== ======== =====================================
``N``               ∬ σ dA                                 N        force at pure sliding, f N
``first``           ∬ σ p dA  (= N x_c)                    N·m      torque at pure sliding, −f N x_c × v̂
``second``          ∬ σ p pᵀ dA  (Q)                       N·m²     torque slope at pure sliding (m)
``polar``           ∬ σ r dA                               N·m      torque at pure spin, M0 = f ∬σ r dA
``inverse``         ∬ σ ê_r ê_rᵀ / r dA  (S)               N/m      force slope at pure spin (a)
``radial``          ∬ σ ê_r dA                             N        force at pure spin, −f ∬σ ê_φ dA
``cos2_r``          ∬ σ r cos² φ dA                        N·m      anisotropic torque at pure spin
``cross``           ∬ σ cos φ sin φ ê_φ dA                 N        its slope in small sliding
=================== ====================================== ======== =====================================

``inverse`` and ``radial`` have integrands that are singular (1/r) or
discontinuous (ê_r) at the origin. When the origin lies inside the quadrature's
domain, σ(0) + ∇σ(0)·p is subtracted from σ on the nodes and its integral added
back exactly along rays from the origin (ρ_max(φ) the distance to the domain
boundary): ∬ (σ0 + G·p) K(φ) r^k dA = ∫ K(φ) [σ0 ρ_max^{k+2}/(k+2) + (G·ê_r) ρ_max^{k+3}/(k+3)] dφ.
This is the same subtraction the exact integrals use at the instantaneous centre
of rotation (`fepost.friction.exact`); it keeps the integrals accurate on
quadratures not centred on the origin (shifted or rolling maps).

`effective_quadrature` folds a pressure-dependent friction coefficient into
the pressure (μσ/f), so everything here holds for that law as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError
from .law import FrictionLaw
from .quadrature import PressureQuadrature

#: Trapezoid nodes in φ for the analytic part of the subtraction (ρ_max is smooth
#: and periodic, so the rule converges spectrally; 4096 is far past round-off).
RAY_NODES = 4096
#: Finite-difference step for ∇σ at the origin, relative to the larger semi-axis.
FD_STEP = 1e-4


@dataclass(frozen=True)
class MapTensors:
    """Pressure integrals of one map about the patch origin (see the module docstring).

    ``radius`` R (m) is the scale the model's dimensionless coefficients use.
    Arrays are read-only: ``first`` (2,), ``second`` (2, 2), ``inverse`` (2, 2),
    ``radial`` (2,), ``cross`` (2,).
    """

    N: float
    radius: float
    first: np.ndarray
    second: np.ndarray
    polar: float
    inverse: np.ndarray
    radial: np.ndarray
    cos2_r: float
    cross: np.ndarray

    def __post_init__(self) -> None:
        for name in ("first", "second", "inverse", "radial", "cross"):
            object.__setattr__(self, name, frozen(getattr(self, name)))
        for name in ("N", "radius", "polar", "cos2_r"):
            object.__setattr__(self, name, float(getattr(self, name)))
        if not (self.N > 0 and np.isfinite(self.N)):
            raise ArgumentError(f"the map carries no load (N = {self.N!r} N)")

    @property
    def centre(self) -> np.ndarray:
        """x_c = ``first``/N (m): the centre of pressure relative to the origin."""
        return frozen(self.first / self.N)

    def to_dict(self) -> dict:
        return {
            "N": self.N,
            "radius": self.radius,
            "first": self.first.tolist(),
            "second": self.second.tolist(),
            "polar": self.polar,
            "inverse": self.inverse.tolist(),
            "radial": self.radial.tolist(),
            "cos2_r": self.cos2_r,
            "cross": self.cross.tolist(),
            "units": {
                "N": "N",
                "radius": "m",
                "first": "N m",
                "second": "N m^2",
                "polar": "N m",
                "inverse": "N/m",
                "radial": "N",
                "cos2_r": "N m",
                "cross": "N",
            },
        }


def effective_quadrature(quad: PressureQuadrature, law: FrictionLaw) -> PressureQuadrature:
    """``quad`` with σ replaced by μ(σ, |w| = 0)·σ/f (Pa), the pressure Coulomb's law
    with the plain coefficient f would need to give the same tractions.

    The identity when the law has no pressure dependence. A speed-dependent law has
    no such equivalent (its resultants depend on the speed, not only on the
    direction of the kinematics): `ArgumentError`.
    """
    if not isinstance(quad, PressureQuadrature):
        raise ArgumentError(f"quad must be a PressureQuadrature, got {type(quad).__name__}")
    if not isinstance(law, FrictionLaw):
        raise ArgumentError(f"law must be a FrictionLaw, got {type(law).__name__}")
    if law.depends_on_speed:
        raise ArgumentError(
            "law has speed_coef != 0: a speed-dependent friction coefficient makes the "
            "resultants depend on the speed, not only on the direction of (vx, vy, wz R)"
        )
    if law.pressure_coef == 0.0:
        return quad
    ref = law.reference_pressure(quad.mean_pressure)
    inner = quad.sigma_at

    def sigma_at(px, py):
        s = np.asarray(inner(px, py), float)
        return law.pressure_factor(s, ref) * s

    return PressureQuadrature(
        x=quad.x,
        y=quad.y,
        dA=quad.dA,
        sigma=law.pressure_factor(quad.sigma, ref) * quad.sigma,
        domain=quad.domain,
        sigma_at=sigma_at,
        source=f"{quad.source} mu(sigma)".strip(),
        polar=quad.polar,
    )


def _origin_linearisation(quad: PressureQuadrature) -> tuple[float, float, float]:
    """σ(0) (Pa) and ∇σ(0) (Pa/m) by central differences of ``sigma_at``."""
    d = quad.domain
    h = FD_STEP * max(d.ax, d.ay)
    s0 = float(np.asarray(quad.sigma_at(np.zeros(1), np.zeros(1)), float)[0])
    grads = []
    for ex, ey in ((h, 0.0), (0.0, h)):
        ip = bool(d.level(ex, ey) < 1.0)
        im = bool(d.level(-ex, -ey) < 1.0)
        gp = float(np.asarray(quad.sigma_at(np.array([ex]), np.array([ey])), float)[0]) if ip else s0
        gm = float(np.asarray(quad.sigma_at(np.array([-ex]), np.array([-ey])), float)[0]) if im else s0
        span = h * (int(ip) + int(im))
        grads.append((gp - gm) / span if span else 0.0)
    return s0, grads[0], grads[1]


def _moment(quad: PressureQuadrature, kernel, power: int) -> np.ndarray:
    """∬ σ K(φ) r^power dA for a kernel K(cos φ, sin φ) -> (n, k) array (power ≥ −1).

    With subtraction of σ(0) + ∇σ(0)·p when the origin lies in the domain.
    """
    x, y, s, da = quad.x, quad.y, quad.sigma, quad.dA
    r = np.hypot(x, y)
    inv = np.divide(1.0, r, out=np.zeros_like(r), where=r > 0)
    c, sn = x * inv, y * inv
    k = np.asarray(kernel(c, sn), float)
    rp = r**power if power >= 0 else inv ** (-power)
    d = quad.domain
    if d.level(0.0, 0.0) >= 1.0:
        return (s * rp * da) @ k
    s0, gx, gy = _origin_linearisation(quad)
    rem = s - s0 - gx * x - gy * y
    nodes = (rem * rp * da) @ k
    theta = np.arange(RAY_NODES) * (2.0 * np.pi / RAY_NODES)
    ct, st = np.cos(theta), np.sin(theta)
    rho = d.ray_length(0.0, 0.0, theta)
    kt = np.asarray(kernel(ct, st), float)
    radial = s0 * rho ** (power + 2) / (power + 2) + (gx * ct + gy * st) * rho ** (power + 3) / (power + 3)
    exact = (2.0 * np.pi / RAY_NODES) * (radial @ kt)
    return nodes + exact


def map_tensors(quad: PressureQuadrature, radius: float | None = None) -> MapTensors:
    """The pressure integrals of ``quad`` about the patch origin (module docstring).

    ``radius``: R (m) the dimensionless coefficients will use (default ``quad.radius``).
    """
    if not isinstance(quad, PressureQuadrature):
        raise ArgumentError(f"quad must be a PressureQuadrature, got {type(quad).__name__}")
    R = quad.radius if radius is None else radius
    if isinstance(R, bool) or not (np.isfinite(R) and R > 0):
        raise ArgumentError(f"radius must be a positive finite length in m, got {radius!r}")
    x, y, s, da = quad.x, quad.y, quad.sigma, quad.dA
    w = s * da
    second = np.array([[w @ (x * x), w @ (x * y)], [w @ (x * y), w @ (y * y)]])
    inverse = _moment(quad, lambda c, sn: np.stack([c * c, c * sn, sn * sn], -1), -1)
    radial = _moment(quad, lambda c, sn: np.stack([c, sn], -1), 0)
    cross = _moment(quad, lambda c, sn: np.stack([-c * sn * sn, c * c * sn], -1), 0)
    return MapTensors(
        N=float(w.sum()),
        radius=float(R),
        first=np.array([w @ x, w @ y]),
        second=second,
        polar=float(w @ np.hypot(x, y)),
        inverse=np.array([[inverse[0], inverse[1]], [inverse[1], inverse[2]]]),
        radial=radial,
        cos2_r=float(w @ np.divide(x * x, np.hypot(x, y), out=np.zeros_like(x), where=(x != 0) | (y != 0))),
        cross=cross,
    )
