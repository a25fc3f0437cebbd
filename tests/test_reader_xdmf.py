"""XDMF files (`.xdmf` + `.h5`) as meshio and FEniCS/dolfinx write them, read through meshio.

Expected values: the same map read from the original `.vtu` by VTK (N, M0, R to
round-off: the same doubles pass through HDF5), and, for a time series whose
pressure is scaled by s at each step, s times the original N_fe.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest

from fepost import analyse
from fepost.errors import PressureError
from fepost.polar import PolarGrid
from fepost.reader import read_contact, time_steps

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "aircraft" / "static_100.vtu"
GRID = PolarGrid.make(nr=24, nphi=48)
TOL = 1e-12


def _values(path, **kw):
    res = analyse(path, grid=GRID, **kw)
    c = res.coefficients
    return res.static_patch.N_fe, c.N, c.M0, c.R


@pytest.fixture(scope="module")
def mesh():
    return meshio.read(SAMPLE)


@pytest.fixture(scope="module")
def original():
    return _values(SAMPLE)


def test_meshio_xdmf_single_grid(mesh, original, tmp_path):
    path = tmp_path / "map.xdmf"
    meshio.write(path, mesh)
    assert (tmp_path / "map.h5").is_file()
    assert _values(path) == pytest.approx(original, rel=TOL)
    assert time_steps(path)[0].index is None


def test_meshio_time_series(mesh, original, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # meshio's TimeSeriesWriter puts the .h5 in the working directory
    path = tmp_path / "series.xdmf"
    with meshio.xdmf.TimeSeriesWriter(path) as w:
        w.write_points_cells(mesh.points, mesh.cells)
        for t in (0.0, 0.5, 1.0):
            w.write_data(
                t,
                point_data={
                    "CPRESS": mesh.point_data["CPRESS"] * t,
                    "displacement": mesh.point_data["displacement"],
                },
            )
    assert [(s.index, s.time) for s in time_steps(path)] == [(0, 0.0), (1, 0.5), (2, 1.0)]
    assert _values(path) == pytest.approx(original, rel=TOL)  # the last step by default
    assert analyse(path, grid=GRID, step=1).static_patch.N_fe == pytest.approx(0.5 * original[0], rel=TOL)
    with pytest.raises(PressureError, match=r"is zero everywhere at step 0 \(t = 0\) \(no contact\)$"):
        read_contact(path, step=0)


DOLFINX = """<?xml version="1.0"?>
<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>
<Xdmf Version="3.0" xmlns:xi="https://www.w3.org/2001/XInclude">
  <Domain>
    <Grid Name="mesh" GridType="Uniform">
      <Topology TopologyType="Quadrilateral" NumberOfElements="{m}" NodesPerElement="4">
        <DataItem Dimensions="{m} 4" NumberType="Int" Format="HDF">{h5}:/Mesh/mesh/topology</DataItem>
      </Topology>
      <Geometry GeometryType="XYZ">
        <DataItem Dimensions="{n} 3" Format="HDF">{h5}:/Mesh/mesh/geometry</DataItem>
      </Geometry>
    </Grid>
{functions}
  </Domain>
</Xdmf>
"""
FUNCTION = """    <Grid Name="{f}" GridType="Collection" CollectionType="Temporal">
{steps}
    </Grid>"""
INCLUDE = "xpointer(/Xdmf/Domain/Grid[@GridType='Uniform'][1]/*[self::Topology or self::Geometry])"
STEP = """      <Grid Name="{f}" GridType="Uniform">
        <xi:include xpointer="{include}" />
        <Time Value="{t}" />
        <Attribute Name="{f}" AttributeType="{kind}" Center="Node">
          <DataItem Dimensions="{n} {c}" Format="HDF">{h5}:/Function/{f}/{k}</DataItem>
        </Attribute>
      </Grid>"""


def write_dolfinx_like(path: Path, mesh, times=(0.0, 1.0)) -> Path:
    """The layout of dolfinx's `XDMFFile.write_mesh` + `write_function` for a pressure `p` and a
    displacement `u` (groups `/Mesh/mesh`, `/Function/<name>/<step>`, one Temporal collection per
    function, the mesh xi:included, the DOCTYPE line and the https XInclude namespace dolfinx
    writes; values as (n, components))."""
    h5 = path.with_suffix(".h5")
    quads = mesh.cells_dict["quad"]
    n, m = len(mesh.points), len(quads)
    with h5py.File(h5, "w") as f:
        f["Mesh/mesh/geometry"] = mesh.points
        f["Mesh/mesh/topology"] = quads.astype(np.int64)
        for k, t in enumerate(times):
            f[f"Function/p/{k}"] = (mesh.point_data["CPRESS"] * t)[:, None]
            f[f"Function/u/{k}"] = mesh.point_data["displacement"]
    functions = "\n".join(
        FUNCTION.format(
            f=name,
            steps="\n".join(
                STEP.format(f=name, t=t, kind=kind, n=n, c=c, h5=h5.name, k=k, include=INCLUDE)
                for k, t in enumerate(times)
            ),
        )
        for name, kind, c in (("p", "Scalar", 1), ("u", "Vector", 3))
    )
    path.write_text(DOLFINX.format(m=m, n=n, h5=h5.name, functions=functions))
    return path


def test_dolfinx_layout_two_functions(mesh, original, tmp_path):
    path = write_dolfinx_like(tmp_path / "solution.xdmf", mesh, times=(0.25, 1.0))
    assert [(s.index, s.time) for s in time_steps(path)] == [(0, 0.25), (1, 1.0)]
    fld = read_contact(path, field="p")
    assert fld.step == 1 and fld.time == 1.0
    assert _values(path, field="p") == pytest.approx(original, rel=TOL)
    assert analyse(path, grid=GRID, field="p", step=0).static_patch.N_fe == pytest.approx(
        0.25 * original[0], rel=TOL
    )


def test_the_read_budget_counts_the_heavy_data(mesh, tmp_path):
    """The deadline and memory budget of the reading child follow the .h5's size, not the small XML's."""
    from fepost.reader import data_size

    path = tmp_path / "map.xdmf"
    meshio.write(path, mesh)
    xml, h5 = path.stat().st_size, path.with_suffix(".h5").stat().st_size
    assert data_size(path, xml) == xml + h5


def test_a_time_series_step_linked_outside_the_folder_is_refused(mesh, tmp_path):
    """A dolfinx time series whose step of the pressure is an HDF5 external link to a file
    outside the folder (h5py would follow it): refused naming the .h5 and the dataset; the
    same link to a file in the folder is read (the linked values, twice the step's)."""
    from fepost.errors import InputFileError

    folder = tmp_path / "run"
    folder.mkdir()
    path = write_dolfinx_like(folder / "solution.xdmf", mesh, times=(0.25, 1.0))
    h5 = path.with_suffix(".h5")
    for where in (folder / "near.h5", tmp_path / "far.h5"):
        with h5py.File(where, "w") as f:
            f["p"] = (2 * mesh.point_data["CPRESS"])[:, None]
    with h5py.File(h5, "a") as f:
        del f["Function/p/1"]
        f["Function/p/1"] = h5py.ExternalLink("near.h5", "/p")
    assert analyse(path, grid=GRID, field="p").static_patch.N_fe == pytest.approx(
        2 * analyse(SAMPLE, grid=GRID).static_patch.N_fe, rel=TOL
    )
    with h5py.File(h5, "a") as f:
        del f["Function/p/1"]
        f["Function/p/1"] = h5py.ExternalLink("../far.h5", "/p")
    with pytest.raises(InputFileError) as err:
        read_contact(path, field="p")
    assert str(err.value) == (
        f"{path}: refused .xdmf file (heavy-data file 'solution.h5': dataset '/Function/p/1' reaches "
        "'../far.h5' through an HDF5 external link, which lies outside the file's folder)"
    )
