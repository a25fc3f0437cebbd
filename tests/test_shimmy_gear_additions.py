"""Gear-file additions: gyroscopic coupling, strut rake, the touchdown's keys, and the new refusals."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fepost.cli import main
from fepost.shimmy.contact import closed_forms_contact
from fepost.shimmy.equations import rhs, scalar_rhs
from fepost.shimmy.gear import GearFileError, gear_from_dict, load_gear
from fepost.shimmy.linear import Linearisation, stability_map

BASE = {
    "yaw_inertia": 80.0,
    "torsional_stiffness": 1.5e6,
    "torsional_damping": 300.0,
    "trail": 0.1,
    "lateral_mass": 700.0,
    "lateral_stiffness": 2.0e7,
    "lateral_damping": 2000.0,
    "wheels": 2,
    "half_track": 0.46,
    "slip_ratio": 0.03,
}
COEF = {"F0": 59578.6, "M0": 8254.3, "a": 0.652, "m": 10.39, "k_x": 0.2406, "R": 0.2538}


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"half_track": None}, "twin wheels (wheels = 2) need half_track > 0"),
        ({"half_track": 0.0}, "twin wheels (wheels = 2) need half_track > 0"),
        ({"yaw_inertia": 1e-9}, "yaw_inertia = 1e-09 kg m^2 is outside the plausible range"),
        ({"lateral_mass": 5e9}, "lateral_mass = 5e+09 kg is outside the plausible range"),
        (
            {"yaw_inertia": 1e-3},
            "yaw_inertia = 0.001 kg m^2 with torsional_stiffness = 1.5e+06 gives a torsional mode",
        ),
        ({"wheel_spin_inertia": 1e12, "rolling_radius": 0.5}, "wheel_spin_inertia = 1e+12 kg m^2 is outside"),
        ({"wheel_spin_inertia": 20.0}, "wheel_spin_inertia needs rolling_radius > 0"),
        ({"rake": 2.0}, "rake must be below pi/2 rad"),
    ],
)
def test_bad_gear_files_are_refused_in_one_line_naming_the_key(tmp_path, capsys, change, message):
    data = dict(BASE)
    for key, value in change.items():
        if value is None:
            data.pop(key)
        else:
            data[key] = value
    path = tmp_path / "gear.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    with pytest.raises(GearFileError) as err:
        load_gear(path)
    text = str(err.value)
    assert "\n" not in text and text.startswith(str(path)) and message in text
    # the command line says the same in one line with exit status 2, before any FE work
    code = main(["shimmy", "meshes/static.vtu", "--gear", str(path), "--out", str(tmp_path / "out")])
    assert code == 2
    err_text = capsys.readouterr().err.strip()
    assert message in err_text and len(err_text.splitlines()) == 1


def test_the_new_keys_absent_or_zero_leave_the_equations_bit_for_bit():
    """Golden path: without the new keys rhs and scalar_rhs are the old equations, written out here."""
    g = gear_from_dict(dict(BASE))
    cf = closed_forms_contact(**COEF)
    x = np.array([0.003, -0.4, 2e-4, 0.01])
    V, e, d = 63.0, g.trail, np.array(g.offsets)
    vx = V * np.cos(x[0]) + x[3] * np.sin(x[0]) - x[1] * d - (1 - g.slip_ratio) * V
    vy = (-V * np.sin(x[0]) + x[3] * np.cos(x[0]) - x[1] * e) * np.ones(2)
    fx, fy, mz = cf(vx, vy, x[1] * np.ones(2))
    want = [
        x[1],
        (-g.torsional_stiffness * x[0] - g.torsional_damping * x[1] + np.sum(-e * fy - d * fx + mz))
        / g.yaw_inertia,
        x[3],
        (
            -g.lateral_stiffness * x[2]
            - g.lateral_damping * x[3]
            + np.sum(fx * np.sin(x[0]) + fy * np.cos(x[0]))
        )
        / g.lateral_mass,
    ]
    np.testing.assert_allclose(rhs(x, V, g, cf), want, rtol=1e-14)
    np.testing.assert_allclose(scalar_rhs(g, V, cf.scalar)(0.0, list(x)), want, rtol=1e-12)
    zeros = g.replace(wheel_spin_inertia=0.0, rolling_radius=0.0, bending_slope=0.0, rake=0.0)
    assert np.array_equal(rhs(x, V, zeros, cf), rhs(x, V, g, cf))


def test_gyroscopic_coupling_is_skew_and_of_the_issue_size():
    """G = s Σ I_w Ω enters as +G ẏ in yaw and −G ψ̇ laterally: no work; 3.3e3 N m s/m at 60 m/s."""
    g = load_gear("examples/gear_a320_main_touchdown.json")
    assert g.gyroscopic * 60.0 == pytest.approx(0.75 * 2 * 21.0 / 0.5694 * 60.0, rel=1e-12)
    assert 2e3 < g.gyroscopic * 60.0 < 5e3
    none = closed_forms_contact(F0=0.0, M0=0.0, a=1.0, m=9.0, k_x=0.0, R=0.25)
    x = np.array([0.0, 0.7, 0.0, -0.3])
    V = 60.0
    with_g = rhs(x, V, g, none)
    without = rhs(x, V, g.replace(bending_slope=0.0), none)
    G = g.gyroscopic * (1 - g.slip_ratio) * V
    assert (with_g[1] - without[1]) * g.yaw_inertia == pytest.approx(G * x[3], rel=1e-12)
    assert (with_g[3] - without[3]) * g.lateral_mass == pytest.approx(-G * x[1], rel=1e-12)
    power = g.yaw_inertia * x[1] * (with_g[1] - without[1]) + g.lateral_mass * x[3] * (with_g[3] - without[3])
    assert abs(power) < 1e-9 * abs(G * x[1] * x[3])
    # it moves the boundary of the example gear (the golden 63.63 m/s without it)
    cf = closed_forms_contact(**COEF)
    speeds = np.linspace(1.0, 150.0, 200)
    base = stability_map(Linearisation.of(g.replace(bending_slope=0.0), cf), speeds).critical_speed
    gyro = stability_map(Linearisation.of(g, cf), speeds).critical_speed
    assert base == pytest.approx(63.63, abs=0.05)
    assert gyro is None or abs(gyro - base) > 0.5


def test_rake_steers_by_psi_cos_gamma_and_projects_the_moment():
    """A raked strut: the equations with ψ are the vertical strut's with δ = ψ cos γ, moment × cos γ."""
    gam = 0.2
    g = gear_from_dict({**BASE, "rake": gam})
    flat = g.replace(rake=0.0)
    cf = closed_forms_contact(**COEF)
    x = np.array([0.004, 0.3, 1e-4, -0.02])
    xs = np.array([x[0] * math.cos(gam), x[1] * math.cos(gam), x[2], x[3]])
    V = 70.0
    got, ref = rhs(x, V, g, cf), rhs(xs, V, flat, cf)
    # the contact's yaw moment in the vertical strut's equation, without the structure's terms
    m_ref = ref[1] * g.yaw_inertia + g.torsional_stiffness * xs[0] + g.torsional_damping * xs[1]
    m_got = got[1] * g.yaw_inertia + g.torsional_stiffness * x[0] + g.torsional_damping * x[1]
    assert m_got == pytest.approx(math.cos(gam) * m_ref, rel=1e-12)
    assert got[3] == pytest.approx(ref[3], rel=1e-12)
    np.testing.assert_allclose(scalar_rhs(g, V, cf.scalar)(0.0, list(x)), got, rtol=1e-10)


def _yaw_damping(tire, gear, V, sliding):
    """∂(yaw moment)/∂ψ̇ of the wheels' steady forces at straight rolling (N m s/rad)."""
    kap = gear.slip_ratio
    vr = (1 - kap) * V
    out = []
    for rate in (1e-4, -1e-4):
        moment = 0.0
        for d in gear.offsets:
            vx, vy = kap * V - rate * d, -rate * gear.trail
            if sliding:
                fx, fy, mz = (float(q) for q in tire.sliding_forces(vx, vy, rate))
            else:
                fx, fy, mz = tire.resultants(*tire.steady(vx, vy, rate, vr))
            moment += -gear.trail * fy - d * fx + mz
        out.append(moment)
    return -(out[0] - out[1]) / 2e-4


def test_twin_wheel_yaw_damping_needs_the_gripping_tire(brush_tire):
    """Doubling half_track: on the gripping tire the wheels' differential longitudinal force
    (slip stiffness times d² per V) damps yaw about 4 times as much; on the sliding wheel
    ∂Fx/∂vx = 0 and half_track changes nothing, as issue 40 found of today's model."""
    from fepost.shimmy.gripping import GripModel

    g = gear_from_dict(dict(BASE))
    g2 = g.replace(half_track=0.92)
    V = 60.0
    grip = [_yaw_damping(brush_tire, gg, V, sliding=False) for gg in (g, g2)]
    slide = [_yaw_damping(brush_tire, gg, V, sliding=True) for gg in (g, g2)]
    assert grip[1] > 3.0 * grip[0] > 0
    assert slide[1] == pytest.approx(slide[0], rel=1e-6)
    # and in the gear's eigenvalues: the sliding wheels' are the same, the gripping ones' are not
    ev = [
        np.sort_complex(Linearisation.of(gg, brush_tire.sliding_contact()).eigenvalues(V)) for gg in (g, g2)
    ]
    np.testing.assert_allclose(ev[0], ev[1], rtol=1e-6)
    grip_ev = [GripModel(gg, brush_tire).eigenvalues(V) for gg in (g, g2)]
    band = [np.sort_complex(e[(e.imag > 50) & (e.imag < 300) & (e.real > -200)]) for e in grip_ev]
    assert band[0].size == 2 and band[1].size == 1  # the torsional mode (-40 1/s) is overdamped at 0.92 m


@pytest.fixture(scope="module")
def brush_tire():
    from fepost.analysis import analyse
    from fepost.friction.quadrature import PressureQuadrature
    from fepost.shimmy.brush import BrushTire

    an = analyse("meshes/rig-aircraft/roll_static.vtu")
    quad = PressureQuadrature.from_polar(an.static_map)
    return BrushTire.from_quadrature(quad, f=an.coefficients.f, stiffness=(3.43e6, 5.9e5), nx=8, ny=3)
