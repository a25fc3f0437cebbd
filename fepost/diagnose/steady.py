"""Steadiness of a recording's commanded kinematics: ranges over time windows and drift splits.

Both rules of `fepost.diagnose.holds` compare the range max − min of each kinematic
channel c (vx, vy, wz) over a stretch of samples with its tolerance

    max − min ≤ abs_c + rel · max |c|.

* `steady_flags` — over a **trailing window in seconds**: sample i is steady when
  the samples of its own segment with t_i − t_j < ``window`` (the window ending at i)
  are within the tolerance and the segment began at least ``window`` before t_i.
  Counted in time, not samples, a ramp of a given slope is steady or not at every
  logging rate alike.
* `drift_pieces` — over a **whole hold**: a stretch whose kinematics drift by more
  than the tolerance (a slow ramp passes any short window) is cut into the longest
  stretch within the tolerance and, recursively, the same of what lies before and
  after it. A piece never averages across two set points; on a slow ramp the pieces
  are as long as the ramp takes to move by one tolerance.

The ranges come from a sparse table (max and min over 2^k samples, level by level):
each range query is the max/min of two overlapping blocks, O(n log w) for n samples
and windows of w samples, vectorised by numpy, however high the logging rate.
"""

from __future__ import annotations

import numpy as np

#: Relative slack of the time comparisons (samples at exactly one window apart).
SLACK = 1e-9
#: A drifting hold is searched for its pieces at a resolution of at most this many blocks.
DRIFT_BLOCKS = 4096


def range_max_min(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(max, min) of ``x[lo[i] : hi[i] + 1]`` along axis 0 for every i (``lo <= hi``; sparse table)."""
    lo, hi = np.asarray(lo, np.int64), np.asarray(hi, np.int64)
    shape = (lo.size, *x.shape[1:])
    mx, mn = np.empty(shape, x.dtype), np.empty(shape, x.dtype)
    if lo.size == 0:
        return mx, mn
    level = np.zeros(lo.size, np.int64)
    length = hi - lo + 1
    while np.any(length >= (2 << level)):  # floor(log2(length)) without rounding issues
        level += length >= (2 << level)
    top, cmax, cmin = int(level.max()), x, x
    for k in range(top + 1):
        sel = np.flatnonzero(level == k)
        if sel.size:
            a, b = lo[sel], hi[sel] - (1 << k) + 1
            mx[sel] = np.maximum(cmax[a], cmax[b])
            mn[sel] = np.minimum(cmin[a], cmin[b])
        if k < top:
            step = 1 << k
            cmax = np.maximum(cmax[:-step], cmax[step:])
            cmin = np.minimum(cmin[:-step], cmin[step:])
    return mx, mn


def within(mx: np.ndarray, mn: np.ndarray, tol_abs: np.ndarray, rel: float) -> np.ndarray:
    """Whether every channel (last axis) spans at most ``tol_abs + rel · max|c|``."""
    top = np.maximum(np.abs(mx), np.abs(mn))
    return np.all(mx - mn <= tol_abs + rel * top, axis=-1)


def steady_flags(t, kin, seg_t0, lead, window, tol_abs, rel) -> np.ndarray:
    """Steady flags of the samples ``lead:`` (module docstring).

    ``t`` (n,): increasing times (s); ``kin`` (n, 3): the kinematics; ``seg_t0`` (n,):
    the time at which each sample's segment began; the first ``lead`` samples are the
    carried-over tail of the previous chunk (windows reach into it, no flags for it).
    """
    i = np.arange(lead, t.size)
    span = window * (1.0 - SLACK)
    covered = t[i] - seg_t0[i] >= span
    i = i[covered]
    j0 = np.searchsorted(t, t[i] - span, side="right")
    mx, mn = range_max_min(kin, j0, i)
    flags = np.zeros(t.size - lead, bool)
    flags[i - lead] = within(mx, mn, tol_abs, rel)
    return flags


def _furthest(bmax: np.ndarray, bmin: np.ndarray, tol_abs, rel) -> np.ndarray:
    """For each block s, the last block e such that blocks s..e are within tolerance (s − 1 if none)."""
    nb = bmax.shape[0]
    s = np.arange(nb)
    lo, hi = s - 1, np.full(nb, nb - 1)
    while np.any(lo < hi):
        act = np.flatnonzero(lo < hi)
        mid = (lo[act] + hi[act] + 1) // 2
        mx, mn = range_max_min(np.stack([bmax, bmin], axis=1), s[act], mid)
        ok = within(mx[:, 0], mn[:, 1], tol_abs, rel)
        lo[act] = np.where(ok, mid, lo[act])
        hi[act] = np.where(ok, hi[act], mid - 1)
    return lo


def drift_pieces(kin: np.ndarray, tol_abs, rel: float, min_len: int) -> list[tuple[int, int]]:
    """[a, b) pieces of the hold ``kin`` (n, 3) each within tolerance (module docstring), in order.

    One piece, the whole hold, when it does not drift. Pieces shorter than
    ``min_len`` samples are dropped. A drifting hold is searched at a resolution of
    ``ceil(n / DRIFT_BLOCKS)`` samples (ranges of whole blocks: a piece may lose up to
    a block at each end, never gain a sample outside the tolerance).
    """
    n = kin.shape[0]
    if n == 0:
        return []
    if within(kin.max(axis=0), kin.min(axis=0), tol_abs, rel):
        return [(0, n)] if n >= min_len else []
    size = -(-n // DRIFT_BLOCKS)
    starts = np.arange(0, n, size)
    bmax, bmin = np.maximum.reduceat(kin, starts, axis=0), np.minimum.reduceat(kin, starts, axis=0)
    furthest = _furthest(bmax, bmin, tol_abs, rel)
    pieces, todo = [], [(0, starts.size - 1)]
    min_blocks = max(1, min_len // size)
    while todo:
        a, b = todo.pop()
        if b - a + 1 < min_blocks:
            continue
        reach = np.minimum(furthest[a : b + 1], b) - np.arange(a, b + 1)
        s = a + int(np.argmax(reach))
        e = s + int(reach[s - a])
        if e < s:  # not even one block is within tolerance
            todo += [(a, s - 1), (s + 1, b)]
            continue
        lo, hi = s * size, min((e + 1) * size, n)
        if hi - lo >= min_len:
            pieces.append((lo, hi))
        todo += [(a, s - 1), (e + 1, b)]
    return sorted(pieces)
