"""Passes over the faces of a million-node mesh in chunks, on two threads when it pays.

numpy lets go of the GIL inside each call on a chunk's arrays, so a second thread
that takes the second half of the chunks nearly halves a pass that is bound by
many small calls (`map_chunks`: `fepost.locate`, the plane fit). The results come
back in chunk order, whatever thread computed them: a pass gives the same
numbers, bit for bit, on one thread or two.

A pass that first gathers each chunk's corner values from the nodes and then does
many small computations on them (`fepost.facesums.face_sums`) is split by kind
instead (`map_gathered`): one thread gathers block after block (few, long numpy
calls, latency-bound random reads), the caller's thread computes on the block
gathered before. Two threads each doing both wait for each other's hold of the
GIL between their many short calls: on the 1.08 M-node surface map the face pass
took 122 ms that way and takes 93 ms split by kind.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

from ._threads import default_threads

T = TypeVar("T")
G = TypeVar("G")
#: Blocks `map_gathered` gathers ahead of the computation (bounds the memory they hold).
AHEAD = 2
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


def map_gathered(
    gather: Callable[[slice], G], work: Callable[[G, slice], T], blocks: Sequence[slice], chunks: int
) -> list[T]:
    """``[work(gather(b), b) for b in blocks]``, the gathers on a second thread, at most `AHEAD`
    blocks ahead of ``work`` on the caller's thread, when more than one thread is allowed and
    the blocks hold at least `SPLIT` chunks (``chunks``: how many they hold). An error of
    either is raised in the caller (the other thread stopped first)."""
    if len(blocks) < 2 or chunks < SPLIT or default_threads() < 2:
        return [work(gather(b), b) for b in blocks]
    ready: queue.Queue = queue.Queue(maxsize=AHEAD)
    stop = threading.Event()

    def produce() -> None:
        try:
            for b in blocks:
                if stop.is_set():
                    return
                ready.put((gather(b), None))
        except BaseException as exc:  # handed to the caller
            ready.put((None, exc))

    side = threading.Thread(target=produce, name="fepost-gather", daemon=True)
    side.start()
    out: list[T] = []
    try:
        for b in blocks:
            got, exc = ready.get()
            if exc is not None:
                raise exc
            out.append(work(got, b))
    finally:
        stop.set()
        while side.is_alive():  # a gather blocked on a full queue: make room until it ends
            try:
                ready.get(timeout=0.01)
            except queue.Empty:
                pass
        side.join()
    return out
