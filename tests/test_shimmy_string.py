"""The tire between sliding and gripping: the brush over the FE patch, its two limits, the string's dip."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from fepost.shimmy.brush import BrushTire, rig_stiffness
from fepost.shimmy.gear import Gear, load_gear
from fepost.shimmy.gripping import GripModel
from fepost.shimmy.linear import Linearisation
from fepost.shimmy.tire_string import dip_wavelength, simulate_yaw, yaw_response

RIG = Path("meshes/rig-aircraft")


@pytest.fixture(scope="module")
def patch():
    from fepost.analysis import analyse
    from fepost.friction.quadrature import PressureQuadrature

    an = analyse(RIG / "roll_static.vtu")
    return PressureQuadrature.from_polar(an.static_map), an.coefficients.f


@pytest.fixture(scope="module")
def tire(patch):
    quad, f = patch
    k = rig_stiffness(RIG)
    return BrushTire.from_quadrature(quad, f=f, stiffness=(k["K_x"], k["K_y"]), nx=8, ny=3)


def test_rig_stiffness_is_the_slides_first_force_over_path():
    k = rig_stiffness(RIG)
    assert k["K_x"] == pytest.approx(3.429e6, rel=1e-3)
    assert k["K_y"] == pytest.approx(5.898e5, rel=1e-3)
    # a second reading: the secant to the fourth increment alone
    for axis, run in (("x", "d000_slide"), ("y", "d090_slide")):
        h = json.loads((RIG / f"{run}.json").read_text())["history"]
        assert -h["F" + axis][3] / h["path"][3] == pytest.approx(k["K_" + axis], rel=0.03)


def test_full_sliding_is_the_exact_coulomb_integral(tire, patch):
    """Locked wheel (V_r = 0): every element slides, F = Σ −f n_i ŵ_i; against fepost's exact
    integrals over the whole FE map within 4 % of F0 and M0 with 8 x 3 cells (3.1 % measured, pure
    spin), 1 % with 16 x 6 (0.65 %)."""
    from fepost.friction.exact import friction_resultants
    from fepost.friction.law import FrictionLaw

    quad, f = patch
    fine_tire = BrushTire.from_quadrature(quad, f=f, stiffness=(1.0, 1.0), nx=16, ny=6)
    kin = [(1.0, 0.0, 0.0), (0.3, -0.8, 2.0), (0.0, 0.0, 1.0), (-0.5, 0.2, -6.0)]
    f0, m0 = f * quad.load, -float(friction_resultants(quad, 0.0, 0.0, 1.0, FrictionLaw(f=f)).Mz)
    for vx, vy, wz in kin:
        got = np.array(tire.resultants(*tire.steady(vx, vy, wz, 0.0)))
        slide = np.array([float(q) for q in tire.sliding_forces(vx, vy, wz)])
        np.testing.assert_allclose(got, slide, rtol=1e-12, atol=1e-9 * f0)
        r = friction_resultants(quad, vx, vy, wz, FrictionLaw(f=f))
        exact = np.array([float(r.Fx), float(r.Fy), float(r.Mz)])
        scale = np.array([f0, f0, m0])
        fine = np.array([float(q) for q in fine_tire.sliding_forces(vx, vy, wz)])
        assert np.all(np.abs(slide - exact) <= 0.04 * scale)
        assert np.all(np.abs(fine - exact) <= 0.01 * scale)


def test_slip_curve_against_the_rolling_runs(tire):
    """Steady braking slip of the brush against the FE rolling runs' Fx/N at the end of the roll
    (the 1 % and 4 % runs are still building up, docs/rolling.md): within 0.015."""
    for run in ("roll_brake01", "roll_brake04", "roll_brake20"):
        d = json.loads((RIG / f"{run}.json").read_text())
        kappa = -d["longitudinal_slip"]
        fe = d["longitudinal_force_ratio"]
        V = 50.0
        fx = tire.resultants(*tire.steady(kappa * V, 0.0, 0.0, (1 - kappa) * V))[0]
        assert fx / tire.load == pytest.approx(fe, abs=0.015), run


def test_stiff_brush_under_the_gear_is_todays_sliding_model(tire):
    """Stiffness x 1e4 at the held slip 0.03: no element grips beyond its first millimetres, and the
    growth rates are those of the rigid sliding wheel with the same elements' Coulomb forces
    (today's model) within 0.02 1/s; at the FE stiffness the gear is stable where that model is not."""
    gear = load_gear("examples/gear_a320_main.json")
    rigid = Linearisation.of(gear, tire.sliding_contact())
    speeds = (30.0, 120.0)
    want = np.array([rigid.growth(V)[0] for V in speeds])
    stiff = np.array([GripModel(gear, tire.stiffer(1e4)).growth_rate(V) for V in speeds])
    middle = GripModel(gear, tire.stiffer(1e2)).growth_rate(speeds[-1])
    fe = np.array([GripModel(gear, tire).growth_rate(V) for V in speeds])
    np.testing.assert_allclose(stiff, want, atol=0.02)
    assert abs(middle - want[-1]) > 10 * np.max(np.abs(stiff - want))
    assert want[-1] > 1.0 and np.all(fe < -3.0)


def _constrained(g: Gear, V: float) -> np.ndarray:
    """Eigenvalues of the gear on a rigid non-holonomic wheel (no side slip at the contact),
    state (ψ, ψ̇, y): ẏ = V ψ + e ψ̇, the side force the multiplier, written out here."""
    e, m = g.trail, g.lateral_mass
    inertia = g.yaw_inertia + m * e * e
    a = np.array(
        [
            [0.0, 1.0, 0.0],
            [
                -(g.torsional_stiffness + e * g.lateral_damping * V) / inertia,
                -(g.torsional_damping + e * m * V + e * e * g.lateral_damping) / inertia,
                -e * g.lateral_stiffness / inertia,
            ],
            [V, e, 0.0],
        ]
    )
    return np.linalg.eigvals(a)


def test_stiff_point_brush_is_the_rigid_non_holonomic_wheel(tire):
    """Free rolling, one wheel: stiffness to infinity with the patch shrunk to a point (cornering
    stiffness ~ k s to infinity, turn-slip stiffness ~ k s² to 0): the gear's slow eigenvalues
    tend to the constrained wheel's."""
    g = Gear(
        yaw_inertia=80.0,
        torsional_stiffness=1.5e6,
        torsional_damping=300.0,
        trail=0.1,
        lateral_mass=700.0,
        lateral_stiffness=2e7,
        lateral_damping=2000.0,
        slip_ratio=1e-9,
    )
    V = 40.0
    want = _constrained(g, V)

    def slow(s, k):
        ev = GripModel(g, tire.shrunk(s).stiffer(k)).eigenvalues(V)
        return ev[np.argsort(np.abs(ev))][:3]

    def distance(got):
        return max(np.min(np.abs(got - w)) / abs(w) for w in want)

    far, near = distance(slow(1e-2, 1e3)), distance(slow(1e-6, 1e10))
    assert near < 0.012 and far > 0.2
    pair = want[np.abs(want.imag) > 0][0]
    assert pair.real > 0  # this gear shimmies on a rigid wheel at 40 m/s, and on the limit brush
    assert np.max(slow(1e-6, 1e10).real) == pytest.approx(pair.real, abs=0.02)


def test_string_dip_at_11_65a_by_the_closed_form_and_by_marching():
    """Pacejka's exact string, σ = 3a, yawed while rolling: the aligning moment dips at 11.65a."""
    lam = dip_wavelength(1.0, 3.0)
    assert lam == pytest.approx(11.65, abs=0.01)
    for w in (0.8 * lam, lam, 1.25 * lam):
        fy, mz = yaw_response(w, 1.0, 3.0)
        f_m, m_m = simulate_yaw(w, 1.0, 3.0, nodes=100, periods=4)
        assert m_m == pytest.approx(abs(mz), rel=1e-3)
        assert f_m == pytest.approx(abs(fy), rel=1e-3)
    marched = [simulate_yaw(w, 1.0, 3.0, nodes=100, periods=4)[1] for w in (0.9 * lam, lam, 1.1 * lam)]
    assert marched[1] < min(marched[0], marched[2])


def test_string_dip_on_the_fe_patch(tire):
    """Driven by the FE patch: half length a from the map, σ = 3a: the dip at 11.65a in metres."""
    a = tire.half_length
    assert 0.2 < a < 0.26  # the rolled patch is 464 mm long (docs/rolling.md)
    assert dip_wavelength(a, 3 * a) == pytest.approx(11.654 * a, rel=1e-3)
