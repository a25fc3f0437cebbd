"""Shared test set-up: headless rendering, and analytic maps written as FE meshes."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

import pytest  # noqa: E402
import pyvista  # noqa: E402

pyvista.OFF_SCREEN = True

from fepost.synthetic import write_map  # noqa: E402


@pytest.fixture
def analytic_mesh(tmp_path):
    """Factory: ``analytic_mesh(name, profile, **kw)`` writes an analytic map into tmp_path."""

    def make(name: str = "map.vtu", profile: str = "hertz", **kw):
        return write_map(tmp_path / name, profile, **kw)

    return make
