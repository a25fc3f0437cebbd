"""Limit surfaces fitted to measured pushes: the ellipsoid and the convex quartic.

Each push gives the support's friction wrench W = (F_x, F_y, M_z) on the body
(N, N, N·m) and the direction of the body's twist (v_x, v_y, ω_z). With the
torque and the spin made force- and speed-like by a length ρ,
w = −(F_x, F_y, M_z/ρ)/s (the wrench that pushes the body, in units of a force
scale s, the median |W| of the data) lies on the limit surface H(w) = 1 and the
twist t = (v_x, v_y, ω_z ρ) is normal to it (`fepost.limitsurface.polynomial`).

The fit follows Zhou et al. (2016): the coefficients a minimise

    Σ_i (H(w_i) − 1)²  +  η² Σ_i |P_i ∇H(w_i)|² |w_i|²/d²,

P_i = I − t̂_i t̂_iᵀ the projection across the measured twist direction (the
part of the normal that the twist does not explain; |w|/d makes it an angle,
since w·∇H = d H), subject to t̂_i·∇H(w_i) ≥ 0 (the normal points along the
twist), H ≥ `POSITIVE_FLOOR` on the unit sphere and ∇²H positive semidefinite:
a convex set, bounded, symmetric. All three are linear in a, so the fit is a
linearly constrained linear least-squares problem, solved by scipy's SLSQP.
Convexity is imposed by cutting planes: yᵀ∇²H(u)y ≥ 0 at sampled (u, y), then,
round by round, at the points of a finer sphere where ∇²H has a negative
eigenvalue, along its eigenvector, until none is left below `CONVEX_TOL`
(for the ellipsoid this is A ⪰ 0; for the quartic it is convexity checked on
`CHECK_POINTS` directions, where Zhou et al. impose the stronger SOS-convexity
by semidefinite programming).

`LimitSurface.wrench` is the inverse map (the friction wrench for a twist
direction: the point of the surface whose normal is the twist, found by a
search over the sphere and Newton steps on ∇H(w) = λ t̂, H(w) = 1);
`LimitSurface.twist` the forward one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ..errors import ArgumentError, FitError
from .polynomial import HomogeneousPolynomial, exponents, monomial_gradients, monomial_hessians, monomials

#: Weight η of the twist-direction term against the wrench term (Zhou et al. weigh them alike).
DIRECTION_WEIGHT = 1.0
#: H ≥ this on the unit sphere of scaled wrenches (the data sit near |w| = 1, H = 1).
POSITIVE_FLOOR = 1e-3
#: Smallest Hessian eigenvalue allowed, relative to the largest over the sphere.
CONVEX_TOL = 1e-9
#: Directions on which convexity is checked (a Fibonacci sphere).
CHECK_POINTS = 2000
#: Cutting-plane rounds at most.
CONVEX_ROUNDS = 12
#: Directions searched for the start of the inverse map's Newton steps.
SEARCH_POINTS = 4000
#: Newton steps of the inverse map at most, and its tolerance on |∇H − λ t̂| and |H − 1|.
NEWTON_STEPS = 50
NEWTON_TOL = 1e-12


def sphere(n: int) -> np.ndarray:
    """``n`` nearly even unit vectors (a Fibonacci sphere), (n, 3)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (1.0 + 5**0.5) * k
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


@dataclass(frozen=True)
class LimitSurface:
    """A fitted limit surface: H over scaled wrenches, the length ρ (m) and the force scale (N).

    ``loss``: the fit's two sums (``wrench``, ``direction``) and their total;
    ``convexity``: the smallest Hessian eigenvalue over `CHECK_POINTS` directions,
    relative to the largest (≥ −`CONVEX_TOL` when convex there).
    """

    polynomial: HomogeneousPolynomial
    rho: float
    force_scale: float
    loss: dict
    convexity: float
    n_pushes: int

    @property
    def name(self) -> str:
        return "ellipsoid" if self.polynomial.degree == 2 else "quartic"

    @property
    def n_params(self) -> int:
        return int(self.polynomial.coefficients.size)

    def _scaled(self, wrench) -> np.ndarray:
        W = np.asarray(wrench, float)
        return -np.column_stack([W[:, 0], W[:, 1], W[:, 2] / self.rho]) / self.force_scale

    def twist(self, wrench) -> np.ndarray:
        """Unit twist directions (v_x, v_y, ω_z ρ)/|·| for friction wrenches (n, 3) (N, N, N·m)."""
        g = self.polynomial.gradient(self._scaled(wrench))
        return g / np.linalg.norm(g, axis=1, keepdims=True)

    def wrench(self, twist) -> np.ndarray:
        """The friction wrench (F_x, F_y, M_z) (N, N, N·m) on the body for twists (v_x, v_y, ω_z) (n, 3)."""
        t = np.asarray(twist, float)
        t = np.column_stack([t[:, 0], t[:, 1], t[:, 2] * self.rho])
        norm = np.linalg.norm(t, axis=1, keepdims=True)
        if np.any(norm == 0):
            raise ArgumentError("twist must not be zero (no motion gives no direction)")
        w = support_points(self.polynomial, t / norm)
        return -np.column_stack([w[:, 0], w[:, 1], w[:, 2] * self.rho]) * self.force_scale

    def to_dict(self) -> dict:
        return {
            "model": self.name,
            "degree": self.polynomial.degree,
            "coefficients": self.polynomial.coefficients.tolist(),
            "rho": self.rho,
            "force_scale": self.force_scale,
            "loss": dict(self.loss),
            "convexity": self.convexity,
            "n_pushes": self.n_pushes,
        }


def support_points(poly: HomogeneousPolynomial, directions: np.ndarray) -> np.ndarray:
    """The points w of H(w) = 1 whose normal ∇H(w) is along each unit direction (n, 3)."""
    d = poly.degree
    U = sphere(SEARCH_POINTS)
    hu = poly.value(U)
    if np.any(hu <= 0):
        raise FitError("the limit surface is not bounded (H <= 0 in some direction)")
    on = U * hu[:, None] ** (-1.0 / d)  # the surface along each sampled direction
    w = on[np.argmax(directions @ on.T, axis=1)]  # the sampled point that reaches furthest along t
    lam = np.einsum("ij,ij->i", poly.gradient(w), directions)
    for _ in range(NEWTON_STEPS):
        g = poly.gradient(w)
        r = np.concatenate([g - lam[:, None] * directions, (poly.value(w) - 1.0)[:, None]], axis=1)
        if np.max(np.abs(r)) < NEWTON_TOL * max(1.0, float(np.max(np.abs(lam)))):
            break
        J = np.zeros((w.shape[0], 4, 4))
        J[:, :3, :3] = poly.hessian(w)
        J[:, :3, 3] = -directions
        J[:, 3, :3] = g
        step = np.linalg.solve(J, -r[:, :, None])[:, :, 0]
        w = w + step[:, :3]
        lam = lam + step[:, 3]
    return w


def _rows(w: np.ndarray, t: np.ndarray, degree: int, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares rows (B, b): wrench rows then the cross-twist rows (module docstring)."""
    M = monomials(w, degree)
    G = monomial_gradients(w, degree)  # (n, 3, K)
    P = np.eye(3)[None] - t[:, :, None] * t[:, None, :]
    cross = np.einsum("nab,nbk->nak", P, G) * (eta * np.linalg.norm(w, axis=1) / degree)[:, None, None]
    B = np.vstack([M, cross.reshape(-1, M.shape[1])])
    b = np.concatenate([np.ones(len(w)), np.zeros(cross.shape[0] * 3)])
    return B, b


def _convexity_rows(poly_degree: int, u: np.ndarray, y: np.ndarray) -> np.ndarray:
    """yᵀ∇²m_k(u)y for each pair (u, y): (n, K)."""
    Hm = monomial_hessians(u, poly_degree)
    return np.einsum("na,nabk,nb->nk", y, Hm, y)


def _worst_eigen(poly: HomogeneousPolynomial, U: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Eigenvalues' minima, their eigenvectors and the largest eigenvalue of ∇²H over ``U``."""
    vals, vecs = np.linalg.eigh(poly.hessian(U))
    return vals[:, 0], vecs[:, :, 0], float(np.max(vals[:, -1]))


def fit_limit_surface(
    wrench, twist, *, degree: int = 2, rho: float, direction_weight: float = DIRECTION_WEIGHT
) -> LimitSurface:
    """Fit a limit surface of ``degree`` 2 (ellipsoid) or 4 (convex quartic) to pushes.

    ``wrench``: the support's friction wrench on the body per push (n, 3): F_x, F_y
    (N) and M_z (N·m); ``twist``: the body's twist direction per push (n, 3): v_x,
    v_y (any length unit per time) and ω_z (rad per the same time); ``rho`` (m):
    the length that turns torques into forces and spins into speeds.
    """
    W = np.asarray(wrench, float)
    T = np.asarray(twist, float)
    if W.ndim != 2 or W.shape[1] != 3 or T.shape != W.shape:
        raise ArgumentError(f"wrench and twist must both be (n, 3), got {W.shape} and {T.shape}")
    if not (np.all(np.isfinite(W)) and np.all(np.isfinite(T))):
        raise ArgumentError("wrench and twist must be finite")
    if not (np.isfinite(rho) and rho > 0):
        raise ArgumentError(f"rho must be a positive length in m, got {rho!r}")
    n_min = len(exponents(degree))  # as many pushes as coefficients
    if W.shape[0] < n_min:
        raise ArgumentError(
            f"a degree-{degree} limit surface needs at least {n_min} pushes, got {W.shape[0]}"
        )
    w = -np.column_stack([W[:, 0], W[:, 1], W[:, 2] / rho])
    scale = float(np.median(np.linalg.norm(w, axis=1)))
    if not scale > 0:
        raise ArgumentError("the wrenches are all zero")
    w = w / scale
    t = np.column_stack([T[:, 0], T[:, 1], T[:, 2] * rho])
    tn = np.linalg.norm(t, axis=1)
    if np.any(tn == 0):
        raise ArgumentError("a push has no twist (the body did not move)")
    t = t / tn[:, None]
    coef, loss, convexity = _solve(w, t, degree, direction_weight)
    poly = HomogeneousPolynomial(degree, coef)
    return LimitSurface(poly, float(rho), scale, loss, convexity, int(W.shape[0]))


def _solve(w, t, degree, eta) -> tuple[np.ndarray, dict, float]:
    """The constrained least squares by SLSQP with convexity cutting planes."""
    B, b = _rows(w, t, degree, eta)
    U = sphere(CHECK_POINTS)
    lin = [
        np.einsum("na,nak->nk", t, monomial_gradients(w, degree)),  # normals along the twists
        monomials(U, degree),  # H ≥ floor on the sphere (the floor is the bound below)
    ]
    floors = [np.zeros(len(w)), np.full(len(U), POSITIVE_FLOOR)]
    start_u = sphere(64)
    axes = np.vstack([np.eye(3), sphere(10)])
    uu = np.repeat(start_u, len(axes), axis=0)
    yy = np.tile(axes, (len(start_u), 1))
    cuts = _convexity_rows(degree, uu, yy)
    # start: the sphere |w|^d scaled to the data's median, feasible for every constraint
    iso = HomogeneousPolynomial.quadratic(np.eye(3)).coefficients
    if degree == 4:
        iso = _square(iso)
    x = iso / np.median(monomials(w, degree) @ iso)
    for _ in range(CONVEX_ROUNDS):
        C = np.vstack([*lin, cuts])
        lo = np.concatenate([*floors, np.zeros(len(cuts))])
        res = optimize.minimize(
            lambda a: 0.5 * float(np.sum((B @ a - b) ** 2)),
            x,
            jac=lambda a: B.T @ (B @ a - b),
            method="SLSQP",
            constraints=[{"type": "ineq", "fun": lambda a, C=C, lo=lo: C @ a - lo, "jac": lambda a, C=C: C}],
            options={"maxiter": 500, "ftol": 1e-14},
        )
        if not np.all(np.isfinite(res.x)):
            raise FitError(f"the limit-surface fit failed: {res.message}")
        x = res.x
        poly = HomogeneousPolynomial(degree, x)
        low, vec, top = _worst_eigen(poly, U)
        bad = np.flatnonzero(low < -CONVEX_TOL * top)
        if not bad.size:
            break
        bad = bad[np.argsort(low[bad])][:200]
        cuts = np.vstack([cuts, _convexity_rows(degree, U[bad], vec[bad])])
    low, _, top = _worst_eigen(HomogeneousPolynomial(degree, x), U)
    r = B @ x - b
    n = len(w)
    loss = {
        "wrench": float(np.sum(r[:n] ** 2)),
        "direction": float(np.sum(r[n:] ** 2)),
        "total": float(np.sum(r**2)),
        "solver": "scipy SLSQP",
        "converged": bool(res.success),
    }
    return x, loss, float(np.min(low) / top) if top > 0 else -np.inf


def _square(quadratic: np.ndarray) -> np.ndarray:
    """Coefficients of (wᵀ A w)² (degree 4) from those of wᵀ A w, by least squares on sample points."""
    U = sphere(60)
    q2 = monomials(U, 2) @ quadratic
    M4 = monomials(U, 4)
    coef, *_ = np.linalg.lstsq(M4, q2 * q2, rcond=None)
    return coef


def wrench_errors(predicted, measured, rho: float) -> dict:
    """Errors of predicted friction wrenches (n, 3) against measured ones: per push.

    ``force``: |F_pred − F_meas| (N); ``torque``: |M_pred − M_meas| (N·m);
    ``angle``: the angle (rad) between the two wrenches as vectors
    (F_x, F_y, M_z/ρ).
    """
    P = np.asarray(predicted, float)
    M = np.asarray(measured, float)
    force = np.hypot(P[:, 0] - M[:, 0], P[:, 1] - M[:, 1])
    torque = np.abs(P[:, 2] - M[:, 2])
    a = np.column_stack([P[:, 0], P[:, 1], P[:, 2] / rho])
    c = np.column_stack([M[:, 0], M[:, 1], M[:, 2] / rho])
    cos = np.einsum("ij,ij->i", a, c) / (np.linalg.norm(a, axis=1) * np.linalg.norm(c, axis=1))
    return {"force": force, "torque": torque, "angle": np.arccos(np.clip(cos, -1.0, 1.0))}
