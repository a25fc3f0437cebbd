"""The correction basis of the generalised friction model: Fourier × Chebyshev on the sphere.

A point of the kinematic sphere (the direction of (v_x, v_y, ω_z R)) with ω_z ≠ 0
is written (θ, t):

* θ: the direction of the instantaneous centre of rotation seen from the patch
  origin, (cos θ, sin θ) = sgn(ω_z)·(−v_y, v_x)/|v| (the sliding direction
  turned by +90° for ω_z > 0);
* t = (2/π)·atan(|v| / (|ω_z| R)) ∈ [0, 1]: 0 at pure spin, 1 at pure sliding;
  ε = |v|/(|ω_z| R) = tan(πt/2) is the distance of that centre from the origin in
  units of R.

A correction is Σ_{k,l} C[k, l] B_k(θ) T_l(2t − 1) times a weight w(t) =
t^p (1 − t)^q that vanishes at both ends, so that the limits the base model gets
right stay right. B = (1, cos θ, sin θ, cos 2θ, sin 2θ, …, cos Kθ, sin Kθ) and T_l
the Chebyshev polynomials of the first kind. Everything is evaluated by
recurrences (no trigonometric call beyond the one atan2 that gives t), which is
what makes the model cheap enough for time integration.

Hand-written rather than numpy.polynomial: the three sums (value and the two
derivatives) are needed together on millions of points; one pass of the
recurrences with two small matrix products does that without building the
(n, K, L) tensor numpy's ``chebvander`` route would need.
"""

from __future__ import annotations

import numpy as np


def fourier(cos1: np.ndarray, sin1: np.ndarray, K: int) -> tuple[np.ndarray, np.ndarray]:
    """B (2K+1, n) and dB/dθ from cos θ and sin θ, by the angle-addition recurrence."""
    n = cos1.shape[0]
    B = np.empty((2 * K + 1, n))
    dB = np.empty((2 * K + 1, n))
    B[0] = 1.0
    dB[0] = 0.0
    if K >= 1:
        B[1], B[2] = cos1, sin1
        dB[1], dB[2] = -sin1, cos1
    for k in range(2, K + 1):
        ck, sk = B[2 * k - 3], B[2 * k - 2]
        np.multiply(ck, cos1, out=B[2 * k - 1])
        B[2 * k - 1] -= sk * sin1
        np.multiply(sk, cos1, out=B[2 * k])
        B[2 * k] += ck * sin1
        np.multiply(B[2 * k], -k, out=dB[2 * k - 1])
        np.multiply(B[2 * k - 1], k, out=dB[2 * k])
    return B, dB


def chebyshev(t: np.ndarray, L: int) -> tuple[np.ndarray, np.ndarray]:
    """T_l(2t − 1), l < L, as rows (L, n), and their derivatives in t (dT_l/dt = 2 l U_{l−1})."""
    x = 2.0 * t - 1.0
    n = t.shape[0]
    T = np.empty((L, n))
    dT = np.empty((L, n))
    T[0] = 1.0
    dT[0] = 0.0
    if L > 1:
        T[1] = x
        dT[1] = 2.0
        u_prev, u_cur = np.ones(n), 2.0 * x  # U_0, U_1
        x2 = 2.0 * x
        for j in range(2, L):
            np.multiply(x2, T[j - 1], out=T[j])
            T[j] -= T[j - 2]
            np.multiply(u_cur, 2.0 * j, out=dT[j])  # u_cur = U_{j-1}
            u_prev, u_cur = u_cur, x2 * u_cur - u_prev
    return T, dT


def weight(t: np.ndarray, p: int, q: int) -> tuple[np.ndarray, np.ndarray]:
    """w = t^p (1 − t)^q and dw/dt."""
    s = 1.0 - t
    w = t**p * s**q
    dw = p * t ** (p - 1) * s**q - q * t**p * s ** (q - 1)
    return w, dw


def sums(C: np.ndarray, cos1, sin1, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """S = Σ C B T, S_t = Σ C B dT/dt and S_θ = Σ C dB/dθ T at each point."""
    K = (C.shape[0] - 1) // 2
    B, dB = fourier(cos1, sin1, K)
    T, dT = chebyshev(t, C.shape[1])
    # einsum, not @: a BLAS call on these thin matrices spends more in thread
    # start-up than in arithmetic (20x slower on a busy machine).
    P = np.einsum("kl,ln->kn", C, T)  # (2K+1, n): the t-polynomial of each harmonic
    dP = np.einsum("kl,ln->kn", C, dT)
    return (
        np.einsum("kn,kn->n", B, P),
        np.einsum("kn,kn->n", B, dP),
        np.einsum("kn,kn->n", dB, P),
    )


def design(cos1, sin1, t, K: int, L: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The basis functions themselves (columns k·L + l): B T, B dT/dt, dB/dθ T, each (n, (2K+1)L)."""
    B, dB = fourier(cos1, sin1, K)
    T, dT = chebyshev(t, L)
    n = t.shape[0]
    return (
        (B.T[:, :, None] * T.T[:, None, :]).reshape(n, -1),
        (B.T[:, :, None] * dT.T[:, None, :]).reshape(n, -1),
        (dB.T[:, :, None] * T.T[:, None, :]).reshape(n, -1),
    )
