"""The joint nonlinear least-squares fit of the three curves, with 95 % intervals.

Statistics (all from scipy; nothing hand-rolled in the fit)
-----------------------------------------------------------
* Solver: `scipy.optimize.least_squares` (MINPACK Levenberg–Marquardt) with
  the form's Jacobian, in the parameters θ = (F0/s_F, M0/s_M, ln a, ln m, k_x):
  s_F, s_M are the data scales (max |F∥|, max |M_C|), so θ is O(1), and ln a,
  ln m keep a, m > 0 and make their Wald intervals follow the skew of the
  likelihood (the interval for a is exp of the interval for ln a).
* Weights: the curves are in different units and carry different noise, so each
  curve c is divided by its own noise level σ_c, estimated from its residuals:
  σ_c² = RSS_c / (n_c − h_c), with h_c = Σ_{i∈c} H_ii the share of the hat
  matrix H = J(JᵀJ)⁻¹Jᵀ of the weighted Jacobian that falls on curve c (the
  parameters the curve "uses up"; Σ_c h_c = p). This is the unbiased estimator
  of each σ_c² in the linearised model. Fit and σ_c are iterated to a fixed point
  (`REWEIGHT_RTOL`, at most `REWEIGHT_MAX` refits).
* Covariance: as in `scipy.optimize.curve_fit` with ``absolute_sigma=False``:
  pcov = s²·(JᵀJ)⁻¹ from the SVD of J, s² = χ²/(n − p). A singular value below
  eps·max(J.shape)·s_max, or a condition number above `COND_MAX`, makes the
  covariance indeterminate: a `FitWarning` naming the
  unidentifiable parameter, and NaN intervals (never a silently wrong interval).
* Wald 95 % bounds: θ̂ ± t_{0.975, n−p}·se(θ̂), mapped to F0, M0, a, m, k_x.
  f = F0/N with N known exactly, so its bounds are those of F0 divided by N.
* Profile-likelihood 95 % bounds for a and m: θ_j fixed, the others re-fitted
  (same weights), bounds where χ²_prof(θ_j) − χ²_min = s²·t²_{0.975, n−p}
  (the F(1, n − p) test). Flagged when an end differs from the Wald end by more
  than `PROFILE_TOLERANCE` of the Wald half-width.
* Curves: `Identification.prediction_band` gives the fitted curve with its
  pointwise 95 % *prediction* band ŷ ± t·√(gᵀΣg + s²σ_c²) (parameter covariance
  through the form's Jacobian g, plus the curve's noise level);
  `Identification.curve_stderr` the standard error √(gᵀΣg) of the mean curve.

The form is the paper's closed forms by default, or the generalised model
(`GeneralisedCurves`).

Why scipy and not lmfit: the fit needs the weighted Jacobian itself (its SVD for
the covariance and the condition check, its hat matrix for each curve's share
h_c of the parameters) and re-fits with fixed weights for the profile bounds;
lmfit would wrap the same ``least_squares`` solver and keep the Jacobian out of
reach, so fepost does not depend on it.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import optimize, special

from ..errors import ArgumentError, DataError, FitError, FitWarning
from ..friction.closed_form import f_parallel_ratio, f_perpendicular_ratio, torque_ratio
from ..lsq import jacobian_svd, leverage
from .curves import CURVES, PARAMETERS, TestCurves
from .forms import PAPER
from .result import CONFIDENCE, Identification

#: Weights: stop when every σ_c changes by less than this (relative) ...
REWEIGHT_RTOL = 1e-6
#: ... or after this many refits.
REWEIGHT_MAX = 20
#: Floor of σ_c relative to the curve's scale (noise-free data: weights stay finite).
SIGMA_FLOOR = 1e-12
#: Covariance is called indeterminate above this condition number of J (θ-space, O(1) scales).
COND_MAX = 1e10
#: Profile and Wald bounds "disagree" when an end differs by more than this fraction
#: of the Wald half-width.
PROFILE_TOLERANCE = 0.10
#: Solver tolerances (θ is O(1)); tight enough for 1e-8 recovery of noise-free data.
SOLVER_TOL = 1e-12


@dataclass(frozen=True)
class _Problem:
    psi: np.ndarray
    ups: np.ndarray
    y: np.ndarray  # stacked data: F∥, M_C, F⊥
    slices: tuple[slice, slice, slice]
    R: float
    sF: float
    sM: float
    form: Any = PAPER

    def natural(self, theta) -> np.ndarray:
        """θ → (F0, M0, a, m, k_x)."""
        return np.array(
            [
                self.sF * theta[0],
                self.sM * theta[1],
                math.exp(theta[2]),
                math.exp(theta[3]),
                theta[4],
            ]
        )

    def theta(self, values) -> np.ndarray:
        F0, M0, a, m, kx = values
        return np.array([F0 / self.sF, M0 / self.sM, math.log(a), math.log(m), kx])

    def _abscissae(self):
        return zip(CURVES, (self.psi, self.ups, self.ups), strict=True)

    def model(self, theta) -> np.ndarray:
        values = self.natural(theta)
        return np.concatenate([self.form.values(name, x, values, self.R) for name, x in self._abscissae()])

    def jacobian(self, theta) -> np.ndarray:
        """∂model/∂θ, (n, 5): ∂model/∂(F0, M0, a, m, k_x) times ∂(F0, M0, a, m, k_x)/∂θ."""
        values = self.natural(theta)
        dvalues_dtheta = np.array([self.sF, self.sM, values[2], values[3], 1.0])
        grad = np.concatenate([self.form(name, x, values, self.R)[1] for name, x in self._abscissae()])
        return grad * dvalues_dtheta


def _initial(prob: _Problem) -> np.ndarray:
    """Starting θ by variable projection on a grid of a and m (F0, M0, k_x are linear)."""
    s1, s2, s3 = prob.slices
    y1, y2, y3 = prob.y[s1], prob.y[s2], prob.y[s3]
    grid = np.logspace(-3, 3, 121)

    def best(g_of, y):
        top, scale = None, None
        for p in grid:
            g = g_of(p)
            gg = float(g @ g)
            amp = float(g @ y) / gg
            rss = float(np.sum((y - amp * g) ** 2))
            if top is None or rss < top[0]:
                top, scale = (rss, p), amp
        return top[1], scale

    a, F0 = best(lambda p: f_parallel_ratio(prob.psi, p), y1)
    m, M0 = best(lambda p: torque_ratio(prob.ups, p), y2)
    g3 = f_perpendicular_ratio(prob.ups, m)
    amp3 = float(g3 @ y3) / float(g3 @ g3)
    F0 = F0 if F0 > 0 else prob.sF
    M0 = M0 if M0 > 0 else prob.sM
    kx = amp3 * 2.0 * prob.R / M0
    return prob.theta((F0, M0, a, m, kx))


def _solve(prob: _Problem, theta0, w, max_nfev, fixed: int | None = None, value: float | None = None):
    """least_squares on the weighted residuals; optionally with θ[fixed] = value."""
    if fixed is None:

        def fun(t):
            return (prob.model(t) - prob.y) * w

        def jac(t):
            return prob.jacobian(t) * w[:, None]

        x0 = np.asarray(theta0, float)
    else:
        free = [i for i in range(5) if i != fixed]

        def full(t):
            th = np.empty(5)
            th[free] = t
            th[fixed] = value
            return th

        def fun(t):
            return (prob.model(full(t)) - prob.y) * w

        def jac(t):
            return (prob.jacobian(full(t)) * w[:, None])[:, free]

        x0 = np.asarray(theta0, float)[free]
    res = optimize.least_squares(
        fun,
        x0,
        jac=jac,
        method="lm",
        xtol=SOLVER_TOL,
        ftol=SOLVER_TOL,
        gtol=SOLVER_TOL,
        max_nfev=max_nfev,
    )
    if res.status <= 0 or not np.all(np.isfinite(res.x)):
        raise FitError(f"least-squares fit did not converge ({res.message.strip()}, nfev={res.nfev})")
    return res


def _covariance(prob: _Problem, J: np.ndarray, s2: float) -> tuple[np.ndarray, str | None]:
    """θ covariance s²(JᵀJ)⁻¹ as in curve_fit, or (NaN, reason) when indeterminate."""
    svd = jacobian_svd(J, COND_MAX)
    if not svd.identifiable:
        p = J.shape[1]
        return np.full((p, p), np.nan), f"(condition number {svd.condition:.3g}): {PARAMETERS[svd.weakest]}"
    return svd.inverse * s2, None


def _profile(prob, theta, w, j, chi2_min, delta, wald, max_nfev) -> tuple[float, float]:
    """Profile-likelihood bounds of θ_j where χ²_prof − χ²_min = delta."""

    def excess(v):
        res = _solve(prob, theta, w, max_nfev, fixed=j, value=v)
        return float(np.sum(res.fun**2)) - chi2_min - delta

    ends = []
    for side, wald_end in ((-1, wald[0]), (1, wald[1])):
        step = abs(wald_end - theta[j]) if np.isfinite(wald_end) else 0.1
        step = max(step, 1e-6)
        inner, outer = theta[j], theta[j] + side * step
        found = False
        for _ in range(12):
            if excess(outer) > 0:
                found = True
                break
            inner, outer = outer, outer + side * step
            step *= 2.0
        if not found:
            ends.append(side * np.inf)
            continue
        lo, hi = sorted((inner, outer))
        ends.append(optimize.brentq(excess, lo, hi, xtol=1e-10, rtol=1e-10))
    return ends[0], ends[1]


def _validate(curves: TestCurves, N) -> float:
    if not isinstance(curves, TestCurves):
        raise ArgumentError(f"curves must be TestCurves, got {type(curves).__name__}")
    try:
        N = float(N)
    except (TypeError, ValueError):
        raise ArgumentError(f"N must be a normal load in N, got {N!r}") from None
    if not (np.isfinite(N) and N > 0):
        raise ArgumentError(f"N must be a positive finite normal load in N, got {N!r}")
    need = len(PARAMETERS) + 2
    if curves.n_points < need:
        raise DataError(
            f"curves has {curves.n_points} points in all; "
            f"the fit of {len(PARAMETERS)} parameters needs at least {need}"
        )
    for name in CURVES:
        x, y = curves.data(name)
        if y.size < 2:
            raise DataError(f"curves.{name} has {y.size} point(s); each curve needs at least 2")
        if not np.any(y != 0) and name != "f_perp":
            raise DataError(f"curves.{name} is all zero; nothing to fit")
    return N


def _problem(curves: TestCurves, form) -> _Problem:
    """The three curves as one least-squares problem, with their data scales."""
    n1, n2 = curves.psi.size, curves.upsilon.size
    slices = (slice(0, n1), slice(n1, n1 + n2), slice(n1 + n2, n1 + 2 * n2))
    y = np.concatenate([curves.f_parallel, curves.torque, curves.f_perp])
    scales = [float(np.max(np.abs(y[s]))) for s in slices]
    return _Problem(
        curves.psi,
        curves.upsilon,
        y,
        slices,
        curves.R,
        sF=scales[0] if scales[0] > 0 else 1.0,
        sM=scales[1] if scales[1] > 0 else 1.0,
        form=PAPER if form is None else form,
    )


@dataclass(frozen=True)
class _Weighted:
    """The fit with the converged weights: the solver's result, the weights per point, each
    curve's noise level σ_c and share h_c of the parameters, the model evaluations."""

    result: Any
    weights: np.ndarray
    sigma: np.ndarray
    share: np.ndarray
    nfev: int


def _weighted_fit(prob: _Problem, *, max_nfev: int | None) -> _Weighted:
    """Fit and σ_c iterated to a fixed point, then the final solve with the converged weights."""
    y, slices = prob.y, prob.slices
    scales = [float(np.max(np.abs(y[s]))) for s in slices]
    theta = _initial(prob)
    floor = np.array([SIGMA_FLOOR * (s if s > 0 else 1.0) for s in scales])
    counts = np.array([s.stop - s.start for s in slices], float)
    # Starting weights: each curve's own RSS at the initial guess.
    r0 = prob.model(theta) - y
    sigma = np.maximum([math.sqrt(np.mean(r0[s] ** 2)) for s in slices], floor)
    nfev = 0
    for _ in range(REWEIGHT_MAX):
        w = np.concatenate([np.full(int(c), 1.0 / sg) for c, sg in zip(counts, sigma, strict=True)])
        res = _solve(prob, theta, w, max_nfev)
        theta, nfev = res.x, nfev + res.nfev
        h = leverage(res.jac)
        r = prob.model(theta) - y
        share = np.array([h[s].sum() for s in slices])
        dof_c = np.maximum(counts - share, 0.5)
        new = np.maximum(
            [math.sqrt(np.sum(r[s] ** 2) / d) for s, d in zip(slices, dof_c, strict=True)], floor
        )
        done = np.all(np.abs(new - sigma) <= REWEIGHT_RTOL * sigma)
        sigma = new
        if done:
            break
    # Final solve with the converged weights (so the fit and the weights agree).
    w = np.concatenate([np.full(int(c), 1.0 / sg) for c, sg in zip(counts, sigma, strict=True)])
    res = _solve(prob, theta, w, max_nfev)
    return _Weighted(res, w, sigma, share, nfev + res.nfev)


def _profile_bounds(
    prob: _Problem, *, theta, w, chi2: float, delta: float, wald, ci, max_nfev: int | None
) -> tuple[dict[str, tuple[float, float]], dict[str, bool]]:
    """Profile-likelihood 95 % bounds of a and m, and whether each agrees with its Wald interval."""
    lo_t, hi_t = wald
    prof: dict[str, tuple[float, float]] = {}
    agree: dict[str, bool] = {}
    for j, name in ((2, "a"), (3, "m")):
        try:
            lo, hi = _profile(prob, theta, w, j, chi2, delta, (lo_t[j], hi_t[j]), max_nfev)
        except FitError as exc:
            warnings.warn(
                f"profile bounds of {name} not computed (a re-fit failed: {exc}); set to NaN",
                FitWarning,
                stacklevel=3,
            )
            prof[name], agree[name] = (math.nan, math.nan), False
            continue
        plo, phi = (
            math.exp(lo) if np.isfinite(lo) else 0.0,
            math.exp(hi) if np.isfinite(hi) else math.inf,
        )
        prof[name] = (plo, phi)
        half = 0.5 * (ci[j, 1] - ci[j, 0])
        agree[name] = bool(max(abs(plo - ci[j, 0]), abs(phi - ci[j, 1])) <= PROFILE_TOLERANCE * half)
    return prof, agree


def fit_table1(
    curves: TestCurves,
    N: float,
    *,
    form=None,
    profile: bool = True,
    max_nfev: int | None = None,
) -> Identification:
    """Fit F0, M0, a, m, k_x jointly to the three curves; f = F0/N (N in N).

    See the module docstring for the method (weights, covariance, intervals).
    ``form``: the curves fitted: the paper's closed forms (default, `PAPER`)
    or a `GeneralisedCurves`.
    ``profile``: also compute profile-likelihood bounds of a and m.
    ``max_nfev``: cap on model evaluations per least-squares solve.
    Raises `FitError` when the solver does not converge and
    `DataError` for too few points; warns
    `FitWarning` (with NaN intervals) when the covariance is
    indeterminate.

    Examples
    --------
    Noise-free curves give back the coefficients they were made with; with the
    paper's 20 % noise the 95 % interval holds them:

    >>> from fepost.identify import fit_table1, make_test_curves
    >>> truth = {"F0": 3870.0, "M0": 277.3, "a": 0.94, "m": 9.5, "k_x": 0.2, "R": 0.12, "N": 12900.0}
    >>> exact = fit_table1(make_test_curves("closed_form", truth, amplitude=0.0), truth["N"])
    >>> [round(exact.value(k), 6) for k in ("F0", "M0", "a", "m", "k_x")]
    [3870.0, 277.3, 0.94, 9.5, 0.2]
    >>> noisy = fit_table1(make_test_curves("closed_form", truth, seed=1), truth["N"], profile=False)
    >>> lo, hi = noisy.interval("a")
    >>> bool(lo < truth["a"] < hi), round(noisy.f, 2)
    (True, 0.31)
    """
    N = _validate(curves, N)
    if form is not None and not (callable(form) and hasattr(form, "values")):
        raise ArgumentError(
            f"form must be a curve form (PaperCurves, GeneralisedCurves), got {type(form).__name__}"
        )
    prob = _problem(curves, form)
    y, slices = prob.y, prob.slices
    weighted = _weighted_fit(prob, max_nfev=max_nfev)
    res, w, sigma, share = weighted.result, weighted.weights, weighted.sigma, weighted.share
    theta, nfev = res.x, weighted.nfev
    J = res.jac
    n, p = y.size, len(PARAMETERS)
    dof = n - p
    chi2 = float(np.sum(res.fun**2))
    s2 = chi2 / dof
    tq = float(special.stdtrit(dof, 0.5 + CONFIDENCE / 2.0))  # Student-t quantile
    cov_t, reason = _covariance(prob, J, s2)
    values = prob.natural(theta)
    # Map θ-space to the natural parameters: linear for F0, M0, k_x; exp for a, m.
    D = np.diag([prob.sF, prob.sM, values[2], values[3], 1.0])
    cov = D @ cov_t @ D
    se_t = np.sqrt(np.diag(cov_t))
    lo_t, hi_t = theta - tq * se_t, theta + tq * se_t
    ci = np.column_stack([prob.natural(lo_t), prob.natural(hi_t)])
    stderr = np.sqrt(np.diag(cov))
    prof: dict[str, tuple[float, float]] = {}
    agree: dict[str, bool] = {}
    determinate = reason is None
    if not determinate:
        warnings.warn(
            f"covariance of the Table 1 fit is indeterminate {reason} is not identifiable "
            "from these curves; intervals set to NaN",
            FitWarning,
            stacklevel=2,
        )
    elif profile:
        prof, agree = _profile_bounds(
            prob, theta=theta, w=w, chi2=chi2, delta=s2 * tq**2, wald=(lo_t, hi_t), ci=ci, max_nfev=max_nfev
        )
    resid = {name: -res.fun[s] / w[s] for name, s in zip(CURVES, slices, strict=True)}
    return Identification(
        values=values,
        stderr=stderr,
        ci95=ci,
        covariance=cov,
        profile_ci95=prof,
        profile_agrees=agree,
        f=float(values[0] / N),
        f_stderr=float(stderr[0] / N),
        f_ci95=(float(ci[0, 0] / N), float(ci[0, 1] / N)),
        N=N,
        R=curves.R,
        noise_sigma=dict(zip(CURVES, map(float, sigma), strict=True)),
        dof_share=dict(zip(CURVES, map(float, share), strict=True)),
        residuals=resid,
        chi2=chi2,
        dof=dof,
        redchi=s2,
        aic=float(n * math.log(chi2 / n) + 2 * p) if chi2 > 0 else -math.inf,
        bic=float(n * math.log(chi2 / n) + p * math.log(n)) if chi2 > 0 else -math.inf,
        nfev=int(nfev),
        n_points=n,
        t_quantile=tq,
        determinate=determinate,
        form=prob.form,
    )
