"""Refusals of a patch that is not flat: the percentage uses the documented R (r_max), and the
hint says what the reader did with the displacements.

A curved contact band (part of a cylinder, a cylindrical interface) with uniform pressure:
every number in the message is recomputed here from the mesh itself. With uniform nodal
pressure the plane's weights are equal, so the RMS distance from the best-fit plane is the
standard deviation of the node heights; by symmetry the centre of pressure lies on the axis
of the band, so R = r_max is the in-plane distance of a corner node, √(L² + (ρ sin θ0)²).
"""

from __future__ import annotations

import re

import meshio
import numpy as np
import pytest

from fepost.cli import main
from fepost.errors import PatchError
from fepost.patch import PLANARITY_TOL, build_patch
from fepost.reader import read_contact

RHO, THETA0, HALF_LENGTH = 0.3, 0.6, 0.1  # cylinder radius (m), half angle (rad), half length (m)
NX, NT = 21, 25
PRESSURE = 2.0e5


def _band(path, *, displacement: bool):
    """A cylindrical band about the x axis, bottom at z = 0, as a .vtu of triangles."""
    x = np.linspace(-HALF_LENGTH, HALF_LENGTH, NX)
    t = np.linspace(-THETA0, THETA0, NT)
    X, T = np.meshgrid(x, t, indexing="ij")
    pts = np.column_stack([X.ravel(), RHO * np.sin(T.ravel()), RHO * (1 - np.cos(T.ravel()))])
    idx = np.arange(NX * NT).reshape(NX, NT)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tri = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    data = {"CPRESS": np.full(len(pts), PRESSURE)}
    if displacement:
        data["U"] = np.zeros((len(pts), 3))  # the band as deformed: adding U changes nothing
    meshio.write(path, meshio.Mesh(pts, [("triangle", tri)], point_data=data))
    return path, pts


def _expected_numbers(pts):
    h = pts[:, 2]
    rms = float(np.sqrt(np.mean((h - h.mean()) ** 2)))
    r_max = float(np.hypot(HALF_LENGTH, RHO * np.sin(THETA0)))
    return rms, r_max


def _message(path, pts, hint):
    rms, r_max = _expected_numbers(pts)
    assert rms > PLANARITY_TOL * r_max  # the band is refused by the documented rule
    return (
        f"{path}: the contact patch is not planar (RMS distance from its best-fit plane "
        f"{rms:.3g} m = {rms / r_max:.1%} of R = r_max {r_max:.4g} m, limit {PLANARITY_TOL:.0%}); {hint}"
    )


CURVED = (
    "the contact surface itself is curved (e.g. a cylindrical interface); "
    "fepost needs a flat tire-road contact patch"
)


def test_curved_band_with_displacements_applied_says_curved(tmp_path):
    path, pts = _band(tmp_path / "band.vtu", displacement=True)
    fld = read_contact(path)
    assert fld.displacement == "U"
    with pytest.raises(PatchError) as err:
        build_patch(fld)
    assert str(err.value) == _message(path, pts, f"the displacements 'U' were applied: {CURVED}")
    assert "try --displacement" not in str(err.value)


def test_curved_band_without_displacement_array_says_curved(tmp_path):
    path, pts = _band(tmp_path / "band.vtu", displacement=False)
    fld = read_contact(path)
    assert fld.displacement is None
    with pytest.raises(PatchError) as err:
        build_patch(fld)
    assert str(err.value) == _message(path, pts, f"the file has no displacement array to apply: {CURVED}")


def test_displacement_left_out_suggests_it(tmp_path):
    path, pts = _band(tmp_path / "band.vtu", displacement=True)
    fld = read_contact(path, displacement=None)
    with pytest.raises(PatchError) as err:
        build_patch(fld)
    assert str(err.value) == _message(path, pts, "are the coordinates undeformed? try --displacement U")


def test_cli_prints_the_refusal_on_one_line(tmp_path, capsys):
    path, pts = _band(tmp_path / "band.vtu", displacement=True)
    assert main(["coefficients", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == "fepost: error: " + _message(path, pts, f"the displacements 'U' were applied: {CURVED}")


def test_percentage_is_of_r_max_not_r_equiv(tmp_path):
    """The band's r_max and r_equiv differ (a rectangle), and the message quotes rms / r_max."""
    path, pts = _band(tmp_path / "band.vtu", displacement=True)
    rms, r_max = _expected_numbers(pts)
    with pytest.raises(PatchError) as err:
        build_patch(read_contact(path))
    shown = float(re.search(r"= ([\d.]+)% of R", str(err.value)).group(1)) / 100
    area = 2 * HALF_LENGTH * 2 * RHO * np.sin(THETA0)  # projected area of the band
    r_equiv = np.sqrt(area / np.pi)
    assert abs(r_equiv - r_max) > 0.1 * r_max
    assert shown == pytest.approx(rms / r_max, abs=5e-4) and shown != pytest.approx(rms / r_equiv, abs=5e-3)
