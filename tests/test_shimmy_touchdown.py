"""Touchdown: spin-up under the coupled friction of the patch, energy balance, the reading of a run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fepost.errors import ArgumentError
from fepost.shimmy.gear import load_gear
from fepost.shimmy.touchdown import read_touchdown, simulate_touchdown, touchdown_tire

GEAR = "examples/gear_a320_main_touchdown.json"


@pytest.fixture(scope="module")
def tire():
    from fepost.analysis import analyse
    from fepost.friction.quadrature import PressureQuadrature

    an = analyse("meshes/rig-aircraft/roll_static.vtu")
    quad = PressureQuadrature.from_polar(an.static_map)
    return touchdown_tire(load_gear(GEAR), quad, an.coefficients.f, nx=8, ny=3)


@pytest.fixture(scope="module")
def run(tire):
    return simulate_touchdown(load_gear(GEAR), tire, 70.0, sink_rate=1.5, yaw=0.01, duration=0.8)


def test_energy_balance_closes_to_the_integrators_tolerance(run):
    """Kinetic + elastic + tread energy change = the contact's work on the forward motion − the
    dampers' − the sliding elements' − the tread's leaving the patch or diluted as it grows."""
    t = run.energy_terms
    assert run.energy_residual < 1e-5
    assert t["sliding"] > 0.4 * t["work_forward"] > 0
    # the wheels' spin energy is most of the change: ½ I_w ω² per wheel at ω = V/R_e
    g = load_gear(GEAR)
    spin = g.wheels * 0.5 * g.wheel_spin_inertia * (70.0 / g.rolling_radius) ** 2
    assert t["energy_change"] == pytest.approx(spin, rel=0.01)
    # half the forward work goes into the spin, half is lost to sliding: the classical spin-up split
    assert t["sliding"] == pytest.approx(0.5 * t["work_forward"], rel=0.05)


def test_wheels_end_rolling_at_the_road_speed(run):
    g = load_gear(GEAR)
    rolling = run.x[4:, -1] * g.rolling_radius / run.speed
    np.testing.assert_allclose(rolling, 1.0, atol=2e-3)
    assert np.mean(rolling) == pytest.approx(1.0, abs=2e-4)


def test_spin_up_time_against_the_sliding_wheel_closed_form(run, tire):
    """A fully sliding wheel under the growing load: I_w ω̇ = R_e f N s(t), s = min(1, t/t_load):
    ω R_e reaches 0.99 V at t = t_load/2 + 0.99 V I_w/(R_e² f N). The tire's grip at the end
    (partial sliding) makes the run's spin-up a little longer."""
    g = load_gear(GEAR)
    t_load = g.tire_deflection / run.sink_rate
    rate = g.rolling_radius**2 * tire.f * tire.load / g.wheel_spin_inertia
    want = t_load / 2 + 0.99 * run.speed / rate
    assert want < run.spin_up_time < 1.1 * want


def test_row_and_csv_follow_the_contract(run):
    row = run.row("touchdown_70.00.csv")
    for key in ("speed", "spin_up_time", "verdict", "amplitude", "csv"):
        assert key in row
    assert row["verdict"] in ("decays", "grows", "limit_cycle")
    assert row["amplitude"] == pytest.approx(float(np.max(np.abs(run.x[0][run.t >= run.spin_up_time]))))
    head = run.to_csv().splitlines()[0].split(",")
    assert head == ["t", "psi", "psi_dot", "y", "y_dot", "omega_1", "omega_2", "load_share"]
    assert run.verdict == "decays"  # the example gear rolls stably once the tire grips


@pytest.mark.parametrize(
    ("envelope", "verdict"),
    [
        (lambda t: 0.01 * np.exp(-3 * t), "decays"),
        (lambda t: 1e-3 * np.exp(2 * t), "grows"),
        (lambda t: 0.004 + 0 * t, "limit_cycle"),
    ],
)
def test_reading_a_run_by_its_settled_amplitude(envelope, verdict):
    """The verdict reads the oscillation's amplitude window by window after spin-up, not the kick."""
    g = load_gear(GEAR)
    t = np.linspace(0.0, 3.0, 3001)
    psi = envelope(t) * np.sin(2 * math.pi * 20 * t)
    omega = np.full((2, t.size), 70.0 / g.rolling_radius)
    omega[:, t < 0.1] = 0.0
    x = np.vstack([psi, np.gradient(psi, t), 0 * t, 0 * t, omega])
    spin_up, got, amplitude, windows = read_touchdown(t, x, g, 70.0)
    assert spin_up == pytest.approx(0.1, abs=2e-3)
    assert got == verdict and len(windows) == 5


def test_gear_without_the_touchdown_parameters_is_refused(tire):
    g = load_gear("examples/gear_a320_main.json")
    with pytest.raises(ArgumentError, match="the touchdown needs wheel_spin_inertia > 0"):
        simulate_touchdown(g, tire, 70.0)
    with pytest.raises(ArgumentError, match="sink_rate must be positive"):
        simulate_touchdown(load_gear(GEAR), tire, 70.0, sink_rate=0.0)


def test_command_writes_the_touchdown_rows(tmp_path, capsys):
    """fepost shimmy ... --touchdown: the rows of ../shared/INTERFACE.md and their CSV files."""
    import json

    from fepost.cli import main

    out = tmp_path / "out"
    args = ["shimmy", "meshes/rig-aircraft/roll_static.vtu", "--gear", GEAR, "--out", str(out)]
    args += ["--models", "closed_forms", "--speeds", "5", "--trails", "0", "--branch-speeds", "0"]
    args += ["--no-simulation", "--no-intervals", "--no-progress"]
    args += ["--touchdown", "60", "--touchdown-yaw", "0.5,1", "--touchdown-duration", "0.15"]
    assert main(args) == 0
    data = json.loads((out / "shimmy.json").read_text())
    rows = data["touchdown"]
    assert [r["initial_yaw"] for r in rows] == pytest.approx([math.radians(0.5), math.radians(1.0)])
    for r in rows:
        assert {"speed", "spin_up_time", "verdict", "amplitude", "csv"} <= set(r)
        assert r["speed"] == 60.0 and 0.05 < r["spin_up_time"] < 0.2
        assert (out / r["csv"]).read_text().startswith("t,psi,psi_dot,y,y_dot,omega_1,omega_2,load_share\n")
    assert capsys.readouterr().out.count("touchdown 60 m/s") == 2


def test_command_refuses_a_touchdown_the_gear_file_cannot_give(tmp_path, capsys):
    from fepost.cli import main

    out = tmp_path / "out"
    args = ["shimmy", "meshes/static.vtu", "--gear", "examples/gear_a320_main.json", "--out", str(out)]
    assert main([*args, "--touchdown", "70"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(
        "gear_a320_main.json: the touchdown needs wheel_spin_inertia > 0 in the gear file (docs/touchdown.md)"
    )
    assert not out.exists()
    assert main([*args, "--touchdown", "70,abc"]) == 2
    assert "--touchdown: must be a comma-separated list of numbers, got 'abc'" in capsys.readouterr().err
