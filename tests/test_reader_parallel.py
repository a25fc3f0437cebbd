"""Parallel VTK files (`.pvtu`, `.pvtp`) and structured XML grids (`.vts`, `.vtr`).

Parallel files are written by VTK's own parallel writers from one map cut into
2 or 3 pieces by VTK's piece extractors (with and without a layer of ghost
cells); the expected values are those of the same map read from the original
single file: the same nodes (shared nodes counted once), N_fe, N, M0 and R. VTK's
piece extractors store the coordinates in single precision, so the single file
compared with has its coordinates rounded to float32 too (otherwise the results
differ by ~1e-8, the rounding, not the join).
Structured grids are compared with the same grid converted to `.vtu` by VTK
(`vtkAppendFilter`), read as an ordinary volume mesh.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from fepost import analyse
from fepost.polar import PolarGrid

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "aircraft" / "static_100.vtu"
GRID = PolarGrid.make(nr=24, nphi=48)
TOL = 1e-9  # the same doubles, summed in another order


def _values(path):
    res = analyse(path, grid=GRID)
    c = res.coefficients
    return res, (res.static_patch.N_fe, c.N, c.M0, c.R)


def write_parallel(grid, path: Path, pieces: int, ghosts: int) -> Path:
    """``grid`` cut into ``pieces`` by VTK's piece extractor and written by VTK's parallel writer."""
    from vtkmodules.vtkFiltersParallel import vtkExtractPolyDataPiece, vtkExtractUnstructuredGridPiece
    from vtkmodules.vtkIOParallelXML import vtkXMLPPolyDataWriter, vtkXMLPUnstructuredGridWriter

    poly = path.suffix == ".pvtp"
    cut = vtkExtractPolyDataPiece() if poly else vtkExtractUnstructuredGridPiece()
    cut.SetInputData(grid)
    cut.SetCreateGhostCells(bool(ghosts))
    w = vtkXMLPPolyDataWriter() if poly else vtkXMLPUnstructuredGridWriter()
    w.SetInputConnection(cut.GetOutputPort())
    w.SetFileName(str(path))
    w.SetNumberOfPieces(pieces)
    w.SetStartPiece(0)
    w.SetEndPiece(pieces - 1)
    w.SetGhostLevel(ghosts)
    w.Write()
    return path


@pytest.fixture(scope="module")
def sample():
    return pv.read(SAMPLE)


def single(grid, path: Path) -> Path:
    """``grid`` with float32 coordinates (as the piece extractors keep them) in one file."""
    g = grid.copy()
    g.points = np.asarray(g.points, np.float32)
    g.save(path)
    return path


@pytest.fixture(scope="module")
def original(sample, tmp_path_factory):
    return _values(single(sample, tmp_path_factory.mktemp("one") / "one.vtu"))


@pytest.mark.parametrize("suffix", [".pvtu", ".pvtp"])
@pytest.mark.parametrize(("pieces", "ghosts"), [(2, 0), (3, 0), (3, 1)])
def test_parallel_pieces_joined_without_double_counting(sample, original, tmp_path, suffix, pieces, ghosts):
    grid = sample if suffix == ".pvtu" else sample.extract_surface(algorithm=None)
    path = write_parallel(grid, tmp_path / f"map{suffix}", pieces, ghosts)
    written = sorted(tmp_path.glob("map_*.vt?"))
    assert len(written) == pieces
    # the pieces as written do share nodes: their node counts add up to more than the map's
    assert sum(pv.read(p).n_points for p in written) > sample.n_points
    res, got = _values(path)
    ref, want = original
    assert len(res.static_field.points) == len(ref.static_field.points)
    assert got == pytest.approx(want, rel=TOL)
    assert any(f"{pieces} pieces joined" in n for n in res.static_field.notes)


def _block(shape=(13, 13, 4), size=0.24, peak=1.0e6, loaded_z=0.0):
    """A hexahedral block on z = 0 with a Hertz pressure on its nodes at ``loaded_z`` (radius 0.1 m)."""
    x = np.linspace(-size / 2, size / 2, shape[0])
    y = np.linspace(-size / 2, size / 2, shape[1])
    z = np.linspace(0.0, 0.06, shape[2])
    rect = pv.RectilinearGrid(x, y, z)
    pts = np.asarray(rect.points)
    r = np.hypot(pts[:, 0], pts[:, 1]) / 0.1
    p = np.where((pts[:, 2] == loaded_z) & (r < 1.0), peak * np.sqrt(np.clip(1 - r * r, 0, None)), 0.0)
    rect.point_data["CPRESS"] = p
    return rect


def _as_vtu(ds, path: Path) -> Path:
    from vtkmodules.vtkFiltersCore import vtkAppendFilter
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    f = vtkAppendFilter()
    f.AddInputData(ds)
    f.Update()
    w = vtkXMLUnstructuredGridWriter()
    w.SetInputData(f.GetOutput())
    w.SetFileName(str(path))
    w.Write()
    return path


@pytest.mark.parametrize("kind", ["vtr", "vts"])
def test_structured_grids_read_as_their_boundary(tmp_path, kind):
    rect = _block()
    ds = rect if kind == "vtr" else rect.cast_to_structured_grid()
    path = tmp_path / f"block.{kind}"
    ds.save(path)
    assert f'type="{"RectilinearGrid" if kind == "vtr" else "StructuredGrid"}"' in path.read_text()[:400]
    res, got = _values(path)
    _, want = _values(_as_vtu(ds, tmp_path / "converted.vtu"))
    assert got == pytest.approx(want, rel=TOL)
    # the bottom faces only: 12 x 12 quads under a patch of radius 0.1 m
    fld = res.static_field
    assert set(fld.faces) == {"quad4"} and len(fld.faces["quad4"]) <= 144
    assert res.static_patch.N_fe == pytest.approx(2 / 3 * np.pi * 0.1**2 * 1e6, rel=0.05)


def test_parallel_volume_mesh_cut_faces_are_not_boundary(tmp_path):
    """A hexahedral block in 3 pieces: faces on the cuts are interior once the shared nodes are merged."""
    grid = _block().cast_to_unstructured_grid()
    one = single(grid, tmp_path / "one.vtu")
    path = write_parallel(grid, tmp_path / "block.pvtu", 3, 0)
    res, got = _values(path)
    ref, want = _values(one)
    assert got == pytest.approx(want, rel=TOL)
    assert {t: len(c) for t, c in res.static_field.faces.items()} == {
        t: len(c) for t, c in ref.static_field.faces.items()
    }


def _two_bodies():
    """Two blocks touching at z = 0 (nodes at the same positions), both sides loaded there."""
    top = _block().cast_to_unstructured_grid()
    below = _block(loaded_z=0.06).cast_to_unstructured_grid()
    below.points = below.points - np.array([0.0, 0.0, 0.06])
    both = pv.merge([top, below], merge_points=False)
    assert both.n_points == 2 * top.n_points  # coincident nodes kept
    return both


@pytest.mark.parametrize("pieces", [2, 3])
def test_two_bodies_in_contact_joined_by_global_ids(tmp_path, pieces):
    both = _two_bodies()
    both.point_data["GlobalNodeIds"] = np.arange(both.n_points, dtype=np.int64)
    path = write_parallel(both, tmp_path / "two.pvtu", pieces, 0)
    res, got = _values(path)
    ref, want = _values(single(both, tmp_path / "two.vtu"))
    assert got == pytest.approx(want, rel=TOL)
    assert len(res.static_field.faces["quad4"]) == len(ref.static_field.faces["quad4"]) > 0


def test_two_bodies_in_separate_pieces_without_global_ids_is_an_error_not_a_number(tmp_path, capsys):
    """Without global ids, touching nodes in different pieces look like a cut: the loaded faces
    become interior and the read is refused in one line (documented: write global ids)."""
    from fepost.cli import main

    path = write_parallel(_two_bodies(), tmp_path / "two.pvtu", 2, 0)
    assert main(["coefficients", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"fepost: error: {path}: the mesh has no surface faces carrying 'CPRESS'"]
