"""Reading FE exports: time steps, displacements, volume meshes, vector arrays, frames."""

import json

import meshio
import numpy as np
import pytest
import pyvista as pv

from fepost import analyse, analytic
from fepost.cli import main
from fepost.errors import FieldError, InputFileError
from fepost.reader import read_contact
from fepost.synthetic import disc_mesh, write_exodus

R = 0.1
PEAK = 5.0e5


def _disc():
    p2, tri = disc_mesh(30)
    return R * p2, tri


def test_exodus_time_steps_last_by_default_and_step_option(tmp_path):
    p2, tri = _disc()
    pts = np.column_stack([p2, np.zeros(len(p2))])
    base = analytic.pressure_function("hertz", R, PEAK)(p2[:, 0], p2[:, 1])
    path = write_exodus(
        tmp_path / "series.e",
        pts,
        tri,
        [{"CPRESS": s * base} for s in (0.5, 1.0, 2.0)],
        times=[0.0, 0.1, 0.2],
    )
    last = read_contact(path)
    assert (last.step, last.time) == (2, pytest.approx(0.2))
    first = read_contact(path, step=0)
    assert first.step == 0
    assert last.values.max() == pytest.approx(4 * first.values.max())
    assert read_contact(path, step=-2).time == pytest.approx(0.1)
    with pytest.raises(InputFileError, match=r"series\.e: --step 5 out of range \(file has 3 time steps\)"):
        read_contact(path, step=5)
    out = tmp_path / "c.json"
    assert main(["coefficients", str(path), "--step", "1", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["N"] == pytest.approx(analytic.load("hertz", R, PEAK), rel=2e-3)


def _bowl(tmp_path, name="bowl.vtu"):
    """Undeformed coordinates on a bowl; the displacement flattens them onto z = 0."""
    p2, tri = _disc()
    z0 = 2.0 * (p2**2).sum(1)
    u = np.column_stack([0 * z0, 0 * z0, -z0])
    val = analytic.pressure_function("hertz", R, PEAK)(p2[:, 0], p2[:, 1])
    path = tmp_path / name
    meshio.write(
        path,
        meshio.Mesh(np.column_stack([p2, z0]), [("triangle", tri)], point_data={"CPRESS": val, "U": u}),
    )
    return path


def test_displacement_is_applied_by_default_and_by_name(tmp_path):
    path = _bowl(tmp_path)
    N_ref = analytic.load("hertz", R, PEAK)
    assert analyse(path).coefficients.N == pytest.approx(N_ref, rel=2e-3)
    assert analyse(path, displacement="U").static_patch.planarity_rms < 1e-12
    with pytest.raises(ValueError, match=r"bowl\.vtu: the contact patch is not planar"):
        analyse(path, displacement=None)
    with pytest.raises(
        FieldError, match=r"bowl\.vtu: no nodal displacement array named 'DISP'; point arrays: "
    ):
        analyse(path, displacement="DISP")


def test_volume_mesh_is_reduced_to_its_loaded_surface(tmp_path):
    """A block of hexahedra whose bottom face carries a Hertz map: only the patch is kept."""
    grid = pv.ImageData(dimensions=(61, 61, 5), spacing=(0.005, 0.005, 0.01), origin=(-0.15, -0.15, 0.0))
    ug = grid.cast_to_unstructured_grid()
    p = np.asarray(ug.points)
    val = analytic.pressure_function("paraboloid", R, PEAK)(p[:, 0], p[:, 1])
    ug.point_data["contact_pressure"] = np.where(p[:, 2] == 0.0, val, 0.0)
    path = tmp_path / "block.vtu"
    ug.save(path)
    a = analyse(path)
    assert a.coefficients.N == pytest.approx(a.static_patch.N_fe, rel=1e-3)
    assert a.static_patch.frame.axes[2] @ [0, 0, 1] == pytest.approx(1.0)
    # the square lattice resolves the paraboloid to O(h²): 20 cells per radius
    assert a.coefficients.N == pytest.approx(analytic.load("paraboloid", R, PEAK), rel=5e-3)


def test_vector_array_component_selection(tmp_path):
    p2, tri = _disc()
    val = analytic.pressure_function("hertz", R, PEAK)(p2[:, 0], p2[:, 1])
    cstr = np.column_stack([val, 0.1 * val, -0.2 * val])
    path = tmp_path / "cstr.vtu"
    meshio.write(
        path, meshio.Mesh(np.column_stack([p2, 0 * val]), [("triangle", tri)], point_data={"CSTR": cstr})
    )
    with pytest.raises(FieldError, match=r"cstr\.vtu: no contact-pressure array found"):
        read_contact(path)
    with pytest.raises(
        FieldError, match=r"cstr\.vtu: array 'CSTR' has 3 components; choose one with --field CSTR:K"
    ):
        read_contact(path, field="CSTR")
    f = read_contact(path, field="CSTR:0")
    assert f.field == "CSTR:0" and f.values.max() == pytest.approx(PEAK, rel=1e-3)


def test_rolling_axis_option_turns_the_frame(tmp_path):
    p2, tri = _disc()
    val = analytic.pressure_function("hertz", R, PEAK, k_x=0.0)(p2[:, 0], p2[:, 1])
    path = tmp_path / "m.vtu"
    meshio.write(
        path, meshio.Mesh(np.column_stack([p2, 0 * val]), [("triangle", tri)], point_data={"CPRESS": val})
    )
    out = tmp_path / "c.json"
    assert main(["coefficients", str(path), "--rolling-axis", "0,1,0", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["patch"]["x_axis"] == pytest.approx([0, 1, 0], abs=1e-12)
    assert main(["coefficients", str(path), "--rolling-axis", "0,0,1"]) == 2


def test_reading_does_not_modify_the_file(tmp_path):
    path = _bowl(tmp_path)
    before = path.read_bytes()
    read_contact(path)
    assert path.read_bytes() == before


def test_results_are_immutable_and_inputs_untouched(tmp_path):
    path = _bowl(tmp_path)
    fld = read_contact(path)
    copies = {k: getattr(fld, k).copy() for k in ("points", "triangles", "values")}
    a = analyse(fld)
    for k, v in copies.items():
        np.testing.assert_array_equal(getattr(fld, k), v)
    for arr in (fld.points, a.static_patch.xy, a.static_patch.values, a.static_map.sigma, a.coefficients.A):
        with pytest.raises(ValueError):
            arr[0] = 0
    with pytest.raises(AttributeError):
        a.coefficients.M0 = 1.0


def test_multiblock_vtm_is_merged(tmp_path):
    """A .vtm with the patch split over two blocks reads as one surface."""
    from fepost.synthetic import write_map

    whole = pv.read(write_map(tmp_path / "w.vtu", "hertz", radius=R, peak=PEAK, n_rings=30))
    centres = whole.cell_centers().points
    left = whole.extract_cells(np.flatnonzero(centres[:, 0] < 0))
    right = whole.extract_cells(np.flatnonzero(centres[:, 0] >= 0))
    pv.MultiBlock([left, right]).save(tmp_path / "split.vtm")
    a = analyse(tmp_path / "split.vtm")
    assert a.coefficients.N == pytest.approx(analyse(tmp_path / "w.vtu").coefficients.N, rel=1e-9)
