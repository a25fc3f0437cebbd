"""The published anchor: Somieski's nose gear with a stretched-string tire, two independent ways."""

from __future__ import annotations

import numpy as np
import pytest

from fepost.shimmy.anchor import (
    SomieskiGear,
    anchor_record,
    eigen_critical_speeds,
    growth,
    nonlinear_rhs,
    routh_hurwitz_speeds,
)
from fepost.shimmy.simulate import verdict_of


def test_published_parameter_table():
    p = SomieskiGear()
    assert (p.a, p.e, p.Iz, p.Fz, p.c, p.cFa, p.cMa, p.kappa, p.sigma) == (
        0.1,
        0.1,
        1.0,
        9000.0,
        -100000.0,
        20.0,
        -2.0,
        -270.0,
        0.3,
    )
    assert np.degrees(p.delta) == pytest.approx(5.0) and np.degrees(p.alpha_g) == pytest.approx(10.0)


@pytest.mark.parametrize("k", [0.0, -10.0, -20.0, -30.0])
def test_eigenvalues_and_routh_hurwitz_agree(k):
    p = SomieskiGear().with_damping(k)
    eig = eigen_critical_speeds(p)
    rh = [v for v in routh_hurwitz_speeds(p) if v <= 300.0]
    assert len(eig) == len(rh) >= 1
    np.testing.assert_allclose([v for v, _ in eig], rh, rtol=1e-9)


def test_boundary_frequency_is_the_hurwitz_one():
    """On the boundary the cubic has roots ±iω with ω² = a₁/a₃ = (D V/σ + C + Q(e − a))/I_z."""
    p = SomieskiGear().with_damping(0.0)
    ((v, f),) = eigen_critical_speeds(p)
    D = -p.k - p.kappa / v
    Q = p.Fz * (p.e * p.cFa - p.cMa) / p.sigma
    omega = np.sqrt((D * v / p.sigma - p.c + Q * (p.e - p.a)) / p.Iz)
    assert f == pytest.approx(omega / (2 * np.pi), rel=1e-9)
    assert v == pytest.approx(15.2593, abs=1e-4)


def test_damper_of_minus_50_removes_shimmy_in_the_speed_range():
    assert eigen_critical_speeds(SomieskiGear()) == ()
    assert max(growth(SomieskiGear(), v)[0] for v in np.linspace(1, 100, 50)) < 0


def test_nonlinear_model_decays_below_and_settles_on_a_066_rad_cycle_above():
    """Saturating tire, k = 0: at 0.8 V_c the kick dies away; at 1.3 V_c the motion settles on
    the limit cycle of 0.66 rad the docs quote (settled: the amplitude of the last 0.6 s within 5 %
    of the 0.6 s before)."""
    from scipy.integrate import solve_ivp

    p = SomieskiGear().with_damping(0.0)
    ((vc, _),) = eigen_critical_speeds(p)
    results = []
    for v in (0.8 * vc, 1.3 * vc):
        t = np.linspace(0, 3.0, 3001)
        sol = solve_ivp(nonlinear_rhs(p, v), (0, 3.0), [0.01, 0.0, 0.0], t_eval=t, rtol=1e-8, atol=1e-11)
        results.append(verdict_of(sol.t, np.abs(sol.y[0]), 0.01))
    assert results[0][0] == "decays"
    verdict, amplitude, _ = results[1]
    assert verdict == "limit_cycle"
    assert amplitude == pytest.approx(0.66, abs=0.005)


def test_anchor_record_keys():
    rec = anchor_record()
    assert set(rec) == {"reference", "published", "computed"}
    assert "Somieski" in rec["reference"]
    k0 = rec["computed"]["cases"][0]
    assert k0["critical_speed_eigenvalues"][0] == pytest.approx(
        k0["critical_speed_routh_hurwitz"][0], rel=1e-9
    )
