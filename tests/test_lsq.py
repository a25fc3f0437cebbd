"""The shared Jacobian covariance against scipy's curve_fit and a rank-deficient case."""

import numpy as np
import pytest
from scipy.optimize import curve_fit

from fepost.lsq import jacobian_svd, leverage


def test_matches_curve_fit_on_a_linear_model():
    rng = np.random.default_rng(3)
    x = np.linspace(0, 1, 40)
    y = 2.0 + 3.0 * x + rng.normal(0, 0.1, x.size)
    popt, pcov = curve_fit(lambda x, a, b: a + b * x, x, y)
    J = np.column_stack([np.ones_like(x), x])
    s2 = np.sum((y - J @ popt) ** 2) / (x.size - 2)
    svd = jacobian_svd(J)
    assert svd.identifiable
    # identity with the normal equations (round-off only)
    np.testing.assert_allclose(svd.inverse, np.linalg.inv(J.T @ J), rtol=1e-12)
    # curve_fit's own estimate is converged to its xtol = 1.5e-8 (finite-difference Jacobian)
    np.testing.assert_allclose(svd.inverse * s2, pcov, rtol=1e-6)
    assert leverage(J).sum() == pytest.approx(2.0, rel=1e-12)  # trace of the hat matrix = rank


def test_rank_deficient_jacobian_is_not_identifiable():
    x = np.linspace(0, 1, 10)
    J = np.column_stack([x, 2 * x, np.ones_like(x)])
    svd = jacobian_svd(J)
    assert not svd.identifiable and svd.weakest in (0, 1)
    assert not jacobian_svd(np.column_stack([x, x + 1e-12 * x**2]), cond_max=1e6).identifiable
    assert leverage(J).sum() == pytest.approx(2.0, rel=1e-9)
