"""Lack of fit: structure that the chosen model leaves and no cause in the vocabulary explains.

All tests use the standardised residuals z_ic = r_ic/σ_ic of the chosen model on
the rows kept (outliers left out), stacked over the three channels (N = 3n
observations), and its whitened Jacobian J (p mean parameters). Observations
whose noise SD is below `FLOOR_FACTOR` × the noise floor
(`fepost.diagnose.noise.NOISE_FLOOR`, the model's numerical accuracy)
are left out of the tests (their z are set to zero and their rows and columns
dropped): there the floor, not the data, sets σ, so their scatter measures
neither noise nor misfit (a force that is zero by symmetry, measured with noise
proportional to the reading, has no scatter at all).

1. **Pure error, per channel** (rows with equal vx, vy, wz, N and roll are
   replicates). For each channel c (Fx, Fy, Mz) separately: with m distinct test
   points, the replicates' scatter about their own means
   SS_pe,c = Σ (z − z̄_group)² (n − m degrees of freedom) estimates that
   channel's noise whatever the model; the rest of its residual sum of squares,
   SS_lof,c = Σ z² − SS_pe,c, has m − p_c degrees of freedom, where p_c is the
   share of the model's p parameters spent on channel c: the sum of the
   leverages (diagonal of the hat matrix of the whitened Jacobian) of its
   observations (Σ_c p_c = p). Each channel's test
   F_c = [SS_lof,c/(m − p_c)] / [SS_pe,c/(n − m)] ~ F(m − p_c, n − m)
   measures the misfit against the pure-error scatter of that channel alone: the
   noise model's σ cancels (replicates share it), so a misfit that inflates one
   channel's fitted noise cannot hide itself, and two clean channels cannot
   dilute it (a pooled three-channel test, `pure_error_test`, is diluted
   by both). Needs at least `MIN_PURE_ERROR_DF` replicate degrees of
   freedom per channel. For the hold means of a time series
   (`fepost.diagnose.holds`) every row has its own standard error s_ic
   from the scatter within its hold (autocorrelation accounted for) on ν_i
   degrees of freedom; then F_c = Σ_i (r_ic/s_ic)²/(m − p_c) ~ F(m − p_c, Σ ν_i),
   with p_c from the Jacobian whitened by s.
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
order. The family of tests (the three pure-error tests, one per channel, and the
run-order tests) is corrected by Holm's step-down method at `LOF_LEVEL`:
lack of fit is **detected** when the smallest p-value times the number of tests
is below it. ``p_value`` is that Holm-adjusted p-value of the strongest test and
``test`` its name; ``channels`` gives each channel's pure-error test
({``detected``, ``p_value`` (Holm-adjusted), ``p_raw``, ...}), and the message
names the channel(s) whose test rejects.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from .measured import CHANNELS, MeasuredData, point_keys
from .noise import NOISE_FLOOR

#: Family-wise level of the lack-of-fit verdict (Holm over the tests that apply).
LOF_LEVEL = 0.01
#: Fewest replicate degrees of freedom (per channel) for the pure-error test.
MIN_PURE_ERROR_DF = 3
#: Observations with σ below this many noise floors are left out of the tests.
FLOOR_FACTOR = 2.0

PREFIX = "the chosen model leaves structure that no cause in the vocabulary explains: "
PURE = tuple(f"pure_error_{ch}" for ch in CHANNELS)
STRUCTURE = tuple(f"structure_{ch}" for ch in CHANNELS)
WHY = {
    "structure": "the residuals follow the predicted forces",
    "pure_error": "the misfit is larger than the scatter of replicated test points",
    "trend_file": "the residuals drift with run order",
    "serial_file": "the residuals drift with run order (neighbouring rows are alike)",
    "trend_time": "the residuals drift with time",
    "serial_time": "the residuals drift with time (points measured close in time are alike)",
}
TITLES = (
    {
        "pure_error": "pure-error lack-of-fit F-test (replicated test points)",
        "trend_file": "run-order trend (file order)",
        "serial_file": "run-order serial correlation (file order)",
        "trend_time": "run-order trend (time column)",
        "serial_time": "run-order serial correlation (time column)",
    }
    | {f"pure_error_{ch}": f"pure-error lack-of-fit F-test of {ch}" for ch in CHANNELS}
    | {
        f"structure_{ch}": f"residual structure of {ch} (F-test on the predicted Fx, Fy, Mz)"
        for ch in CHANNELS
    }
)


def _rank_basis(X: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """Orthonormal basis of the column space of X (rank-revealing SVD)."""
    if X.size == 0 or X.shape[1] == 0:
        return np.zeros((X.shape[0], 0))
    u, s, _ = np.linalg.svd(X, full_matrices=False)
    keep = s > rtol * (s[0] if s.size else 0.0)
    return u[:, keep]


def pure_error_test(z: np.ndarray, labels: np.ndarray, p: int, used: np.ndarray | None = None) -> dict | None:
    """The pooled pure-error F-test over the three channels; None when there are too few replicates.

    ``used`` (n, 3) marks the observations tested (default all); replicates share
    a prediction and a σ, so a channel is used in all rows of a group or in none.
    The verdict uses the per-channel tests (`channel_pure_error_test`); this
    pooled form is kept for comparison.
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


def channel_pure_error_test(z: np.ndarray, labels: np.ndarray, p_c: float) -> dict | None:
    """The pure-error F-test of one channel (module docstring, test 1); None without replicates.

    ``z`` (n,) the channel's standardised residuals on the rows it is tested on,
    ``labels`` their test points, ``p_c`` the parameters it spends (sum of its leverages).
    """
    groups, inverse, counts = np.unique(labels, return_inverse=True, return_counts=True)
    m = groups.size
    means = np.bincount(inverse, weights=z, minlength=m) / counts
    df_pe = int(z.size - m)
    df_lof = m - p_c
    if df_pe < MIN_PURE_ERROR_DF or df_lof <= 0.5:
        return None
    ss_pe = float(np.sum((z - means[inverse]) ** 2))
    if ss_pe <= 0:
        return None
    ss_lof = max(float(np.sum(z**2)) - ss_pe, 0.0)
    F = (ss_lof / df_lof) / (ss_pe / df_pe)
    return {
        "p": float(stats.f.sf(F, df_lof, df_pe)),
        "statistic": F,
        "df": [float(df_lof), df_pe],
        "replicated_points": int(np.count_nonzero(counts > 1)),
        "rms_over_pure_error": float(np.sqrt(np.mean(z**2) / (ss_pe / df_pe))),
    }


def hold_pure_error_test(z: np.ndarray, dof: np.ndarray, p_c: float) -> dict | None:
    """The pure-error test of one channel of hold means (module docstring, test 1).

    ``z`` (m,) residuals over each hold mean's standard error, ``dof`` (m,) the
    degrees of freedom of each standard error.
    """
    df_lof = z.size - p_c
    df_pe = float(np.sum(dof))
    if df_pe < MIN_PURE_ERROR_DF or df_lof <= 0.5:
        return None
    F = float(np.sum(z**2)) / df_lof
    return {
        "p": float(stats.f.sf(F, df_lof, df_pe)),
        "statistic": F,
        "df": [float(df_lof), df_pe],
        "replicated_points": int(z.size),
        "rms_over_pure_error": float(np.sqrt(np.mean(z**2))),
    }


def channel_leverages(J: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """(n, 3) leverages of the observations (zero where not ``keep``) of the whitened Jacobian."""
    h = np.zeros(keep.size)
    if J.size:
        Q = _rank_basis(J[keep])
        h[keep] = np.sum(Q**2, axis=1)
    return h.reshape(-1, 3)


def structure_test(z: np.ndarray, J: np.ndarray, basis: np.ndarray) -> dict:
    """Partial F-test of ``basis`` (n, q) for one channel's ``z`` (n,) after its Jacobian block ``J`` (n, p).

    The fitted residuals are orthogonal to the whole Jacobian, so after removing
    this channel's block J_c they are (I − P_J_c) times the noise exactly (linear
    model): F = [SS_basis/q] / [SS_rest/(n − k − q)] ~ F(q, n − k − q).
    """
    return _partial_f(z, J, basis, rtol=1e-6)


def _partial_f(y: np.ndarray, base: np.ndarray, extra: np.ndarray, *, rtol: float = 1e-9) -> dict:
    """Partial F-test of the columns ``extra`` for ``y`` after the columns ``base``.

    ``rtol``: rank tolerance of the extra columns once ``base`` is projected out.
    """
    Qb = _rank_basis(base)
    r0 = y - Qb @ (Qb.T @ y)
    d = extra - Qb @ (Qb.T @ extra)
    Qd = _rank_basis(d, rtol=rtol)
    q, N, k = Qd.shape[1], y.size, Qb.shape[1]
    if q == 0 or N - k - q < 1:
        return {"p": 1.0, "statistic": 0.0, "df": [0, N - k]}
    ss_d = float(np.sum((Qd.T @ r0) ** 2))
    ss_e = float(np.sum(r0**2)) - ss_d
    F = (ss_d / q) / (max(ss_e, 1e-300) / (N - k - q))
    return {"p": float(stats.f.sf(F, q, N - k - q)), "statistic": F, "df": [q, N - k - q]}


def trend_test(z: np.ndarray, level: np.ndarray, inv_sigma: np.ndarray, J: np.ndarray, t: np.ndarray) -> dict:
    """Partial F-test of t·L and t·e_c/σ after J, L and e_c/σ (module docstring)."""
    n = z.shape[0]
    t = np.asarray(t, float)
    tt = (t - t.mean()) / (t.std() or 1.0)
    static = [level.ravel()] + [(np.eye(3)[c][None, :] * inv_sigma).ravel() for c in range(3)]
    base = np.column_stack([J, *static]) if J.size else np.column_stack(static)
    drift = np.column_stack([(tt[:, None] * s.reshape(n, 3)).ravel() for s in static])
    keep = np.ravel(inv_sigma) > 0
    return _partial_f(z.ravel()[keep], base[keep], drift[keep])


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


def _pure_error_tests(z, used, labels, h, pure_error) -> dict[str, dict]:
    """Test 1 per channel: on replicates, or on hold means with their own standard errors."""
    tests: dict[str, dict] = {}
    for c, ch in enumerate(CHANNELS):
        u = used[:, c]
        if not np.any(u):
            continue
        p_c = float(np.sum(h[u, c]))
        if pure_error is None:
            got = channel_pure_error_test(z[u, c], labels[u], p_c)
        else:
            got = hold_pure_error_test(z[u, c], np.asarray(pure_error[1])[u], p_c)
        if got is not None:
            tests[f"pure_error_{ch}"] = got | {"leverage": p_c}
    return tests


def _structure_tests(z, used, level, inv_sigma, J) -> dict[str, dict]:
    """Test 4 per channel: z_c against the model's three predicted channels and a constant."""
    tests: dict[str, dict] = {}
    n = z.shape[0]
    Jr = J.reshape(n, 3, -1) if J.size else np.zeros((n, 3, 0))
    sig_ratio = np.where(used, inv_sigma, 0.0)
    for c, ch in enumerate(CHANNELS):
        u = used[:, c]
        if np.count_nonzero(u) < 8:
            continue
        # the other channels' predictions in this channel's whitened units: ŷ_k·(1/σ_c)
        basis = np.column_stack([level[u, k] / np.where(sig_ratio[u, k] > 0, sig_ratio[u, k], 1.0)
                                 for k in range(3)] + [np.ones(int(np.count_nonzero(u)))])  # fmt: skip
        basis = basis * sig_ratio[u, c][:, None]
        tests[f"structure_{ch}"] = structure_test(z[u, c], Jr[u, c, :], basis)
    return tests


def _message(tests: dict, adjusted: dict, strongest: str, detected: bool, has_time: bool) -> str:
    if detected:
        if strongest in PURE or strongest in STRUCTURE:
            kind = PURE if strongest in PURE else STRUCTURE
            channels = [k.rsplit("_", 1)[1] for k in kind if k in adjusted and adjusted[k] < LOF_LEVEL]
            why = WHY["pure_error"] if kind is PURE else WHY["structure"]
            return PREFIX + why + f" in {', '.join(channels)}"
        return PREFIX + WHY[strongest]
    order = "run order" + (" or time" if has_time else "")
    checked = [f"the residuals do not drift with {order}"]
    if any(k in tests for k in PURE):
        checked.insert(0, "the misfit is within the scatter of replicated test points in every channel")
    else:
        checked.append("no replicated test points: the pure-error test was not possible")
    return "no structure left beyond the noise: " + "; ".join(checked)


def lack_of_fit(
    data: MeasuredData,
    rows: np.ndarray,
    residuals: np.ndarray,
    prediction: np.ndarray,
    sigma: np.ndarray,
    jacobian: np.ndarray | None,
    *,
    pure_error: tuple[np.ndarray, np.ndarray] | None = None,
) -> dict:
    """The lack-of-fit verdict of the chosen model on ``rows`` (module docstring).

    ``residuals``, ``prediction`` and ``sigma`` are (len(rows), 3) in scaled
    units; ``jacobian`` the whitened Jacobian (3·len(rows), p) or None.
    ``pure_error``: for hold means, (standard errors (len(rows), 3) in scaled
    units, their degrees of freedom (len(rows),)); None for test points, whose
    replicates give the pure error.
    Returns {detected, p_value, test, message, level, channels: {...}, tests: {...}}.
    """
    rows = np.asarray(rows)
    used = sigma >= FLOOR_FACTOR * NOISE_FLOOR
    z = np.where(used, residuals / sigma, 0.0)
    level = np.where(used, prediction / sigma, 0.0)
    inv_sigma = np.where(used, 1.0 / sigma, 0.0)
    J = np.zeros((z.size, 0)) if jacobian is None else np.asarray(jacobian) * used.ravel()[:, None]
    keep = used.ravel()
    if pure_error is None:
        h = channel_leverages(J, keep)
        tests = _pure_error_tests(z, used, point_keys(data)[rows], h, None)
    else:
        se = np.asarray(pure_error[0], float)
        used_pe = used & (se > 0)
        ratio = np.where(used_pe, sigma / np.where(se > 0, se, 1.0), 0.0)
        h = channel_leverages(J * ratio.ravel()[:, None], used_pe.ravel())
        tests = _pure_error_tests(z * ratio, used_pe, np.arange(rows.size), h, pure_error)
    tests |= _structure_tests(z, used, level, inv_sigma, J)
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
    channels = {}
    for ch, key, key_s in zip(CHANNELS, PURE, STRUCTURE, strict=True):
        t, ts = tests.get(key), tests.get(key_s)
        channels[ch] = {
            "detected": bool(
                (t is not None and adjusted[key] < LOF_LEVEL)
                or (ts is not None and adjusted[key_s] < LOF_LEVEL)
            ),
            "structure_p_value": None if ts is None else float(adjusted[key_s]),
            "p_value": None if t is None else float(adjusted[key]),
            "p_raw": None if t is None else float(t["p"]),
            "statistic": None if t is None else float(t["statistic"]),
            "df": None if t is None else t["df"],
            "rms_over_pure_error": None if t is None else t["rms_over_pure_error"],
        }
    return {
        "detected": bool(detected),
        "p_value": float(adjusted[strongest]),
        "test": TITLES[strongest],
        "message": _message(tests, adjusted, strongest, detected, data.time is not None),
        "level": LOF_LEVEL,
        "correction": f"Holm over {len(tests)} tests",
        "observations_tested": int(np.count_nonzero(used)),
        "pure_error_source": "replicated test points" if pure_error is None else "scatter within holds",
        "channels": channels,
        "tests": tests,
    }
