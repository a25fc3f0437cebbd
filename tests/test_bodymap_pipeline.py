"""The planar-sliding block's maps through fepost's pipeline with its default options.

Three legs are 2 mm discs up to 130 mm apart: the default polar grid misses them
(43 % of the load), so the analysis refines its grid where the pressure is
(`fepost.refine`). Checked against an independent calculation for each of the five
real bodies (``../shared/real/planar-sliding/bodies``): N = m g, pure sliding
F = f N, pure spin about the reference point M = f Σ N_i r_i (legs, statics loads
solved here) or f N × the mean distance from the centroid over the triangle (base,
by scipy's dblquad), within 0.5 %; the command line's ``predict`` on one body;
the diagnosis's fit grid keeps the legs' load (it used to keep one loaded node).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate

import fepost
from fepost.body import load_body
from fepost.bodymap import body_map, write_map
from fepost.cli import main
from fepost.errors import PatchWarning
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature
from fepost.refine import REFINE_TOL, RULE, loaded_segments, polar_moment

BODIES = Path(__file__).resolve().parents[1] / ".." / "shared" / "real" / "planar-sliding" / "bodies"
NAMES = (
    "10_130_10_10_10_130",
    "10_90_10_10_30_130",
    "30_63.33_43.33_30_43.33_63.33",
    "30_90_30_30_30_90",
    "patch",
)
F = 0.3
#: The pure-slide force and the pure-spin torque agree with the independent values within this.
TOL = 5e-3

pytestmark = pytest.mark.skipif(not BODIES.is_dir(), reason="../shared/real/planar-sliding is absent")


def expected(name: str) -> tuple[float, float]:
    """(N, M about the reference point / f) from the body file alone."""
    body = json.loads((BODIES / f"{name}.json").read_text())
    weight = body["mass"] * body["gravity"]
    ref = np.array(body["reference_point"])
    if "supports" in body:
        legs = np.array(body["supports"], float)
        a = np.vstack([np.ones(3), legs.T])
        loads = np.linalg.solve(a, weight * np.array([1.0, *body["centre_of_mass"]]))
        return weight, float(loads @ np.hypot(*(legs - ref).T))
    (x0, y0), (x1, _), (_, y2) = body["base"]  # the right-angle triangle at (x0, y0)
    area = 0.5 * (x1 - x0) * (y2 - y0)
    total, _ = integrate.dblquad(
        lambda y, x: np.hypot(x - ref[0], y - ref[1]),
        x0,
        x1,
        y0,
        lambda x: y0 + (y2 - y0) * (1.0 - (x - x0) / (x1 - x0)),
        epsabs=1e-14,
        epsrel=1e-11,
    )
    return weight, weight * total / area


@pytest.fixture(scope="module")
def maps(tmp_path_factory):
    out = tmp_path_factory.mktemp("bodymaps")
    paths = {}
    for name in NAMES:
        paths[name] = out / f"{name}.vtu"
        write_map(body_map(load_body(BODIES / f"{name}.json")), paths[name])
    return paths


@pytest.fixture(scope="module")
def analyses(maps):
    return {name: fepost.analyse(path) for name, path in maps.items()}


@pytest.mark.parametrize("name", NAMES)
def test_default_options_give_the_load_slide_force_and_spin_torque(analyses, name):
    a = analyses[name]
    N, lever = expected(name)
    assert a.coefficients.N == pytest.approx(N, rel=REFINE_TOL), "the grid carries m g"
    quad = PressureQuadrature.from_polar(a.static_map)
    r = friction_resultants(quad, [1.0, 0.0], [0.0, 0.0], [0.0, 1.0], FrictionLaw(f=F))
    assert float(np.hypot(r.Fx[0], r.Fy[0])) == pytest.approx(F * N, rel=TOL)
    assert -float(r.Mz[1]) == pytest.approx(F * lever, rel=TOL)
    assert a.coefficients.M0 == pytest.approx(F * lever, rel=TOL)


def test_only_maps_the_default_grid_misses_are_refined(analyses):
    rules = {name: a.grid.rule for name, a in analyses.items()}
    assert rules == {**dict.fromkeys(NAMES[:4], RULE), "patch": "gauss"}
    for name in NAMES[:4]:
        a = analyses[name]
        nodes = a.grid.rho.size * a.grid.phi.size
        assert nodes < 256 * 1024 / 5, f"{name}: refined where the pressure is, not everywhere"
        moment = polar_moment(a.static_patch)
        assert a.static_moments.spin == pytest.approx(moment, rel=REFINE_TOL)


def test_loaded_segments_are_the_legs_annuli(analyses):
    a = analyses["10_130_10_10_10_130"]
    R = a.static_map.radius
    d = np.array([np.hypot(0.04, 0.04), np.hypot(0.08, 0.04)])  # legs from the reference point
    got = np.array(loaded_segments(a.static_patch, (0.0, 0.0), R)) * R
    # each disc is a 32-gon inscribed in its 2 mm circle: its extent lies between theirs
    inner = 0.002 * np.cos(np.pi / 32)
    assert got.shape == (2, 2)
    assert np.all(got[:, 0] >= d - 0.002 - 1e-12) and np.all(got[:, 0] <= d - inner + 1e-12)
    assert np.all(got[:, 1] <= d + 0.002 + 1e-12) and np.all(got[:, 1] >= d + inner - 1e-12)


def test_a_grid_the_caller_chose_is_kept_and_warned_about(maps):
    with pytest.warns(PatchWarning, match=r"the polar grid carries -\d+\.\d% of the FE load"):
        a = fepost.analyse(maps["10_130_10_10_10_130"], nr=64, nphi=256)
    assert a.grid.shape == (64, 256) and a.grid.rule == "gauss"


def test_diagnosis_fit_grid_keeps_the_legs(maps):
    from fepost.diagnose.shape import rim_weight
    from fepost.diagnose.simulation import load_simulation

    sim = load_simulation(maps["30_90_30_30_30_90"])
    N, _ = expected("30_90_30_30_30_90")
    assert sim.load == pytest.approx(N, rel=REFINE_TOL)
    rim = rim_weight(sim.quads[0])  # the pressure_shape cause's basis: three discs, no line
    loaded = sim.quads[0].sigma > 0
    w = sim.quads[0].sigma[loaded] * sim.quads[0].dA[loaded]
    assert abs(float(w @ rim(sim.quads[0].x[loaded], sim.quads[0].y[loaded]))) < 1e-9 * N


def test_predict_command_with_defaults(maps, tmp_path, capsys):
    name = "30_63.33_43.33_30_43.33_63.33"
    kin = tmp_path / "k.csv"
    kin.write_text("vx,vy,wz\n1,0,0\n0,0,1\n")
    out = tmp_path / "p.csv"
    assert main(["predict", str(maps[name]), "--kinematics", str(kin), "--out", str(out)]) == 0
    assert "warning" not in capsys.readouterr().err
    rows = list(csv.DictReader(out.open()))
    N, lever = expected(name)
    assert -float(rows[0]["Fx_exact"]) == pytest.approx(F * N, rel=TOL)
    assert -float(rows[1]["Mz_exact"]) == pytest.approx(F * lever, rel=TOL)
    assert -float(rows[1]["Mz_paper"]) == pytest.approx(F * lever, rel=TOL)


@pytest.mark.parametrize("location", ["point", "cell"])
def test_polar_moment_of_a_disc_is_its_closed_form(tmp_path, location):
    """∬ σ r dA of σ = 1 + (r/a)² over a disc of radius a is 2π a³ (1/3 + 1/5) about its
    centre; of σ = 1 about a point at distance d outside it, a² π d (1 + a²/(8 d²)) to
    O(a⁴/d⁴). Nodal and face data alike, over more triangles than one chunk."""
    import pyvista as pv

    from fepost.patch import build_patch
    from fepost.reader import read_contact

    a = 0.05
    disc = pv.Disc(inner=0.0, outer=a, r_res=40, c_res=720).triangulate()
    xy = disc.points[:, :2] if location == "point" else disc.cell_centers().points[:, :2]
    r2 = np.sum(xy**2, axis=1) / a**2
    for name, values in (("rim", 1.0 + r2), ("flat", np.ones_like(r2))):
        (disc.point_data if location == "point" else disc.cell_data)["CPRESS"] = values
        path = tmp_path / f"{name}.vtu"
        pv.UnstructuredGrid(disc).save(path)
        patch = build_patch(read_contact(path))
        assert patch.location == location and len(patch.triangles) > 32768
        if name == "rim":
            # the map's own centre of pressure is the disc's centre (symmetry)
            assert polar_moment(patch) == pytest.approx(2 * np.pi * a**3 * (1 / 3 + 1 / 5), rel=2e-3)
        else:
            polygon = 0.5 * 720 * np.sin(2 * np.pi / 720) / np.pi  # the 720-gon's area over the disc's
            far = a**2 * np.pi * 0.4 * (1 + a**2 / (8 * 0.4**2)) * polygon
            assert polar_moment(patch, (0.4, 0.0)) == pytest.approx(far, rel=2e-5)
