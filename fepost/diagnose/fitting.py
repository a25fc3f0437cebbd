"""Nonlinear least squares with one noise level per channel, profiled out.

The data are Fx, Fy, Mz in the dimensionless units of
:meth:`~fepost.diagnose.simulation.Simulation.scales`. Each channel c has its own
Gaussian noise σ_c, unknown. The log-likelihood of model parameters θ with the
σ_c at their maximum-likelihood values σ̂_c² = RSS_c(θ)/n is

    ℓ(θ) = −(n/2) Σ_c [ln(2π RSS_c(θ)/n) + 1].

It is maximised by iteratively reweighted least squares: fix σ_c, minimise
Σ_c RSS_c/σ_c² with :func:`scipy.optimize.least_squares` (trust-region
reflective, bounds, finite-difference Jacobian), set σ_c² = RSS_c/n, repeat until
the σ_c settle (a fixed point of this loop is a stationary point of ℓ).

95 % intervals are Wald intervals from the whitened Jacobian at the optimum
(covariance (JᵀJ)⁻¹ via its SVD, scaled by n_obs/(n_obs − k), Student t with
n_obs − k degrees of freedom, k = parameters + 3 variances), as at the end of
:func:`scipy.optimize.curve_fit`; a rank-deficient Jacobian gives a FitWarning and
infinite intervals. Every model here is linear or nearly so in its parameters
over the ranges that matter, where Wald and profile intervals agree.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import optimize, stats

from .._arrays import frozen
from ..errors import FitError, FitWarning
from ..lsq import jacobian_svd
from .causes import Candidate

#: IRLS stops when every σ_c changes by less than this (relative) ...
SIGMA_RTOL = 1e-4
#: ... or after this many rounds.
MAX_ROUNDS = 12
#: Relative step of the finite-difference Jacobian, in units of each parameter's scale.
DIFF_STEP = 1e-6
#: Geometry fits (see :func:`fit`): at most this many expansions ...
GN_MAX = 12
#: ... each step halved at most this many times ...
GN_HALVINGS = 6
#: ... and stop when the geometry moves by less than this many standard errors.
GN_TOL = 0.01


@dataclass(frozen=True)
class Fit:
    """One model fitted to some rows: values, 95 % intervals, noise levels and scores.

    ``values``/``ci95`` in the parameters' own units; ``sigma`` the three σ̂_c
    (dimensionless); ``log_likelihood`` ℓ (nats); ``aicc`` and ``bic`` with
    k = n_params + 3 and n_obs = 3·n_rows.
    """

    name: str
    names: tuple[str, ...]
    values: np.ndarray
    ci95: np.ndarray
    stderr: np.ndarray
    sigma: np.ndarray
    rss: np.ndarray
    n_rows: int
    log_likelihood: float
    at_bound: tuple[str, ...] = ()
    model: Candidate | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("values", "ci95", "stderr", "sigma", "rss"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    @property
    def n_params(self) -> int:
        return len(self.names)

    @property
    def k(self) -> int:
        return self.n_params + 3

    @property
    def n_obs(self) -> int:
        return 3 * self.n_rows

    @property
    def aic(self) -> float:
        return -2.0 * self.log_likelihood + 2.0 * self.k

    @property
    def aicc(self) -> float:
        k, n = self.k, self.n_obs
        return self.aic + 2.0 * k * (k + 1) / (n - k - 1)

    @property
    def bic(self) -> float:
        return -2.0 * self.log_likelihood + self.k * np.log(self.n_obs)

    def to_dict(self) -> dict:
        return {
            "parameters": {
                n: {"value": float(v), "ci95": [float(lo), float(hi)], "stderr": float(s)}
                for n, v, (lo, hi), s in zip(self.names, self.values, self.ci95, self.stderr, strict=True)
            },
            "sigma": [float(s) for s in self.sigma],
            "log_likelihood": self.log_likelihood,
            "aicc": self.aicc,
            "bic": self.bic,
            "n_params": self.n_params,
            "at_bound": list(self.at_bound),
        }


def log_likelihood(rss: np.ndarray, n: int) -> float:
    """ℓ with the per-channel variances profiled out (nats)."""
    rss = np.maximum(np.asarray(rss, float), 1e-300)
    return float(-0.5 * n * np.sum(np.log(2.0 * np.pi * rss / n) + 1.0))


def _covariance(jac: np.ndarray, n_obs: int, k: int) -> tuple[np.ndarray, bool]:
    """(JᵀJ)⁻¹ of the whitened Jacobian, scaled by n/(n − k) for the fitted variances."""
    svd = jacobian_svd(jac)
    return svd.inverse * n_obs / max(n_obs - k, 1), svd.identifiable


def fit(
    cand: Candidate,
    Y: np.ndarray,
    rows: np.ndarray | None = None,
    *,
    start: np.ndarray | None = None,
    sigma: np.ndarray | None = None,
    intervals: bool = True,
) -> Fit:
    """Fit ``cand`` to the dimensionless channels ``Y`` (n, 3) on ``rows`` (default all).

    ``start``: initial parameter values (default each parameter's start);
    ``sigma``: initial noise levels. Raises :class:`FitError` when the solver fails.

    A candidate with ``expand`` (costly geometry) is fitted through local
    models: fit its second-order expansion about the current values, move there
    (halving the step while the exact likelihood drops), expand again, until the
    geometry moves by less than :data:`GN_TOL` standard errors. The returned
    ``model`` is the final expansion (exact at the expansion point, its
    Jacobian there that of the exact model to O(h²); it gives the intervals).
    """
    if cand.expand is None:
        return _fit_direct(cand, Y, rows, start=start, sigma=sigma, intervals=intervals)
    values = np.array([p.start for p in cand.parameters]) if start is None else np.asarray(start, float)
    lin = cand.expand(values)
    current = _fit_direct(lin, Y, rows, start=values, sigma=sigma, intervals=False, evaluate_only=True)
    for _ in range(GN_MAX):
        trial = _fit_direct(lin, Y, rows, start=values, sigma=current.sigma, intervals=True)
        step = trial.values - values
        for _half in range(GN_HALVINGS):
            new_lin = cand.expand(values + step)
            new = _fit_direct(
                new_lin,
                Y,
                rows,
                start=values + step,
                sigma=trial.sigma,
                intervals=False,
                evaluate_only=True,
            )
            if new.log_likelihood >= current.log_likelihood - 1e-9 * abs(current.log_likelihood):
                break
            step = 0.5 * step
        values, lin, current = values + step, new_lin, new
        se = np.where(np.isfinite(trial.stderr) & (trial.stderr > 0), trial.stderr, np.inf)
        if np.all(np.abs(step[1:]) <= GN_TOL * se[1:]) or not np.any(step[1:]):
            break
    else:
        warnings.warn(
            f"{cand.name}: the geometry fit did not settle in {GN_MAX} steps",
            FitWarning,
            stacklevel=2,
        )
    final = _fit_direct(lin, Y, rows, start=values, sigma=current.sigma, intervals=intervals)
    return replace(final, model=lin)


def _fit_direct(
    cand: Candidate,
    Y: np.ndarray,
    rows: np.ndarray | None = None,
    *,
    start: np.ndarray | None = None,
    sigma: np.ndarray | None = None,
    intervals: bool = True,
    evaluate_only: bool = False,
) -> Fit:
    """Least squares with profiled channel variances; ``evaluate_only`` scores ``start`` as is."""
    Y = np.asarray(Y, float)
    rows = np.arange(Y.shape[0]) if rows is None else np.asarray(rows)
    y = Y[rows]
    n = rows.size
    names = tuple(p.name for p in cand.parameters)
    if cand.n_params == 0 or evaluate_only:
        z = np.empty(0) if start is None else np.asarray(start, float)
        rss = np.sum((y - cand.predict(z)[rows]) ** 2, axis=0)
        inf = np.full(z.size, np.inf)
        ci = np.column_stack([-inf, inf])
        return Fit(
            cand.name,
            names,
            z,
            ci,
            inf,
            np.sqrt(rss / n),
            rss,
            n,
            log_likelihood(rss, n),
            model=cand,
        )
    scale = np.array([p.scale for p in cand.parameters])
    lower = np.array([p.lower for p in cand.parameters]) / scale
    upper = np.array([p.upper for p in cand.parameters]) / scale
    u = (np.array([p.start for p in cand.parameters]) if start is None else np.asarray(start, float)) / scale
    width = np.where(np.isfinite(upper - lower), upper - lower, 0.0)
    u = np.clip(u, lower + 1e-9 * width, upper - 1e-9 * width)

    def residual(uu: np.ndarray, sig: np.ndarray) -> np.ndarray:
        return ((y - cand.predict(uu * scale)[rows]) / sig).ravel()

    sig = (
        np.asarray(sigma, float)
        if sigma is not None
        else np.sqrt(np.mean((y - cand.predict(u * scale)[rows]) ** 2, axis=0))
    )
    sig = np.maximum(sig, 1e-12)
    result = None
    used = sig
    for _ in range(MAX_ROUNDS):
        used = sig
        try:
            result = optimize.least_squares(
                residual,
                u,
                args=(used,),
                bounds=(lower, upper),
                method="trf",
                diff_step=DIFF_STEP,
                x_scale=1.0,
            )
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise FitError(f"{cand.name}: least squares failed ({exc})") from None
        if result.status <= 0:
            raise FitError(f"{cand.name}: least squares did not converge ({result.message})")
        u = result.x
        rss = np.sum((y - cand.predict(u * scale)[rows]) ** 2, axis=0)
        sig = np.maximum(np.sqrt(rss / n), 1e-12)
        if np.all(np.abs(sig / used - 1.0) < SIGMA_RTOL):
            break
    assert result is not None
    values = u * scale
    stderr = np.full(values.size, np.inf)
    ci = np.column_stack([np.full(values.size, -np.inf), np.full(values.size, np.inf)])
    if intervals:
        # The last Jacobian was whitened with the σ of the round before; rescale to the final σ.
        jac = result.jac * np.tile(used / sig, n)[:, None]
        k = cand.n_params + 3
        cov, ok = _covariance(jac, 3 * n, k)
        if not ok:
            warnings.warn(
                f"{cand.name}: parameters not identifiable from these data (singular Jacobian)",
                FitWarning,
                stacklevel=2,
            )
        else:
            stderr = np.sqrt(np.diag(cov)) * scale
            t = stats.t.ppf(0.975, max(3 * n - k, 1))
            ci = np.column_stack([values - t * stderr, values + t * stderr])
    tol = np.where(width > 0, 1e-6 * width, -1.0)
    at_bound = tuple(
        nm
        for nm, uu, lo, hi, tt in zip(names, u, lower, upper, tol, strict=True)
        if uu - lo < tt or hi - uu < tt
    )
    return Fit(cand.name, names, values, ci, stderr, sig, rss, n, log_likelihood(rss, n), at_bound, cand)
