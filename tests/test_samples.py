"""Checks on the committed CalculiX sample results in meshes/ (issue #3).

These tests read the exports with meshio/pyvista directly, so they do not
depend on the fepost package except where noted.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from tire_samples import assert_exodus_matches_vtu, centre_of_pressure, face_stats

MESHES = Path(__file__).resolve().parents[1] / "meshes"
CASES = ("static", "rolling", "heavy")


def _load(case: str):
    """(deformed points, quads, CPRESS, displacement, sidecar); files hold reference points."""
    import meshio

    vtu = MESHES / f"{case}.vtu"
    if not vtu.exists():
        pytest.fail(
            f"missing sample {vtu}; regenerate with: .venv/bin/python -m scripts.tiremodel build --case all"
        )
    m = meshio.read(vtu)
    side = json.loads((MESHES / f"{case}.json").read_text())
    quads = m.cells_dict["quad"]
    u = m.point_data["displacement"]
    return m.points + u, quads, m.point_data["CPRESS"], u, side


def _patch_radius(points, p, centre):
    loaded = p > 0
    return float(np.max(np.hypot(points[loaded, 0] - centre[0], points[loaded, 1] - centre[1])))


def _aspect(points, quads, p):
    """Best-fit ellipse aspect (length/width) from the area second moments of loaded faces."""
    a, pm, c = face_stats(points, quads, p)
    loaded = (p[quads] > 0).all(axis=1)
    a, c = a[loaded], c[loaded, :2]
    mu = (a[:, None] * c).sum(0) / a.sum()
    d = c - mu
    cov = np.einsum("i,ij,ik->jk", a, d, d) / a.sum()
    ev = np.linalg.eigvalsh(cov)
    return float(np.sqrt(ev[-1] / ev[0])), np.linalg.eigh(cov)[1][:, -1]


@pytest.mark.parametrize("case", CASES)
def test_sidecar_keys_and_units(case):
    *_, side = _load(case)
    for key in (
        "reaction_z",
        "inflation_pressure",
        "deflection",
        "friction",
        "arrays",
        "solver",
        "runtime_s",
        "mesh",
        "case",
    ):
        assert key in side, key
    assert side["case"] == case
    assert side["inflation_pressure"] == pytest.approx(2.0e5)
    assert side["friction"] == pytest.approx(0.3)
    assert side["reaction_z"] > 0
    assert "CalculiX" in side["solver"]
    assert set(side["arrays"]) >= {"CPRESS", "displacement"}
    if case == "rolling":
        assert side["rolling_standin"]["direction"] == "+x"
        assert side["rolling_standin"]["imposed_rim_displacement"][0] > 0


@pytest.mark.parametrize("case", CASES)
def test_cpress_integral_matches_solver_reaction(case):
    """pyvista integrate_data (no division by area) of CPRESS over the deformed outer surface
    vs the sidecar's reaction_z (CalculiX reaction on the road): within 3 %."""
    import pyvista as pv

    mesh = pv.read(MESHES / f"{case}.vtu")
    mesh.points = mesh.points + mesh.point_data["displacement"]  # deformed surface
    assert mesh.point_data["CPRESS"].min() >= 0.0
    integ = float(np.asarray(mesh.integrate_data().point_data["CPRESS"])[0])
    side = json.loads((MESHES / f"{case}.json").read_text())
    assert integ == pytest.approx(side["reaction_z"], rel=0.03)
    # the road plane is z = 0: loaded points lie on it (penalty penetration < 1 mm)
    pts = np.asarray(mesh.points)
    loaded = np.asarray(mesh.point_data["CPRESS"]) > 0
    assert np.abs(pts[loaded, 2]).max() < 1e-3


def test_static_map_is_symmetric():
    """Static: centre of pressure within 2 % of the patch radius of the rim-axis projection
    (x = y = 0), and the map mirrored about x = 0 and about y = 0 differs from itself by
    less than 2 % of the peak pressure at every node (the mesh is mirror-symmetric)."""
    from scipy.spatial import cKDTree

    pts, quads, p, u, side = _load("static")
    centre = centre_of_pressure(pts, quads, p)
    radius = _patch_radius(pts, p, centre)
    assert np.hypot(centre[0], centre[1]) < 0.02 * radius
    ref = pts - u  # reference (undeformed) positions: exactly mirror-symmetric mesh
    tree = cKDTree(ref)
    for flip in (np.array([-1.0, 1.0, 1.0]), np.array([1.0, -1.0, 1.0])):
        dist, idx = tree.query(ref * flip)
        assert dist.max() < 1e-6
        assert np.abs(p - p[idx]).max() < 0.02 * p.max()


def test_rolling_centre_of_pressure_moves_with_the_rim():
    """The rim is pushed along +x; the road's friction on the tire points along -x, and the
    centre of pressure moves forward (+x) relative to the static map, as for a rolling tire."""
    pts0, q0, p0, _, s0 = _load("static")
    pts1, q1, p1, _, s1 = _load("rolling")
    c0 = centre_of_pressure(pts0, q0, p0)
    c1 = centre_of_pressure(pts1, q1, p1)
    dx = s1["rolling_standin"]["imposed_rim_displacement"][0]
    fx = s1["rolling_standin"]["friction_force_on_road_x"]
    radius = _patch_radius(pts0, p0, c0)
    assert np.sign(fx) == -np.sign(dx)  # traction opposes the rim's motion
    assert np.sign(c1[0] - c0[0]) == np.sign(dx)
    assert abs(c1[0] - c0[0]) > 0.01 * radius  # a real shift, not noise
    assert abs(c1[1] - c0[1]) < 0.02 * radius  # no lateral shift
    assert abs(fx) <= 1.01 * s1["friction"] * s1["reaction_z"]  # Coulomb bound


def test_heavy_patch_is_oblong():
    pts, quads, p, _, side = _load("heavy")
    aspect, major = _aspect(pts, quads, p)
    assert aspect > 1.15
    assert abs(major[0]) > 0.9  # elongated along the rolling direction x
    s_pts, s_q, s_p, _, s_side = _load("static")
    assert side["reaction_z"] > s_side["reaction_z"]
    assert side["deflection"] > s_side["deflection"]


@pytest.mark.parametrize("case", CASES)
def test_exodus_and_vtu_agree(case):
    assert_exodus_matches_vtu(MESHES / f"{case}.vtu", MESHES / f"{case}.e")


def test_samples_are_small():
    total = sum(f.stat().st_size for f in MESHES.iterdir() if f.is_file())
    assert total < 20e6


@pytest.mark.parametrize("case", ("static", "heavy"))
def test_fepost_reader_and_patch(case):
    """fepost's own reader and patch geometry on the samples (N against the solver)."""
    from fepost.patch import build_patch
    from fepost.reader import read_contact

    side = json.loads((MESHES / f"{case}.json").read_text())
    for path in (MESHES / f"{case}.vtu", MESHES / f"{case}.e"):
        patch = build_patch(read_contact(path))
        assert patch.N_fe == pytest.approx(side["reaction_z"], rel=0.03)
        assert np.hypot(*patch.centre_of_pressure) < 0.02 * patch.r_max
        if case == "heavy":
            assert patch.aspect > 1.15 and not patch.circular
