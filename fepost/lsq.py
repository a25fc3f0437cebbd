"""Covariance of a least-squares fit from its Jacobian, as scipy's ``curve_fit`` does it.

The thin SVD J = U S Vᵀ gives (JᵀJ)⁻¹ = V S⁻² Vᵀ. Singular values below
eps·max(J.shape)·s_max count as zero (the rank rule of ``curve_fit``); a
Jacobian with such a value, or with a condition number above ``cond_max``,
is reported as not identifiable rather than given a meaningless inverse.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class JacobianSVD:
    """(JᵀJ)⁻¹ (unscaled covariance), whether it is determinate, and why not."""

    inverse: np.ndarray  # (p, p); pseudo-inverse restricted to the kept singular values
    identifiable: bool
    condition: float
    weakest: int  # parameter with the largest weight in the weakest direction


def jacobian_svd(J: np.ndarray, cond_max: float = np.inf) -> JacobianSVD:
    """Unscaled covariance (JᵀJ)⁻¹ of the parameters of a fit with Jacobian ``J`` (n, p)."""
    J = np.asarray(J, float)
    p = J.shape[1]
    if not np.all(np.isfinite(J)):
        return JacobianSVD(np.full((p, p), np.nan), False, np.inf, 0)
    _, s, vt = np.linalg.svd(J, full_matrices=False)
    threshold = np.finfo(float).eps * max(J.shape) * (s[0] if s.size else 0.0)
    keep = s > threshold
    s_inv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)
    inverse = (vt.T * s_inv**2) @ vt
    condition = float(s[0] / s[-1]) if s.size == p and s[-1] > 0 else np.inf
    identifiable = bool(s.size == p and keep.all() and condition <= cond_max)
    weakest = int(np.argmax(np.abs(vt[-1]))) if s.size else 0
    return JacobianSVD(inverse, identifiable, condition, weakest)


def leverage(J: np.ndarray) -> np.ndarray:
    """Diagonal of the hat matrix J (JᵀJ)⁺ Jᵀ (rank-revealing, from the thin SVD)."""
    U, s, _ = np.linalg.svd(np.asarray(J, float), full_matrices=False)
    keep = s > np.finfo(float).eps * max(J.shape) * (s[0] if s.size else 0.0)
    return np.sum(U[:, keep] ** 2, axis=1)
