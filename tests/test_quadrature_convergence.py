"""Observed convergence orders of the polar quadratures and of the FE pipeline.

The trapezoid rule (the paper's) is second order in the radial step; the
Gauss–Legendre default converges exponentially on smooth maps; on FE data
the whole pipeline converges at the FE interpolation's second order.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from fepost import analyse, analytic
from fepost.moments import moments
from fepost.polar import PolarGrid, PolarMap


def smooth(x, y):
    """A smooth, non-polynomial, non-axisymmetric map on the unit disc (Pa)."""
    r2 = x**2 + y**2
    return np.exp(-2.0 * r2) * (1.0 + 0.3 * x + 0.2 * y**2)


def exact_A():
    # angular mean of smooth at radius ρ: e^{-2ρ²}(1 + 0.1ρ²)
    return np.array(
        [
            quad(lambda r, k=k: np.exp(-2 * r * r) * (1 + 0.1 * r * r) * r**k, 0, 1, epsabs=1e-14)[0]
            for k in range(4)
        ]
    )


def errors(rule, sizes):
    ref = exact_A()
    out = []
    for n in sizes:
        pm = PolarMap.from_function(smooth, 1.0, PolarGrid.make(n, 64, rule))
        out.append(np.max(np.abs(moments(pm).A - ref) / ref))
    return np.array(out)


def observed_order(sizes, errs):
    return -np.polyfit(np.log(sizes), np.log(errs), 1)[0]


def test_trapezoid_is_second_order():
    sizes = np.array([17, 33, 65, 129])
    p = observed_order(sizes - 1, errors("trapezoid", sizes))
    assert 1.9 < p < 2.1


def test_gauss_converges_exponentially():
    e = errors("gauss", [4, 6, 8, 10])
    # each step of 2 nodes gains more than a factor 30: faster than any fixed order here
    assert np.all(e[1:] / e[:-1] < 1 / 30)
    assert e[-1] < 1e-12


def test_periodic_trapezoid_in_phi_is_spectral():
    # x·y² and x terms average out exactly; a cos(3φ) field needs nphi > 3 nodes only
    ref = quad(lambda r: r * r, 0, 1)[0]
    for nphi in (8, 16):
        pm = PolarMap.from_function(
            lambda x, y: np.hypot(x, y) * (1 + np.cos(3 * np.arctan2(y, x))), 1.0, PolarGrid.make(8, nphi)
        )
        assert moments(pm).A[1] == pytest.approx(ref, rel=1e-13)


def test_fe_pipeline_is_second_order_in_mesh_size(analytic_mesh):
    """N of a paraboloid map on refined FE meshes: error ∝ h², h ∝ 1/rings."""
    rings = np.array([8, 16, 32])
    N_ref = analytic.load("paraboloid", 0.1, 1e6)
    errs = []
    for n in rings:
        a = analyse(
            analytic_mesh(f"p{n}.vtu", "paraboloid", radius=0.1, peak=1e6, n_rings=int(n), kind="quad")
        )
        errs.append(abs(a.coefficients.N / N_ref - 1))
    p = observed_order(rings, np.array(errs))
    assert 1.7 < p < 2.3
