"""Node sums of the exact friction integrals by whole-array numpy, over chunks of kinematic points.

For each kinematic point the exact integrals need seven sums over the nodes of
the map of the sliding direction ŵ times per-node weights (`Nodes`): ŵ is a
(points × nodes) field, so the points go in chunks of `CHUNK_ELEMENTS`, on
worker threads, each chunk's fields into working arrays that the thread's next
chunk reuses (`Scratch`), and so do later calls (`_SPARE`: at most one set of
4 × `CHUNK_ELEMENTS` doubles, 4 MB, per thread that ever worked at once). numpy
cannot be told to keep its temporaries: fresh arrays of a megabyte are mapped
from the system and zeroed by it on first touch, page by page, for every chunk;
on a virtual machine that took two thirds of the time (0.19 against 0.07 s for
1000 points on a 64 × 128 map).
"""

from __future__ import annotations

import queue
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .._blas import one_blas_thread
from .law import FrictionLaw
from .quadrature import PressureQuadrature

#: Elements (kinematic points × nodes) per chunk: 2^17 doubles = 1 MB per array, a
#: handful of arrays per worker thread that stay in cache (8 MB arrays ran 1.4x slower).
CHUNK_ELEMENTS = 1 << 17


@dataclass(frozen=True)
class Nodes:
    """Per-node matrices the chunks share (read-only).

    Columns multiplied by ŵ_x: g dA, g dA y | dA, dA x, dA y, dA xy, dA y²;
    by ŵ_y: g dA, g dA x | dA, dA x, dA y, dA x², dA xy. (g = μσ without the
    speed factor, Pa.) Columns after the bar serve the singularity subtraction.
    """

    x: np.ndarray
    y: np.ndarray
    bx: np.ndarray
    by: np.ndarray


def node_loads(quad: PressureQuadrature, law: FrictionLaw, sigma_ref: float) -> np.ndarray:
    """g dA at every node (N): μσ dA without μ's sliding-speed factor (``sigma_ref``: the
    law's reference pressure, Pa)."""
    return law.f * law.pressure_factor(quad.sigma, sigma_ref) * quad.sigma * quad.dA


def node_matrices(quad: PressureQuadrature, law: FrictionLaw, sigma_ref: float) -> Nodes:
    """`Nodes` of a map under a law (``sigma_ref``: the law's reference pressure, Pa)."""
    x, y, da = quad.x, quad.y, quad.dA
    g = node_loads(quad, law, sigma_ref)
    bx = np.column_stack([g, g * y, da, da * x, da * y, da * x * y, da * y * y])
    by = np.column_stack([g, g * x, da, da * x, da * y, da * x * x, da * x * y])
    return Nodes(x, y, bx, by)


class Scratch:
    """Four working arrays of ``elements`` doubles, lent as (points × nodes) views."""

    def __init__(self, elements: int) -> None:
        self.elements = elements
        self._flat = np.empty((4, elements))

    def arrays(self, points: int, nodes: int) -> tuple[np.ndarray, ...]:
        n = points * nodes
        return tuple(row[:n].reshape(points, nodes) for row in self._flat)


#: Working arrays between uses (one chunk at a time each); `_lend` takes from here.
_SPARE: queue.SimpleQueue[Scratch] = queue.SimpleQueue()


def _lend(elements: int) -> Scratch:
    """A spare `Scratch` of at least ``elements`` doubles (a smaller spare is dropped), or
    a new one of at least `CHUNK_ELEMENTS`, so that it can serve every later chunk."""
    while True:
        try:
            scratch = _SPARE.get_nowait()
        except queue.Empty:
            return Scratch(max(elements, CHUNK_ELEMENTS))
        if scratch.elements >= elements:
            return scratch


def directions(
    nodes: Nodes, law: FrictionLaw, vx, vy, wz, scratch: Scratch | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """ŵ_x, ŵ_y (points, nodes) of the sliding velocity at every node (0 at the centre of
    rotation), and |w| when μ depends on the sliding speed (else None); in the arrays
    of ``scratch`` when given (then valid until its next use)."""
    shape = (vx.size, nodes.x.size)
    wx, wy, speed, tmp = (np.empty(shape) for _ in range(4)) if scratch is None else scratch.arrays(*shape)
    np.multiply(wz[:, None], nodes.y[None, :], out=wx)
    np.subtract(vx[:, None], wx, out=wx)
    np.multiply(wz[:, None], nodes.x[None, :], out=wy)
    np.add(vy[:, None], wy, out=wy)
    # |w| as √(wx² + wy²), 6x cheaper than np.hypot (the bulk of a model build); hypot
    # only where the squares could underflow or overflow
    np.multiply(wx, wx, out=speed)
    np.multiply(wy, wy, out=tmp)
    speed += tmp
    np.sqrt(speed, out=speed)
    # two reductions decide whether any square could have under- or overflowed (rare)
    low = speed.min(initial=np.inf)
    if not (low > 1e-150 and speed.max(initial=0.0) < 1e150):
        odd = ~((speed > 1e-150) & (speed < 1e150))
        speed[odd] = np.hypot(wx[odd], wy[odd])
        low = speed.min(initial=np.inf)
    if law.depends_on_speed:
        tmp.fill(0.0)
        inv = np.divide(1.0, speed, out=tmp, where=speed > 0)
    else:  # |w| is not needed after this: 1/|w| in its place (0 at the centre of rotation)
        where = True if low > 0 else speed > 0  # 0 stays 0
        inv = np.divide(1.0, speed, out=speed, where=where)
    wx *= inv
    wy *= inv
    return wx, wy, (speed if law.depends_on_speed else None)


def chunk_sums(
    nodes: Nodes, law: FrictionLaw, vx, vy, wz, scratch: Scratch | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Sums over the nodes for one chunk of kinematic points: ŵ_x @ bx and ŵ_y @ by.

    Columns 0, 1 carry the speed factor of μ; the others (plain dA) do not.
    """
    wx, wy, speed = directions(nodes, law, vx, vy, wz, scratch)
    if speed is None:  # one product per component: ŵ read once
        return wx @ nodes.bx, wy @ nodes.by
    ncol = nodes.bx.shape[1]
    sx = np.empty((vx.size, ncol))
    sy = np.empty((vx.size, ncol))
    sx[:, 2:] = wx @ nodes.bx[:, 2:]
    sy[:, 2:] = wy @ nodes.by[:, 2:]
    factor = law.speed_factor(speed)
    wx *= factor
    wy *= factor
    sx[:, :2] = wx @ nodes.bx[:, :2]
    sy[:, :2] = wy @ nodes.by[:, :2]
    return sx, sy


def in_parallel(work, starts: range, workers: int) -> None:
    """``work(start)`` for each start, on up to ``workers`` threads."""
    if workers > 1 and len(starts) > 1:
        with ThreadPoolExecutor(max_workers=min(workers, len(starts))) as pool:
            list(pool.map(work, starts))
    else:
        for start in starts:
            work(start)


def numpy_sums(nodes: Nodes, law: FrictionLaw, vx, vy, wz, workers: int) -> tuple[np.ndarray, np.ndarray]:
    """The node sums (points, 7) over chunks of `CHUNK_ELEMENTS` on up to ``workers``
    threads, each working in a `Scratch` of its own (taken from a pool per chunk)."""
    k = vx.size
    sx = np.zeros((k, nodes.bx.shape[1]))
    sy = np.zeros((k, nodes.by.shape[1]))
    block = max(1, CHUNK_ELEMENTS // max(1, nodes.x.size))
    need = min(block, k) * nodes.x.size

    def work(start: int) -> None:
        sl = slice(start, start + block)
        scratch = _lend(need)
        try:
            sx[sl], sy[sl] = chunk_sums(nodes, law, vx[sl], vy[sl], wz[sl], scratch)
        finally:
            if scratch.elements <= CHUNK_ELEMENTS:  # a map's single row may need more: not kept
                _SPARE.put(scratch)

    # Parallel over chunks, one BLAS thread each: a multi-threaded BLAS under our
    # own thread pool oversubscribes the cores (5x slower on a busy 2-core machine).
    with one_blas_thread():
        in_parallel(work, range(0, k, block), workers)
    return sx, sy
