"""How many threads fepost's own parallel loops take: the CPU count, or ``FEPOST_THREADS``.

The exact friction integrals (`fepost.friction.exact`) and the passes over a large
mesh's faces (`fepost._chunks`) share their work among threads. Where the cores are
already taken by other processes — several fepost processes side by side, a test
session on every core, a batch system's slot of one core — more threads than cores only
make the operating system switch between them; ``FEPOST_THREADS=1`` keeps each process
on one thread. The results are the same, bit for bit, on any number of threads.
"""

from __future__ import annotations

import os

from .errors import ArgumentError

#: Environment variable: the number of threads (a positive integer; default: the CPU count).
THREADS_ENV = "FEPOST_THREADS"


def default_threads() -> int:
    """``FEPOST_THREADS`` when set (an `ArgumentError` naming it unless a positive integer),
    else the number of CPUs."""
    text = os.environ.get(THREADS_ENV, "").strip()
    if not text:
        return os.cpu_count() or 1
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise ArgumentError(f"{THREADS_ENV}={text!r}: must be a positive integer (the threads to use)")
    return n
