"""Compiled node sums of the exact friction integrals (numba, optional).

`fepost.friction.exact` needs, for every kinematic point and every quadrature
node, the unit sliding direction ŵ = w/|w| (w = (v_x − ω_z y, v_y + ω_z x)) and
its sums against seven node columns each for x and y. numpy does that as ten
whole-array passes over (points × nodes) plus two matrix products; this loop
does it in one pass, in registers, which is what brings 1000 points on the
default 64 × 128 grid from a quarter of a second to a few hundredths.

numba is an optional dependency (``pip install fepost[fast]``); without it
`AVAILABLE` is False and `fepost.friction.exact` keeps its numpy path. The two
agree to round-off: the sums run in another order (vectorised partial sums), and
the kinematics are scaled per point to max(|v_x|, |v_y|, |ω_z| r_max) = 1 before
the squares, so |w|² can neither overflow nor underflow (numpy falls back to
hypot where it could); a node closer to the instantaneous centre of rotation than
1e-150 of that scale counts as the centre itself (ŵ = 0).
"""

from __future__ import annotations

import numpy as np

from . import compiled

#: True when numba is importable (the compiled node sums can be used).
AVAILABLE = compiled.AVAILABLE
_COMPILED = False

#: Columns of `columns`: the distinct node weights (g = μσ dA without the speed factor).
COLUMNS = ("g", "g y", "g x", "dA", "dA x", "dA y", "dA xy", "dA y²", "dA x²")


def columns(x: np.ndarray, y: np.ndarray, g: np.ndarray, da: np.ndarray) -> np.ndarray:
    """The node weights in the order of `COLUMNS`, shape (9, nodes), C-contiguous."""
    return np.ascontiguousarray(
        np.vstack([g, g * y, g * x, da, da * x, da * y, da * x * y, da * y * y, da * x * x])
    )


def _sums(vx, vy, wz, x, y, W, speed_coef, rmax, sx, sy):
    """sx[i] = Σ_j ŵx(i, j) (g f, g y f, dA, dA x, dA y, dA xy, dA y²)_j and sy[i] = Σ_j
    ŵy (g f, g x f, dA, dA x, dA y, dA x², dA xy)_j, f = max(0, 1 + c_v |w|)."""
    for i in range(vx.shape[0]):
        s = max(abs(vx[i]), abs(vy[i]), abs(wz[i]) * rmax)
        k = 1.0 / s if s > 0.0 else 0.0
        a = vx[i] * k
        b = vy[i] * k
        c = wz[i] * k
        x0 = x1 = x2 = x3 = x4 = x5 = x6 = 0.0
        y0 = y1 = y2 = y3 = y4 = y5 = y6 = 0.0
        for j in range(x.shape[0]):
            ex = a - c * y[j]
            ey = b + c * x[j]
            r = np.sqrt(ex * ex + ey * ey)
            inv = 1.0 / r if r > 0.0 else 0.0
            ex *= inv
            ey *= inv
            f = max(0.0, 1.0 + speed_coef * (r * s))
            x0 += ex * f * W[0, j]
            x1 += ex * f * W[1, j]
            y0 += ey * f * W[0, j]
            y1 += ey * f * W[2, j]
            x2 += ex * W[3, j]
            y2 += ey * W[3, j]
            x3 += ex * W[4, j]
            y3 += ey * W[4, j]
            x4 += ex * W[5, j]
            y4 += ey * W[5, j]
            x5 += ex * W[6, j]
            y6 += ey * W[6, j]
            x6 += ex * W[7, j]
            y5 += ey * W[8, j]
        sx[i, 0] = x0
        sx[i, 1] = x1
        sx[i, 2] = x2
        sx[i, 3] = x3
        sx[i, 4] = x4
        sx[i, 5] = x5
        sx[i, 6] = x6
        sy[i, 0] = y0
        sy[i, 1] = y1
        sy[i, 2] = y2
        sy[i, 3] = y3
        sy[i, 4] = y4
        sy[i, 5] = y5
        sy[i, 6] = y6


def prepare() -> None:
    """Compile the node sums with numba (once per process; from numba's disk cache
    after the first time). reassoc: the sums over nodes may run as vector partial
    sums (round-off only)."""
    compiled.compile_functions(globals(), ("_sums",), fastmath={"reassoc", "contract"})


def node_sums(
    vx: np.ndarray,
    vy: np.ndarray,
    wz: np.ndarray,
    *,
    x: np.ndarray,
    y: np.ndarray,
    weights: np.ndarray,
    speed_coef: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The (points, 7) sums ŵx @ bx and ŵy @ by of `fepost.friction.exact` for flat
    float arrays of kinematics, nodes ``x``, ``y`` (m) and ``weights`` from `columns`."""
    prepare()
    n = vx.shape[0]
    sx = np.empty((n, 7))
    sy = np.empty((n, 7))
    rmax = float(np.max(np.hypot(x, y))) if x.size else 0.0
    _sums(vx, vy, wz, x, y, weights, float(speed_coef), rmax, sx, sy)
    return sx, sy
