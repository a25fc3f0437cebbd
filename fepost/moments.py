"""Integrals of a polar pressure map (docs/theory.md, "Integrals of the
pressure"; paper 1.1, 1.2, 1.5).

All moments are about the map's centre (the static centre of pressure):

* ``N`` = ∬ σ dA (N)
* ``A[k]`` = ∫₀¹ σ̄(ρ) ρᵏ dρ, k = 0…3 (Pa), σ̄ the angular mean
* ``centroid`` = ∬ σ (x, y) dA / N (m)
* ``x2`` = ⟨x²⟩ = ∬ σ x² dA / N (m²)
* ``spin`` = ∬ σ r dA (N·m), so that M0 = f · spin
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._arrays import frozen
from .polar import PolarMap


@dataclass(frozen=True)
class Moments:
    N: float
    A: np.ndarray
    centroid: tuple[float, float]
    x2: float
    spin: float
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "A", frozen(self.A))

    def to_dict(self) -> dict:
        return {
            "N": self.N,
            "A": [float(a) for a in self.A],
            "centroid": list(self.centroid),
            "x2": self.x2,
            "spin": self.spin,
            "R": self.radius,
        }


def moments(pmap: PolarMap) -> Moments:
    """Integrals of ``pmap`` about its centre, with R = ``pmap.radius``."""
    g = pmap.grid
    sbar = pmap.angular_mean()
    A = np.array([np.sum(sbar * g.rho**k * g.w_rho) for k in range(4)])
    x, y = pmap.xy()
    N = pmap.integrate()
    r = np.hypot(x, y)
    if N > 0:
        cen = (pmap.integrate(x) / N, pmap.integrate(y) / N)
        x2 = pmap.integrate(x * x) / N
    else:
        cen, x2 = (0.0, 0.0), 0.0
    return Moments(
        N=N,
        A=A,
        centroid=(float(cen[0]), float(cen[1])),
        x2=float(x2),
        spin=pmap.integrate(r),
        radius=pmap.radius,
    )
