"""Shimmy equations and linear stability: known limits, the Jacobian, linear against nonlinear."""

from __future__ import annotations

import numpy as np
import pytest

from fepost.shimmy.contact import COMPLEX_STEP, Contact, closed_forms_contact, exact_contact, model_contact
from fepost.shimmy.equations import equilibrium, rhs, scalar_rhs
from fepost.shimmy.gear import Gear
from fepost.shimmy.linear import Linearisation, stability_map
from fepost.shimmy.simulate import simulate
from fepost.shimmy.table import DirectionTable

ROUND_OFF = 1e-9

GEAR = Gear(
    yaw_inertia=80.0,
    torsional_stiffness=1.5e6,
    torsional_damping=300.0,
    trail=0.1,
    lateral_mass=700.0,
    lateral_stiffness=2.0e7,
    lateral_damping=2000.0,
    wheels=2,
    half_track=0.46,
    slip_ratio=0.03,
)
COEF = {"F0": 59578.6, "M0": 8254.3, "a": 0.652, "m": 10.39, "k_x": 0.2406, "R": 0.2538}


def _no_friction() -> Contact:
    def forces(vx, vy, wz):
        z = 0 * np.asarray(vx)
        return z, z, z

    return Contact("none", forces, 0.25, 0.0, 0.0, complex_ok=True, scalar=lambda *_: (0.0, 0.0, 0.0))


def test_without_friction_the_free_gear_modes():
    """No contact forces: the eigenvalues are those of I s² + c s + k and m s² + c_y s + k_y."""
    lin = Linearisation.of(GEAR, _no_friction())
    got = np.sort_complex(lin.eigenvalues(50.0))
    g = GEAR
    want = np.sort_complex(
        np.concatenate(
            [
                np.roots([g.yaw_inertia, g.torsional_damping, g.torsional_stiffness]),
                np.roots([g.lateral_mass, g.lateral_damping, g.lateral_stiffness]),
            ]
        )
    )
    np.testing.assert_allclose(got, want, rtol=ROUND_OFF)


def test_jacobian_equals_complex_step_of_the_nonlinear_equations():
    cf = closed_forms_contact(**COEF)
    lin = Linearisation.of(GEAR, cf)
    for V in (10.0, 63.0, 140.0):
        full = np.empty((4, 4))
        for j in range(4):
            x = lin.state.astype(complex)
            x[j] += 1j * COMPLEX_STEP
            full[:, j] = np.imag(rhs(x, V, GEAR, cf)) / COMPLEX_STEP
        np.testing.assert_allclose(lin.jacobian(V), full, rtol=ROUND_OFF, atol=ROUND_OFF, err_msg=f"V = {V}")


def test_scalar_rhs_equals_rhs():
    cf = closed_forms_contact(**COEF)
    rng = np.random.default_rng(5)
    for x in rng.normal(scale=[0.02, 0.5, 0.002, 0.05], size=(20, 4)):
        np.testing.assert_allclose(
            scalar_rhs(GEAR, 70.0, cf.scalar)(0.0, x), rhs(x, 70.0, GEAR, cf), rtol=1e-12
        )


def test_symmetric_closed_forms_roll_straight():
    np.testing.assert_array_equal(equilibrium(GEAR, closed_forms_contact(**COEF)), np.zeros(4))


def test_critical_speed_scales_as_homogeneity_says():
    """Speeds enter only through V and the friction Jacobian ∝ 1/V: the map at V equals the direct
    eigenvalues of the nonlinear equations' Jacobian at V."""
    cf = closed_forms_contact(**COEF)
    lin = Linearisation.of(GEAR, cf)
    smap = stability_map(lin, np.linspace(1.0, 150.0, 200))
    assert smap.critical_speed == pytest.approx(63.63, abs=0.05)
    assert lin.growth(smap.critical_speed)[0] == pytest.approx(0.0, abs=1e-8)


def _contacts(aircraft):
    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature

    c = aircraft.coefficients
    yield closed_forms_contact(F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=c.k_x, R=c.R)
    yield model_contact(aircraft.model_summary.rolling)
    yield exact_contact(PressureQuadrature.from_polar(aircraft.rolling_map), FrictionLaw(f=c.f), c.R)


def test_linear_and_nonlinear_verdicts_agree_on_both_sides(aircraft):
    """For each friction model: 0.8 V_c decays, 1.2 V_c does not (grows or settles on a limit cycle)."""
    for contact in _contacts(aircraft):
        lin = Linearisation.of(GEAR, contact)
        vc = stability_map(lin, np.linspace(1.0, 150.0, 60)).critical_speed
        assert vc is not None, contact.name
        sim = contact if contact.scalar is not None else DirectionTable.build(contact, 97, 49).as_contact()
        below = simulate(GEAR, sim, 0.8 * vc, equilibrium=lin.state, duration=4.0, sampling=200.0)
        above = simulate(GEAR, sim, 1.2 * vc, equilibrium=lin.state, duration=4.0, sampling=200.0)
        assert lin.growth(0.8 * vc)[0] < 0 < lin.growth(1.2 * vc)[0]
        assert below.verdict == "decays", contact.name
        assert above.verdict in ("grows", "limit_cycle"), contact.name
        assert above.final_amplitude > 1.5 * above.perturbation, contact.name


def test_trail_map_reuses_the_contact_jacobian_faithfully():
    from fepost.shimmy.linear import trail_map

    cf = closed_forms_contact(**COEF)
    lin = Linearisation.of(GEAR, cf)
    other = GEAR.replace(trail=0.2)
    reused, fresh = lin.for_gear(other, cf).jacobian(70.0), Linearisation.of(other, cf).jacobian(70.0)
    np.testing.assert_allclose(reused, fresh, rtol=ROUND_OFF, atol=ROUND_OFF)
    speeds = np.linspace(1.0, 150.0, 60)
    tm = trail_map(lin, cf, [0.0, GEAR.trail], speeds)
    assert tm.critical_speeds[0] is None, "no trail: the coupling through e vanishes, no shimmy"
    assert tm.critical_speeds[1] == pytest.approx(stability_map(lin, speeds).critical_speed, rel=1e-9)
