"""Friction-model coefficients from the moments (docs/theory.md, "Integrals of the
pressure"; paper 1.2, 1.4–1.6).

    F0 = 2π f R² A¹ = f N          M0 = 2π f R³ A² = f ∬σ0 r dA
    √a = 2A¹/A⁰                     √m = 2A²/A³        b = m/4     b1 = M0/2
    k_x = R · x_c / ⟨x²⟩             (x_c: centre of pressure of the rolling map)

a, m and k_x depend on R (reported as ``R``); aR², m/R² and k_x/R do not.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._arrays import frozen
from .errors import ArgumentError
from .friction_coefficient import DEFAULT_FRICTION, check_friction
from .moments import Moments


@dataclass(frozen=True)
class Coefficients:
    """The coupled dry-friction model's coefficients, SI units.

    ``N`` (N), ``R`` (m), ``A`` (Pa), ``F0`` (N), ``M0`` (N·m), ``a``, ``m``,
    ``b`` (dimensionless with R as given), ``b1`` (N·m), ``f``; ``k_x`` and
    ``x_c`` (m) when a rolling map was given.
    """

    N: float
    R: float
    A: np.ndarray
    F0: float
    M0: float
    a: float
    m: float
    b: float
    b1: float
    f: float
    k_x: float | None = None
    x_c: float | None = None
    N_rolling: float | None = None
    extra: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "A", frozen(self.A))

    def to_dict(self) -> dict:
        d = {
            "N": self.N,
            "R": self.R,
            "A": [float(v) for v in self.A],
            "F0": self.F0,
            "M0": self.M0,
            "a": self.a,
            "m": self.m,
            "b": self.b,
            "b1": self.b1,
            "f": self.f,
            "aR2": self.a * self.R**2,
            "m_over_R2": self.m / self.R**2,
        }
        if self.k_x is not None:
            d.update(
                {
                    "k_x": self.k_x,
                    "x_c": self.x_c,
                    "N_rolling": self.N_rolling,
                    "k_x_over_R": self.k_x / self.R,
                }
            )
        d.update(self.extra)
        return d


def coefficients_from_moments(
    static: Moments, rolling: Moments | None = None, friction: float = DEFAULT_FRICTION
) -> Coefficients:
    """Coefficients from the static map's moments (and the rolling map's, for k_x)."""
    friction = check_friction(friction)
    R = static.radius
    A = static.A
    if not (A[0] > 0 and A[3] > 0):
        raise ArgumentError("the static map has no load (A⁰ or A³ is zero)")
    F0 = 2.0 * np.pi * friction * R**2 * A[1]
    M0 = 2.0 * np.pi * friction * R**3 * A[2]
    a = (2.0 * A[1] / A[0]) ** 2
    m = (2.0 * A[2] / A[3]) ** 2
    k_x = x_c = n_roll = None
    if rolling is not None:
        x_c = rolling.centroid[0]
        k_x = R * x_c / static.x2
        n_roll = rolling.N
    return Coefficients(
        N=static.N,
        R=R,
        A=A,
        F0=F0,
        M0=M0,
        a=a,
        m=m,
        b=m / 4.0,
        b1=M0 / 2.0,
        f=friction,
        k_x=k_x,
        x_c=x_c,
        N_rolling=n_roll,
    )
