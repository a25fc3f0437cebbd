"""Closed-form friction approximations (fepost.friction.closed_form, .accuracy).

Tolerance tiers:
- IDENTITY (1e-10): coefficients whose integrands the 64x128 sine grid integrates
  exactly up to round-off (polynomials in ρ against smooth profiles).
- EXACT (1e-5): agreement with the exact integrals where the closed forms are
  exact (pure sliding, pure spin), limited by the quadrature (~1e-7).
- LIMIT: the closed forms match the exact asymptotes to first order; at υ = 1e-3
  (or 1e3) the next-order terms leave a relative difference far below 1e-2.
- Error bands for the theory note (docs/theory.md): it quotes 0.12·F0 and 0.21·M0
  (asymptotic a, m) and 0.07–0.08 (fitted); the bands are ±0.02 around those.
"""

from __future__ import annotations

import numpy as np
import pytest

from fepost.analytic import coefficients, pressure_function
from fepost.errors import ArgumentError
from fepost.friction.accuracy import approximation_error, rolling_shift
from fepost.friction.closed_form import asymptotic_coefficients, components
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.polar import PolarMap

IDENTITY = 1e-10
EXACT = 1e-5
LIMIT = 1e-2
R = 0.1
K = 0.13
F = 0.3


def make_quad(profile="hertz", k_x=0.0):
    fn = pressure_function(profile, R, peak=2e5, k_x=k_x)
    return PressureQuadrature.from_polar(PolarMap.from_function(fn, R, edge_grid(64, 128)))


@pytest.fixture(scope="module")
def shifted_hertz():
    quad = make_quad("hertz", K)
    return quad, asymptotic_coefficients(quad, F, radius=R)


@pytest.mark.parametrize("profile", ["uniform", "hertz", "paraboloid"])
def test_asymptotic_coefficients_equal_theory_for_axisymmetric_maps(profile):
    got = asymptotic_coefficients(make_quad(profile), F)
    ref = coefficients(profile, R, peak=2e5, friction=F)
    assert got.radius == pytest.approx(R, rel=1e-12)
    for name in ("F0", "M0", "a", "m"):
        assert getattr(got, name) == pytest.approx(ref[name], rel=IDENTITY), name


def test_asymptotic_coefficients_of_a_shifted_field_are_the_moved_origin_values():
    # Moving the field moves the origin relative to it: a, m must then follow the
    # singular 1/r integral about an off-centre point, done by subtraction.
    quad = make_quad("hertz")
    moved = quad.shifted(0.02, 0.0)
    got = asymptotic_coefficients(moved, F, radius=R)
    assert np.isfinite(got.a) and np.isfinite(got.m)
    # Independent: the same integrals on a fine grid centred on the origin.
    fine = PressureQuadrature.from_polar(
        PolarMap.from_function(
            lambda x, y: pressure_function("hertz", R, peak=2e5)(x - 0.02, y),
            0.12,
            edge_grid(512, 1024),
        )
    )
    ref = asymptotic_coefficients(fine, F, radius=R)
    assert got.a == pytest.approx(ref.a, rel=1e-4)
    assert got.m == pytest.approx(ref.m, rel=1e-4)


KINEMATICS = [
    (0.2, 0.0, 3.0),
    (-0.2, 0.0, 3.0),
    (0.2, 0.0, -3.0),
    (0.0, 0.2, 3.0),
    (0.0, -0.2, -3.0),
    (0.05, 0.01, -30.0),
    (0.03, -0.04, 5.0),
    (0.0, 0.0, 5.0),
    (0.0, 0.0, -5.0),
]


@pytest.mark.parametrize("kin", KINEMATICS)
def test_component_signs_match_exact_integrals(shifted_hertz, kin):
    quad, c = shifted_hertz
    exact = friction_resultants(quad, *kin, FrictionLaw(f=F))
    cf = components(*kin, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=K, radius=R)
    for name, e, approx, scale in zip(
        ("Fx", "Fy", "Mz"), (exact.Fx, exact.Fy, exact.Mz), cf, (c.F0, c.F0, c.M0), strict=True
    ):
        e = float(e)
        if abs(e) > 1e-3 * scale:
            assert np.sign(float(approx)) == np.sign(e), name


def test_closed_form_torque_omits_the_offset_of_the_centre_of_pressure(shifted_hertz):
    # A finding, not a sign error: when sliding dominates (υ = 10) on a map whose
    # centre of pressure x_c is off the origin, the exact M_z tends to
    # −fN (x_c v̂_y − y_c v̂_x), which M_C = M0 u/√(u² + m v²) does not contain.
    quad, c = shifted_hertz
    vx, vy, w = 0.3, -0.4, 0.5
    exact = float(friction_resultants(quad, vx, vy, w, FrictionLaw(f=F)).Mz)
    _, _, mz = components(vx, vy, w, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=K, radius=R)
    xc = float(quad.sigma @ (quad.x * quad.dA)) / quad.load
    offset = -c.F0 * xc * vy / np.hypot(vx, vy)
    assert np.sign(exact) != np.sign(float(mz))
    assert exact == pytest.approx(offset + float(mz), rel=0.2)


def test_theory_sign_statement(shifted_hertz):
    # sign convention: v_x > 0, ω_z > 0, k_x > 0 gives F_y < 0 and M_z < 0.
    quad, _ = shifted_hertz
    res = friction_resultants(quad, 0.1, 0.0, 2.0, FrictionLaw(f=F))
    assert float(res.Fy) < 0 and float(res.Mz) < 0 and float(res.Fx) < 0


@pytest.mark.parametrize("w", [4.0, -4.0])
def test_pure_spin_is_exact(shifted_hertz, w):
    quad, c = shifted_hertz
    exact = friction_resultants(quad, 0.0, 0.0, w, FrictionLaw(f=F))
    fx, fy, mz = components(0.0, 0.0, w, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=K, radius=R)
    assert float(fy) == pytest.approx(-np.sign(w) * K * c.M0 / (2 * R), rel=1e-12)
    assert float(fy) == pytest.approx(float(exact.Fy), rel=EXACT)
    assert float(mz) == pytest.approx(float(exact.Mz), rel=EXACT)
    assert float(fx) == 0.0


def test_pure_sliding_is_exact(shifted_hertz):
    quad, c = shifted_hertz
    beta = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    vx, vy = np.cos(beta), np.sin(beta)
    exact = friction_resultants(quad, vx, vy, 0.0, FrictionLaw(f=F))
    fx, fy, mz = components(vx, vy, 0.0, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=K, radius=R)
    np.testing.assert_allclose(fx, exact.Fx, atol=EXACT * c.F0)
    np.testing.assert_allclose(fy, exact.Fy, atol=EXACT * c.F0)
    assert np.all(mz == 0.0)


def test_limits_match_exact_asymptotes():
    quad = make_quad("hertz")
    c = asymptotic_coefficients(quad, F)
    w = 1.0 / R  # u = 1 m/s
    for ups in (1e-3, 1e3):
        exact = friction_resultants(quad, ups, 0.0, w, FrictionLaw(f=F))
        fx, _, mz = components(ups, 0.0, w, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=0.0, radius=R)
        if ups < 1:
            assert float(fx) == pytest.approx(float(exact.Fx), rel=LIMIT)  # F∥ ≈ F0 υ/√a
        else:
            assert float(mz) == pytest.approx(float(exact.Mz), rel=LIMIT)  # M_C ≈ M0/(√m υ)


def test_approximation_error_reproduces_theory_figures():
    err = approximation_error(make_quad("hertz", K), F, k_x=K, radius=R)
    asym, fit = err.asymptotic, err.fitted
    assert 0.10 < asym.max_parallel < 0.14
    assert 0.19 < asym.max_torque < 0.23
    assert 0.05 < fit.max_parallel < 0.10
    assert 0.05 < fit.max_torque < 0.10
    assert fit.max_parallel < asym.max_parallel and fit.max_torque < asym.max_torque
    assert fit.rms_parallel < asym.rms_parallel and fit.rms_torque < asym.rms_torque
    assert np.isfinite(asym.max_perpendicular) and asym.max_perpendicular < 0.2
    d = err.to_dict()
    assert set(d["fitted"]) >= {"a", "m", "max_parallel", "rms_torque"}


def test_approximation_error_without_shift_reports_nan_perpendicular():
    err = approximation_error(make_quad("uniform"), F, upsilon=np.geomspace(0.1, 10, 9))
    assert abs(err.k_x) < 1e-12
    assert np.isnan(err.asymptotic.max_perpendicular)
    assert err.asymptotic.a == pytest.approx(1.0, rel=IDENTITY)
    assert err.fitted.a < 1.0  # the exact F∥ curve rises faster than 1/√(1 + 1/υ²)


def test_rolling_shift_of_shifted_map():
    # σ0(1 + k x/R): x_c = k ⟨x²⟩/R exactly, so the moment form returns k.
    assert rolling_shift(make_quad("hertz", K), R) == pytest.approx(K, rel=IDENTITY)


def test_approximation_error_validates_upsilon():
    with pytest.raises(ArgumentError, match=r"^upsilon must hold at least 2 positive finite values"):
        approximation_error(make_quad("hertz"), F, upsilon=[1.0, -1.0])


def test_asymptotic_a_weights_the_sliding_direction_on_an_ellipse():
    """Near pure spin F = −(f/|ω|) S v: the slope along v̂ is v̂ᵀS v̂ (not the perpendicular
    direction's), checked against the exact integrals on an ellipse of aspect 2."""
    quad = make_quad("hertz").stretched(np.sqrt(2.0))
    R, h = quad.radius, 1e-4
    for beta in (0.0, np.pi / 2):
        got = asymptotic_coefficients(quad, F, direction=beta)
        ex = friction_resultants(quad, h * np.cos(beta), h * np.sin(beta), 1.0 / R, FrictionLaw(f=F))
        slope = -(float(ex.Fx) * np.cos(beta) + float(ex.Fy) * np.sin(beta)) / (h * F * quad.load)
        assert 1.0 / np.sqrt(got.a) == pytest.approx(slope, rel=1e-3)
