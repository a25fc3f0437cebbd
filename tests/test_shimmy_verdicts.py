"""Shimmy verdicts that cannot be quietly wrong (issue 40, E1-E4): a gear unstable over the whole
range, a restabilisation speed, round-off growth rates, and a limit cycle smaller than the kick."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

# the example gear (examples/gear_a320_main.json) and closed forms of the rated-load tire
from test_shimmy_linear import COEF, GEAR

from fepost.cli import main
from fepost.shimmy.contact import closed_forms_contact, model_contact
from fepost.shimmy.linear import Linearisation, stability_map
from fepost.shimmy.result import ModelStability
from fepost.shimmy.simulate import simulate, verdict_of

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "gear_a320_main.json"
STATIC = REPO / "meshes" / "aircraft" / "static_100.vtu"


@pytest.fixture(scope="module")
def closed_forms():
    return closed_forms_contact(**COEF)


def test_e1_unstable_over_the_whole_range_is_said(closed_forms):
    """E1: above 90 m/s the example gear grows everywhere; no boundary, one open unstable range."""
    smap = stability_map(Linearisation.of(GEAR, closed_forms), np.linspace(90.0, 150.0, 40))
    assert np.all(smap.growth_rate > 0.5)
    assert smap.verdict == "unstable"
    assert smap.boundaries == ()
    assert smap.critical_speed is None
    assert smap.unstable_ranges == ((90.0, None),)
    assert smap.summary() == "unstable over the whole range (90 to 150 m/s)"
    d = ModelStability("closed_forms", smap, None, "none").to_dict()
    assert d["critical_speed"] is None and d["unstable_ranges"] == [[90.0, None]] and d["boundaries"] == []


def test_e1_the_command_says_unstable_over_the_whole_range(tmp_path, capsys):
    if not STATIC.is_file():
        pytest.skip(f"{STATIC} not shipped")
    out = tmp_path / "o"
    argv = ["shimmy", str(STATIC), "--gear", str(EXAMPLE), "--out", str(out), "--models", "closed_forms"]
    opts = ["--speed-min", "90", "--speeds", "20", "--no-intervals", "--no-simulation", "--trails", "0"]
    assert main([*argv, *opts]) == 0
    printed = capsys.readouterr().out
    assert "closed_forms: unstable over the whole range (90 to 150 m/s)" in printed, printed
    fm = json.loads((out / "shimmy.json").read_text())["friction_models"]["closed_forms"]
    assert fm["critical_speed"] is None and fm["unstable_ranges"] == [[90.0, None]]


def test_e2_restabilisation_is_an_end_not_a_critical_speed(closed_forms):
    """E2: with k_psi = 0.75e6 the gear is unstable at 60 m/s and stable again above a speed:
    that speed is the end of the unstable range, and there is no onset in 60-300 m/s."""
    gear = GEAR.replace(torsional_stiffness=0.75e6)
    lin = Linearisation.of(gear, closed_forms)
    smap = stability_map(lin, np.linspace(60.0, 300.0, 120))
    assert smap.critical_speed is None
    (b,) = smap.boundaries
    assert b.direction == "end"
    assert lin.growth(b.speed - 1.0)[0] > 0 > lin.growth(b.speed + 1.0)[0]
    assert abs(lin.growth(b.speed)[0]) < 1e-9
    assert smap.critical_speed is None
    assert smap.unstable_ranges == ((60.0, b.speed),)
    d = ModelStability("closed_forms", smap, None, "none").to_dict()
    assert d["boundaries"] == [{"speed": b.speed, "direction": "end", "frequency_hz": b.frequency_hz}]
    assert d["unstable_ranges"] == [[60.0, b.speed]] and d["critical_speed"] is None
    # over 1-300 m/s the same gear has an onset first: the critical speed is that onset
    full = stability_map(lin, np.linspace(1.0, 300.0, 200))
    assert [x.direction for x in full.boundaries] == ["onset", "end"]
    onset, end = (x.speed for x in full.boundaries)
    assert full.critical_speed == onset and end == pytest.approx(b.speed, rel=1e-9)
    assert full.unstable_ranges == ((onset, end),)
    assert lin.growth(onset - 1.0)[0] < 0 < lin.growth(onset + 1.0)[0]


def test_e3_round_off_growth_rates_give_no_critical_speed(aircraft):
    """E3: no torsional stiffness, damping or trail: the yaw is neutral (growth rate zero up to
    round-off, about 1e-13 1/s, on the generalised static map); no boundary may come of it."""
    gear = GEAR.replace(torsional_stiffness=0.0, torsional_damping=0.0, trail=0.0)
    smap = stability_map(
        Linearisation.of(gear, model_contact(aircraft.model_summary.static)), np.linspace(1.0, 150.0, 200)
    )
    assert np.max(np.abs(smap.growth_rate)) < 1e-11, "the growth rates are round-off"
    assert smap.critical_speed is None
    assert 1e-5 > smap.tolerance > np.max(np.abs(smap.growth_rate)), "e-folding time over a day"
    assert smap.boundaries == () and smap.critical_speed is None
    assert smap.verdict == "stable" and smap.unstable_ranges == ()


def test_e4_a_limit_cycle_smaller_than_the_kick_is_a_limit_cycle(closed_forms):
    """E4: at 76.4 m/s the example gear settles on a 0.0072 rad cycle; kicked with 0.01 rad it
    comes down onto that cycle, which is a limit cycle, not a decay."""
    lin = Linearisation.of(GEAR, closed_forms)
    h = simulate(
        GEAR, closed_forms, 76.4, equilibrium=lin.state, perturbation=0.01, duration=4.0, sampling=400.0
    )
    assert h.verdict == "limit_cycle"
    assert h.amplitude == pytest.approx(0.00716, rel=0.01)


def test_verdict_reads_where_the_motion_settles():
    """Synthetic deviations: each verdict from its shape, whatever the kick's size."""
    t = np.linspace(0.0, 10.0, 10001)
    wave = np.abs(np.sin(2 * np.pi * 23.0 * t))
    settled = (0.007 + 0.003 * np.exp(-2.0 * t)) * wave  # from 0.01 down onto 0.007
    assert verdict_of(t, settled, 0.01)[:2] == ("limit_cycle", pytest.approx(0.007, rel=1e-4))
    assert verdict_of(t, 0.01 * np.exp(-1.0 * t) * wave, 0.01)[0] == "decays"
    assert verdict_of(t, 1e-3 * np.exp(0.5 * t) * wave, 1e-3)[0] == "grows"
    assert verdict_of(t, 1e-14 * wave, 1e-3)[0] == "decays", "round-off left of a decay"
