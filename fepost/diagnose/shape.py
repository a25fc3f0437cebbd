"""The ``pressure_shape`` cause: the same load and centre of pressure, distributed differently.

A real contact may carry its load more towards its rim or edges (a rigid flat
punch on an elastic board, a base that is slightly concave) or more towards its
centre (a slightly convex base, a worn edge) than the simulation says. The
reshaped pressure is

    σ'(x, y) = σ(x, y) · (1 + c_rim · r(x, y)),

with r the rim weight of the simulated map:

* q(x, y) = dᵀ S⁻¹ d, d the distance vector from the centre of pressure and S the
  pressure-weighted covariance of the contact points (the map's own second
  moments): q is the squared distance in the patch's own metric, so "the rim"
  follows an elongated or a triangular patch as it follows a disc; its
  pressure-weighted mean is 2 (in two dimensions);
* r = (q − ℓ)/2, ℓ = a + b·dx + c·dy the pressure-weighted least-squares fit of q
  on (1, dx, dy). r is orthogonal to 1, x and y under σ dA, so σ' carries the
  same load and the same centre of pressure as σ, to round-off, for every c_rim;
  for a symmetric map ℓ = 2.

For a uniform disc of radius R, r = 2ρ²/R² − 1: c_rim = 1 leaves no pressure at
the centre and twice the mean at the rim; c_rim = −1 the reverse (a paraboloid);
the polar second moment ∬σρ² dA grows by the factor 1 + c_rim/3. c_rim is bounded
by σ' ≥ 0 at every loaded node (`rim_bounds`).

The resultants are linear in σ', so for Coulomb's law they are exactly linear in
c_rim (and for a pressure-dependent law quadratic): the second-order expansion
that the diagnosis fits geometric parameters with (`fepost.diagnose.models`) is
exact for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..friction.quadrature import PressureQuadrature


@dataclass(frozen=True)
class RimWeight:
    """r(x, y) = (q − a − b·dx − c·dy)/2 of one map (module docstring); positions in m."""

    cx: float
    cy: float
    inverse: tuple[float, float, float]  # S⁻¹ entries (xx, xy, yy), 1/m²
    linear: tuple[float, float, float]  # a, b (1/m), c (1/m)

    def __call__(self, x, y) -> np.ndarray:
        dx = np.asarray(x, float) - self.cx
        dy = np.asarray(y, float) - self.cy
        ixx, ixy, iyy = self.inverse
        q = ixx * dx * dx + 2.0 * ixy * dx * dy + iyy * dy * dy
        a, b, c = self.linear
        return 0.5 * (q - a - b * dx - c * dy)


def rim_weight(quad: PressureQuadrature) -> RimWeight:
    """The rim weight r of ``quad``'s pressure (module docstring)."""
    w = np.maximum(quad.sigma, 0.0) * quad.dA
    load = float(w.sum())
    if not load > 0:
        raise ArgumentError("pressure_shape: the map carries no load")
    cx, cy = float(w @ quad.x) / load, float(w @ quad.y) / load
    dx, dy = quad.x - cx, quad.y - cy
    sxx, sxy, syy = (float(w @ v) / load for v in (dx * dx, dx * dy, dy * dy))
    det = sxx * syy - sxy * sxy
    if not det > 1e-12 * max(sxx, syy) ** 2:
        raise ArgumentError("pressure_shape: the map's pressure lies on a line (no rim to speak of)")
    inverse = (syy / det, -sxy / det, sxx / det)
    q = inverse[0] * dx * dx + 2.0 * inverse[1] * dx * dy + inverse[2] * dy * dy
    basis = np.column_stack([np.ones_like(dx), dx, dy])
    root = np.sqrt(w)
    coef, *_ = np.linalg.lstsq(basis * root[:, None], q * root, rcond=None)
    return RimWeight(cx, cy, inverse, (float(coef[0]), float(coef[1]), float(coef[2])))


def rim_bounds(quad: PressureQuadrature) -> tuple[float, float]:
    """The range of c_rim that keeps σ' ≥ 0 at every loaded node of ``quad``."""
    loaded = quad.sigma > 0
    r = rim_weight(quad)(quad.x[loaded], quad.y[loaded])
    lo = -1.0 / float(r.max()) if r.max() > 0 else -np.inf
    hi = -1.0 / float(r.min()) if r.min() < 0 else np.inf
    return lo, hi


def reshaped(quad: PressureQuadrature, c_rim: float, weight: RimWeight | None = None) -> PressureQuadrature:
    """``quad`` with its pressure σ → σ (1 + c_rim r) (same load and centre of pressure).

    ``weight``: the rim weight of ``quad`` when already computed (`rim_weight`).
    Nodes and weights are unchanged; the pressure may dip below zero only for a
    c_rim outside `rim_bounds`.
    """
    if not np.isfinite(c_rim):
        raise ArgumentError(f"c_rim must be a finite number, got {c_rim!r}")
    c_rim = float(c_rim)
    if c_rim == 0.0:
        return quad
    r = weight or rim_weight(quad)
    inner = quad.sigma_at

    def sigma_at(px, py):
        return np.asarray(inner(px, py), float) * (1.0 + c_rim * r(px, py))

    return PressureQuadrature(
        x=quad.x,
        y=quad.y,
        dA=quad.dA,
        sigma=quad.sigma * (1.0 + c_rim * r(quad.x, quad.y)),
        domain=quad.domain,
        sigma_at=sigma_at,
        source=f"{quad.source} reshaped({c_rim:g})".strip(),
        polar=quad.polar,
    )
