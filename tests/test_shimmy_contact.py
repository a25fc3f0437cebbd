"""Shimmy contact adapters: the closed forms as fepost has them, their derivatives, the tables."""

from __future__ import annotations

import numpy as np
import pytest

from fepost.friction.closed_form import components
from fepost.shimmy.contact import Contact, closed_forms_contact, exact_contact, model_contact
from fepost.shimmy.table import DirectionTable

#: Tolerance tiers: identities (round-off), high-order differences, tabulation.
ROUND_OFF = 1e-12
DIFFERENCES = 1e-7
TABLE = 2e-3

COEF = {"F0": 59578.6, "M0": 8254.3, "a": 0.652, "m": 10.39, "k_x": 0.2406, "R": 0.2538}


def _points(n=200, seed=3):
    rng = np.random.default_rng(seed)
    k = rng.normal(size=(3, n))
    k[2] *= 4.0
    return k


def test_closed_forms_equal_fepost_components():
    c = closed_forms_contact(**COEF)
    vx, vy, wz = _points()
    mine = c(vx, vy, wz)
    ref = components(vx, vy, wz, **{k: v for k, v in COEF.items() if k != "R"}, radius=COEF["R"])
    for a, b, name in zip(mine, ref, ("Fx", "Fy", "Mz"), strict=True):
        np.testing.assert_allclose(a, b, rtol=ROUND_OFF, atol=ROUND_OFF * COEF["F0"], err_msg=name)
    one = np.array([c.scalar(*p) for p in zip(vx, vy, wz, strict=True)]).T
    np.testing.assert_allclose(one, np.array(mine), rtol=ROUND_OFF, atol=ROUND_OFF * COEF["F0"])


def test_complex_step_jacobian_matches_closed_form_derivatives():
    """At pure sliding v along x: dFy/dvy = −F0/v, dMz/dwz = −M0 R/(√m v), dFy/dwz = −k_x M0/(√m v)."""
    c = closed_forms_contact(**COEF)
    v = 3.0
    jac = c.jacobian(v, 0.0, 0.0)
    F0, M0, m, kx, R = (COEF[k] for k in ("F0", "M0", "m", "k_x", "R"))
    expect = {(1, 1): -F0 / v, (2, 2): -M0 * R / (np.sqrt(m) * v), (1, 2): -kx * M0 / (np.sqrt(m) * v)}
    for (i, j), value in expect.items():
        np.testing.assert_allclose(jac[i, j], value, rtol=ROUND_OFF, err_msg=f"J[{i},{j}]")
    np.testing.assert_allclose(
        jac[0], 0.0, atol=ROUND_OFF * F0, err_msg="Fx is stationary in every direction"
    )


def test_high_order_differences_match_complex_step_on_the_closed_forms():
    c = closed_forms_contact(**COEF)
    real_only = Contact("closed_forms", c.forces, c.R, c.F0, c.M0, complex_ok=False)
    for point in [(3.0, 0.0, 0.0), (1.0, 0.4, 2.0), (-0.5, 1.2, -3.0)]:
        np.testing.assert_allclose(
            real_only.jacobian(*point),
            c.jacobian(*point),
            rtol=DIFFERENCES,
            atol=DIFFERENCES * c.F0,
            err_msg=str(point),
        )


def test_exact_jacobian_at_pure_sliding_is_the_first_order_integral(aircraft):
    """Sliding at v along x with a small spin: Mz ≈ −(f ω/v)∬σx² dA, Fy ≈ −(f ω/v)∬σx dA, Fy ≈ −f N vy/v."""
    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature

    c = aircraft.coefficients
    quad = PressureQuadrature.from_polar(aircraft.rolling_map)
    ex = exact_contact(quad, FrictionLaw(f=c.f), c.R)
    v = 2.0
    jac = ex.jacobian(v, 0.0, 0.0)
    f = c.f
    np.testing.assert_allclose(jac[2, 2], -f / v * np.sum(quad.sigma * quad.x**2 * quad.dA), rtol=1e-6)
    np.testing.assert_allclose(jac[1, 2], -f / v * np.sum(quad.sigma * quad.x * quad.dA), rtol=1e-5)
    np.testing.assert_allclose(jac[1, 1], -f / v * np.sum(quad.sigma * quad.dA), rtol=1e-6)


def test_generalised_model_agrees_with_exact_derivatives(aircraft):
    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature

    c = aircraft.coefficients
    gen = model_contact(aircraft.model_summary.rolling)
    ex = exact_contact(PressureQuadrature.from_polar(aircraft.rolling_map), FrictionLaw(f=c.f), c.R)
    jg, je = gen.jacobian(1.0, 0.0, 0.0), ex.jacobian(1.0, 0.0, 0.0)
    np.testing.assert_allclose(jg[1:, 1:], je[1:, 1:], rtol=1e-3, err_msg="lateral force and torque")


def test_direction_table_reproduces_its_model(aircraft):
    gen = model_contact(aircraft.model_summary.rolling)
    table = DirectionTable.build(gen)
    k = _points(300, seed=7)
    got, want = np.array(table(*k)), np.array(gen(*k))
    np.testing.assert_allclose(got[:2], want[:2], atol=TABLE * gen.F0, err_msg="forces")
    np.testing.assert_allclose(got[2], want[2], atol=TABLE * gen.M0, err_msg="torque")
    scaled = k * np.array([[5.0], [5.0], [5.0]])
    np.testing.assert_allclose(
        np.array(table(*scaled)), got, rtol=ROUND_OFF, atol=ROUND_OFF * gen.F0, err_msg="degree-0 homogeneity"
    )


def test_scaled_contact_scales_every_load():
    c = closed_forms_contact(**COEF)
    s = c.scaled(1.1)
    np.testing.assert_allclose(np.array(s(1.0, 0.3, 2.0)), 1.1 * np.array(c(1.0, 0.3, 2.0)), rtol=ROUND_OFF)
    assert s.scalar(1.0, 0.3, 2.0) == pytest.approx(tuple(1.1 * np.array(c.scalar(1.0, 0.3, 2.0))))
