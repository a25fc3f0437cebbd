"""Passes over the faces of a million-node mesh in chunks, on two threads when it pays.

numpy lets go of the GIL inside each call on a chunk's arrays, so a second thread
that takes the second half of the chunks nearly halves a pass that is bound by
many small calls (`fepost.facesums.face_sums`, `fepost.locate`). The results come
back in chunk order, whatever thread computed them: a pass gives the same
numbers, bit for bit, on one thread or two.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from ._threads import default_threads

T = TypeVar("T")
#: From this many chunks on, two threads share them (below, a thread costs more than it saves).
SPLIT = 16


def slices(n: int, size: int) -> list[slice]:
    """Consecutive slices of at most ``size`` items covering range(n)."""
    return [slice(i, min(i + size, n)) for i in range(0, n, size)]


def map_chunks(work: Callable[[slice], T], chunks: Sequence[slice]) -> list[T]:
    """``[work(c) for c in chunks]``, the second half on a second thread from `SPLIT`
    chunks on (when more than one thread is allowed: `fepost._threads.default_threads`)."""
    out: list = [None] * len(chunks)

    def run(first: int, stop: int) -> None:
        for i in range(first, stop):
            out[i] = work(chunks[i])

    half = len(chunks) // 2 if len(chunks) >= SPLIT and default_threads() > 1 else 0
    if half:
        with ThreadPoolExecutor(max_workers=1) as side:
            other = side.submit(run, half, len(chunks))
            run(0, half)
            other.result()
    else:
        run(0, len(chunks))
    return out
