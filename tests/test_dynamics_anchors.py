"""Outside anchors of the dynamics (../shared/paper/dynamics-anchors.md), each reproduced.

Published: the sliding, spinning disc's ε (0.653 homogeneous, 1 ring); the towed rigid wheel's
band 0.3 < a/l < 0.7; Pacejka's dip (11.65a exact string, tests/test_shimmy_string.py).
Cross-checks (independent computations, no printed value): Somieski's nose gear.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fepost.shimmy.anchors_dynamics import (
    PUBLISHED_EPSILON,
    closed_form_disc,
    disc_epsilon,
    disc_stop,
    ring_forces,
    somieski_damping_needed,
    somieski_peak_damping,
    towed_wheel_band,
    towed_wheel_matrix,
    towed_wheel_polynomial,
)

ANCHORS = Path("../shared/paper/dynamics-anchors.md")


@pytest.fixture(scope="module")
def uniform():
    from fepost.friction.reference_maps import ellipse_quad

    return ellipse_quad("uniform")


def _normalised(fun, load):
    def forces(vx, vy, wz):
        return tuple(np.ravel(c) / load for c in fun(vx, vy, wz))

    return forces


def test_published_values_are_those_of_the_anchor_file():
    if not ANCHORS.exists():
        pytest.skip("../shared/paper/dynamics-anchors.md is not beside the repository")
    text = ANCHORS.read_text(encoding="utf-8")
    assert "ε → 0.653" in text and "ε → 1" in text and "0.3 < a/l < 0.7" in text and "11.65a" in text


def test_disc_epsilon_exact_integrals_give_the_published_values(uniform):
    """Homogeneous disc (uniform pressure, I = mR²/2): 0.653; ring (I = mR²): 1."""
    from fepost.friction.exact import friction_resultants
    from fepost.friction.law import FrictionLaw

    def exact(vx, vy, wz):
        r = friction_resultants(uniform, vx, vy, wz, FrictionLaw(f=0.3), threads=1)
        return r.Fx, r.Fy, r.Mz

    R = uniform.radius
    eps = disc_epsilon(_normalised(exact, uniform.load), R, 0.5)
    assert eps == pytest.approx(PUBLISHED_EPSILON["homogeneous"], abs=5e-4)
    ring = disc_epsilon(lambda vx, vy, wz: ring_forces(vx, vy, wz, R=R), R, 1.0)
    assert ring == pytest.approx(PUBLISHED_EPSILON["ring"], abs=1e-9)
    from fepost.shimmy.anchors_dynamics import pressure_inertia_ratio

    assert pressure_inertia_ratio(uniform) == pytest.approx(0.5, rel=1e-9)


def test_disc_epsilon_by_time_integration_to_the_stop():
    """Integrating m v̇ = −F, I ω̇ = −M: both stop together, at the ratio of the root."""
    cf = closed_form_disc("uniform")
    root = disc_epsilon(cf, 1.0, 0.5)
    stop = disc_stop(cf, 1.0, 0.5, eps0=0.2)
    assert stop.v_left < 1e-5 and stop.w_left < 1e-5
    assert stop.epsilon == pytest.approx(root, abs=3e-3)
    ring = disc_stop(lambda vx, vy, wz: ring_forces(vx, vy, wz, nodes=512), 1.0, 1.0, eps0=3.0)
    assert ring.epsilon == pytest.approx(1.0, abs=1e-3)


def test_disc_epsilon_closed_forms_and_generalised_model(uniform):
    """The closed forms' ε for the homogeneous disc is √(7/48) = 0.382 (their error on a dynamic
    quantity: −41 %); they are exact for the ring (1). The generalised model gives 0.652."""
    from fepost.friction.build import build_model
    from fepost.friction.law import FrictionLaw

    cf = disc_epsilon(closed_form_disc("uniform"), 1.0, 0.5)
    assert cf == pytest.approx(np.sqrt(7 / 48), rel=1e-9)
    assert disc_epsilon(closed_form_disc("ring"), 1.0, 1.0) == pytest.approx(1.0, rel=1e-9)
    model = build_model(uniform, FrictionLaw(f=0.3))
    gen = disc_epsilon(_normalised(model, uniform.load), uniform.radius, 0.5)
    assert gen == pytest.approx(PUBLISHED_EPSILON["homogeneous"], abs=3e-3)


def test_disc_epsilon_on_the_fe_map():
    """The FE pressure of the aircraft tire at its rated load as a flat body whose mass is spread
    like the pressure (I/mR² = 0.339), sliding along x: its own ε, 0.437 by the exact integrals,
    0.432 by the generalised model, 0.298 by the closed forms (−32 %)."""
    from fepost.analysis import analyse
    from fepost.friction.exact import friction_resultants
    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature
    from fepost.shimmy.anchors_dynamics import pressure_inertia_ratio
    from fepost.shimmy.contact import closed_form_forces

    an = analyse("meshes/aircraft/static_100.vtu")
    c = an.coefficients
    quad = PressureQuadrature.from_polar(an.static_map)
    ratio = pressure_inertia_ratio(quad)
    assert ratio == pytest.approx(0.3387, abs=1e-4)

    def exact(vx, vy, wz):
        r = friction_resultants(quad, vx, vy, wz, FrictionLaw(f=c.f), threads=1)
        return r.Fx, r.Fy, r.Mz

    def closed(vx, vy, wz):
        return closed_form_forces(vx, vy, wz, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=0.0, R=c.R)

    e_exact = disc_epsilon(_normalised(exact, c.N), c.R, ratio)
    e_gen = disc_epsilon(_normalised(an.model_summary.static, c.N), c.R, ratio)
    e_closed = disc_epsilon(_normalised(closed, c.N), c.R, ratio)
    assert e_exact == pytest.approx(0.4367, abs=1e-3)
    assert e_gen == pytest.approx(0.4323, abs=1e-3)
    assert e_closed == pytest.approx(0.2984, abs=1e-3)


def test_towed_wheel_band_and_polynomial():
    """Schwab–Meijaard: the published cubic's roots are the constrained equations' eigenvalues
    (written independently), and the body is stable iff ab > r²: 0.3 < a/l < 0.7."""
    for q in (0.2, 0.5, 0.8):
        for u in (0.5, 3.0):
            a, b = q, 1 - q
            want = np.sort_complex(np.roots(towed_wheel_polynomial(a, b, 0.21, u, 1.5, 5.0)))
            got = np.sort_complex(np.linalg.eigvals(towed_wheel_matrix(a, b, 0.21, u, 1.5, 5.0)))
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    lo, hi = towed_wheel_band(n=1001)
    assert lo == pytest.approx(0.3, abs=1.5e-3) and hi == pytest.approx(0.7, abs=1.5e-3)


def test_somieski_cross_check_values():
    """Independent values (not Somieski's printed ones): eigenvalues at 80 m/s with k = −50,
    onsets at k = 0 and −10, and the damping needed peaking at −49.79 near 100.7 m/s."""
    from fepost.shimmy.anchor import SomieskiGear, eigen_critical_speeds, routh_hurwitz_speeds, state_matrix

    p = SomieskiGear()
    ev = np.linalg.eigvals(state_matrix(p, 80.0))
    real = ev[np.abs(ev.imag) < 1e-9].real
    pair = ev[ev.imag > 0][0]
    assert real[0] == pytest.approx(-318.69, abs=0.01)
    assert pair.real == pytest.approx(-0.678, abs=1e-3) and pair.imag == pytest.approx(337.34, abs=0.01)
    for k, want in ((0.0, 15.26), (-10.0, 20.51)):
        q = p.with_damping(k)
        assert eigen_critical_speeds(q)[0][0] == pytest.approx(want, abs=0.005)
        assert routh_hurwitz_speeds(q)[0] == pytest.approx(want, abs=0.005)
    speed, k_peak = somieski_peak_damping()
    assert speed == pytest.approx(100.7, abs=0.05) and k_peak == pytest.approx(-49.79, abs=0.005)
    assert somieski_damping_needed(speed) == pytest.approx(k_peak, abs=1e-9)
    # the nominal k = -50 is stable by the 0.4 % margin the anchor file states
    assert abs((-50.0 - k_peak) / k_peak) == pytest.approx(0.004, abs=5e-4)
