"""Shared test set-up: headless rendering, and analytic maps written as FE meshes."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

import pytest  # noqa: E402
import pyvista  # noqa: E402

pyvista.OFF_SCREEN = True

from pathlib import Path  # noqa: E402

from fepost.synthetic import write_map  # noqa: E402

#: The aircraft tire's sample maps (`meshes/aircraft`).
AIRCRAFT = Path(__file__).resolve().parents[1] / "meshes" / "aircraft"


@pytest.fixture
def analytic_mesh(tmp_path):
    """Factory: ``analytic_mesh(name, profile, **kw)`` writes an analytic map into tmp_path."""

    def make(name: str = "map.vtu", profile: str = "hertz", **kw):
        return write_map(tmp_path / name, profile, **kw)

    return make


@pytest.fixture(scope="session")
def aircraft():
    """The demo's case: the aircraft tire at its rated load, static and rolling, analysed."""
    from fepost import analyse

    static, rolling = AIRCRAFT / "static_100.vtu", AIRCRAFT / "rolling_100.vtu"
    if not (static.is_file() and rolling.is_file()):
        pytest.skip(f"{AIRCRAFT} not shipped")
    return analyse(static, rolling)
