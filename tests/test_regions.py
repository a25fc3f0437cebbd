"""The raster regions of the patch step: fepost's numpy dilation and labelling against scipy.ndimage."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from fepost.regions import dilate, label

SQUARE = np.ones((3, 3), bool)
REPO = Path(__file__).resolve().parents[1]


def _rasters():
    rng = np.random.default_rng(7)
    for _ in range(200):
        shape = tuple(int(n) for n in rng.integers(1, 48, 2))
        yield rng.random(shape) < rng.uniform(0.02, 0.75)
    yield np.zeros((5, 7), bool)
    yield np.ones((6, 4), bool)
    yield np.ones((1, 1), bool)
    snake = np.zeros((41, 37), bool)  # one region, the longest path: rows joined at alternate ends
    snake[::2] = True
    snake[1::4, -1] = True
    snake[3::4, 0] = True
    yield snake
    yield np.eye(30, dtype=bool)[::-1] | np.eye(30, dtype=bool)  # diagonal-only contacts


@pytest.mark.parametrize("occupied", list(_rasters()))
def test_dilation_and_labels_match_scipy_ndimage(occupied):
    grown = dilate(occupied)
    np.testing.assert_array_equal(grown, ndimage.binary_dilation(occupied, structure=SQUARE))
    for raster in (occupied, grown):
        labels, count = label(raster)
        ref, ref_count = ndimage.label(raster, structure=SQUARE)
        assert count == ref_count
        np.testing.assert_array_equal(labels, ref)


def test_snake_is_one_region():
    snake = np.zeros((201, 5), bool)
    snake[::2] = True
    snake[1::4, -1] = True
    snake[3::4, 0] = True
    labels, count = label(snake)
    assert count == 1
    assert set(np.unique(labels)) == {0, 1}


def test_coefficients_command_imports_no_scipy():
    """The patch step runs on numpy alone: scipy's import would cost a quarter of the command."""
    code = (
        "import sys, io, contextlib\n"
        "import fepost.cli\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    status = fepost.cli.main(['coefficients', sys.argv[1]])\n"
        "assert status == 0, status\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('scipy', 'matplotlib', 'pyvista')))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, str(REPO / "meshes" / "static.vtu")],
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.strip() == "[]"
