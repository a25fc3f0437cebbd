"""Helpers for the checks on the committed CalculiX tire samples (tests/test_samples.py,
tests/test_aircraft_samples.py): read with meshio and numpy only, independent of fepost."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def face_stats(points: np.ndarray, quads: np.ndarray, p: np.ndarray):
    """Per face: area projected on the road plane (m^2), mean nodal pressure (Pa), centroid (m)."""
    x = points[quads]
    d1 = x[:, 2] - x[:, 0]
    d2 = x[:, 3] - x[:, 1]
    area_z = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    return area_z, p[quads].mean(axis=1), x.mean(axis=1)


def centre_of_pressure(points: np.ndarray, quads: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Pressure-weighted mean of the face centroids (m), weights = projected area x mean pressure."""
    a, pm, c = face_stats(points, quads, p)
    w = a * pm
    return (w[:, None] * c).sum(axis=0) / w.sum()


def assert_exodus_matches_vtu(vtu: Path, exodus: Path) -> None:
    """The Exodus II export holds the same points, quads, CPRESS and displacement as the .vtu."""
    import meshio

    v = meshio.read(vtu)
    e = meshio.read(exodus)
    np.testing.assert_allclose(e.points, v.points, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(e.cells_dict["quad"], v.cells_dict["quad"])
    np.testing.assert_allclose(e.point_data["CPRESS"], v.point_data["CPRESS"], rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(e.point_data["displacement"], v.point_data["displacement"], atol=1e-12)
