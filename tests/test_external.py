"""fepost on real files written by other solvers (MOOSE Exodus, CalculiX via ccx2paraview).

The files live in ``../shared/external`` beside the repository and are never
copied into it. Every expected value is worked out independently of fepost's
reader: the models' applied loads, the reactions and nodal areas the solver
stored in the files, and exact integrals of the stored fields computed by
tests/independent_fe.py (netCDF4/meshio, contact faces found geometrically,
textbook shape functions).

MOOSE runs these models with small strains: its reactions and nodal areas are
those of the reference configuration, so N_fe is compared with them with
``displacement=None``; with the displacement applied (fepost's default) the
load changes by the change of the contact area (stated per case).
"""

from pathlib import Path

import meshio
import numpy as np
import pytest
from independent_fe import exodus, integrate, planar_faces

from fepost import analyse
from fepost.errors import DimensionError, PatchError, PatchWarning, PressureError
from fepost.reader import read_contact, time_steps

EXT = Path(__file__).resolve().parents[1].parent / "shared" / "external"
pytestmark = pytest.mark.skipif(
    not EXT.is_dir(), reason=f"{EXT} is absent: the external solver files live in ../shared/external"
)
F = 0.3  # the default friction coefficient
#: The polar grid meets the pressure jump along a square patch's edges: measured 0.4 % (N) and
#: 0.6 % (M0) on the default 64 × 128 grid, converging when refined (tests/test_reader_exodus.py).
SQUARE_GRID_TOL = 1e-2


def _reference(name, block, axis, step=-1, deformed=False):
    x, u, blocks, nodal, glob = exodus(EXT / name, step)
    p = nodal["contact_pressure"]
    value = float(np.median(x[p > 0, axis]))
    corners, mids = planar_faces(x, blocks[block][1], axis, value)
    nodes = corners if mids is None else np.concatenate([corners, mids], axis=1)
    loaded = p[nodes].max(axis=1) > 0  # the faces the pressure reaches (the support of the FE field)
    corners, mids = corners[loaded], (None if mids is None else mids[loaded])
    pts = x + u if deformed else x
    return integrate(pts, p, corners, mids, normal_axis=axis), p, nodal, glob, pts, corners, mids


def _r_max(pts, corners, mids, axis, centre):
    others = [a for a in range(3) if a != axis]
    nodes = corners if mids is None else np.concatenate([corners, mids], axis=1)
    return float(np.max(np.hypot(*(pts[np.unique(nodes)][:, others] - centre).T)))


def _check_square(name, block, axis, applied=None, reaction=None, warns=False, step=None, **kw):
    """N_fe, area, R, M0 and the verdict on a flat square contact, against the independent integrals."""
    ref, p, nodal, glob, pts, corners, mids = _reference(name, block, axis, step=-1 if step is None else step)
    area_name = next(n for n in nodal if n.startswith("nodal_area"))
    lumped = float(p @ nodal[area_name])  # MOOSE's own ∑ p_i ∫N_i dA
    ctx = (
        pytest.warns(PatchWarning, match="rolling axis: global x is normal to the patch")
        if warns
        else _null()
    )
    with ctx:
        ref_patch = analyse(EXT / name, displacement=None, step=step).static_patch
    assert ref_patch.N_fe == pytest.approx(ref["N"], rel=1e-9)
    assert ref_patch.N_fe == pytest.approx(lumped, rel=1e-9)
    assert ref_patch.area == pytest.approx(ref["area"], rel=1e-9)
    assert ref_patch.R == pytest.approx(_r_max(pts, corners, mids, axis, ref["centre"]), rel=1e-9)
    if applied is not None:
        assert ref["N"] == pytest.approx(applied, rel=5e-4)
    if reaction is not None:
        assert ref_patch.N_fe == pytest.approx(abs(glob[reaction]), rel=1e-8)
    with ctx:
        a = analyse(EXT / name, step=step)
    dref = _reference(name, block, axis, step=-1 if step is None else step, deformed=True)[0]
    assert a.static_patch.N_fe == pytest.approx(dref["N"], rel=1e-6)
    assert a.coefficients.N == pytest.approx(dref["N"], rel=SQUARE_GRID_TOL)
    assert a.coefficients.M0 == pytest.approx(F * dref["spin"], rel=SQUARE_GRID_TOL)
    assert a.static_patch.area == pytest.approx(dref["area"], rel=1e-6)
    assert not a.static_patch.circular  # a square: r_max / r_equiv = √(π/2) = 1.25 > 1.15
    assert a.static_patch.R / a.static_patch.r_equiv == pytest.approx(np.sqrt(np.pi / 2), rel=1e-3)
    return a, ref


class _null:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_pressure_penalty_cube_on_slab():
    """1000 Pa on the cube's 1 × 1 face: the cube's block alone, not the slab's, nor the side sets."""
    a, ref = _check_square("moose_pressurePenalty_out.e", block=0, axis=1, applied=1000.0)
    assert "element block 1" in a.static_field.body and "element block 2" not in a.static_field.body


def test_brick_patch_test_matches_the_stored_reactions():
    a, _ = _check_square("moose_brick1_frictionless_pen_out.e", block=0, axis=1, reaction="bot_react_y")
    assert a.to_dict()["reactions"]["bot_react_y"] == pytest.approx(109.89724572710091, rel=1e-12)


def test_two_blocks_with_mismatched_faces():
    """Contact normal along x: the rolling axis falls back to global y, with a warning."""
    a, ref = _check_square("moose_2blocks3d_out.e", block=0, axis=0, warns=True)
    assert a.static_patch.frame.axes[0] == pytest.approx([0.0, 1.0, 0.0], abs=1e-9)


def test_hex20_faces_carry_the_applied_load():
    """10 Pa on a 1 × 1 face of HEX20 elements (quad8 faces): N_fe = 10 N and the stored react_x."""
    a, ref = _check_square(
        "moose_nodal_area_Hex20_out.e", block=0, axis=0, applied=10.0, reaction="react_x", warns=True
    )
    assert a.static_patch.face_types == ("quad8",)


def test_catch_release_has_contact_at_one_step_only():
    name = "moose_catch_release_out.e"
    assert [s.time for s in time_steps(EXT / name)] == [0.0, 1.0, 2.0, 3.0, 4.0]
    with pytest.raises(
        PressureError,
        match=r"at step 4 \(t = 4\) \(no contact\); contact pressure is positive at "
        r"step\(s\) 2 \(t = 2\): choose one with --step",
    ):
        read_contact(EXT / name)
    _check_square(name, block=1, axis=1, step=2)


def test_ring_pressed_into_a_base_curved_quadratic_contact():
    """HEX20 ring on a HEX20 base: the base carries the pressure on quad8 faces that the ring indents.
    N_fe (the load normal to the patch plane) is the independent serendipity integral over the
    deformed faces; MOOSE's nodal areas are true (not projected) areas of the deformed surface, so
    ∑ p A exceeds it by the cosine of the indentation (0.28 %)."""
    name = "moose_ring_contact_out.e"
    ref, p, nodal, glob, pts, corners, mids = _reference(name, 1, 1, deformed=True)
    a = analyse(EXT / name)
    s = a.static_patch
    assert "element block 2" in a.static_field.body
    assert s.face_types == ("quad8",)
    assert s.N_fe == pytest.approx(ref["N"], rel=1e-9)
    lumped = float(p @ nodal["nodal_area_dummy_name"])
    assert 0 < lumped / s.N_fe - 1 < 5e-3
    assert abs(s.refine_error) <= 1e-4
    assert a.coefficients.N == pytest.approx(ref["N"], rel=1e-2)
    assert a.coefficients.M0 == pytest.approx(F * ref["spin"], rel=1e-2)
    assert s.R == pytest.approx(_r_max(pts, corners, mids, 1, ref["centre"]), rel=1e-3)
    assert s.aspect == pytest.approx(1.857, abs=0.01) and not s.circular


@pytest.mark.parametrize(
    "name",
    [
        "moose_multiple_pairs_out.e",
        "moose_sliding_frictional_02_penalty_out.e",
        "moose_simple_contact_rz_test_out.e",
    ],
)
def test_two_dimensional_models_are_refused(name):
    with pytest.raises(
        DimensionError,
        match=r"2-D model \(num_dim = 2: plane strain, plane stress or "
        r"axisymmetric\): the contact is a line, not a patch",
    ):
        analyse(EXT / name)


def _ccx_face(path):
    """The prism's bottom face (z = 1) of CalculiX's changefric model, integrated independently."""
    m = meshio.read(path)
    x, u = m.points.astype(float), m.point_data["U"].astype(float)
    p = m.point_data["CONTACT"][:, 3].astype(float)  # CPRESS: 4th component (ccx2paraview)
    hexes = m.cells_dict["hexahedron"]
    corners, _ = planar_faces(x, hexes, 2, 1.0, tol=1e-6)
    corners = corners[[p[c].min() > 0 for c in corners]]
    return integrate(x + u, p, corners, None, normal_axis=2), x + u, corners


@pytest.mark.parametrize("name", ["ccx_changefric.06.vtu", "ccx_changefric.06.vtk"])
def test_calculix_prism_on_a_cube(name):
    """100 Pa on the prism's 0.2 × 0.2 face: N = 4 N; CPRESS as the CONTACT vector's component."""
    ref, pts, corners = _ccx_face(EXT / "ccx_changefric.06.vtu")
    a = analyse(EXT / name)
    s = a.static_patch
    assert a.static_field.field == "CONTACT:CPRESS"
    assert s.N_fe == pytest.approx(ref["N"], rel=1e-6)  # the .vtk holds the values as 6-digit text
    assert s.N_fe == pytest.approx(4.0, rel=1e-3)
    assert s.area == pytest.approx(0.04, rel=1e-3)
    assert s.R == pytest.approx(0.1 * np.sqrt(2), rel=1e-3)
    assert a.coefficients.N == pytest.approx(ref["N"], rel=SQUARE_GRID_TOL)
    assert a.coefficients.M0 == pytest.approx(F * ref["spin"], rel=SQUARE_GRID_TOL)
    assert not s.circular
    legacy_note = any("ccx2paraview's layout" in n for n in s.notes)
    assert legacy_note == name.endswith(".vtk")


def test_calculix_beam_between_two_plates_is_two_patches():
    """Contact on both faces of the beam (x = 0 and x = 1): refused as two patches, with the load
    shares of each face integrated independently (quad8 faces of the HEX20 beam)."""
    m = meshio.read(EXT / "ccx_beamcontact.vtu")
    x = m.points.astype(float)
    p = m.point_data["CONTACT"][:, 3].astype(float)
    # VTK's quadratic hexahedron lists its mid-edge nodes after the 8 corners; they are found by position
    beam = m.cells_dict["hexahedron20"]
    loads = []
    for value in (0.0, 1.0):
        corners, mids = planar_faces(x, beam, 0, value)
        keep = [p[np.r_[c, mm]].max() > 0 for c, mm in zip(corners, mids, strict=True)]
        loads.append(integrate(x, p, corners[keep], mids[keep], normal_axis=0)["N"])
    shares = sorted((v / sum(loads) for v in loads), reverse=True)
    parts = ", ".join(f"{s:.0%}" for s in shares)
    with pytest.raises(PatchError, match=rf"2 separate contact patches \(load shares {parts}\) on different"):
        analyse(EXT / "ccx_beamcontact.vtu")
