"""Tests of fepost.identify: test curves, the Table 1 fitter and the exact-data bias.

Tolerances:
* IDENTITY = 1e-12: algebraic identities (f = F0/N, read-only arrays, ...).
* RECOVERY = 1e-8: noise-free closed-form data must give the coefficients back
  (solver tolerances 1e-12 on O(1) parameters).
* TABLE_TOL = 5e-7: exact integrals against the reference table of docs/theory.md (trusted to ~1e-7,
  plus ~1e-7 quadrature error of the 48 x 96 edge grid, measured).
* AGREE = 1e-6: our fit against scipy.optimize.curve_fit on the same weighted problem
  (two solvers stopping at ~1e-8 relative changes).
* BAND_AGREE = 1e-5: prediction band against one built from curve_fit's covariance and
  a finite-difference gradient; limited by the covariance agreement (1e-5 on the
  standard errors, test_agrees_with_scipy_curve_fit).
* Monte-Carlo (300 seeded Gaussian data sets, 50 points per curve):
  COVERAGE_TOL = 0.006, 4 x the measured standard error (0.0015) of the mean coverage;
  STD_TOL = 0.16, 4 x the relative standard error 1/sqrt(2(M - 1)) = 0.041 of a
  sample standard deviation from M = 300 fits.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from scipy.optimize import approx_fprime, curve_fit

from fepost import analytic
from fepost.errors import ArgumentError, DataError, FitError, FitWarning
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.identify import (
    PARAMETERS,
    TestCurves,
    approximation_bias,
    curve_model,
    exact_curves,
    fit_table1,
    lag1_autocorrelation,
    make_test_curves,
    rolling_model,
    runs_test,
)
from fepost.polar import PolarMap

IDENTITY = 1e-12
RECOVERY = 1e-8
TABLE_TOL = 5e-7
AGREE = 1e-6
BAND_AGREE = 1e-5
MC_FITS = 300
COVERAGE_TOL = 0.006
STD_TOL = 0.16

R, PEAK, FRICTION, K_X = 0.1, 2.0e5, 0.3, 0.13


@pytest.fixture(scope="module")
def truth() -> dict:
    c = analytic.coefficients("hertz", R, PEAK, FRICTION)
    return {
        "F0": c["F0"],
        "M0": c["M0"],
        "a": c["a"],
        "m": c["m"],
        "k_x": K_X,
        "R": R,
        "N": analytic.load("hertz", R, PEAK),
    }


@pytest.fixture(scope="module")
def hertz_quad() -> PressureQuadrature:
    pm = PolarMap.from_function(analytic.pressure_function("hertz", R, PEAK), R, grid=edge_grid())
    return PressureQuadrature.from_polar(pm)


# --- test curves ---------------------------------------------------------------------
def test_closed_form_curves_follow_theory_and_noise_is_bounded(truth):
    c = make_test_curves("closed_form", truth, n_points=40, seed=3)
    assert c.psi.size == c.upsilon.size == 40 and c.n_points == 120
    assert c.f_parallel_true[0] == pytest.approx(truth["F0"], rel=IDENTITY)
    assert c.torque_true[0] == pytest.approx(truth["M0"], rel=IDENTITY)
    assert c.f_perp_true[0] == pytest.approx(K_X * truth["M0"] / (2 * R), rel=IDENTITY)
    np.testing.assert_allclose(
        c.f_parallel_true, truth["F0"] / np.sqrt(1 + truth["a"] * c.psi**2), rtol=IDENTITY
    )
    for name, top in (
        ("f_parallel", truth["F0"]),
        ("torque", truth["M0"]),
        ("f_perp", K_X * truth["M0"] / (2 * R)),
    ):
        e = getattr(c, name) - getattr(c, f"{name}_true")
        assert np.max(np.abs(e)) <= 0.2 * top * (1 + IDENTITY)
        assert c.noise["amplitude"][name] == pytest.approx(0.2 * top, rel=IDENTITY)
        assert np.std(e) > 0.05 * top  # the noise is there (uniform: std = 0.2/sqrt(3) = 0.115)


def test_seeded_noise_is_reproducible_and_gaussian_has_uniform_variance(truth):
    a = make_test_curves("closed_form", truth, seed=11)
    b = make_test_curves("closed_form", truth, seed=11)
    np.testing.assert_array_equal(a.torque, b.torque)
    g = make_test_curves("closed_form", truth, seed=11, noise="gaussian", n_points=4000)
    e = g.f_parallel - g.f_parallel_true
    # std of the mean of 4000 draws: 0.115/sqrt(2*4000) relative -> 5 % band is > 10 sigma
    assert np.std(e) == pytest.approx(0.2 * truth["F0"] / np.sqrt(3), rel=0.05)
    assert np.max(np.abs(e)) > 0.2 * truth["F0"]  # unbounded, unlike the uniform noise


def test_curves_are_read_only_and_inputs_untouched(truth):
    t = dict(truth)
    c = make_test_curves("closed_form", t, seed=0)
    assert t == truth
    with pytest.raises(ValueError):
        c.torque[0] = 1.0
    fit = fit_table1(c, truth["N"], profile=False)
    with pytest.raises(ValueError):
        fit.values[0] = 1.0


def test_exact_curves_match_theory_table(hertz_quad, truth):
    eps = np.array([0.25, 0.5, 0.75, 1.5, 2.0, 5.0])
    F = [0.28992237, 0.55223308, 0.75932049, 0.95311839, 0.97427858, 0.99598266]
    M = [0.55309595, 0.45559229, 0.32760077, 0.13813766, 0.10190933, 0.04011545]
    fpar, torque, _ = exact_curves(hertz_quad, 1.0 / eps, eps, R, friction=FRICTION)
    fN = FRICTION * truth["N"]
    np.testing.assert_allclose(fpar / fN, F, atol=TABLE_TOL)
    np.testing.assert_allclose(torque / (fN * R), M, atol=TABLE_TOL)


def test_exact_lateral_force_sign_and_pure_spin_value(hertz_quad, truth):
    """Sign convention: forward shift, v_x > 0, w_z > 0 -> F_y < 0; pure spin |F_y| = k M0/(2R)."""
    roll = rolling_model(hertz_quad, K_X, R)
    ups = np.array([0.0, 0.5, 2.0])
    _, _, fperp = exact_curves(hertz_quad, ups, ups, R, rolling_quad=roll, friction=FRICTION)
    assert np.all(fperp > 0)  # F⊥ = -F_y > 0
    assert fperp[0] == pytest.approx(K_X * truth["M0"] / (2 * R), rel=TABLE_TOL)
    back = rolling_model(hertz_quad, -K_X, R)
    _, _, neg = exact_curves(hertz_quad, ups, ups, R, rolling_quad=back, friction=FRICTION)
    np.testing.assert_allclose(neg, -fperp, rtol=1e-9)


# --- the fitter, certified ---------------------------------------------------------------
def test_noise_free_data_recovered_exactly(truth):
    c = make_test_curves("closed_form", truth, amplitude=0.0, seed=0)
    fit = fit_table1(c, truth["N"])
    for name in PARAMETERS:
        assert fit.value(name) == pytest.approx(truth[name], rel=RECOVERY), name
    assert fit.f == pytest.approx(FRICTION, rel=RECOVERY)


def test_f_is_F0_over_N(truth):
    fit = fit_table1(make_test_curves("closed_form", truth, seed=5), truth["N"], profile=False)
    N = truth["N"]
    assert fit.f == pytest.approx(fit.value("F0") / N, rel=IDENTITY)
    assert fit.f_ci95 == pytest.approx(tuple(v / N for v in fit.interval("F0")), rel=IDENTITY)
    assert fit.f_stderr == pytest.approx(fit.stderr[0] / N, rel=IDENTITY)


def test_agrees_with_scipy_curve_fit(truth):
    """Same data, same per-curve sigma: curve_fit (natural parameters) agrees, covariance too."""
    c = make_test_curves("closed_form", truth, seed=7)
    fit = fit_table1(c, truth["N"], profile=False)
    n = c.psi.size
    x = np.arange(3 * n)
    sig = np.repeat([fit.noise_sigma[k] for k in ("f_parallel", "torque", "f_perp")], n)

    def model(i, F0, M0, a, m, kx):
        p, u = c.psi, c.upsilon
        return np.concatenate(
            [
                F0 / np.sqrt(1 + a * p**2),
                M0 / np.sqrt(1 + m * u**2),
                kx * M0 / (2 * R) / np.sqrt(1 + 0.25 * m * u**2),
            ]
        )[i.astype(int)]

    y = np.concatenate([c.f_parallel, c.torque, c.f_perp])
    p0 = [truth[k] for k in PARAMETERS]
    popt, pcov = curve_fit(model, x, y, p0=p0, sigma=sig, absolute_sigma=False, xtol=1e-14, ftol=1e-14)
    np.testing.assert_allclose(fit.values, popt, rtol=AGREE)
    sd = np.sqrt(np.diag(pcov))
    np.testing.assert_allclose(np.sqrt(np.diag(fit.covariance)), sd, rtol=1e-5)
    # off-diagonals, scaled (the F∥ and M_C blocks are uncorrelated: exact zeros vs 1e-16)
    np.testing.assert_allclose(fit.covariance / np.outer(sd, sd), pcov / np.outer(sd, sd), atol=1e-6)
    # 95 % bounds: t-quantile x s.e.; linear in F0, M0, k_x, in log space for a and m
    t = stats.t.ppf(0.975, y.size - len(PARAMETERS))
    half = 0.5 * (fit.ci95[:, 1] - fit.ci95[:, 0])
    np.testing.assert_allclose(half[[0, 1, 4]], t * sd[[0, 1, 4]], rtol=1e-5)
    log_half = 0.5 * np.log(fit.ci95[2:4, 1] / fit.ci95[2:4, 0])
    np.testing.assert_allclose(log_half, t * sd[2:4] / popt[2:4], rtol=1e-5)


def test_interval_widths_scale_like_one_over_sqrt_n(truth):
    """Observed order of the half-width/t (the standard error) vs points per curve: -1/2.

    16 seeds per n; the seed-to-seed scatter of the mean width (~3 %) gives a slope
    uncertainty of about 0.02, so a 0.05 band is about 2.5 of its standard errors.
    """
    ns = np.array([100, 200, 400, 800])
    widths = []
    for n in ns:
        w = []
        for seed in range(16):
            fit = fit_table1(
                make_test_curves("closed_form", truth, n_points=int(n), seed=seed),
                truth["N"],
                profile=False,
            )
            w.append((fit.ci95[:, 1] - fit.ci95[:, 0]) / fit.t_quantile)
        widths.append(np.mean(w, axis=0))
    slopes = np.polyfit(np.log(ns), np.log(np.array(widths)), 1)[0]
    np.testing.assert_allclose(slopes, -0.5, atol=0.05)


def test_profile_bounds_exist_and_bracket_the_fit(truth):
    fit = fit_table1(make_test_curves("closed_form", truth, seed=2), truth["N"])
    for name in ("a", "m"):
        lo, hi = fit.profile_ci95[name]
        assert lo < fit.value(name) < hi
        wlo, whi = fit.interval(name)
        # log parametrisation: the Wald bounds follow the skew; they agree with the profile here
        assert fit.profile_agrees[name]
        assert abs(lo - wlo) < 0.1 * (whi - wlo) and abs(hi - whi) < 0.1 * (whi - wlo)


def test_noise_levels_estimated_per_curve(truth):
    """sigma_c from the residuals is near the true uniform std A/sqrt(3) of each curve."""
    c = make_test_curves("closed_form", truth, n_points=400, seed=9)
    fit = fit_table1(c, truth["N"], profile=False)
    for name in ("f_parallel", "torque", "f_perp"):
        # relative s.e. of a std estimate from 400 uniform draws: sqrt(0.8/400)/2 ~ 2.2 %
        assert fit.noise_sigma[name] == pytest.approx(c.noise["std"][name], rel=0.1)
    assert sum(fit.dof_share.values()) == pytest.approx(len(PARAMETERS), rel=1e-9)
    assert fit.redchi == pytest.approx(1.0, rel=1e-4)


# --- fitted curves and their prediction band ------------------------------------------
def test_fitted_curve_is_data_minus_residuals(truth):
    c = make_test_curves("closed_form", truth, seed=7)
    fit = fit_table1(c, truth["N"], profile=False)
    for name in ("f_parallel", "torque", "f_perp"):
        x, y = c.data(name)
        scale = np.max(np.abs(y))
        np.testing.assert_allclose(
            fit.curve(name, x), y - fit.residuals[name], rtol=IDENTITY, atol=IDENTITY * scale
        )


def test_prediction_band_against_scipy(truth):
    """Band from curve_fit's covariance, a finite-difference gradient and the t-quantile
    with the n_c - h_c degrees of freedom of each curve's noise estimate."""
    c = make_test_curves("closed_form", truth, seed=7)
    fit = fit_table1(c, truth["N"], profile=False)
    names = ("f_parallel", "torque", "f_perp")
    n = c.psi.size

    def curve(name, x, F0, M0, a, m, kx):
        if name == "f_parallel":
            return F0 / np.sqrt(1 + a * x**2)
        if name == "torque":
            return M0 / np.sqrt(1 + m * x**2)
        return kx * M0 / (2 * R) / np.sqrt(1 + 0.25 * m * x**2)

    def model(i, *p):
        return np.concatenate([curve(k, c.data(k)[0], *p) for k in names])[i.astype(int)]

    y = np.concatenate([c.f_parallel, c.torque, c.f_perp])
    sig = np.repeat([fit.noise_sigma[k] for k in names], n)
    p0 = [truth[k] for k in PARAMETERS]
    popt, pcov = curve_fit(
        model, np.arange(3 * n), y, p0=p0, sigma=sig, absolute_sigma=False, xtol=1e-14, ftol=1e-14
    )
    s2 = np.sum(((model(np.arange(3 * n), *popt) - y) / sig) ** 2) / (y.size - len(PARAMETERS))
    x = np.linspace(0.0, 7.0, 29)  # beyond the data too
    for j, name in enumerate(names):
        xd = c.data(name)[0]

        def grad(at, name=name):
            return approx_fprime(popt, lambda p: curve(name, at, *p), 1e-7 * np.abs(popt))

        # leverage of the curve's own points: h_c = sum_i w_i^2 g_i^T (J_w^T J_w)^-1 g_i
        gd = grad(xd)
        h = np.einsum("ij,jk,ik->", gd, pcov / s2, gd) / fit.noise_sigma[name] ** 2
        t = stats.t.ppf(0.975, n - h)
        g = grad(x)
        yhat = curve(name, x, *popt)
        half = t * np.sqrt(np.einsum("ij,jk,ik->i", g, pcov, g) + s2 * sig[j * n] ** 2)
        ours, lo, hi = fit.prediction_band(name, x)
        np.testing.assert_allclose(ours, yhat, rtol=AGREE, atol=AGREE * np.max(np.abs(yhat)))
        np.testing.assert_allclose(hi - ours, half, rtol=BAND_AGREE)
        np.testing.assert_allclose(ours - lo, half, rtol=BAND_AGREE)
        se = np.sqrt(np.einsum("ij,jk,ik->i", g, pcov, g))
        np.testing.assert_allclose(fit.curve_stderr(name, x), se, rtol=BAND_AGREE, atol=BAND_AGREE * se.max())


def test_curve_model_gradient_is_the_derivative(truth):
    """Analytic gradient against central differences (step 1e-6 relative: error ~1e-10)."""
    values = np.array([truth[k] for k in PARAMETERS])
    x = np.linspace(0, 5, 11)
    for name in ("f_parallel", "torque", "f_perp"):
        _, g = curve_model(name, x, values, R)
        for j in range(len(PARAMETERS)):
            h = 1e-6 * values[j]
            up, dn = values.copy(), values.copy()
            up[j] += h
            dn[j] -= h
            fd = (curve_model(name, x, up, R)[0] - curve_model(name, x, dn, R)[0]) / (2 * h)
            scale = np.max(np.abs(curve_model(name, x, values, R)[0])) / values[j]
            np.testing.assert_allclose(g[:, j], fd, rtol=1e-7, atol=1e-7 * scale)


@pytest.mark.slow
def test_prediction_band_monte_carlo(truth):
    """Independent check by simulation: MC_FITS data sets with Gaussian noise of known
    std. (1) Across fits, the scatter of the fitted curve matches curve_stderr (the
    delta method); (2) the band holds a new measurement 95 % of the time: per fit,
    P(lo <= y_true + e <= hi) for e ~ N(0, std^2) in closed form, averaged."""
    names = ("f_parallel", "torque", "f_perp")
    yhat = {k: [] for k in names}
    var = {k: [] for k in names}
    cover = {k: [] for k in names}
    for seed in range(MC_FITS):
        c = make_test_curves("closed_form", truth, seed=seed, noise="gaussian")
        fit = fit_table1(c, truth["N"], profile=False)
        for name in names:
            x, _ = c.data(name)
            true = getattr(c, f"{name}_true")
            std = c.noise["std"][name]
            y, lo, hi = fit.prediction_band(name, x)
            yhat[name].append(y)
            var[name].append(fit.curve_stderr(name, x) ** 2)
            cover[name].append(stats.norm.cdf((hi - true) / std) - stats.norm.cdf((lo - true) / std))
    for name in names:
        ratio = np.std(yhat[name], axis=0, ddof=1) / np.sqrt(np.mean(var[name], axis=0))
        np.testing.assert_allclose(ratio, 1.0, atol=STD_TOL, err_msg=name)
        assert np.mean(cover[name]) == pytest.approx(0.95, abs=COVERAGE_TOL), name


def test_prediction_band_bad_arguments(truth):
    fit = fit_table1(make_test_curves("closed_form", truth, seed=1), truth["N"], profile=False)
    with pytest.raises(ArgumentError, match=r"^level must be a probability in \(0, 1\), got 1\.0$"):
        fit.prediction_band("torque", [0.0], level=1)
    with pytest.raises(ArgumentError, match=r"^name must be one of f_parallel, torque, f_perp, got 'fx'$"):
        fit.prediction_band("fx", [0.0])
    with pytest.raises(ArgumentError, match=r"^x must be finite, got nan at index 1$"):
        fit.curve_stderr("torque", [0.0, np.nan])
    # a wider level gives a wider band around the same curve
    y90, lo90, hi90 = fit.prediction_band("f_perp", [0.0, 2.0], level=0.90)
    y99, lo99, hi99 = fit.prediction_band("f_perp", [0.0, 2.0], level=0.99)
    np.testing.assert_array_equal(y90, y99)
    assert np.all(lo99 < lo90) and np.all(hi90 < hi99)


# --- bad input ---------------------------------------------------------------------------
def _curves(n, **over):
    grid = np.linspace(0, 3, n)
    kw = dict(
        psi=grid,
        f_parallel=1 / np.sqrt(1 + grid**2),
        upsilon=grid,
        torque=1 / np.sqrt(1 + 8 * grid**2),
        f_perp=0.1 / np.sqrt(1 + 2 * grid**2),
        R=0.1,
    )
    kw.update(over)
    return TestCurves(**kw)


def test_too_few_points_is_a_data_error():
    with pytest.raises(
        DataError, match=r"^curves has 6 points in all; the fit of 5 parameters needs at least 7$"
    ):
        fit_table1(_curves(2), 100.0)


def test_non_finite_data_is_a_data_error():
    bad = np.ones(10)
    bad[4] = np.nan
    with pytest.raises(DataError, match=r"^torque must be finite, got nan at index 4$"):
        _curves(10, torque=bad)
    with pytest.raises(DataError, match=r"^f_perp must have 10 entries like its abscissa, got 9$"):
        _curves(10, f_perp=np.ones(9))


def test_bad_arguments():
    with pytest.raises(ArgumentError, match=r"^N must be a positive finite normal load in N, got -1.0$"):
        fit_table1(_curves(10), -1.0)
    with pytest.raises(ArgumentError, match=r"^source must be 'closed_form' or 'exact', got 'fem'$"):
        make_test_curves("fem", {})
    with pytest.raises(
        ArgumentError,
        match=r"^coefficients.k_x is missing \(no rolling map: give k_x explicitly\)$",
    ):
        make_test_curves("closed_form", {"F0": 1, "M0": 1, "a": 1, "m": 1, "R": 1, "N": 1})
    with pytest.raises(ArgumentError, match=r"^quad must be a PressureQuadrature of the static map"):
        make_test_curves("exact", {"F0": 1, "M0": 1, "a": 1, "m": 1, "k_x": 0, "R": 1, "N": 1})


def test_non_convergence_is_a_fit_error(truth):
    c = make_test_curves("closed_form", truth, seed=1)
    with pytest.raises(FitError, match=r"^least-squares fit did not converge"):
        fit_table1(c, truth["N"], max_nfev=1)


def test_degenerate_design_warns_and_gives_nan_intervals():
    """All points at psi = upsilon = 0: a and m do not enter the model -> indeterminate cov."""
    z = np.zeros(10)
    rng = np.random.default_rng(0)
    c = _curves(
        10,
        psi=z,
        upsilon=z,
        f_parallel=1 + 0.1 * rng.standard_normal(10),
        torque=1 + 0.1 * rng.standard_normal(10),
        f_perp=0.1 + 0.01 * rng.standard_normal(10),
    )
    with pytest.warns(
        FitWarning,
        match=r"^covariance of the Table 1 fit is indeterminate \(condition number inf\): "
        r"(a|m) is not identifiable from these curves; intervals set to NaN$",
    ):
        fit = fit_table1(c, 100.0)
    assert not fit.determinate
    assert np.all(np.isnan(fit.ci95)) and np.all(np.isnan(fit.f_ci95))
    assert fit.profile_ci95 == {}
    y, lo, hi = fit.prediction_band("torque", [0.0, 1.0])
    assert np.all(np.isfinite(y)) and np.all(np.isnan(lo)) and np.all(np.isnan(hi))


# --- the approximation's own bias (exact-integral data) ------------------------------------
def test_bias_of_the_closed_forms_on_exact_data(hertz_quad, truth):
    b = approximation_bias(truth, hertz_quad, seed=4)
    # Noise-free exact curves: the square-root forms cannot follow them; the best fit moves
    # a and m by several percent (the theory note: structural error ~0.07-0.12 of the curve max).
    assert abs(b.relative_bias("a")) > 0.03 and abs(b.relative_bias("m")) > 0.03
    for name, s in b.structure.items():
        assert 0.02 < s["max_abs_error_relative"] < 0.2, name
        assert s["lag1_autocorrelation"] > 0.5, name  # smooth, systematic residuals
        assert s["runs_p"] < 1e-3, name
    # control: noise-free closed-form data through the same code shows no bias
    c = make_test_curves("closed_form", truth, amplitude=0.0)
    fit = fit_table1(c, truth["N"], profile=False)
    assert fit.value("a") == pytest.approx(truth["a"], rel=RECOVERY)
    d = b.to_dict()
    assert set(d["bias"]) == set(PARAMETERS)


def test_bias_integrates_the_exact_curves_once(hertz_quad, truth, monkeypatch):
    """The noisy curves are the noise-free ones plus noise (with_noise): one integration."""
    import fepost.identify.curves as curves

    calls = []
    real = curves.exact_curves
    monkeypatch.setattr(curves, "exact_curves", lambda *a, **k: calls.append(1) or real(*a, **k))
    b = approximation_bias(truth, hertz_quad, seed=4)
    assert len(calls) == 1
    noisy = make_test_curves("exact", truth, quad=hertz_quad, seed=4)
    assert b.noisy.value("a") == fit_table1(noisy, truth["N"], profile=False).value("a")


def test_runs_test_and_autocorrelation_on_known_sequences():
    alt = np.array([1.0, -1.0] * 20)
    runs, mu, p = runs_test(alt)
    assert runs == 40 and mu == pytest.approx(21.0) and p < 1e-8  # too many runs
    block = np.array([1.0] * 20 + [-1.0] * 20)
    assert runs_test(block)[0] == 2 and runs_test(block)[2] < 1e-8
    assert lag1_autocorrelation(alt) == pytest.approx(-1.0, abs=0.05)
    white = np.random.default_rng(0).standard_normal(4000)
    assert abs(lag1_autocorrelation(white)) < 4 / np.sqrt(4000)


def test_failed_profile_refit_warns_and_leaves_nan(truth, monkeypatch):
    import fepost.identify as identify

    def fail(*args, **kwargs):
        raise FitError("least-squares fit did not converge (forced)")

    monkeypatch.setattr(identify.fit, "_profile", fail)
    c = make_test_curves("closed_form", truth, seed=1)
    with pytest.warns(FitWarning, match=r"^profile bounds of (a|m) not computed"):
        fit = fit_table1(c, truth["N"])
    assert np.isnan(fit.profile_ci95["a"][0]) and fit.profile_agrees["a"] is False
    assert np.all(np.isfinite(fit.ci95))  # the Wald bounds are unaffected
