"""Compiled evaluation of the generalised friction model (numba, optional).

The numpy evaluation (`GeneralisedModel._evaluate`) makes about a hundred
passes over whole arrays, each reading and writing memory. Here the kinematic
points go in blocks of `BLOCK` through a few fused, branch-free loops that LLVM
vectorises (4 points per instruction with AVX2) and whose rows stay in cache:
the same formulas (the module docstring of `fepost.friction.model`), about 15 ×
the numpy speed with the default 72 numbers and 17 × with 204
(benchmarks/bench_model.py). numpy alone cannot
fuse the passes, which is why this is hand-written. Two library calls would
keep the loops scalar, so they are replaced by vectorisable equivalents:

* P^(−5/6) by Newton steps for P^(−1/6) from a guess read off P's bits (to a
  few ulp; `pow` only for P below `_TINY`, which normalised kinematics never
  reach with a non-degenerate model);
* atan2 by Cephes' reduction and rational form (S. L. Moshier, to ~1 ulp);

and the t-derivative of the Chebyshev sums by the coefficients of the derivative
series (numpy.polynomial.chebyshev.chebder), so that one set of polynomial
values serves both sums.

Those sums are most of the work (2 (2K + 1) L multiply-adds a point). Written
as loops over rows of the block they pass every partial sum through memory;
for correction blocks of up to `UNROLL_MAX` numbers they are instead written
out for the block's shape (`_unrolled_source`, Python source that numba
compiles as the implementation of `_sums` for that shape, picked by the type of
`KernelCoefficients.shape`), one loop whose body keeps the Chebyshev values,
the harmonics and the sums in registers: 1.4 × the general loops' speed with
the default 72 numbers. numba compiles and caches `_loop` once per such shape.

numba is an optional dependency (``pip install fepost[fast]``) and is imported
only when the kernel is first used (`prepare`); without it `AVAILABLE` is False
and the model keeps its numpy path. Both give the same numbers to round-off
(tests/test_model_kernel.py). The C evaluator (`fepost.friction.cexport`)
follows the numpy path with the C library's pow and atan2.
"""

from __future__ import annotations

import numpy as np

from . import compiled
from .kernelpack import UNROLL_MAX, KernelCoefficients, coefficients

__all__ = ["AVAILABLE", "BLOCK", "UNROLL_MAX", "KernelCoefficients", "coefficients", "evaluate", "prepare"]

#: True when numba is importable (the compiled kernel can be used).
AVAILABLE = compiled.AVAILABLE

#: Kinematic points per block: the working rows stay in L1 cache.
BLOCK = 256
#: First guess of P^(−1/6) from the bits of P: 7/6 of the bits of 1.0 less a tuned
#: constant (the exponent field read as a logarithm), within 6.1 % for every normal P.
_MAGIC = 0x4A97C00000000000
#: Newton steps for P^(−1/6) from that guess (6 % → round-off in four; one more for margin).
_NEWTON = 5
#: The smallest normal double (its reciprocal is finite).
_NORMAL = 2.2250738585072014e-308
#: P below this (only with degenerate tensors, the kinematics are normalised) takes `pow`.
_TINY = 1e-280
# Cephes' atan (S. L. Moshier): rational approximation on |x| ≤ 0.66 after reduction.
_AP = (
    -8.750608600031904122785e-1,
    -1.615753718733365076637e1,
    -7.500855792314704667340e1,
    -1.228866684490136173410e2,
    -6.485021904942025371773e1,
)
_AQ = (
    2.485846490142306297962e1,
    1.650270098316988542046e2,
    4.328810604912902668951e2,
    4.853903996359136964868e2,
    1.945506571482613964425e2,
)
_MOREBITS = 6.123233995736765886130e-17
_T3P8 = 2.41421356237309504880


def _atan_ratio(y, x):
    """atan2(y, x) for y, x ≥ 0 without a library call (Cephes' reduction and rational
    form, to ~1 ulp), so that the loop around it vectorises; 0 for y = x = 0."""
    big = y > _T3P8 * x
    small = y <= 0.66 * x
    num = -x if big else (y if small else y - x)
    den = y if big else (x if small else y + x)
    den = den if den > 0.0 else 1.0
    r = num / den
    z = r * r
    pz = (((_AP[0] * z + _AP[1]) * z + _AP[2]) * z + _AP[3]) * z + _AP[4]
    qz = ((((z + _AQ[0]) * z + _AQ[1]) * z + _AQ[2]) * z + _AQ[3]) * z + _AQ[4]
    a = r * (z * pz / qz) + r
    off = np.pi / 2 + _MOREBITS if big else (0.0 if small else np.pi / 4 + 0.5 * _MOREBITS)
    return off + a


def _base_block(p, vx, vy, wz, b, n, kin, P, bits, guess):
    """Normalise the block's kinematics (rows of ``kin``: v_x, v_y, u over
    max(|v_x|, |v_y|, |u|); every resultant is of degree 0) and its P."""
    R = p[0]
    k5, k6 = p[3], p[4]
    q00, q01, q11 = p[5], p[6], p[7]
    s00, s01, s11 = p[8], p[9], p[10]
    for j in range(n):
        x = vx[b + j]
        y = vy[b + j]
        u = wz[b + j] * R
        # 1/s without a branch (a mispredicted branch costs more than the arithmetic
        # here): s = 0 means all three are 0, and they stay 0 whatever k is
        k = 1.0 / max(abs(x), abs(y), abs(u), _NORMAL)
        x *= k
        y *= k
        u *= k
        kin[0, j] = x
        kin[1, j] = y
        kin[2, j] = u
        u2 = u * u
        v2 = x * x + y * y
        qv = x * (q00 * x + q01 * y) + y * (q01 * x + q11 * y)
        sv = x * (s00 * x + s01 * y) + y * (s01 * x + s11 * y)
        P[j] = v2 * v2 * v2 + 3.0 * u2 * v2 * qv + 3.0 * k5 * u2 * u2 * sv + k6 * u2 * u2 * u2
    for j in range(n):  # first guess of P^(-1/6) from the bits (P > 0 normal; others fixed below)
        guess[j] = _MAGIC - bits[j] // 6


def _inverse(P, y, n):
    """y ← P^(−5/6) (0 where P ≤ 0), from the guess of P^(−1/6) in y, by Newton."""
    for j in range(n):
        g = y[j]
        q = P[j]
        for _ in range(_NEWTON):
            g2 = g * g
            g = g * (7.0 - q * g2 * g2 * g2) * (1.0 / 6.0)
        g2 = g * g
        y[j] = g2 * g2 * g if q >= _TINY else 0.0
    for j in range(n):
        if 0.0 < P[j] < _TINY:
            y[j] = 1.0 / P[j] ** (5.0 / 6.0)


def _forces_block(p, kin, inv, n, res, sph):
    """The base resultants into ``res`` and the sphere coordinates into ``sph``: t,
    cos θ, sin θ, sgn ω_z, c = cos(πt/2), sn = sin(πt/2).

    Reads and writes go to different arrays: LLVM checks at run time that the
    arrays a vectorised loop reads do not overlap those it writes, and counts rows
    of one array as one range, so writing some rows of an array while reading
    others would always send the block down the scalar loop."""
    R, F0 = p[0], p[1]
    k5, k6 = p[3], p[4]
    q00, q01, q11 = p[5], p[6], p[7]
    s00, s01, s11 = p[8], p[9], p[10]
    gx, gy, xx, xy = p[11], p[12], p[13], p[14]
    for j in range(n):
        vx = kin[0, j]
        vy = kin[1, j]
        u = kin[2, j]
        iv = inv[j]
        u2 = u * u
        v2 = vx * vx + vy * vy
        Qvx = q00 * vx + q01 * vy
        Qvy = q01 * vx + q11 * vy
        Svx = s00 * vx + s01 * vy
        Svy = s01 * vx + s11 * vy
        qv = vx * Qvx + vy * Qvy
        sv = vx * Svx + vy * Svy
        cv = v2 * v2 + u2 * qv
        cq = u2 * v2
        cs = k5 * u2 * u2
        dvx = (cv * vx + cq * Qvx + cs * Svx) * iv
        dvy = (cv * vy + cq * Qvy + cs * Svy) * iv
        du = (u * v2 * qv + 2.0 * k5 * u * u2 * sv + k6 * u * u2 * u2) * iv
        jx = -vy
        jy = vx
        a = u2 + v2  # ≥ 1 after normalisation, 0 only at rest (then every term is 0)
        ia = 1.0 / max(a, 0.5)
        au = abs(u)
        au3 = au * au * au
        gj = gx * jx + gy * jy
        w1 = u * au3 * ia * ia
        dw1_du = (4.0 * au3 - 4.0 * u * au3 * u * ia) * ia * ia
        dw1_dv2 = -2.0 * u * au3 * ia * ia * ia
        dvx += gy * w1 + gj * dw1_dv2 * 2.0 * vx
        dvy += -gx * w1 + gj * dw1_dv2 * 2.0 * vy
        du += gj * dw1_du
        xj = xx * jx + xy * jy
        ia15 = ia * np.sqrt(ia)
        w2 = u * v2 * ia15
        dw2_du = v2 * ia15 - 3.0 * u2 * v2 * ia15 * ia
        dw2_dv2 = u * ia15 - 1.5 * u * v2 * ia15 * ia
        dvx -= xy * w2 + xj * dw2_dv2 * 2.0 * vx
        dvy -= -xx * w2 + xj * dw2_dv2 * 2.0 * vy
        du -= xj * dw2_du
        res[0, j] = -F0 * dvx
        res[1, j] = -F0 * dvy
        res[2, j] = -F0 * R * du
        # sphere coordinates
        # sphere coordinates, branch-free: selects between values computed anyway
        v = np.sqrt(v2)
        live = a > 0.0
        sgn = (1.0 if u > 0.0 else 0.0) - (1.0 if u < 0.0 else 0.0)
        irho = np.sqrt(ia)
        iv1 = 1.0 / max(v, _NORMAL)
        sph[0, j] = (2.0 / np.pi) * _atan_ratio(v, au)
        cos1 = -vy * sgn * iv1
        sph[1, j] = cos1 if v > 0.0 else 1.0
        sph[2, j] = vx * sgn * iv1
        sph[3, j] = sgn
        c = au * irho
        sph[4, j] = c if live else 1.0
        sph[5, j] = v * irho


def _sums_block(C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk):
    """acc[0–2]: Σ C B T, Σ C B dT/dt, Σ C dB/dθ T (`fepost.friction.basis.sums`) at the
    block's points (t, cos θ, sin θ); ck, sk, pk, dpk are scratch (cos kθ, sin kθ, the
    partial sums), separate arrays (see `_forces_block`).

    ``Cd`` holds the coefficients of the t-derivative in the same basis (so that
    Σ C B dT/dt = Σ Cd B T); both have a multiple of four columns (zero-padded by
    `coefficients`, ≥ 4). Each loop writes one array and reads few: LLVM vectorises
    a loop only when it can check every written array against every other one it
    touches, and gives up beyond a handful of checks.
    """
    L = C.shape[1]
    s0, st, sth = acc[0], acc[1], acc[2]
    for j in range(n):
        T[0, j] = 1.0
    for j in range(n):
        T[1, j] = 2.0 * t[j] - 1.0
    # the recurrence runs on two rows of their own (ck, sk hold T_{m−1}, T_{m−2}
    # until the harmonics need them): reading rows of T while writing another
    # would fail the overlap check
    for j in range(n):
        ck[j] = 2.0 * t[j] - 1.0
        sk[j] = 1.0
    for m in range(2, L):
        for j in range(n):
            new = (4.0 * t[j] - 2.0) * ck[j] - sk[j]
            T[m, j] = new
            sk[j] = ck[j]
            ck[j] = new
    s0[:n] = 0.0
    st[:n] = 0.0
    sth[:n] = 0.0
    ck[:n] = 1.0
    sk[:n] = 0.0
    for row in range(C.shape[0]):
        if row % 2 == 1:  # next harmonic: cos kθ, sin kθ by angle addition
            for j in range(n):
                a = ck[j]
                ck[j] = a * c1[j] - sk[j] * s1[j]
                sk[j] = sk[j] * c1[j] + a * s1[j]
        _combine(C, row, T, pk, n)
        _combine(Cd, row, T, dpk, n)
        if row == 0:
            _axpy(s0, 1.0, ck, pk, n)
            _axpy(st, 1.0, ck, dpk, n)
        elif row % 2 == 1:  # cos kθ; d/dθ = −k sin kθ
            k = float((row + 1) // 2)
            _axpy(s0, 1.0, ck, pk, n)
            _axpy(st, 1.0, ck, dpk, n)
            _axpy(sth, -k, sk, pk, n)
        else:  # sin kθ; d/dθ = k cos kθ
            k = float(row // 2)
            _axpy(s0, 1.0, sk, pk, n)
            _axpy(st, 1.0, sk, dpk, n)
            _axpy(sth, k, ck, pk, n)


def _combine(C, row, T, out, n):
    """out = Σ_l C[row, l] T[l] over the block, four terms a pass."""
    a0, a1, a2, a3 = C[row, 0], C[row, 1], C[row, 2], C[row, 3]
    for j in range(n):
        out[j] = a0 * T[0, j] + a1 * T[1, j] + a2 * T[2, j] + a3 * T[3, j]
    for q in range(4, C.shape[1], 4):
        a0, a1, a2, a3 = C[row, q], C[row, q + 1], C[row, q + 2], C[row, q + 3]
        for j in range(n):
            out[j] += a0 * T[q, j] + a1 * T[q + 1, j] + a2 * T[q + 2, j] + a3 * T[q + 3, j]


def _axpy(y, k, b, p, n):
    """y += k b p over the block."""
    for j in range(n):
        y[j] += k * b[j] * p[j]


def _sums(shape, C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk):
    """`_sums_block`, or the same sums unrolled for C's shape (`_unrolled_source`): numba
    picks by the type of ``shape`` (`fepost.friction.kernelpack.KernelCoefficients.shape`)
    when it compiles `_loop` (`_sums_typed`); plain Python calls take the general loops."""
    _sums_block(C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk)


def _sums_general(shape, C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk):
    """`_sums` for blocks beyond `UNROLL_MAX` numbers: the general loops."""
    _sums_block(C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk)


def _sums_typed(shape, C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk):
    """numba's implementation of `_sums` for the types given (an overload, `prepare`)."""
    rows, cols = len(shape[0]), len(shape[1])
    if not rows:
        return _sums_general
    namespace: dict = {}
    exec(_unrolled_source(rows, cols), namespace)  # noqa: S102 - source of our own, numbers only
    return namespace["_sums_unrolled"]


def _unrolled_source(rows: int, cols: int) -> str:
    """Python source of `_sums_block` for a C of ``rows`` × ``cols``: one loop over the
    block whose body holds every row and column, so that the Chebyshev values, the
    harmonics and the three partial sums stay in registers (the general loops pass
    them through memory row by row, about twice the time). The same terms in the same
    order; only the grouping of a row's terms (the general loops add them four at a
    time) changes the rounding."""
    lines = ["def _sums_unrolled(shape, C, Cd, t, c1, s1, n, T, acc, ck, sk, pk, dpk):"]
    lines += [
        f"    c{r}_{m} = C[{r}, {m}]\n    d{r}_{m} = Cd[{r}, {m}]" for r in range(rows) for m in range(cols)
    ]
    body = ["x = 2.0 * t[j] - 1.0", "x2 = 4.0 * t[j] - 2.0", "T0 = 1.0", "T1 = x"]
    body += [f"T{m} = x2 * T{m - 1} - T{m - 2}" for m in range(2, cols)]
    body += ["cj = c1[j]", "sj = s1[j]", "ck1 = 1.0", "sk1 = 0.0"]
    for r in range(rows):
        body.append("p = " + " + ".join(f"c{r}_{m} * T{m}" for m in range(cols)))
        body.append("dp = " + " + ".join(f"d{r}_{m} * T{m}" for m in range(cols)))
        if r == 0:
            body += ["s0 = ck1 * p", "st = ck1 * dp", "sth = 0.0"]
        elif r % 2 == 1:  # next harmonic: cos kθ (d/dθ = −k sin kθ)
            k = float((r + 1) // 2)
            body += ["a = ck1", "ck1 = a * cj - sk1 * sj", "sk1 = sk1 * cj + a * sj"]
            body += ["s0 += ck1 * p", "st += ck1 * dp", f"sth += {-k!r} * sk1 * p"]
        else:  # sin kθ (d/dθ = k cos kθ)
            body += ["s0 += sk1 * p", "st += sk1 * dp", f"sth += {float(r // 2)!r} * ck1 * p"]
    body += ["acc[0, j] = s0", "acc[1, j] = st", "acc[2, j] = sth"]
    lines.append("    for j in range(n):")
    lines += [f"        {line}" for line in body]
    return "\n".join(lines) + "\n"


def _correction_block(p, shape, C, Cd, sph, n, T, sums, ck, sk, pk, dpk, cor):
    """The correction's resultants into ``cor`` (module docstring of the model)."""
    R, F0 = p[0], p[1]
    _sums(shape, C, Cd, sph[0], sph[1], sph[2], n, T, sums, ck, sk, pk, dpk)
    for j in range(n):
        t = sph[0, j]
        cos1 = sph[1, j]
        sin1 = sph[2, j]
        sgn = sph[3, j]
        c = sph[4, j]
        sn = sph[5, j]
        s0 = sums[0, j]
        om = 1.0 - t
        w = t * t * t * om * om
        dw = 3.0 * t * t * om * om - 2.0 * t * t * t * om
        Ut = dw * s0 + w * sums[1, j]
        Ur = (2.0 / np.pi) * c * c * Ut
        rUr = (2.0 / np.pi) * c * sn * Ut
        Uth_r = w * sums[2, j] * c / (sn if sn > 0.0 else 1.0)
        cor[0, j] = sgn * F0 * (-Ur * sin1 - Uth_r * cos1)
        cor[1, j] = sgn * F0 * (Ur * cos1 - Uth_r * sin1)
        cor[2, j] = sgn * F0 * R * (rUr - w * s0)


def _lateral_block(p, Cg, corr_g, kin, sph, n, T, sums, ck, sk, pk, dpk, lat):
    """G = ∬ x τ_y dA of the isotropic law into ``lat`` (`GeneralisedModel.lateral_moment`)."""
    R, F0 = p[0], p[1]
    q00, q01 = p[5], p[6]
    if corr_g:
        _sums_block(Cg, Cg, sph[0], sph[1], sph[2], n, T, sums, ck, sk, pk, dpk)
    for j in range(n):
        vx = kin[0, j]
        vy = kin[1, j]
        u = kin[2, j]
        v2 = vx * vx + vy * vy
        rho2 = max(u * u + v2, 0.5)  # ≥ 1 after normalisation, 0 only at rest (G = 0)
        irho3 = 1.0 / (rho2 * np.sqrt(rho2))
        jx = -vy
        jy = vx
        qjx = q00 * jx + q01 * jy
        G = (
            p[16] * u * u * u
            + (p[17] * jx + p[18] * jy) * u * u
            - p[13] * vy * v2
            - u * (q00 * v2 - jx * qjx)
        ) * irho3
        lat[j] = F0 * R * G
    if corr_g:
        for j in range(n):
            t = sph[0, j]
            om = 1.0 - t
            lat[j] += sph[3, j] * F0 * R * (t * t * om * om) * sums[0, j]


def _store_block(p, corr, res, cor, lat, n, fx, fy, mz, b):
    """F_x, F_y, M_z of the block: base + correction; α ≠ 1: F_y ← α F_y, M_z += (α − 1) G."""
    alpha = p[15]
    if corr:
        for j in range(n):
            fx[b + j] = res[0, j] + cor[0, j]
        for j in range(n):
            fy[b + j] = res[1, j] + cor[1, j]
        for j in range(n):
            mz[b + j] = res[2, j] + cor[2, j]
    else:
        for j in range(n):
            fx[b + j] = res[0, j]
        for j in range(n):
            fy[b + j] = res[1, j]
        for j in range(n):
            mz[b + j] = res[2, j]
    if alpha != 1.0:
        for j in range(n):
            fy[b + j] = alpha * fy[b + j]
        for j in range(n):
            mz[b + j] = mz[b + j] + (alpha - 1.0) * lat[j]


def _loop(p, shape, C, Cd, Cg, corr, corr_g, vx, vy, wz, fx, fy, mz):
    n = vx.shape[0]
    L = max(C.shape[1], Cg.shape[1])
    kin = np.empty((3, BLOCK))
    sph = np.empty((6, BLOCK))
    res = np.empty((3, BLOCK))
    cor = np.empty((3, BLOCK))
    lat = np.empty(BLOCK)
    T = np.empty((L, BLOCK))
    sums = np.empty((3, BLOCK))
    ck = np.empty(BLOCK)
    sk = np.empty(BLOCK)
    pk = np.empty(BLOCK)
    dpk = np.empty(BLOCK)
    P = np.empty(BLOCK)
    y = np.empty(BLOCK)
    bits = P.view(np.int64)
    guess = y.view(np.int64)
    for b in range(0, n, BLOCK):
        m = min(BLOCK, n - b)
        _base_block(p, vx, vy, wz, b, m, kin, P, bits, guess)
        _inverse(P, y, m)
        _forces_block(p, kin, y, m, res, sph)
        if corr:
            _correction_block(p, shape, C, Cd, sph, m, T, sums, ck, sk, pk, dpk, cor)
        if p[15] != 1.0:
            _lateral_block(p, Cg, corr_g, kin, sph, m, T, sums, ck, sk, pk, dpk, lat)
        _store_block(p, corr, res, cor, lat, m, fx, fy, mz, b)


_COMPILED = False
_FUNCTIONS = (
    "_atan_ratio",
    "_base_block",
    "_inverse",
    "_forces_block",
    "_combine",
    "_axpy",
    "_sums_block",
    "_correction_block",
    "_lateral_block",
    "_store_block",
    "_loop",
)


def prepare() -> None:
    """Compile the kernel with numba (once per process; from numba's disk cache after
    the first time). `evaluate` calls it; without numba it raises ImportError."""
    # contraction into FMAs only (no reassociation, no approximate functions): every
    # loop over a block is written so that LLVM vectorises it, and LLVM contracts the
    # vector body and its scalar remainder alike, so a point gets the same bits wherever
    # it sits in the array (tests/test_model_kernel.py); about a fifth faster than
    # without contraction
    compiled.compile_functions(globals(), _FUNCTIONS, fastmath={"contract"}, overloads={"_sums": _sums_typed})


def evaluate(coef: KernelCoefficients, vx: np.ndarray, vy: np.ndarray, wz: np.ndarray, out=None):
    """(F_x, F_y, M_z) at flat float64 arrays of equal length, by the compiled loop; into
    ``out`` (three such arrays, checked by the caller) when given. Each block's inputs are
    read before its outputs are written, so ``out`` may be the inputs themselves."""
    prepare()
    n = vx.shape[0]
    fx, fy, mz = (np.empty(n), np.empty(n), np.empty(n)) if out is None else out
    corr = bool(np.any(coef.C))  # as the numpy path: no correction, no sphere sums
    corr_g = bool(np.any(coef.Cg))
    _loop(coef.scalars, coef.shape, coef.C, coef.Cd, coef.Cg, corr, corr_g, vx, vy, wz, fx, fy, mz)
    return fx, fy, mz
