"""The closed forms shipped in fepost.analytic against quadrature of their defining integrals."""

import numpy as np
import pytest
from scipy.integrate import quad

from fepost import analytic

# Identities between closed forms and adaptive quadrature: quad reaches ~1e-12.
QUAD_TOL = 1e-10


@pytest.mark.parametrize("name", sorted(analytic.MOMENTS))
def test_moments_match_quadrature(name):
    g = analytic.profile(name)
    for k in range(4):
        val, _ = quad(lambda r, k=k: g(r) * r**k, 0.0, 1.0, epsabs=1e-13, epsrel=1e-13)
        assert analytic.moments(name)[k] == pytest.approx(val, rel=QUAD_TOL)


def test_theory_reference_values():
    # docs/theory.md, "Reference values": Hertz a = (8/3π)², m = (15π/16)², M0 = (3π/16) f N R
    c = analytic.coefficients("hertz", radius=1.0, peak=1.0, friction=1.0)
    N = analytic.load("hertz", 1.0, 1.0)
    assert c["a"] == pytest.approx((8 / (3 * np.pi)) ** 2, rel=1e-14)
    assert c["m"] == pytest.approx((15 * np.pi / 16) ** 2, rel=1e-14)
    assert c["M0"] == pytest.approx(3 * np.pi / 16 * N, rel=1e-14)
    u = analytic.coefficients("uniform", radius=1.0, peak=1.0, friction=1.0)
    assert u["a"] == pytest.approx(1.0) and u["m"] == pytest.approx(64 / 9)
    assert u["M0"] == pytest.approx(2 / 3 * analytic.load("uniform", 1.0, 1.0), rel=1e-14)


def test_unknown_profile_is_named():
    with pytest.raises(ValueError, match="profile must be one of .*got 'cone'"):
        analytic.profile("cone")
