"""A one-line progress bar on stderr, shown only when stderr is a terminal.

Dask's own ``distributed.progress`` blocks the calling thread until every
future is done, but the sweep's client thread must save each row the moment it
arrives (that is what makes a killed sweep resumable), so the bar is this
small class, updated from that loop.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressBar:
    """``[#####.....]  12/40 rows  1 error  3.1 rows/s  ETA 9 s`` redrawn in place.

    Parameters
    ----------
    total : int
        Rows to compute in this run.
    done : int
        Rows already done (taken from an earlier run), counted in the bar.
    stream : text stream
        Where to draw (default ``sys.stderr``).
    enabled : bool or None
        None (default): only when ``stream`` is a terminal.
    """

    width = 30

    def __init__(self, total: int, done: int = 0, stream: TextIO | None = None, enabled: bool | None = None):
        self.stream = stream or sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.total = total + done
        self.done = done
        self.errors = 0
        self._start = time.monotonic()
        self._first = done
        self._last_draw = 0.0

    def update(self, ok: bool) -> None:
        self.done += 1
        self.errors += 0 if ok else 1
        now = time.monotonic()
        if now - self._last_draw >= 0.1 or self.done == self.total:
            self._last_draw = now
            self.draw(now)

    def draw(self, now: float | None = None) -> None:
        if not self.enabled:
            return
        now = time.monotonic() if now is None else now
        frac = self.done / self.total if self.total else 1.0
        filled = int(round(frac * self.width))
        computed = self.done - self._first
        rate = computed / max(now - self._start, 1e-9)
        eta = (self.total - self.done) / rate if rate > 0 else float("inf")
        parts = [f"[{'#' * filled}{'.' * (self.width - filled)}] {self.done}/{self.total} rows"]
        if self.errors:
            parts.append(f"{self.errors} error{'s' if self.errors > 1 else ''}")
        if computed:
            parts.append(f"{rate:.2g} rows/s")
            if eta != float("inf") and self.done < self.total:
                parts.append(f"ETA {eta:.0f} s")
        self.stream.write("\r" + "  ".join(parts) + "\033[K")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.draw()
            self.stream.write("\n")
            self.stream.flush()
