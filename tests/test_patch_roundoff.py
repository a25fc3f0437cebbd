"""The patch's integrals after the speed-ups of issue 41 equal the earlier ones to round-off.

`fepost.facesums.face_sums` now sums each chunk's faces as one weighted Gram matrix of their
corner coordinates and pressures (a matrix product) instead of one pass per integral. The
numbers are the same closed forms added in another order:

* against the per-face closed forms written out here over whole arrays (the earlier
  formulation, no chunks), every total agrees to 1e-13 of its natural scale (N; N L for the
  load moments; A; A L and A L² for the area moments, L the largest coordinate), on a mesh
  placed far from the origin (so the sums cancel) and spread over many chunks;
* end to end, the coefficients and patch figures of a tilted, shifted, elliptic
  triangulated map (nodal and face data) equal the values the code gave before
  the change (commit 8121227), to 1e-13 relative (measured: 2e-15 at most).
"""

from __future__ import annotations

import numpy as np
import pytest

from fepost import analyse, facesums
from fepost.synthetic import write_map

ROUND_OFF = 1e-13


def _closed_forms(x, y, tri, values, location):
    """The integrals of the module docstring of `fepost.facesums`, face by face."""
    px, py = x[tri], y[tri]
    a2 = np.abs((px[:, 1] - px[:, 0]) * (py[:, 2] - py[:, 0]) - (py[:, 1] - py[:, 0]) * (px[:, 2] - px[:, 0]))
    area = a2 / 2
    sx, sy = px.sum(1), py.sum(1)
    if location == "point":
        s = values[tri]
        ss = s.sum(1)
        N = area * ss / 3
        Mx = area / 12 * (ss * sx + (s * px).sum(1))
        My = area / 12 * (ss * sy + (s * py).sum(1))
    else:
        N = area * values
        Mx, My = N * sx / 3, N * sy / 3
    Sxx = area / 12 * ((px * px).sum(1) + sx * sx)
    Syy = area / 12 * ((py * py).sum(1) + sy * sy)
    Sxy = area / 12 * ((px * py).sum(1) + sx * sy)
    edges = [(px[:, i] - px[:, j]) ** 2 + (py[:, i] - py[:, j]) ** 2 for i, j in ((0, 1), (0, 2), (1, 2))]
    return {
        "N": N.sum(),
        "Mx": Mx.sum(),
        "My": My.sum(),
        "A": area.sum(),
        "Sx": (area * sx / 3).sum(),
        "Sy": (area * sy / 3).sum(),
        "Sxx": Sxx.sum(),
        "Syy": Syy.sum(),
        "Sxy": Sxy.sum(),
        "max_edge": np.sqrt(max(e.max() for e in edges)),
    }


@pytest.mark.parametrize("location", ["point", "cell"])
def test_face_sums_equal_the_per_face_closed_forms(location):
    n = 121  # a jittered grid of 28 800 triangles: several chunks, two threads
    rng = np.random.default_rng(7)
    u, v = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n), indexing="ij")
    u = u + rng.uniform(-0.3, 0.3, u.shape) / n
    v = v + rng.uniform(-0.3, 0.3, v.shape) / n
    k = np.arange(n * n).reshape(n, n)[:-1, :-1].ravel()
    tri = np.concatenate([np.column_stack([k, k + n, k + 1]), np.column_stack([k + 1, k + n, k + n + 1])])
    assert len(tri) > 3 * facesums.CHUNK
    x, y = 0.2 * u.ravel() + 3.0, 0.15 * v.ravel() - 2.0  # far from the origin: the moments cancel
    r2 = ((x - 3.0) / 0.2) ** 2 + ((y + 2.0) / 0.15) ** 2
    p = 1e6 * np.sqrt(np.clip(1 - r2, 0, None)) * (1 + 0.3 * (x - 3.0))
    values = p if location == "point" else p[tri].mean(axis=1)
    got = facesums.face_sums(x, y, tri, values, location)
    want = _closed_forms(x, y, tri, values, location)
    L = max(np.abs(x).max(), np.abs(y).max())
    scale = {"N": want["N"], "Mx": want["N"] * L, "My": want["N"] * L, "A": want["A"], "max_edge": L}
    scale.update({k: want["A"] * L for k in ("Sx", "Sy")})
    scale.update({k: want["A"] * L * L for k in ("Sxx", "Syy", "Sxy")})
    for name, value in want.items():
        assert abs(getattr(got, name) - value) <= ROUND_OFF * scale[name], name


#: `fepost analyse` of the maps of `_map` before the change (commit 8121227).
BEFORE = {
    "point": {
        "N": 24105.53908540387,
        "N_fe": 24104.401581613572,
        "R": 0.13682133406913363,
        "M0": 517.6262062724271,
        "a": 0.5587166653531461,
        "m": 10.815699386227816,
        "A0": 548357.1636855026,
        "area": 0.045238410639405466,
        "r_equiv": 0.11999930558867722,
        "aspect": 1.3000000000000005,
        "load_outside": 0.03521725717999497,
        "max_edge": 0.009650132992263671,
    },
    "cell": {
        "N": 24140.938538976312,
        "N_fe": 24134.622579255527,
        "R": 0.13682094434607142,
        "M0": 518.6928436147576,
        "a": 0.5593980866655558,
        "m": 10.80285747073885,
        "A0": 548830.985058568,
        "area": 0.045238410639405494,
        "r_equiv": 0.11999930558867725,
        "aspect": 1.299999999999999,
        "load_outside": 0.035516252956738784,
        "max_edge": 0.00965013299226372,
    },
}


@pytest.mark.parametrize("location", ["point", "cell"])
def test_coefficients_equal_those_before_the_change(tmp_path, location):
    path = write_map(
        tmp_path / "map.vtu",
        "hertz",
        radius=0.12,
        peak=8e5,
        aspect=1.3,
        shift=(0.004, -0.002),
        origin=(12.0, -3.0, 0.5),
        normal=(0.1, 0.2, 1.0),
        n_rings=30,
        location=location,
        seed=3,
    )
    res = analyse(path, friction=0.3)
    c, p = res.coefficients, res.static_patch
    got = {
        "N": c.N,
        "N_fe": p.N_fe,
        "R": c.R,
        "M0": c.M0,
        "a": c.a,
        "m": c.m,
        "A0": c.A[0],
        "area": p.area,
        "r_equiv": p.r_equiv,
        "aspect": p.aspect,
        "load_outside": p.load_outside,
        "max_edge": p.max_edge,
    }
    assert got == pytest.approx(BEFORE[location], rel=ROUND_OFF)
