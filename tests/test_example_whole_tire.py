"""examples/gear_a320_main_whole.json: every tire value it says comes from the FE is what the FE gives.

The gear file puts the example gear on the whole 360-degree tire (meshes/rig-tire360/) with the
carcass tire's keys; its ``sources`` name the computation behind each value, and this test does
each computation again on the committed runs.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

GEAR = REPO / "examples" / "gear_a320_main_whole.json"
RIG = REPO / "meshes" / "rig-tire360"
ROLL = RIG / "roll"

pytestmark = pytest.mark.skipif(
    not (RIG / "spin_p.json").is_file(), reason="meshes/rig-tire360/ not committed"
)


@pytest.fixture(scope="module")
def gear() -> dict:
    return json.loads(GEAR.read_text())


def test_loads_as_a_carcass_tire_gear(gear):
    from fepost.shimmy.gear import load_gear

    g = load_gear(GEAR)
    assert g.tread_slip_stiffness == 11.15 and g.tire_stiffness_z > 0 and g.wheel_spin_inertia > 0
    fe_keys = [k for k, v in gear["sources"].items() if v.startswith("FE:")]
    assert set(fe_keys) >= {"tire_stiffness_x", "tire_stiffness_y", "tire_stiffness_z", "rolling_radius"}
    assert all("rig-tire360" in gear["sources"][k] for k in fe_keys)


def test_stiffnesses_are_the_whole_tires(gear):
    from fepost.shimmy.brush import rig_stiffness
    from fepost.shimmy.carcass import rig_torsional_stiffness

    k = rig_stiffness(RIG)
    assert gear["tire_stiffness_x"] == pytest.approx(k["K_x"], rel=1e-3)
    assert gear["tire_stiffness_y"] == pytest.approx(k["K_y"], rel=1e-3)
    assert gear["tire_stiffness_z"] == pytest.approx(rig_torsional_stiffness(RIG)["K_z"], rel=1e-3)


def test_grip_deflection_and_rolling_radius_are_the_whole_tires(gear):
    from scripts.tiremodel import aircraft_roll360_results as res

    sides = res.rolling_sidecars(ROLL)
    assert gear["tread_slip_stiffness"] == pytest.approx(res.brush_slope(sides[-1]), abs=0.005)
    fr = res.free_rolling([res.RunPoint.from_sidecar(s) for s in sides])
    assert gear["rolling_radius"] == pytest.approx(fr.effective_radius, abs=1e-4)
    static = json.loads((RIG / "static.json").read_text())["model"]
    deflection = static["rim_travel_z"] - static["inflated_clearance"]
    assert gear["tire_deflection"] == pytest.approx(deflection, abs=5e-5)
