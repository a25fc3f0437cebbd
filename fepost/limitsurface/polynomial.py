"""Homogeneous polynomials in three variables: the limit surfaces of planar sliding.

A planar contact that slides and spins quasi-statically under a wrench
w = (F_x, F_y, M_z/ρ) (ρ a length that gives the torque force units) moves with
a twist t = (v_x, v_y, ω_z ρ). Goyal, Ruina and Papadopoulos's limit surface is
the set of wrenches that make the contact slide, H(w) = 1 with H convex; by the
maximum-dissipation principle the twist is normal to it, t ∝ ∇H(w).

Two families are used (both even and homogeneous, so H(−w) = H(w) and the
surface is a level set of a gauge):

* degree 2: H = wᵀ A w, A symmetric positive definite (6 coefficients): the
  ellipsoid of Lee & Cutkosky and Howe & Cutkosky;
* degree 4: H = Σ a_ijk w_x^i w_y^j w_z^k over the 15 monomials with
  i + j + k = 4: the convex quartic of Zhou, Paolini, Bagnell & Mason (2016).

`HomogeneousPolynomial` evaluates H, ∇H and ∇²H of either degree; all three
are linear in the coefficients, which is what the fit (`fepost.limitsurface.fit`)
uses.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError

#: Degrees a limit surface may have here (the ellipsoid and the quartic).
DEGREES = (2, 4)


@cache
def exponents(degree: int) -> np.ndarray:
    """The exponents (i, j, k), i + j + k = ``degree``, of the monomials, (K, 3), in a fixed order."""
    if degree not in DEGREES:
        raise ArgumentError(f"degree must be one of {DEGREES}, got {degree!r}")
    rows = [(i, j, degree - i - j) for i in range(degree, -1, -1) for j in range(degree - i, -1, -1)]
    out = np.array(rows, int)
    out.setflags(write=False)
    return out


def _powers(w: np.ndarray, degree: int) -> np.ndarray:
    """w[..., c] ** p for p = 0..degree: (..., 3, degree + 1)."""
    return w[..., :, None] ** np.arange(degree + 1)


def monomials(w, degree: int) -> np.ndarray:
    """The monomials at the points ``w`` (..., 3): (..., K)."""
    w = np.asarray(w, float)
    e = exponents(degree)
    p = _powers(w, degree)
    return p[..., 0, e[:, 0]] * p[..., 1, e[:, 1]] * p[..., 2, e[:, 2]]


def monomial_gradients(w, degree: int) -> np.ndarray:
    """∂m_k/∂w_c at the points ``w`` (..., 3): (..., 3, K)."""
    w = np.asarray(w, float)
    e = exponents(degree)
    p = _powers(w, degree)
    out = []
    for c in range(3):
        factor = np.ones(e.shape[0])
        terms = []
        for d in range(3):
            k = e[:, d] - (1 if d == c else 0)
            if d == c:
                factor = e[:, d].astype(float)
            terms.append(p[..., d, np.maximum(k, 0)])
        out.append(factor * terms[0] * terms[1] * terms[2])
    return np.stack(out, axis=-2)


def monomial_hessians(w, degree: int) -> np.ndarray:
    """∂²m_k/∂w_a∂w_b at the points ``w`` (..., 3): (..., 3, 3, K)."""
    w = np.asarray(w, float)
    e = exponents(degree)
    p = _powers(w, degree)
    shape = w.shape[:-1] + (3, 3, e.shape[0])
    out = np.zeros(shape)
    for a in range(3):
        for b in range(a, 3):
            k = e.copy()
            k[:, a] -= 1
            k[:, b] -= 1
            factor = e[:, a] * (e[:, b] - (1 if a == b else 0)).astype(float)
            term = factor * p[..., 0, np.maximum(k[:, 0], 0)] * p[..., 1, np.maximum(k[:, 1], 0)]
            term = term * p[..., 2, np.maximum(k[:, 2], 0)]
            term = np.where(np.all(k >= 0, axis=1), term, 0.0)
            out[..., a, b, :] = term
            out[..., b, a, :] = term
    return out


@dataclass(frozen=True)
class HomogeneousPolynomial:
    """H(w) = Σ_k ``coefficients``[k] m_k(w) of ``degree`` 2 or 4 (monomials in `exponents` order)."""

    degree: int
    coefficients: np.ndarray

    def __post_init__(self) -> None:
        e = exponents(self.degree)
        c = frozen(np.asarray(self.coefficients, float).ravel())
        if c.size != e.shape[0] or not np.all(np.isfinite(c)):
            raise ArgumentError(
                f"coefficients must be {e.shape[0]} finite numbers for degree {self.degree}, got {c.size}"
            )
        object.__setattr__(self, "coefficients", c)

    @classmethod
    def quadratic(cls, A) -> HomogeneousPolynomial:
        """wᵀ A w for a symmetric 3 × 3 ``A``."""
        A = np.asarray(A, float)
        if A.shape != (3, 3) or not np.allclose(A, A.T, rtol=1e-12, atol=0.0):
            raise ArgumentError(f"A must be a symmetric 3 x 3 matrix, got shape {A.shape}")
        coef = [A[a, b] * (1.0 if a == b else 2.0) for a, b in (_pair(e) for e in exponents(2))]
        return cls(2, np.array(coef))

    def matrix(self) -> np.ndarray:
        """A of a degree-2 polynomial (H = wᵀ A w)."""
        if self.degree != 2:
            raise ArgumentError(f"matrix() needs degree 2, got {self.degree}")
        A = np.zeros((3, 3))
        for c, e in zip(self.coefficients, exponents(2), strict=True):
            a, b = _pair(e)
            A[a, b] = A[b, a] = c if a == b else 0.5 * c
        return A

    def value(self, w) -> np.ndarray:
        return monomials(w, self.degree) @ self.coefficients

    def gradient(self, w) -> np.ndarray:
        return monomial_gradients(w, self.degree) @ self.coefficients

    def hessian(self, w) -> np.ndarray:
        return monomial_hessians(w, self.degree) @ self.coefficients


def _pair(e) -> tuple[int, int]:
    """The two variables of a degree-2 monomial's exponents."""
    idx = [c for c in range(3) for _ in range(int(e[c]))]
    return idx[0], idx[1]
