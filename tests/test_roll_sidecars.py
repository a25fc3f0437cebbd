"""The committed rolling runs' sidecars say what is true of their runs and maps.

The runs in ``meshes/rig-aircraft/roll_*`` are driven (an imposed turn, or the free run's
elastic drive with its 1.87 kN m), their contact slaves cover the arc the mesh has, and their
end-of-roll centre of pressure is the exact integral of the map committed beside them. The
sidecars are brought up to the exporter by ``python -m scripts.tiremodel.roll_refresh --update``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

ROLL = Path(__file__).resolve().parents[1] / "meshes" / "rig-aircraft"
STATIC = ROLL / "roll_static.json"
SIDECARS = sorted(ROLL.glob("roll_*.json"))
RUNS = [p for p in SIDECARS if p != STATIC]
#: m: the end-of-roll centre against the exact integral of its map (the two agree to ~1e-15 m)
CENTRE_TOL = 1e-5
#: a run is driven when its axle torque exceeds this share of N h (h: the axle's height)
DRIVEN = 1e-3
#: "torque-free" not preceded by a negation
TORQUE_FREE = re.compile(r"(?<!not )torque-free")
#: an arc written as symmetric about the bottom: "+-78", "± 78"
SYMMETRIC_ARC = re.compile(r"(\+-|±)\s*\d")

pytestmark = pytest.mark.skipif(not RUNS, reason="meshes/rig-aircraft/ holds no rolling runs")
REFRESH = "run 'python -m scripts.tiremodel.roll_refresh --update'"


def _texts(value) -> list[str]:
    """Every string leaf of a JSON value."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, dict):
        return [t for v in value.values() for t in _texts(v)]
    if isinstance(value, list):
        return [t for v in value for t in _texts(v)]
    return []


def _read(path: Path) -> dict:
    return json.loads(path.read_text())


def _road_centre(vtu: Path) -> float:
    """x of the pressure centre on the deformed faces projected on the road, from tests/independent_fe
    (its own shape functions and a 4 x 4 Gauss rule per face: exact for the bilinear p times x)."""
    import meshio
    from independent_fe import integrate

    m = meshio.read(vtu)
    p = np.asarray(m.point_data["CPRESS"], float)
    x = m.points + m.point_data["displacement"]
    quads = m.cells_dict["quad"]
    tot = integrate(x, p, quads[np.any(p[quads] > 0, axis=1)], normal_axis=2, cut=1)
    return tot["Mx"] / tot["N"]


def test_the_torque_free_finder_finds_the_old_label():
    assert TORQUE_FREE.search("free rolling (elastic drive, nearly torque-free)")
    assert not TORQUE_FREE.search("an elastic drive: not torque-free, the spring's torque is axle_torque_Nm")
    assert SYMMETRIC_ARC.search("tread and shoulder nodes within +-78 deg of the bottom")


@pytest.mark.parametrize("path", RUNS, ids=[p.stem for p in RUNS])
def test_a_driven_run_is_not_called_torque_free(path):
    from scripts.tiremodel.aircraft_geometry import AircraftParams

    side = _read(path)
    h = AircraftParams().axle_z - side["rim_travel_z"]
    assert abs(side["axle_torque_Nm"]) > DRIVEN * side["reaction"]["force"][2] * h  # every run is driven
    said = [t for t in _texts(side) if TORQUE_FREE.search(t)]
    assert not said, f"{path.name} calls its driven run torque-free: {said}; {REFRESH}"


@pytest.mark.parametrize("path", SIDECARS, ids=[p.stem for p in SIDECARS])
def test_the_contact_arc_is_the_meshs(path):
    side = _read(path)
    lo, hi = side["mesh"]["fine_arc_deg"]
    assert lo != -hi  # the rolling mesh's arc is turned towards +x
    contact = side["model"]["contact"]
    assert f"from {lo:g} to {hi:g} deg" in contact, f"{path.name}: {contact!r}; {REFRESH}"
    said = [t for t in _texts(side) if SYMMETRIC_ARC.search(t)]
    assert not said, f"{path.name} gives a symmetric arc: {said}; {REFRESH}"


@pytest.mark.parametrize("path", RUNS, ids=[p.stem for p in RUNS])
def test_the_end_of_roll_centre_is_the_exact_integral_of_its_map(path):
    """centre_of_pressure_x_m and the last sample's shift (plus the static centre) against an
    independent exact integration of the committed map (measured: equal to ~1e-15 m; the old
    sidecars' interpolated nodal products p x were off by -0.45 ... +0.45 mm)."""
    side = _read(path)
    exact = _road_centre(path.with_suffix(".vtu"))
    last = side["samples"][-1]
    assert last["axle_travel_m"] == pytest.approx(side["axle_travel_m"])  # the end of the roll
    end = last["centre_of_pressure_shift_m"] + side["static_centre_of_pressure_x_m"]
    assert end == pytest.approx(exact, abs=CENTRE_TOL), REFRESH
    # the keys the refresh adds (an export since b87383b has exact samples and no note)
    assert side.get("centre_of_pressure_x_m", exact) == pytest.approx(exact, abs=CENTRE_TOL), REFRESH
    note = side.get("centre_of_pressure_note")
    if note is not None:
        against = exact - _road_centre(STATIC.with_suffix(".vtu"))
        assert note["end_of_roll_shift_against_roll_static_m"] == pytest.approx(against, abs=CENTRE_TOL)


def test_the_free_runs_static_centre_is_the_exact_integral_of_roll_static():
    """roll_static.vtu is the free run's own static state (the same load to rounding), so its shift
    is exact end to end: 1.927 mm (the old sidecar: 1.835; fepost's x_c 1.931)."""
    side = _read(ROLL / "roll_free.json")
    assert side["static_cpress_integral"] == pytest.approx(
        _read(STATIC)["cpress_integral_projected"], rel=1e-12
    )
    static = _road_centre(STATIC.with_suffix(".vtu"))
    assert side["static_centre_of_pressure_x_m"] == pytest.approx(static, abs=CENTRE_TOL)
    shift = side["samples"][-1]["centre_of_pressure_shift_m"]
    assert shift == pytest.approx(_road_centre(ROLL / "roll_free.vtu") - static, abs=CENTRE_TOL)


@pytest.mark.parametrize("path", RUNS, ids=[p.stem for p in RUNS])
def test_the_labels_are_the_current_programmes(path):
    """The texts the programme and the exporter write for this run (decks unchanged: the refresh
    checks that the current programme writes the deck whose sha256 the sidecar holds)."""
    from scripts.tiremodel import aircraft_roll_programme as prog
    from scripts.tiremodel.aircraft_roll_export import SLIP_DEFINITION

    side = _read(path)
    spec = next(s for s in prog.programme() if s.name == path.stem)
    assert side["description"] == spec.description(prog.AIRCRAFT), REFRESH
    assert side["longitudinal_slip_definition"] == SLIP_DEFINITION, REFRESH
