"""Checks on the committed aircraft-tire results in meshes/aircraft/ (CalculiX).

Independent of the fepost package: the files are read with meshio (and, for
a second integration, pyvista) and the contact force is integrated here with
2x2 Gauss quadrature of the bilinear CPRESS field on the deformed faces.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from tire_samples import assert_exodus_matches_vtu, centre_of_pressure

FOLDER = Path(__file__).resolve().parents[1] / "meshes" / "aircraft"
STATIC = ("static_025", "static_050", "static_075", "static_100", "static_125", "static_150")
CASES = (*STATIC, "rolling_100")
REGEN = ".venv/bin/python -m scripts.tiremodel aircraft"


def _side(case: str) -> dict:
    path = FOLDER / f"{case}.json"
    if not path.exists():
        pytest.fail(f"missing sample {path}; regenerate with: {REGEN}")
    return json.loads(path.read_text())


def _load(case: str):
    """(deformed points, quads, CPRESS, sidecar) from the .vtu, read with meshio."""
    import meshio

    m = meshio.read(FOLDER / f"{case}.vtu")
    return m.points + m.point_data["displacement"], m.cells_dict["quad"], m.point_data["CPRESS"], _side(case)


def _gauss_integral(points: np.ndarray, quads: np.ndarray, values: np.ndarray) -> float:
    """Integral of the bilinear nodal field over bilinear quads, 2x2 Gauss points."""
    x, v = points[quads], values[quads]
    total = 0.0
    for a in (-1 / np.sqrt(3), 1 / np.sqrt(3)):
        for b in (-1 / np.sqrt(3), 1 / np.sqrt(3)):
            n = 0.25 * np.array([(1 - a) * (1 - b), (1 + a) * (1 - b), (1 + a) * (1 + b), (1 - a) * (1 + b)])
            da = 0.25 * np.array([-(1 - b), 1 - b, 1 + b, -(1 + b)])
            db = 0.25 * np.array([-(1 - a), -(1 + a), 1 + a, 1 - a])
            jac = np.cross(np.einsum("k,fkj->fj", da, x), np.einsum("k,fkj->fj", db, x))
            total += float(np.sum(np.linalg.norm(jac, axis=1) * (v @ n)))
    return total


@pytest.mark.parametrize("case", CASES)
def test_sidecar_keys(case):
    side = _side(case)
    for key in (
        "case",
        "reaction_z",
        "inflation_pressure",
        "deflection",
        "load",
        "rated_load",
        "load_target",
        "friction",
        "arrays",
        "solver",
        "runtime_s",
        "model",
        "mesh",
        "patch",
    ):
        assert key in side, key
    assert side["case"] == case
    assert "CalculiX" in side["solver"] and side["runtime_s"] > 0
    assert set(side["arrays"]) >= {"CPRESS", "displacement"}
    # the size class asked for: ~1.1-1.3 m, 1.0-1.5 MPa, rated load of order 200 kN
    assert 1.1 <= side["model"]["outer_diameter"] <= 1.3
    assert 1.0e6 <= side["inflation_pressure"] <= 1.5e6
    assert 150e3 <= side["rated_load"] <= 250e3
    assert side["load"] == side["reaction_z"]


@pytest.mark.parametrize("case", CASES)
def test_cpress_integral_matches_solver_reaction(case):
    """CPRESS integrated here (meshio + Gauss) and by VTK (pyvista integrate_data) on the
    deformed surface both equal CalculiX's road reaction within 2 %."""
    import pyvista as pv

    pts, quads, p, side = _load(case)
    assert p.min() >= 0.0
    mine = _gauss_integral(pts, quads, p)
    assert mine == pytest.approx(side["reaction_z"], rel=0.02)
    mesh = pv.read(FOLDER / f"{case}.vtu")
    mesh.points = mesh.points + mesh.point_data["displacement"]
    vtk_value = float(np.asarray(mesh.integrate_data().point_data["CPRESS"])[0])
    assert vtk_value == pytest.approx(mine, rel=1e-3)
    # loaded points lie on the road plane z = 0 (penalty overclosure below 1 mm)
    assert np.abs(pts[p > 0, 2]).max() < 1e-3


@pytest.mark.parametrize("case", CASES)
def test_loads_hit_targets(case):
    side = _side(case)
    assert side["load"] == pytest.approx(side["load_target"], rel=0.03)


def test_load_increases_with_deflection():
    sides = [_side(c) for c in STATIC]
    loads = np.array([s["load"] for s in sides])
    defl = np.array([s["deflection"] for s in sides])
    assert np.all(np.diff(loads) > 0) and np.all(np.diff(defl) > 0)
    np.testing.assert_allclose(loads / sides[0]["rated_load"], [0.25, 0.5, 0.75, 1.0, 1.25, 1.5], rtol=0.03)
    # the sweep's load-deflection curve at increment resolution: monotonic once in contact
    with open(FOLDER / "load_deflection.csv") as fh:
        rows = [r for r in csv.DictReader(fh) if r["run"] == "sweep"]
    d = np.array([float(r["deflection_m"]) for r in rows])
    f = np.array([float(r["load_N"]) for r in rows])
    touching = f > 0.01 * sides[0]["rated_load"]
    assert np.all(np.diff(d[touching]) > 0) and np.all(np.diff(f[touching]) > 0)
    # the six cases lie on that curve
    for s in sides:
        assert np.interp(s["deflection"], d[touching], f[touching]) == pytest.approx(s["load"], rel=0.01)


@pytest.mark.parametrize("case", STATIC)
def test_patch_resolution_and_shape(case):
    """>= 40 loaded nodes along the patch length (centre line y = 0); an oblong patch,
    longer than wide, elongated along the rolling direction x."""
    pts, quads, p, side = _load(case)
    centre = (p > 0) & (np.abs(pts[:, 1]) < 1e-6)
    assert centre.sum() >= 40
    assert side["patch"]["loaded_nodes_along_length"] == centre.sum()
    loaded = pts[p > 0]
    length = np.ptp(loaded[:, 0])
    width = np.ptp(loaded[:, 1])
    assert length == pytest.approx(side["patch"]["length"], rel=1e-6)
    assert 1.1 <= length / width <= 2.5


def test_patch_grows_with_load():
    patches = [_side(c)["patch"] for c in STATIC]
    for key in ("length", "area"):
        values = np.array([pt[key] for pt in patches])
        assert np.all(np.diff(values) > 0), key
    aspect = np.array([pt["aspect"] for pt in patches])
    assert aspect[-1] > aspect[0]


@pytest.mark.parametrize("case", STATIC)
def test_static_centre_of_pressure_under_the_axle(case):
    pts, quads, p, side = _load(case)
    cop = centre_of_pressure(pts, quads, p)
    assert abs(cop[0]) < 0.02 * side["patch"]["length"]
    assert abs(cop[1]) < 1e-9  # mirrored half model


def test_rolling_standin():
    pts0, q0, p0, s0 = _load("static_100")
    pts1, q1, p1, s1 = _load("rolling_100")
    roll = s1["rolling_standin"]
    dx = roll["imposed_rim_displacement"][0]
    fx = roll["friction_force_on_road_x"]
    assert dx > 0 and fx < 0  # traction opposes the rim's motion
    assert abs(fx) <= 1.01 * s1["friction"] * s1["reaction_z"]
    c0 = centre_of_pressure(pts0, q0, p0)
    c1 = centre_of_pressure(pts1, q1, p1)
    assert c1[0] - c0[0] > 0.005 * s0["patch"]["length"]


@pytest.mark.parametrize("case", ("static_025", "static_100", "rolling_100"))
def test_exodus_and_vtu_agree(case):
    assert_exodus_matches_vtu(FOLDER / f"{case}.vtu", FOLDER / f"{case}.e")


def test_samples_are_small():
    total = sum(f.stat().st_size for f in FOLDER.iterdir() if f.is_file())
    assert total < 10e6
    # everything under meshes/ (small tire + aircraft tire) stays within 25 MB
    assert sum(f.stat().st_size for f in FOLDER.parent.rglob("*") if f.is_file()) < 25e6


def test_travel_for_loads_inverts_a_known_curve():
    """The pre-estimate inversion: a curve F = k (d - c)^1.4 sampled at increments, zero before
    contact, is inverted to within the sampling error; a target beyond it is extrapolated."""
    import sys

    sys.path.insert(0, str(FOLDER.parents[1]))
    from scripts.tiremodel.aircraft_solve import travel_for_loads

    c, k = 0.02, 3.0e6
    d = np.linspace(0.0, 0.15, 151)
    f = k * np.clip(d - c, 0.0, None) ** 1.4
    targets = np.array([5e4, 1e5, 2e5])
    exact = c + (targets / k) ** (1 / 1.4)
    np.testing.assert_allclose(travel_for_loads(d, f, targets), exact, atol=0.5 * (d[1] - d[0]))
    beyond = travel_for_loads(d, f, np.array([f[-1] * 1.05]))[0]
    assert d[-1] < beyond < d[-1] + 0.01
