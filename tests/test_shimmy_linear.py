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


def test_without_friction_the_linear_modes_are_the_free_gears():
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


def test_sweep_jacobian_equals_complex_step_of_the_nonlinear_equations():
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


def test_symmetric_closed_forms_steady_state_is_straight_rolling():
    np.testing.assert_array_equal(equilibrium(GEAR, closed_forms_contact(**COEF)), np.zeros(4))


def test_closed_forms_critical_speed_of_the_example_gear():
    """The golden value: the example gear on the rated-load closed forms loses stability at
    63.63 m/s, where the refined growth rate is zero."""
    cf = closed_forms_contact(**COEF)
    lin = Linearisation.of(GEAR, cf)
    smap = stability_map(lin, np.linspace(1.0, 150.0, 200))
    assert smap.critical_speed == pytest.approx(63.63, abs=0.05)
    assert lin.growth(smap.critical_speed)[0] == pytest.approx(0.0, abs=1e-8)


def test_contact_jacobian_scales_as_one_over_speed():
    """Coulomb friction is homogeneous of degree 0 in the kinematics: the contact's Jacobian at
    speed V is its Jacobian at 1 m/s divided by V, which lets one linearisation serve a sweep;
    and the sweep's Jacobian at V equals the one from the contact differentiated at V."""
    cf = closed_forms_contact(**COEF)
    k1 = np.array([0.03, 0.004, 0.02])
    for V in (7.0, 63.0, 140.0):
        np.testing.assert_allclose(cf.jacobian(*(V * k1)), cf.jacobian(*k1) / V, rtol=ROUND_OFF)
    lin = Linearisation.of(GEAR, cf)
    V = 90.0
    k = np.array([[GEAR.slip_ratio * V] * 2, [0.0, 0.0], [0.0, 0.0]])
    direct = np.array([cf.jacobian(*k[:, j]) for j in range(2)])
    np.testing.assert_allclose(lin.gradients / V, direct, rtol=ROUND_OFF, atol=1e-12 * np.max(np.abs(direct)))


def _hand_jacobian(g: Gear, V: float, A: float, B: float, C: float, D: float, F0: float) -> np.ndarray:
    """The Jacobian of the gear's equations about straight rolling (ψ = y = 0), written out by
    hand. Wheel j's contact slides at vx = V cos ψ + ẏ sin ψ − ψ̇ d_j − (1 − κ) V,
    vy = −V sin ψ + ẏ cos ψ − ψ̇ e, spins at wz = ψ̇; to first order δvx = −d_j δψ̇,
    δvy = −V δψ + δẏ − e δψ̇. At pure longitudinal sliding (Fx = −F0, Fy = Mz = 0) the contact's
    first-order terms are δFx = 0, δFy = −A δvy − B δwz, δMz = −D δvy − C δwz. Then
    I ψ̈ = −k ψ − c ψ̇ + n(−e δFy + δMz) and m ÿ = −k_y y − c_y ẏ + n(−F0 ψ + δFy)
    (the lateral force Σ Fx sin ψ + Fy cos ψ to first order)."""
    n, e = g.wheels, g.trail
    # δFy and δMz as rows over (ψ, ψ̇, y, ẏ)
    dvy = np.array([-V, -e, 0.0, 1.0])
    dwz = np.array([0.0, 1.0, 0.0, 0.0])
    dfy = -A * dvy - B * dwz
    dmz = -D * dvy - C * dwz
    yaw = np.array([-g.torsional_stiffness, -g.torsional_damping, 0.0, 0.0]) + n * (-e * dfy + dmz)
    lat = np.array([-n * F0, 0.0, -g.lateral_stiffness, -g.lateral_damping]) + n * dfy
    yaw, lat = yaw / g.yaw_inertia, lat / g.lateral_mass
    return np.array([[0.0, 1.0, 0.0, 0.0], yaw, [0.0, 0.0, 0.0, 1.0], lat])


def test_jacobian_against_the_equations_written_out_by_hand():
    """The closed forms at pure sliding κV, differentiated by hand: ∂Fy/∂vy = −F0/(κV),
    ∂Fy/∂wz = −k_x M0/(√m κV), ∂Mz/∂wz = −M0 R/(√m κV), ∂Mz/∂vy = 0. A flipped sign of the
    trail in vy (critical speed 63.6 → 43.1 m/s) or of any other term shows here."""
    c = COEF
    for g in (GEAR, GEAR.replace(wheels=1, half_track=0.0, trail=0.2, slip_ratio=0.1)):
        lin = Linearisation.of(g, closed_forms_contact(**c))
        for V in (10.0, 63.0, 140.0):
            kv = g.slip_ratio * V
            A, B = c["F0"] / kv, c["k_x"] * c["M0"] / (np.sqrt(c["m"]) * kv)
            C = c["M0"] * c["R"] / (np.sqrt(c["m"]) * kv)
            want = _hand_jacobian(g, V, A, B, C, 0.0, c["F0"])
            got = lin.jacobian(V)
            np.testing.assert_allclose(got, want, rtol=ROUND_OFF, atol=ROUND_OFF, err_msg=f"V = {V}")


def test_exact_critical_speed_against_the_first_order_integrals(aircraft):
    """The exact integrals' critical speed against an independent computation: the contact's
    derivatives at pure sliding from the pressure's moments (∂Fy/∂vy = −fN/v,
    ∂Fy/∂wz = ∂Mz/∂vy = −(f/v)∬σx dA, ∂Mz/∂wz = −(f/v)∬σx² dA), the hand-written Jacobian, and
    the speed where its largest real part crosses zero (bisection)."""
    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature

    c = aircraft.coefficients
    q = PressureQuadrature.from_polar(aircraft.rolling_map)
    contact = exact_contact(q, FrictionLaw(f=c.f), c.R)
    got = stability_map(Linearisation.of(GEAR, contact), np.linspace(1.0, 150.0, 60)).critical_speed
    w = q.sigma * q.dA
    N, Sx, Sxx = float(np.sum(w)), float(np.sum(w * q.x)), float(np.sum(w * q.x**2))

    def top(V):
        kv = GEAR.slip_ratio * V
        jac = _hand_jacobian(GEAR, V, c.f * N / kv, c.f * Sx / kv, c.f * Sxx / kv, c.f * Sx / kv, c.f * N)
        return float(np.max(np.linalg.eigvals(jac).real))

    lo, hi = 40.0, 120.0
    assert top(lo) < 0 < top(hi)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if top(mid) < 0 else (lo, mid)
    assert got == pytest.approx(lo, rel=1e-4)
    assert got == pytest.approx(86.7, abs=0.1), "the docs' sliding stand-in value"


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


def test_trail_map_reuses_the_contact_jacobian_and_finds_no_shimmy_without_trail():
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


def test_without_friction_the_motion_is_the_free_damped_oscillator():
    """No contact forces: the time integration's yaw is ψ0 e^(−ζωt)(cos ω_d t + ζω/ω_d sin ω_d t)."""
    g = GEAR
    h = simulate(g, _no_friction(), 50.0, equilibrium=np.zeros(4), duration=0.5, sampling=2000.0)
    w = np.sqrt(g.torsional_stiffness / g.yaw_inertia)
    z = g.torsional_damping / (2 * np.sqrt(g.torsional_stiffness * g.yaw_inertia))
    wd = w * np.sqrt(1 - z * z)
    want = h.perturbation * np.exp(-z * w * h.t) * (np.cos(wd * h.t) + z * w / wd * np.sin(wd * h.t))
    # the integrator's rtol 1e-7 per step, accumulated over 70 periods: a few 1e-7 of the amplitude
    np.testing.assert_allclose(h.x[0], want, atol=1e-5 * h.perturbation)
    assert np.max(np.abs(h.x[2])) == 0.0, "no friction, no lateral force: the strut stays straight"


def test_critical_interval_by_value_against_fresh_linearisations():
    """The map-based models' interval: V_c of the contact scaled over f's interval, each level
    from a fresh linearisation of the scaled contact (not the reused, scaled Jacobian); the
    closed forms' delta method: its half-width against a central difference of V_c in F0 with
    another step, for a covariance in F0 alone."""
    from dataclasses import replace
    from types import SimpleNamespace

    from fepost.shimmy.study import F_POINTS, critical_interval

    cf = closed_forms_contact(**COEF)
    speeds = np.linspace(30.0, 120.0, 40)
    lin = Linearisation.of(GEAR, cf)
    vc = stability_map(lin, speeds).critical_speed
    f_row = SimpleNamespace(name="f", ci95=(0.27, 0.34), fitted=0.3)
    table = SimpleNamespace(identification=None, rows=[f_row])
    as_map = replace(cf, name="generalised")  # any model but the closed forms is scaled through f
    (lo, hi), _ = critical_interval(GEAR, as_map, vc, speeds, table, lin)
    fresh = [
        stability_map(Linearisation.of(GEAR, as_map.scaled(level / 0.3)), speeds).critical_speed
        for level in np.linspace(0.27, 0.34, F_POINTS)
    ]
    assert lo == pytest.approx(min([vc, *fresh]), rel=1e-9)
    assert hi == pytest.approx(max([vc, *fresh]), rel=1e-9)
    assert lo < vc < hi, "more friction, more damping: V_c moves with f"

    sd = 0.02 * COEF["F0"]
    cov = np.zeros((5, 5))
    cov[0, 0] = sd**2
    ident = SimpleNamespace(covariance=cov, t_quantile=1.96)
    (lo, hi), _ = critical_interval(GEAR, cf, vc, speeds, SimpleNamespace(identification=ident, rows=[]))
    h = 0.003 * COEF["F0"]
    ends = [
        stability_map(Linearisation.of(GEAR, closed_forms_contact(**{**COEF, "F0": COEF["F0"] + s})), speeds)
        for s in (h, -h)
    ]
    slope = (ends[0].critical_speed - ends[1].critical_speed) / (2 * h)
    assert (hi - lo) / 2 == pytest.approx(1.96 * abs(slope) * sd, rel=1e-3)
    assert (lo + hi) / 2 == pytest.approx(vc, rel=1e-12)


def test_speed_terms_are_used_only_where_they_reproduce_the_jacobian(monkeypatch):
    """J(V) = C0 + C1/V + C2 V holds for these equations (checked against the complex step at
    other speeds); equations with another speed dependence (here a V² term) fall back on the
    direct Jacobian."""
    import fepost.shimmy.linear as linear

    lin = Linearisation.of(GEAR, closed_forms_contact(**COEF))
    assert lin.speed_terms is not None
    for V in (0.7, 33.0, 211.0):
        np.testing.assert_allclose(lin.jacobian(V), lin.direct_jacobian(V), rtol=ROUND_OFF, atol=ROUND_OFF)
    plain = linear.rhs

    def with_v2(x, V, gear, contact):
        return plain(x, V, gear, contact) + np.array([0.0, 1e-3 * V * V * x[0], 0.0, 0.0])

    monkeypatch.setattr(linear, "rhs", with_v2)
    other = Linearisation.of(GEAR, closed_forms_contact(**COEF))
    assert other.speed_terms is None
    assert other.jacobian(100.0)[1, 0] == pytest.approx(lin.jacobian(100.0)[1, 0] + 10.0, rel=1e-12)
