"""Lack of fit: structure that the chosen model leaves and no cause in the vocabulary explains.

All tests use the standardised residuals z_ic = r_ic/σ_ic of the chosen model on
the rows kept (outliers left out), stacked over the three channels (N = 3n
observations), and its whitened Jacobian J (p mean parameters). Observations
whose noise SD is below :data:`FLOOR_FACTOR` × the noise floor
(:data:`~fepost.diagnose.noise.NOISE_FLOOR`, the model's numerical accuracy)
are left out of the tests (their z are set to zero and their rows and columns
dropped): there the floor, not the data, sets σ, so their scatter measures
neither noise nor misfit (a force that is zero by symmetry, measured with noise
proportional to the reading, has no scatter at all).

1. **Pure error** (rows with equal vx, vy, wz, N and roll are replicates). With m
   distinct test points, the replicates' scatter about their own means
   SS_pe = Σ (z − z̄_group)² (3(n − m) degrees of freedom) estimates the noise
   whatever the model; the rest of the residual sum of squares,
   SS_lof = Σ z² − SS_pe, has 3m − p degrees of freedom (every model predicts
   the same value for replicates, so its fitted values lie in the span of the
   group means). The classical lack-of-fit test:
   F = [SS_lof/(3m − p)] / [SS_pe/(3(n − m))] ~ F(3m − p, 3(n − m)).
   Needs at least :data:`MIN_PURE_ERROR_DF` replicate degrees of freedom.
2. **Run-order trend.** With t the run position (row order in the file; or the
   ``time`` column), regress z on t·L and t·e_c/σ, where L_ic = ŷ_ic/σ_ic is the
   row's own prediction (a friction level changing along the run moves every
   force along it) and e_c/σ a unit offset of channel c (a drifting sensor),
   after the model's own directions J, L and e_c/σ: the partial F-test of those
   q ≤ 4 regressors.
3. **Run-order serial correlation.** The residual along each row's prediction,
   u_i = Σ_c z_ic L_ic/‖L_i‖, in run order: its lag-1 autocorrelation ρ₁,
   one-sided test √n (ρ₁ + 1/n) ~ N(0, 1) under independence. A level that wanders
   (not only linearly) makes neighbours alike.

Tests 2 and 3 run in file order and, when the data carry ``time``, in time
order. The family of tests is corrected by Holm's step-down method at
:data:`LOF_LEVEL`: lack of fit is **detected** when the smallest p-value times the
number of tests is below it. ``p_value`` is that Holm-adjusted p-value of the
strongest test and ``test`` its name.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from .measured import MeasuredData, point_keys
from .noise import NOISE_FLOOR

#: Family-wise level of the lack-of-fit verdict (Holm over the tests that apply).
LOF_LEVEL = 0.01
#: Fewest replicate degrees of freedom (per channel) for the pure-error test.
MIN_PURE_ERROR_DF = 3
#: Observations with σ below this many noise floors are left out of the tests.
FLOOR_FACTOR = 2.0

PREFIX = "the chosen model leaves structure that no cause in the vocabulary explains: "
WHY = {
    "pure_error": "the misfit is larger than the scatter of replicated test points",
    "trend_file": "the residuals drift with run order",
    "serial_file": "the residuals drift with run order (neighbouring rows are alike)",
    "trend_time": "the residuals drift with time",
    "serial_time": "the residuals drift with time (points measured close in time are alike)",
}
TITLES = {
    "pure_error": "pure-error lack-of-fit F-test (replicated test points)",
    "trend_file": "run-order trend (file order)",
    "serial_file": "run-order serial correlation (file order)",
    "trend_time": "run-order trend (time column)",
    "serial_time": "run-order serial correlation (time column)",
}


def _rank_basis(X: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """Orthonormal basis of the column space of X (rank-revealing SVD)."""
    if X.size == 0 or X.shape[1] == 0:
        return np.zeros((X.shape[0], 0))
    u, s, _ = np.linalg.svd(X, full_matrices=False)
    keep = s > rtol * (s[0] if s.size else 0.0)
    return u[:, keep]


def pure_error_test(z: np.ndarray, labels: np.ndarray, p: int, used: np.ndarray | None = None) -> dict | None:
    """The pure-error F-test (module docstring); None when there are too few replicates.

    ``used`` (n, 3) marks the observations tested (default all); replicates share
    a prediction and a σ, so a channel is used in all rows of a group or in none.
    """
    used = np.ones(z.shape, bool) if used is None else used
    groups, inverse, counts = np.unique(labels, return_inverse=True, return_counts=True)
    m = groups.size
    sums = np.zeros((m, 3))
    np.add.at(sums, inverse, np.where(used, z, 0.0))
    nobs = np.zeros((m, 3))
    np.add.at(nobs, inverse, used.astype(float))
    means = np.divide(sums, nobs, out=np.zeros_like(sums), where=nobs > 0)
    df_pe = int(np.sum(np.maximum(nobs - 1, 0)))
    cells = int(np.count_nonzero(nobs))
    if df_pe < 3 * MIN_PURE_ERROR_DF:
        return None
    ss_pe = float(np.sum(np.where(used, z - means[inverse], 0.0) ** 2))
    ss_res = float(np.sum(np.where(used, z, 0.0) ** 2))
    df_lof = cells - p
    if df_lof < 1 or ss_pe <= 0:
        return None
    ss_lof = max(ss_res - ss_pe, 0.0)
    F = (ss_lof / df_lof) / (ss_pe / df_pe)
    return {
        "p": float(stats.f.sf(F, df_lof, df_pe)),
        "statistic": F,
        "df": [df_lof, df_pe],
        "replicated_points": int(np.count_nonzero(counts > 1)),
        "ratio_lof_to_pure_error": F,
    }


def trend_test(z: np.ndarray, level: np.ndarray, inv_sigma: np.ndarray, J: np.ndarray, t: np.ndarray) -> dict:
    """Partial F-test of t·L and t·e_c/σ after J, L and e_c/σ (module docstring)."""
    n = z.shape[0]
    t = np.asarray(t, float)
    tt = (t - t.mean()) / (t.std() or 1.0)
    static = [level.ravel()] + [(np.eye(3)[c][None, :] * inv_sigma).ravel() for c in range(3)]
    base = np.column_stack([J, *static]) if J.size else np.column_stack(static)
    drift = np.column_stack([(tt[:, None] * s.reshape(n, 3)).ravel() for s in static])
    keep = np.ravel(inv_sigma) > 0
    base, drift = base[keep], drift[keep]
    Qb = _rank_basis(base)
    y = z.ravel()[keep]
    r0 = y - Qb @ (Qb.T @ y)
    d = drift - Qb @ (Qb.T @ drift)
    Qd = _rank_basis(d)
    q = Qd.shape[1]
    N, k = y.size, Qb.shape[1]
    if q == 0 or N - k - q < 1:
        return {"p": 1.0, "statistic": 0.0, "df": [0, N - k]}
    ss_d = float(np.sum((Qd.T @ r0) ** 2))
    ss_e = float(np.sum(r0**2)) - ss_d
    F = (ss_d / q) / (max(ss_e, 1e-300) / (N - k - q))
    return {"p": float(stats.f.sf(F, q, N - k - q)), "statistic": F, "df": [q, N - k - q]}


def serial_test(z: np.ndarray, level: np.ndarray, order: np.ndarray) -> dict:
    """Lag-1 autocorrelation of the residual along each row's prediction, in ``order``."""
    norm = np.sqrt(np.sum(level**2, axis=1))
    ok = norm > 1e-12 * max(float(norm.max()), 1e-300)
    u = np.sum(z * level, axis=1)[order] / np.where(norm > 0, norm, 1.0)[order]
    u = u[ok[order]]
    m = u.size
    if m < 3:
        return {"p": 1.0, "statistic": 0.0, "rho1": 0.0}
    u = u - u.mean()
    den = float(np.sum(u * u))
    rho = float(np.sum(u[1:] * u[:-1]) / den) if den > 0 else 0.0
    zstat = np.sqrt(m) * (rho + 1.0 / m)
    return {"p": float(stats.norm.sf(zstat)), "statistic": float(zstat), "rho1": rho}


def holm(pvalues: dict[str, float]) -> dict[str, float]:
    """Holm's step-down adjusted p-values."""
    names = sorted(pvalues, key=pvalues.__getitem__)
    m = len(names)
    out, running = {}, 0.0
    for i, name in enumerate(names):
        running = max(running, min(1.0, (m - i) * pvalues[name]))
        out[name] = running
    return out


def lack_of_fit(
    data: MeasuredData,
    rows: np.ndarray,
    residuals: np.ndarray,
    prediction: np.ndarray,
    sigma: np.ndarray,
    jacobian: np.ndarray | None,
) -> dict:
    """The lack-of-fit verdict of the chosen model on ``rows`` (module docstring).

    ``residuals``, ``prediction`` and ``sigma`` are (len(rows), 3) in scaled
    units; ``jacobian`` the whitened Jacobian (3·len(rows), p) or None.
    Returns {detected, p_value, test, message, level, tests: {...}}.
    """
    rows = np.asarray(rows)
    used = sigma >= FLOOR_FACTOR * NOISE_FLOOR
    z = np.where(used, residuals / sigma, 0.0)
    level = np.where(used, prediction / sigma, 0.0)
    inv_sigma = np.where(used, 1.0 / sigma, 0.0)
    J = np.zeros((z.size, 0)) if jacobian is None else np.asarray(jacobian) * used.ravel()[:, None]
    keep = used.ravel()
    p = _rank_basis(J[keep]).shape[1] if J.size else 0
    tests: dict[str, dict] = {}
    pe = pure_error_test(z, point_keys(data)[rows], p, used)
    if pe is not None:
        tests["pure_error"] = pe
    position = np.arange(rows.size, dtype=float)  # rows are in file order
    tests["trend_file"] = trend_test(z, level, inv_sigma, J, position)
    tests["serial_file"] = serial_test(z, level, np.arange(rows.size))
    if data.time is not None:
        time = np.asarray(data.time, float)[rows]
        tests["trend_time"] = trend_test(z, level, inv_sigma, J, time)
        tests["serial_time"] = serial_test(z, level, np.argsort(time, kind="stable"))
    adjusted = holm({k: v["p"] for k, v in tests.items()})
    for k, v in tests.items():
        v["p_holm"] = adjusted[k]
        v["title"] = TITLES[k]
    strongest = min(adjusted, key=lambda k: (adjusted[k], tests[k]["p"]))
    detected = adjusted[strongest] < LOF_LEVEL
    if detected:
        message = PREFIX + WHY[strongest]
    else:
        order = "run order" + (" or time" if data.time is not None else "")
        checked = [f"the residuals do not drift with {order}"]
        if pe is not None:
            checked.insert(0, "the misfit is within the scatter of replicated test points")
        else:
            checked.append("no replicated test points: the pure-error test was not possible")
        message = "no structure left beyond the noise: " + "; ".join(checked)
    return {
        "detected": bool(detected),
        "p_value": float(adjusted[strongest]),
        "test": TITLES[strongest],
        "message": message,
        "level": LOF_LEVEL,
        "correction": f"Holm over {len(tests)} tests",
        "observations_tested": int(np.count_nonzero(used)),
        "tests": tests,
    }
