"""Nonlinear least squares under a per-channel noise model, Gaussian or robust.

The data are Fx, Fy, Mz in the dimensionless units of
`scales`. The noise of channel c at
row i has standard deviation σ_ic from a `Noise`
model (constant, proportional to a fixed reference |F|, or both), whose
parameters are estimated with the model's.

**Gaussian fit** (``loss="gaussian"``). The log-likelihood is

    ℓ(θ, a, b) = −½ Σ_ic [ln(2π σ_ic²) + r_ic(θ)²/σ_ic²].

It is maximised by alternating: fix σ, minimise Σ r²/σ² with
`scipy.optimize.least_squares` (trust-region reflective, bounds,
finite-difference Jacobian); fix θ, maximise over the noise parameters
(`Noise.refit <fepost.diagnose.noise.Noise.refit>`); until the σ settle.
The variances do not depend on θ (the reference magnitudes are fixed), so a
fixed point is a stationary point of ℓ. With constant noise this is the
profiled likelihood −(n/2) Σ_c [ln(2π RSS_c/n) + 1].

**Robust fit** (``loss="huber"``). The same alternation with Huber's loss
ρ_k(z) (k = 1.345: quadratic within k noise SDs, linear beyond; ``loss="huber"``
with ``f_scale=k`` of least_squares on the whitened residuals) and Huber's scale
equation for the noise parameters (Huber's Proposal 2, `noise`);
the first scale is 1.4826 × MAD of the residuals at the start values.
``log_likelihood`` is then −Σ [ρ_k(z) + ln σ], the log-likelihood of Huber's
least-favourable density up to a constant, evaluated at that scale.
Robust fits serve only to find outliers and the noise model's reference
(`robust`); every score, test and interval comes from a
Gaussian fit on the rows that remain.

95 % intervals are Wald intervals from the whitened Jacobian at the optimum
(covariance (JᵀJ)⁻¹ via its SVD, scaled by n_obs/(n_obs − k), Student t with
n_obs − k degrees of freedom, k = parameters + noise parameters), as at the end
of `scipy.optimize.curve_fit`; a rank-deficient Jacobian gives a
FitWarning and infinite intervals. Every model here is linear or nearly so in
its parameters over the ranges that matter, where Wald and profile intervals
agree.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import optimize, stats

from .._arrays import frozen
from ..errors import FitError, FitWarning
from ..lsq import jacobian_svd
from .models import Candidate
from .noise import HUBER_K, Noise

#: The noise parameters' rounds stop when every σ changes by less than this (relative) ...
SIGMA_RTOL = 1e-4
#: ... or after this many rounds.
MAX_ROUNDS = 12
#: Relative step of the finite-difference Jacobian, in units of each parameter's scale.
DIFF_STEP = 1e-6
#: Geometry fits (see `fit`): at most this many expansions ...
GN_MAX = 12
#: ... each step halved at most this many times ...
GN_HALVINGS = 6
#: ... and stop when the parameters move by less than this many standard errors.
GN_TOL = 0.01

LOSSES = ("gaussian", "huber")


@dataclass(frozen=True)
class Fit:
    """One model fitted to some rows: values, 95 % intervals, noise model and scores.

    ``values``/``ci95`` in the parameters' own units; ``noise`` the fitted noise
    model; ``sigma`` the RMS σ per channel over the fitted rows (dimensionless);
    ``rss`` the unweighted residual sums of squares; ``log_likelihood`` ℓ (nats);
    ``aicc`` and ``bic`` with k = n_params + noise parameters, n_obs = 3·n_rows.
    ``rows`` are the data rows fitted.
    """

    name: str
    names: tuple[str, ...]
    values: np.ndarray
    ci95: np.ndarray
    stderr: np.ndarray
    noise: Noise
    rss: np.ndarray
    rows: np.ndarray
    log_likelihood: float
    at_bound: tuple[str, ...] = ()
    model: Candidate | None = field(default=None, repr=False, compare=False)
    loss: str = "gaussian"
    jacobian: np.ndarray | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("values", "ci95", "stderr", "rss"):
            object.__setattr__(self, name, frozen(getattr(self, name)))
        object.__setattr__(self, "rows", frozen(self.rows, dtype=int))
        if self.jacobian is not None:
            object.__setattr__(self, "jacobian", frozen(self.jacobian))

    @property
    def n_rows(self) -> int:
        return int(self.rows.size)

    @property
    def sigma(self) -> np.ndarray:
        return np.sqrt(np.mean(self.noise.variance(self.rows), axis=0))

    @property
    def n_params(self) -> int:
        return len(self.names)

    @property
    def k(self) -> int:
        return self.n_params + self.noise.n_params

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
    """ℓ with constant per-channel variances profiled out (nats)."""
    rss = np.maximum(np.asarray(rss, float), 1e-300)
    return float(-0.5 * n * np.sum(np.log(2.0 * np.pi * rss / n) + 1.0))


def huber_rho(z: np.ndarray, k: float = HUBER_K) -> np.ndarray:
    """Huber's ρ_k(z): z²/2 for |z| ≤ k, k|z| − k²/2 beyond."""
    a = np.abs(z)
    return np.where(a <= k, 0.5 * a * a, k * a - 0.5 * k * k)


def _score(res: np.ndarray, noise: Noise, rows, loss: str) -> float:
    if loss == "gaussian":
        return float(np.sum(noise.log_likelihood(res, rows)))
    sig = noise.sigma(rows)
    return float(-np.sum(huber_rho(res / sig)) - np.sum(np.log(sig)))


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
    noise: Noise | None = None,
    loss: str = "gaussian",
    intervals: bool = True,
) -> Fit:
    """Fit ``cand`` to the dimensionless channels ``Y`` (n, 3) on ``rows`` (default all).

    ``start``: initial parameter values (default each parameter's start);
    ``noise``: the noise model and its starting parameters (default: constant
    variance per channel); ``loss``: ``"gaussian"`` or ``"huber"`` (module
    docstring). Raises `FitError` when the solver fails.

    A candidate with ``expand`` (costly geometry) is fitted through local
    models: fit its second-order expansion about the current values; when that
    moves the parameters by less than `GN_TOL` standard errors, stop;
    else move there (halving the step while the exact objective, one set of
    integrals per trial point, drops; stop when no halving improves it, or when
    the step taken is under the tolerance) and expand again. The returned ``model``
    is the final expansion (exact at its expansion point, within GN_TOL standard
    errors of the optimum; its Jacobian that of the exact model to O(h²); it
    gives the intervals).
    """
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {LOSSES}, got {loss!r}")
    Y = np.asarray(Y, float)
    rows = np.arange(Y.shape[0]) if rows is None else np.asarray(rows)
    if noise is None:
        noise = Noise.start("constant", np.zeros_like(Y))
    if cand.expand is None:
        return _fit_direct(cand, Y, rows, start=start, noise=noise, loss=loss, intervals=intervals)
    values = np.array([p.start for p in cand.parameters]) if start is None else np.asarray(start, float)
    lin = cand.expand(values)
    current = _fit_direct(lin, Y, rows, start=values, noise=noise, loss=loss, evaluate_only=True)
    for _ in range(GN_MAX):
        trial = _fit_direct(lin, Y, rows, start=values, noise=current.noise, loss=loss, intervals=True)
        step = trial.values - values
        se = np.where(np.isfinite(trial.stderr) & (trial.stderr > 0), trial.stderr, np.inf)
        if np.all(np.abs(step) <= GN_TOL * se) or not np.any(step):
            # settled: the local model about ``values`` is exact there, and its error at
            # values + step is third order in a step of under GN_TOL standard errors
            break
        new, accepted = current, False
        for _half in range(GN_HALVINGS):
            # the exact objective at a trial point costs one set of integrals ...
            new = _fit_direct(
                cand, Y, rows, start=values + step, noise=trial.noise, loss=loss, evaluate_only=True
            )
            if new.log_likelihood >= current.log_likelihood - 1e-9 * abs(current.log_likelihood):
                accepted = True
                break
            step = 0.5 * step
        if not accepted:
            # no better point along the step: settled to the resolution of the integrals
            # (they jump by ~1e-4 f·N when a centre of rotation crosses the patch edge)
            break
        values, current = values + step, new
        if np.all(np.abs(step) <= GN_TOL * se):
            break  # a halved step under the tolerance: the local model still holds there
        lin = cand.expand(values)  # ... and only an accepted point is expanded (its centre is cached)
    else:
        warnings.warn(
            f"{cand.name}: the geometry fit did not settle in {GN_MAX} steps",
            FitWarning,
            stacklevel=2,
        )
    final = _fit_direct(lin, Y, rows, start=values, noise=current.noise, loss=loss, intervals=intervals)
    return replace(final, model=lin)


def _fit_direct(
    cand: Candidate,
    Y: np.ndarray,
    rows: np.ndarray,
    *,
    start: np.ndarray | None = None,
    noise: Noise,
    loss: str = "gaussian",
    intervals: bool = True,
    evaluate_only: bool = False,
) -> Fit:
    """Least squares with the noise parameters re-estimated; ``evaluate_only`` scores ``start`` as is."""
    y = Y[rows]
    n = rows.size
    robust = loss == "huber"
    names = tuple(p.name for p in cand.parameters)
    if cand.n_params == 0 or evaluate_only:
        z = np.empty(0) if start is None else np.asarray(start, float)
        res = y - cand.predict(z)[rows]
        nz = noise.refit(res, rows, robust=robust)
        inf = np.full(z.size, np.inf)
        return Fit(
            cand.name, names, z, np.column_stack([-inf, inf]), inf, nz, np.sum(res**2, axis=0), rows,
            _score(res, nz, rows, loss), model=cand, loss=loss,
        )  # fmt: skip
    scale = np.array([p.scale for p in cand.parameters])
    lower = np.array([p.lower for p in cand.parameters]) / scale
    upper = np.array([p.upper for p in cand.parameters]) / scale
    u = (np.array([p.start for p in cand.parameters]) if start is None else np.asarray(start, float)) / scale
    width = np.where(np.isfinite(upper - lower), upper - lower, 0.0)
    u = np.clip(u, lower + 1e-9 * width, upper - 1e-9 * width)

    def residual(uu: np.ndarray, sig: np.ndarray) -> np.ndarray:
        return ((y - cand.predict(uu * scale)[rows]) / sig).ravel()

    if not noise.fitted:
        noise = noise.refit(y - cand.predict(u * scale)[rows], rows, robust=robust)
    sig = noise.sigma(rows)
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
                loss="huber" if robust else "linear",
                f_scale=HUBER_K if robust else 1.0,
            )
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise FitError(f"{cand.name}: least squares failed ({exc})") from None
        if result.status <= 0:
            raise FitError(f"{cand.name}: least squares did not converge ({result.message})")
        u = result.x
        res = y - cand.predict(u * scale)[rows]
        noise = noise.refit(res, rows, robust=robust)
        sig = noise.sigma(rows)
        if np.all(np.abs(sig / used - 1.0) < SIGMA_RTOL):
            break
    assert result is not None
    values = u * scale
    stderr = np.full(values.size, np.inf)
    ci = np.column_stack([np.full(values.size, -np.inf), np.full(values.size, np.inf)])
    jac = None
    if intervals:
        # The last Jacobian was whitened with the σ of the round before; rescale to the final σ.
        jac = result.jac * (used / sig).ravel()[:, None]
        k = cand.n_params + noise.n_params
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
        jac = jac / scale[None, :]  # per unit of each parameter
    tol = np.where(width > 0, 1e-6 * width, -1.0)
    at_bound = tuple(
        nm
        for nm, uu, lo, hi, tt in zip(names, u, lower, upper, tol, strict=True)
        if uu - lo < tt or hi - uu < tt
    )
    return Fit(
        cand.name, names, values, ci, stderr, noise, np.sum(res**2, axis=0), rows,
        _score(res, noise, rows, loss), at_bound, cand, loss, jac,
    )  # fmt: skip
