"""Point location / FE interpolation (fepost.locate) against closed forms and VTK's probe."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from fepost import locate
from fepost.errors import ArgumentError
from fepost.patch import build_patch
from fepost.polar import PolarGrid
from fepost.reader import read_contact
from fepost.resample import resample
from fepost.synthetic import disc_mesh

MESHES = Path(__file__).resolve().parents[1] / "meshes"


def _vtk_probe(xy, tri, values, location, pts):
    mesh = pv.PolyData.from_regular_faces(np.column_stack([xy, np.zeros(len(xy))]), tri)
    if location == "point":
        mesh.point_data["p"] = values
    else:
        mesh.cell_data["p"] = values
    probe = pv.PolyData(np.column_stack([pts, np.zeros(len(pts))]))
    out = probe.sample(mesh, tolerance=1e-12, snap_to_closest_point=False, locator="cell")
    return np.asarray(out.point_data["p"], float), np.asarray(out.point_data["vtkValidPointMask"], bool)


def _random_points(n, seed, reach=1.2):
    rng = np.random.default_rng(seed)
    return rng.uniform(-reach, reach, size=(n, 2))


def test_linear_field_is_reproduced_exactly():
    xy, tri = disc_mesh(30, "tri", seed=3)
    f = 1.0 + 2.0 * xy[:, 0] - 3.0 * xy[:, 1]
    pts = _random_points(5000, 1, reach=0.7)  # inside the unit disc's mesh
    v, ok = locate.interpolate(xy, tri, f, "point", pts)
    assert ok.all()
    np.testing.assert_allclose(v, 1.0 + 2.0 * pts[:, 0] - 3.0 * pts[:, 1], rtol=0, atol=1e-12)


def test_weights_are_barycentric_coordinates_of_the_found_face():
    xy, tri = disc_mesh(20, "tri", seed=4)
    pts = _random_points(2000, 2, reach=0.6)
    loc = locate.locate(xy, tri, pts)
    assert loc.valid.all()
    w = loc.weights
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    assert (w >= -locate.TOL).all()
    corners = xy[tri[loc.face]]  # (q, 3, 2)
    np.testing.assert_allclose(np.einsum("qk,qkd->qd", w, corners), pts, atol=1e-12)


@pytest.mark.parametrize("location", ["point", "cell"])
@pytest.mark.parametrize("graded", [True, False])
def test_agrees_with_vtk_probe(location, graded):
    xy, tri = disc_mesh(40, "tri", seed=5, graded=graded)
    rng = np.random.default_rng(6)
    values = rng.uniform(0.0, 1.0, len(xy) if location == "point" else len(tri))
    pts = _random_points(20000, 7)  # inside and outside the disc
    v, ok = locate.interpolate(xy, tri, values, location, pts)
    vv, vok = _vtk_probe(xy, tri, values, location, pts)
    np.testing.assert_array_equal(ok, vok)
    assert 0.3 < ok.mean() < 0.7
    np.testing.assert_allclose(v[ok], vv[ok], rtol=1e-12, atol=1e-12)
    assert (v[~ok] == 0).all()


def test_points_on_nodes_and_edges_are_found():
    xy, tri = disc_mesh(15, "tri", seed=8)
    f = np.sin(3 * xy[:, 0]) + xy[:, 1] ** 2
    mid = 0.5 * (xy[tri[:, 0]] + xy[tri[:, 1]])  # edge midpoints
    pts = np.vstack([xy, mid])
    v, ok = locate.interpolate(xy, tri, f, "point", pts)
    assert ok.all()
    np.testing.assert_allclose(v[: len(xy)], f, atol=1e-12)
    np.testing.assert_allclose(v[len(xy) :], 0.5 * (f[tri[:, 0]] + f[tri[:, 1]]), atol=1e-12)


def test_holes_and_the_outside_are_invalid():
    xy, tri = disc_mesh(20, "tri", seed=9, graded=False)
    centroid = xy[tri].mean(axis=1)
    hole = np.hypot(centroid[:, 0] - 0.3, centroid[:, 1]) < 0.2
    kept = tri[~hole]
    pts = np.array([[0.3, 0.0], [2.0, 2.0], [-0.5, -0.1], [0.0, 0.0]])
    _, ok = locate.interpolate(xy, kept, np.ones(len(xy)), "point", pts)
    np.testing.assert_array_equal(ok, [False, False, True, True])


def test_strongly_graded_mesh_and_degenerate_faces():
    # rings from 1e-3 to 1 (edge ratio ~1000) plus a zero-area face: no NaN, all inside points found
    xy, tri = disc_mesh(60, "tri", seed=10)
    xy = xy * np.hypot(xy[:, 0], xy[:, 1])[:, None] ** 3  # crowd the nodes at the centre
    tri = np.vstack([tri, [[0, 0, 1]]])
    f = 2.0 + xy[:, 0]
    pts = _random_points(4000, 11, reach=0.6) ** 3
    v, ok = locate.interpolate(xy, tri, f, "point", pts)
    inside = np.hypot(pts[:, 0], pts[:, 1]) < 0.99 * np.hypot(xy[:, 0], xy[:, 1]).max() * np.cos(np.pi / 6)
    assert ok[inside].all()
    np.testing.assert_allclose(v[ok], 2.0 + pts[ok, 0], atol=1e-12)


def test_empty_inputs_and_bad_arguments():
    xy, tri = disc_mesh(5, "tri")
    loc = locate.locate(xy, tri, np.empty((0, 2)))
    assert loc.face.shape == (0,)
    loc = locate.locate(xy, np.empty((0, 3), np.int64), np.zeros((3, 2)))
    assert not loc.valid.any()
    with pytest.raises(ArgumentError, match="points"):
        locate.locate(xy, tri, np.zeros((3, 3)))
    with pytest.raises(ArgumentError, match="triangles"):
        locate.locate(xy, tri[:, :2], np.zeros((3, 2)))
    with pytest.raises(ArgumentError, match="location"):
        locate.interpolate(xy, tri, np.ones(len(xy)), "node", np.zeros((3, 2)))


@pytest.mark.parametrize("case", ["static", "rolling"])
@pytest.mark.parametrize("rule", ["gauss", "trapezoid"])
def test_resample_methods_agree_on_solver_output(case, rule):
    patch = build_patch(read_contact(MESHES / f"{case}.vtu"))
    grid = PolarGrid.make(rule=rule)
    a = resample(patch, grid, radius=patch.r_max, method="bins")
    b = resample(patch, grid, radius=patch.r_max, method="vtk")
    peak = float(np.max(patch.values))
    np.testing.assert_array_equal(a.valid, b.valid)
    np.testing.assert_allclose(a.sigma, b.sigma, rtol=0, atol=1e-9 * peak)
    with pytest.raises(ArgumentError, match="method"):
        resample(patch, grid, method="nearest")


def test_huge_faces_are_expanded_in_bounded_batches(monkeypatch):
    """A fine mesh plus faces spanning the whole raster: same answer with tiny batches."""
    xy, tri = disc_mesh(40, "tri", seed=12, graded=False)
    big = np.array([[-10.0, -10.0], [10.0, -10.0], [0.0, 10.0]])  # one face holding every query point
    xy2 = np.vstack([xy, big])
    n = len(xy)
    tri2 = np.vstack([tri, [[n, n + 1, n + 2]]])
    f = 1.0 + xy2[:, 0] - 2.0 * xy2[:, 1]
    pts = _random_points(3000, 13, reach=2.0)
    ref, ref_ok = locate.interpolate(xy2, tri2, f, "point", pts)
    monkeypatch.setattr(locate, "EXPAND_MAX", 64)
    v, ok = locate.interpolate(xy2, tri2, f, "point", pts)
    np.testing.assert_array_equal(ok, ref_ok)
    np.testing.assert_allclose(v, ref, atol=1e-12)
    assert ok.all()  # every point lies in the big face at least
    np.testing.assert_allclose(v, 1.0 + pts[:, 0] - 2.0 * pts[:, 1], atol=1e-12)
