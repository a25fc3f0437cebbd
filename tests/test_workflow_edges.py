"""Hostile values at the workflow's edges: one line naming the file, never an internal error."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from fepost.cli import main
from fepost.synthetic import write_map

ROOT = Path(__file__).resolve().parents[1]


def one_error(capsys, argv) -> str:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2, err
    assert "Traceback" not in err and "internal error" not in err
    return lines[-1]


@pytest.mark.parametrize("command", [["coefficients", ROOT / "meshes" / "static.vtu"], ["table1"]])
def test_a_json_path_that_is_a_symlink_loop_is_named(capsys, tmp_path, command):
    loop = tmp_path / "loop.json"
    os.symlink(loop, loop)
    line = one_error(capsys, [*command, "--json", loop])
    assert line == f"fepost: error: {loop}: cannot write here (a symbolic-link loop)"


def test_an_output_folder_that_is_a_symlink_loop_is_named(capsys, tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    os.symlink(b, a)
    os.symlink(a, b)
    line = one_error(capsys, ["sweep", ROOT / "meshes" / "static.vtu", "--out", a, "--no-progress"])
    assert line == f"fepost: error: {a}: cannot write here (a symbolic-link loop)"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "b"]


def test_values_at_the_end_of_the_float_range_are_refused_naming_the_file(capsys, tmp_path):
    # radius 1e-150 "mm" = 1e-153 m: R^2 underflows inside the model (a division by zero)
    f = write_map(tmp_path / "tiny.vtu", "hertz", radius=1e-150, peak=1e29, n_rings=8)
    line = one_error(capsys, ["coefficients", f, "--units", "mm-t-s"])
    assert line.startswith(f"fepost: error: {f}: values beyond the floating-point range")
