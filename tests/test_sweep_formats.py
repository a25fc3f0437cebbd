"""The sweep meets the newer formats: a parallel file is one case (its pieces are not
cases of their own), and a series format (XDMF time series) gives one row per step."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest
import pyvista as pv
from test_reader_parallel import write_parallel

from fepost.sweep import run_sweep
from fepost.sweep.inputs import expand_inputs, piece_paths
from fepost.sweep.steps import SERIES_SUFFIXES, time_steps
from fepost.synthetic import disc_mesh

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "static.vtu"


@pytest.mark.parametrize("suffix", [".pvtu", ".pvtp"])
def test_a_parallel_file_is_one_case_whatever_the_input_form(tmp_path, suffix):
    grid = pv.read(SAMPLE)
    if suffix == ".pvtp":
        grid = grid.extract_surface(algorithm="dataset_surface")
    folder = tmp_path / "runs"
    folder.mkdir()
    par = write_parallel(grid, folder / f"case{suffix}", pieces=3, ghosts=0)
    pieces = piece_paths(par)
    assert len(pieces) == 3 and all(Path(p).is_file() for p in pieces)
    # the pieces sit beside the parallel file or in a folder of their own: list them too
    for p in pieces:
        if Path(p).parent == folder:
            assert Path(p).suffix in (".vtu", ".vtp")
    for given in (str(folder), str(folder / "**" / "*"), str(par)):
        sources = expand_inputs([given])
        assert [Path(s.path).name for s in sources] == [par.name], given
    # a piece given on its own is still read as the user asked
    one = sorted(pieces)[0]
    assert [s.path for s in expand_inputs([one])] == [one]


def test_an_unreadable_parallel_file_names_no_pieces(tmp_path):
    assert piece_paths(tmp_path / "missing.pvtu") == set()


def test_series_formats_list_their_steps(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # meshio's TimeSeriesWriter puts the .h5 in the working directory
    assert {".e", ".exo", ".xdmf", ".xmf", ".frd"} <= set(SERIES_SUFFIXES)
    pts, tri = disc_mesh(12)
    pts = 0.1 * pts
    p = 2e5 * np.sqrt(np.clip(1.0 - (pts**2).sum(axis=1) / 0.01, 0.0, None))  # Hertz, R = 0.1 m
    path = tmp_path / "series.xdmf"
    with meshio.xdmf.TimeSeriesWriter(path) as w:
        w.write_points_cells(np.c_[pts, np.zeros(len(pts))], [("triangle", tri)])
        for t, scale in [(0.5, 0.5), (1.0, 1.0)]:
            w.write_data(t, point_data={"CPRESS": scale * p})
    assert time_steps(path) == (0.5, 1.0)
    res = run_sweep([str(path)], tmp_path / "out", steps="all", workers=1, processes=False, progress=False)
    assert res.ok and [r["step"] for r in res.rows] == [0, 1]
    n = [r["N"] for r in res.rows]
    assert n[0] == pytest.approx(0.5 * n[1], rel=1e-12)  # the same map at half the pressure
