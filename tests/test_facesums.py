"""Exact face integrals (fepost.facesums.face_sums) against a quadrature of their own, and
the same bits on one thread or two.

Reference: each triangle integrated with the 7-point degree-5 rule written out here from
barycentric corners (the integrands are of degree ≤ 2 on a triangle: exact up to round-off).
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from fepost import _chunks, facesums

_A1, _B1 = 0.059715871789770, 0.470142064105115
_A2, _B2 = 0.797426985353087, 0.101286507323456
BARY = np.array(
    [[1 / 3] * 3]
    + [[_A1, _B1, _B1], [_B1, _A1, _B1], [_B1, _B1, _A1]]
    + [[_A2, _B2, _B2], [_B2, _A2, _B2], [_B2, _B2, _A2]]
)
WEIGHTS = np.array([0.225, *([0.132394152788506] * 3), *([0.125939180544827] * 3)])


def mesh(n: int = 3000, seed: int = 4):
    """A scattered, Delaunay-triangulated disc with a pressure linear on every face."""
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(0, 1, n)) * 0.12
    a = rng.uniform(0, 2 * np.pi, n)
    x, y = r * np.cos(a) + 0.01, r * np.sin(a) - 0.02
    tri = Delaunay(np.column_stack([x, y])).simplices.astype(np.int64)
    p = 1e6 * (1 - (x / 0.13) ** 2 - (y / 0.13) ** 2) + 2e5 * x / 0.12
    return x, y, tri, p


def reference(x, y, tri, values, location):
    cx, cy = x[tri], y[tri]  # (m, 3)
    area = 0.5 * np.abs(
        (cx[:, 1] - cx[:, 0]) * (cy[:, 2] - cy[:, 0]) - (cy[:, 1] - cy[:, 0]) * (cx[:, 2] - cx[:, 0])
    )
    qx, qy = cx @ BARY.T, cy @ BARY.T  # (m, 7) quadrature points
    s = values[tri] @ BARY.T if location == "point" else np.repeat(values[:, None], 7, axis=1)

    def integral(f):
        return float(np.sum(area * (f @ WEIGHTS)))

    return {
        "N": integral(s),
        "Mx": integral(s * qx),
        "My": integral(s * qy),
        "A": float(area.sum()),
        "Sx": integral(qx),
        "Sy": integral(qy),
        "Sxx": integral(qx * qx),
        "Syy": integral(qy * qy),
        "Sxy": integral(qx * qy),
    }


@pytest.mark.parametrize("location", ["point", "face"])
def test_face_sums_equal_a_quadrature(location):
    x, y, tri, p = mesh()
    values = p if location == "point" else p[tri].mean(axis=1)
    got = facesums.face_sums(x, y, tri, values, location)
    ref = reference(x, y, tri, values, location)
    for name, want in ref.items():
        assert getattr(got, name) == pytest.approx(want, rel=1e-12, abs=1e-15), name
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    longest = np.max(np.hypot(*(np.array([x, y])[:, edges[:, 0]] - np.array([x, y])[:, edges[:, 1]])))
    assert got.max_edge == pytest.approx(longest, rel=1e-15)


@pytest.mark.parametrize("location", ["point", "face"])
def test_two_threads_give_the_bits_of_one(monkeypatch, location):
    """Chunks small enough that the faces make many of them: split over two threads (the
    default from `fepost._chunks.SPLIT` chunks on: one gathers the corners, the caller's
    sums them, `fepost._chunks.map_gathered`) and on one, the totals are identical."""
    x, y, tri, p = mesh()
    values = p if location == "point" else p[tri].mean(axis=1)
    monkeypatch.setattr(facesums, "CHUNK", 97)
    monkeypatch.setattr(facesums, "BLOCK", 4 * 97)
    assert len(tri) > _chunks.SPLIT * 97
    monkeypatch.setattr(_chunks, "default_threads", lambda: 2)
    threads = set()
    real, real_sums = facesums._corners, facesums._chunk_sums

    def spy(*args):
        threads.add(threading.get_ident())
        return real(*args)

    def spy_sums(*args):
        threads.add(threading.get_ident())
        return real_sums(*args)

    monkeypatch.setattr(facesums, "_corners", spy)
    monkeypatch.setattr(facesums, "_chunk_sums", spy_sums)
    two = facesums.face_sums(x, y, tri, values, location)
    assert len(threads) == 2
    monkeypatch.setattr(_chunks, "SPLIT", 10**9)
    threads.clear()
    one = facesums.face_sums(x, y, tri, values, location)
    assert threads == {threading.get_ident()}
    assert two == one


def test_no_faces_give_zero_totals():
    got = facesums.face_sums(np.zeros(3), np.zeros(3), np.zeros((0, 3), np.int64), np.zeros(3), "point")
    assert (got.N, got.A, got.max_edge) == (0.0, 0.0, 0.0)
