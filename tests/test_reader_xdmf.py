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


# ------------------------------------------------- heavy data reaching files outside the folder

SMALL = Path(__file__).resolve().parents[1] / "meshes" / "static.vtu"  # 2961 nodes


@pytest.fixture(scope="module")
def small_n_fe():
    from fepost.patch import build_patch

    return build_patch(read_contact(SMALL)).N_fe


def _n_fe(path: Path, **kw) -> float:
    from fepost.patch import build_patch

    return build_patch(read_contact(path, **kw)).N_fe


def _map_with_far(tmp_path: Path) -> tuple[Path, Path, Path, str]:
    """A meshio XDMF map in ``tmp_path/run``, and ``far.h5`` beside the folder and ``near.h5``
    in it, each holding the pressure tripled as ``/p``; returns (xdmf, its .h5, far.h5, the
    pressure's dataset)."""
    folder = tmp_path / "run"
    folder.mkdir()
    path = folder / "map.xdmf"
    meshio.write(path, meshio.read(SMALL))
    text = path.read_text()
    item = text.index("<DataItem", text.index('Name="CPRESS"'))
    dataset = text[text.index(">", item) + 1 : text.index("</DataItem>", item)].split(":")[1]
    h5 = path.with_suffix(".h5")
    with h5py.File(h5) as f:
        tripled = 3 * f[dataset][()]
    for where in (tmp_path / "far.h5", folder / "near.h5"):
        with h5py.File(where, "w") as g:
            g["p"] = tripled
    return path, h5, tmp_path / "far.h5", dataset


def _rename(path: Path, dataset: str, new: str) -> None:
    path.write_text(path.read_text().replace(f"map.h5:{dataset}<", f"map.h5:{new}<"))


def _absolute_on_the_dataset(path, h5, far, ds):
    with h5py.File(h5, "a") as f:
        del f[ds]
        f[ds] = h5py.ExternalLink(str(far), "/p")
    return f"dataset {ds!r} reaches {str(far)!r} through an HDF5 external link"


def _absolute_on_a_group(path, h5, far, ds):
    with h5py.File(h5, "a") as f:
        f["g"] = h5py.ExternalLink(str(far), "/")
    _rename(path, ds, "/g/p")
    return f"dataset '/g/p' reaches {str(far)!r} through an HDF5 external link"


def _a_space_after_the_colon(path, h5, far, ds):
    """meshio splits 'map.h5: /p' into the keys ' ' and 'p' (no space stripped); the plain '/p'
    is a clean copy, so a check that strips the space would pass the file."""
    with h5py.File(h5, "a") as f:
        f["p"] = f[ds][()]
        f[" /p"] = h5py.ExternalLink(str(far), "/p")
    path.write_text(path.read_text().replace(f"map.h5:{ds}<", "map.h5: /p<"))
    return f"dataset ' /p' reaches {str(far)!r} through an HDF5 external link"


def _a_relative_soft_link(path, h5, far, ds):
    """A soft link 'sub/p' in group /g: HDF5 resolves it from /g (into the external link /g/sub),
    not from the root, where /sub/p is a clean copy."""
    with h5py.File(h5, "a") as f:
        f["sub/p"] = f[ds][()]
        f["g/sub"] = h5py.ExternalLink(str(far), "/")
        f["g/d"] = h5py.SoftLink("sub/p")
    _rename(path, ds, "/g/d")
    return f"dataset '/g/d' reaches {str(far)!r} through an HDF5 external link"


def _a_link_off_the_named_paths(path, h5, far, ds):
    with h5py.File(h5, "a") as f:
        f["spare"] = h5py.ExternalLink("../far.h5", "/p")
    return "link '/spare' reaches '../far.h5' through an HDF5 external link"


def _through_a_file_in_the_folder(path, h5, far, ds):
    with h5py.File(path.with_name("near.h5"), "a") as f:
        del f["p"]
        f["p"] = h5py.ExternalLink(str(far), "/p")
    with h5py.File(h5, "a") as f:
        del f[ds]
        f[ds] = h5py.ExternalLink("near.h5", "/p")
    return f"dataset {ds!r} reaches {str(far)!r} through an HDF5 external link"


def _a_virtual_dataset(path, h5, far, ds):
    with h5py.File(h5, "a") as f:
        n = f[ds].shape
        del f[ds]
        layout = h5py.VirtualLayout(shape=n, dtype="f8")
        layout[:] = h5py.VirtualSource(str(far), "p", shape=n)
        f.create_virtual_dataset(ds, layout)
    return f"dataset {ds!r} reaches {str(far)!r} through a virtual dataset"


def _external_raw_storage(path, h5, far, ds):
    raw = far.with_suffix(".bin")
    with h5py.File(far) as g:
        g["p"][()].astype("<f8").tofile(raw)
    with h5py.File(h5, "a") as f:
        n = f[ds].shape
        del f[ds]
        f.create_dataset(ds, shape=n, dtype="<f8", external=[(str(raw), 0, 8 * n[0])])
    return f"dataset {ds!r} reaches {str(raw)!r} through external raw storage (from the working directory)"


def _a_link_to_a_file_not_in_the_folder(path, h5, far, ds):
    """'far.h5' is not in the folder: HDF5 would go on to the working directory (the test's is
    the folder above, where far.h5 is)."""
    with h5py.File(h5, "a") as f:
        del f[ds]
        f[ds] = h5py.ExternalLink("far.h5", "/p")
    return (
        f"dataset {ds!r} reaches 'far.h5' through an HDF5 external link, which is not in the file's "
        "folder (HDF5 would look for it in the working directory)"
    )


@pytest.mark.parametrize(
    "damage",
    [
        _absolute_on_the_dataset,
        _absolute_on_a_group,
        _a_space_after_the_colon,
        _a_relative_soft_link,
        _a_link_off_the_named_paths,
        _through_a_file_in_the_folder,
        _a_virtual_dataset,
        _external_raw_storage,
        _a_link_to_a_file_not_in_the_folder,
    ],
)
def test_heavy_data_reaching_a_file_outside_the_folder_is_refused(tmp_path, capsys, monkeypatch, damage):
    """Every way an .h5 can make HDF5 open a file outside the XDMF file's folder (each of these
    was read, or would be, to 3 × N with the file tripled outside): one line naming the link
    or dataset and the file it names; exit 2 through the CLI."""
    from fepost.cli import main
    from fepost.errors import InputFileError

    monkeypatch.chdir(tmp_path)  # where far.h5 is: HDF5's last resort for names it cannot find
    path, h5, far, ds = _map_with_far(tmp_path)
    what = damage(path, h5, far, ds)
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == f"{path}: refused .xdmf file (heavy-data file 'map.h5': {what}" + (
        ")" if "HDF5 would look" in what else ", which lies outside the file's folder)"
    )
    assert main(["coefficients", str(path), "--nr", "12", "--nphi", "24"]) == 2
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert lines == [f"fepost: error: {err.value}"]


def test_links_inside_the_folder_are_read_as_hdf5_reads_them(tmp_path, small_n_fe, monkeypatch):
    """The same constructions pointing inside the folder are read, to the linked (tripled)
    values: an external link on a group, a soft link and a virtual dataset; with
    HDF5_EXT_PREFIX naming a folder whose near.h5 holds the pressure times 5 (HDF5 would
    look there first), still the folder's near.h5."""
    path, h5, far, ds = _map_with_far(tmp_path)
    decoy = tmp_path / "decoy"
    decoy.mkdir()
    with h5py.File(far) as f, h5py.File(decoy / "near.h5", "w") as g:
        g["p"] = f["p"][()] * 5 / 3
    with h5py.File(h5, "a") as f:
        n = f[ds].shape
        f["g"] = h5py.ExternalLink("near.h5", "/")
        f["h/d"] = h5py.SoftLink("/g/p")
        layout = h5py.VirtualLayout(shape=n, dtype="f8")
        layout[:] = h5py.VirtualSource("near.h5", "p", shape=n)
        f.create_virtual_dataset("v", layout)
    for new in ("/g/p", "/h/d", "/v"):
        text = path.read_text()
        path.write_text(text.replace(f"map.h5:{ds}<", f"map.h5:{new}<"))
        assert _n_fe(path) == pytest.approx(3 * small_n_fe, rel=TOL), new
        path.write_text(text)
    monkeypatch.setenv("HDF5_EXT_PREFIX", str(decoy))
    _rename(path, ds, "/g/p")
    assert _n_fe(path) == pytest.approx(3 * small_n_fe, rel=TOL)


def test_a_symbolic_link_to_an_xdmf_file_reads_the_heavy_data_beside_its_target(tmp_path, small_n_fe):
    """meshio looks for the .h5 beside the XDMF file's real path, and so do the checks: a link
    to the map from another folder, with no .h5 beside the link, is read to the map's N."""
    path, h5, far, ds = _map_with_far(tmp_path)
    other = tmp_path / "elsewhere"
    other.mkdir()
    (other / "map.xdmf").symlink_to(path)
    assert _n_fe(other / "map.xdmf") == pytest.approx(small_n_fe, rel=TOL)
