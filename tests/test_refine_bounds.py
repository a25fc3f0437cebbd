"""The enclosure of the FE polar moment that decides whether `fepost.refine` refines a grid.

`polar_moment_bounds` must hold the exact ∬ σ r dA (closed forms of discs, the degree-4
rule), narrow as (h/r)², and `refined_map` must decide as the degree-4 value decides:
leave a map the default grid carries, refine one it misses, and compute the degree-4
value only where the enclosure cannot decide.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fepost import refine
from fepost.moments import moments
from fepost.patch import build_patch
from fepost.polar import PolarGrid
from fepost.reader import read_contact
from fepost.resample import resample
from fepost.synthetic import write_map

A = 0.05  # disc radius (m)


def _disc(tmp_path, location: str, c_res: int, r_res: int, values) -> object:
    import pyvista as pv

    disc = pv.Disc(inner=0.0, outer=A, r_res=r_res, c_res=c_res).triangulate()
    xy = disc.points[:, :2] if location == "point" else disc.cell_centers().points[:, :2]
    (disc.point_data if location == "point" else disc.cell_data)["CPRESS"] = values(xy)
    path = tmp_path / f"disc-{location}-{c_res}.vtu"
    pv.UnstructuredGrid(disc).save(path)
    return build_patch(read_contact(path))


def _bounds(patch, centre=(0.0, 0.0)):
    return refine.polar_moment_bounds(patch.xy, patch.triangles, patch.values, patch.location, centre)


@pytest.mark.parametrize("location", ["point", "cell"])
def test_bounds_hold_the_closed_form_and_narrow_as_h_squared(tmp_path, location):
    """σ = 1 + (r/a)² on a disc: ∬ σ r dA = 2π a³ (1/3 + 1/5) about the centre (the polygon's
    shortfall, (1 − cos π/n) of the rim, far below the enclosure's width). Twice the
    resolution narrows the enclosure about four times."""

    def rim(xy):
        return 1.0 + np.sum(xy**2, axis=1) / A**2

    widths = []
    for c_res, r_res in ((180, 10), (360, 20)):
        patch = _disc(tmp_path, location, c_res, r_res, rim)
        lo, hi = _bounds(patch)
        exact = refine.polar_moment(patch)
        assert lo <= exact <= hi
        closed = 2 * np.pi * A**3 * (1 / 3 + 1 / 5)
        assert lo <= closed * (1 + 1e-3) and closed * (1 - 2e-3) <= hi
        widths.append((hi - lo) / exact)
    assert 0 < widths[1] < widths[0]
    assert widths[0] / widths[1] == pytest.approx(4.0, rel=0.35), widths


def test_bounds_about_a_far_point(tmp_path):
    """σ = 1 about a point 0.4 m away: a² π d (1 + a²/(8d²)) to O(a⁴/d⁴), inside a narrow enclosure."""
    patch = _disc(tmp_path, "point", 360, 20, lambda xy: np.ones(len(xy)))
    lo, hi = _bounds(patch, (0.4, 0.0))
    polygon = 0.5 * 360 * np.sin(2 * np.pi / 360) / np.pi
    far = A**2 * np.pi * 0.4 * (1 + A**2 / (8 * 0.4**2)) * polygon
    assert lo <= far * (1 + 1e-5) and far * (1 - 1e-5) <= hi
    assert (hi - lo) / far < 1e-3


def test_no_enclosure_for_negative_pressure():
    """Jensen's lower bound needs σ ≥ 0: negative values give no enclosure, and no decision from it."""
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    tri = np.array([[0, 1, 2]])
    assert refine.polar_moment_bounds(xy, tri, np.array([1.0, -0.1, 1.0]), "point") == (0.0, math.inf)
    assert refine.carried_within(None, None, (0.0, 1.0)) == math.inf


def _default(patch):
    pmap = resample(patch, PolarGrid.make(), radius=patch.r_max)
    return pmap, moments(pmap)


def _decision_by_the_degree_4_rule(patch, pmap, mom) -> bool:
    """Whether the default grid misses the map (refinement starts), by the degree-4 value."""
    exact = refine.polar_moment(patch, pmap.centre)
    return refine.carried(patch, mom, exact) > refine.TRIGGER_TOL


@pytest.fixture(scope="module")
def hertz(tmp_path_factory):
    path = tmp_path_factory.mktemp("hertz") / "hertz.vtu"
    write_map(path, "hertz", radius=0.1, peak=1.0e6, n_rings=120)
    return build_patch(read_contact(path))


def test_a_carried_map_is_decided_by_the_enclosure_alone(hertz, monkeypatch):
    """A fine Hertz map the default grid carries: kept as it is, without the degree-4 rule."""
    pmap, mom = _default(hertz)
    lo, hi = _bounds(hertz, pmap.centre)
    assert (hi - lo) / lo < 1e-3
    assert not _decision_by_the_degree_4_rule(hertz, pmap, mom)
    calls = []
    monkeypatch.setattr(refine, "polar_moment", lambda *a: calls.append(a) or 0.0)
    out, out_mom = refine.refined_map(hertz, pmap, mom)
    assert out is pmap and out_mom is mom and not calls


def test_the_patch_enclosure_decides_a_fine_map_without_a_pass_of_its_own(hertz, monkeypatch):
    """The face pass of the patch step already summed an enclosure (`fepost.facesums.PolarSums`):
    on a fine map the default grid carries, neither the separate enclosure pass nor the degree-4
    rule runs."""
    pmap, mom = _default(hertz)
    assert hertz.polar is not None and hertz.polar.bounds(pmap.centre) is not None
    calls = []
    monkeypatch.setattr(refine, "polar_moment_bounds", lambda *a: calls.append(a) or (0.0, math.inf))
    monkeypatch.setattr(refine, "polar_moment", lambda *a: calls.append(a) or 0.0)
    out, out_mom = refine.refined_map(hertz, pmap, mom)
    assert out is pmap and out_mom is mom and not calls


@pytest.mark.parametrize("location", ["point", "cell"])
def test_the_patch_enclosure_holds_the_moment_about_nearby_centres(tmp_path, location):
    """The face pass's enclosure about points up to near/2 from its origin (the fitted plane's
    centre, off the patch frame's origin, the centre of pressure, on this tilted pressure)
    holds the degree-4 value, is at most a few times wider than the separate pass's (plus the
    2 δ N its move by δ costs), and beyond near/2 gives way (None) to that pass."""

    def tilted(xy):
        return 1.0 + np.sum(xy**2, axis=1) / A**2 + 0.5 * xy[:, 0] / A

    patch = _disc(tmp_path, location, 360, 20, tilted)
    enc = patch.polar
    assert enc is not None and enc.origin != (0.0, 0.0)  # the fitted plane's centre is not the CoP
    for frac in (0.0, 0.2, 0.49):
        centre = (enc.origin[0] + 0.8 * frac * enc.near, enc.origin[1] - 0.6 * frac * enc.near)
        lo, hi = enc.bounds(centre)
        exact = refine.polar_moment(patch, centre)
        assert lo <= exact <= hi, frac
        tight = _bounds(patch, centre)
        assert (hi - lo) < 4.0 * (tight[1] - tight[0]) + 2.5 * np.hypot(*np.subtract(centre, enc.origin)) * (
            enc.load
        ), frac
    assert enc.bounds((enc.origin[0] + 0.6 * enc.near, enc.origin[1])) is None


def test_no_patch_enclosure_for_negative_pressure():
    """The face pass gives no enclosure where a value is negative (Jensen's bound needs σ ≥ 0)."""
    from fepost import facesums

    x, y = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    tri = np.array([[0, 1, 2]])
    assert facesums.face_sums(x, y, tri, np.array([1.0, -0.1, 1.0]), "point").polar is None
    assert facesums.face_sums(x, y, tri, np.array([1.0, 0.1, 1.0]), "point").polar is not None


def test_a_missed_map_is_refined_as_before(tmp_path):
    """Two small discs far apart (the default grid falls between its nodes): the enclosure
    cannot clear it, the degree-4 value says refine, and the refined grid carries the load
    and the polar moment within REFINE_TOL."""
    import pyvista as pv

    parts = []
    for cx in (-0.12, 0.12):
        d = pv.Disc(center=(cx, 0.0, 0.0), inner=0.0, outer=0.002, r_res=6, c_res=48).triangulate()
        parts.append(d)
    mesh = parts[0].merge(parts[1])
    r2 = ((np.abs(mesh.points[:, 0]) - 0.12) ** 2 + mesh.points[:, 1] ** 2) / 0.002**2
    mesh.point_data["CPRESS"] = 1.0e6 * np.sqrt(np.clip(1.0 - r2, 0.0, None)) + 1.0e5
    path = tmp_path / "legs.vtu"
    pv.UnstructuredGrid(mesh).save(path)
    path.with_suffix(".json").write_text('{"separate_patches": 2}')  # two legs, as a body map declares
    patch = build_patch(read_contact(path))
    pmap, mom = _default(patch)
    assert _decision_by_the_degree_4_rule(patch, pmap, mom)
    assert refine.carried_within(patch, mom, _bounds(patch, pmap.centre)) > refine.TRIGGER_TOL
    out, out_mom = refine.refined_map(patch, pmap, mom)
    assert out is not pmap and out.grid.rule == refine.RULE
    assert refine.carried(patch, out_mom, refine.polar_moment(patch, out.centre)) <= refine.REFINE_TOL


def test_decisions_agree_with_the_degree_4_rule_on_coarse_and_fine_maps(tmp_path):
    """Hertz maps from 6 to 60 rings: the enclosure's decision (or the degree-4 fallback it
    falls to) is the degree-4 rule's on every one."""
    for rings in (6, 12, 25, 60):
        path = tmp_path / f"h{rings}.vtu"
        write_map(path, "hertz", radius=0.1, peak=1.0e6, n_rings=rings)
        patch = build_patch(read_contact(path))
        pmap, mom = _default(patch)
        out, _ = refine.refined_map(patch, pmap, mom)
        assert (out is not pmap) == _decision_by_the_degree_4_rule(patch, pmap, mom), rings
