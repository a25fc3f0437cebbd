"""Dropouts and clock resets of a rig recording, found while it is read chunk by chunk.

* A **dropout** is a run of rows in which a channel the diagnosis reads (``time``,
  ``vx``, ``vy``, ``wz``, ``Fx``, ``Fy``, ``Mz``, and ``N``, ``roll`` when the file has
  them; not ``point``, whose empty values mark transitions) is not a finite number.
  Its rows are left out; the holds it falls in are cut there.
* A **clock reset** is a row whose time is not later than the time before it (a
  logger restart). It starts a new segment; no hold spans it.

Either ends a **segment**: the holds of `fepost.diagnose.holds` lie inside one
segment, and a segment's samples are steady only once a whole steady window of
them has passed. `GapTracker.scan` also gives the **run clock**: the time with each
reset's jump taken out (the clock runs on one typical sample interval after the
last time before the reset), so that it increases through the whole recording and
hold times, spans and the recording figure keep the recording's order. Without
resets the run clock is the time column itself.

With ``strict`` the first non-finite value or reset is an error instead, as
fepost had it before it read recordings with gaps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DataError, FepostWarning
from .recording import Chunk

#: The channels whose non-finite values make a dropout (those present in the file).
READ = ("time", "vx", "vy", "wz", "Fx", "Fy", "Mz", "N", "roll")


class RecordingWarning(FepostWarning):
    """A recording has dropouts or clock resets: their rows are left out, holds cut there."""


@dataclass(frozen=True)
class Dropout:
    """Rows ``first`` … ``last`` (0-based); ``time``: run clock at its ends; ``channels`` non-finite."""

    first: int
    last: int
    time: tuple[float, float]
    channels: tuple[str, ...]

    @property
    def rows(self) -> int:
        return self.last - self.first + 1

    def to_dict(self) -> dict:
        return {
            "rows": [self.first + 1, self.last + 1],
            "time": list(self.time),
            "channels": list(self.channels),
        }


@dataclass(frozen=True)
class Reset:
    """The clock went back at ``row`` (0-based): from ``before`` to ``after`` (s, as written).

    ``clock``: the run clock at that row.
    """

    row: int
    before: float
    after: float
    clock: float

    def to_dict(self) -> dict:
        return {
            "row": self.row + 1,
            "time_before": self.before,
            "time_after": self.after,
            "clock": self.clock,
        }


@dataclass(frozen=True)
class Scan:
    """Per row of a chunk: ``good`` (every channel finite), ``clock`` (run clock, NaN without a time),
    ``breaks`` (a good row that starts a new segment)."""

    good: np.ndarray
    clock: np.ndarray
    breaks: np.ndarray


class GapTracker:
    """Streaming state: the open dropout, the last time, the clock offset, what was found."""

    def __init__(self, source: str, strict: bool = False) -> None:
        self.source, self.strict = source, strict
        self.dropouts: list[Dropout] = []
        self.resets: list[Reset] = []
        self.bad_rows = 0
        self.segments = 0
        self.dt = float("nan")  # typical sample interval (median of the first chunk's steps)
        self._open: tuple[int, int, float, float, np.ndarray] | None = None
        self._last_t = self._last_clock = float("nan")
        self._offset = 0.0
        self._prev_bad = True  # the first good row starts a segment
        self._chans: list[str] = []

    @property
    def rate(self) -> float:
        """Samples per second (from the median sample interval)."""
        return 1.0 / self.dt if self.dt > 0 else float("nan")

    def scan(self, chunk: Chunk) -> Scan:
        chans = [c for c in READ if c in chunk.values]
        badm = np.column_stack([~np.isfinite(chunk.values[c]) for c in chans])
        bad: np.ndarray = np.any(badm, axis=1)
        if self.strict and bad.any():
            i = int(np.flatnonzero(bad)[0])
            ch = chans[int(np.argmax(badm[i]))]
            name = chunk.names.get(ch, ch)
            raise DataError(
                f"{self.source}: row {chunk.start + i + 1}, column {name}: not a finite number "
                "(--strict-recording)"
            )
        clock, reset = self._clock(chunk)
        good = ~bad
        prev_bad = np.concatenate([[self._prev_bad], bad[:-1]])
        breaks = good & (prev_bad | reset)
        self._prev_bad = bool(bad[-1])
        self.segments += int(np.count_nonzero(breaks))
        self.bad_rows += int(np.count_nonzero(bad))
        self._dropouts(chunk.start, bad, badm, clock, chans)
        return Scan(good, clock, breaks)

    def _clock(self, chunk: Chunk) -> tuple[np.ndarray, np.ndarray]:
        """The run clock of every row and whether a row is a reset (module docstring)."""
        t = chunk.values["time"]
        n = t.size
        idx = np.flatnonzero(np.isfinite(t))
        clock, reset = np.full(n, np.nan), np.zeros(n, bool)
        if idx.size == 0:
            return clock, reset
        tf = t[idx]
        prev = np.concatenate([[self._last_t], tf[:-1]])
        step = tf - prev
        back = step <= 0
        if np.isnan(self.dt):
            pos = step[step > 0]
            self.dt = float(np.median(pos)) if pos.size else 1.0
        if self.strict and back.any():
            k = int(np.flatnonzero(back)[0])
            name = chunk.names.get("time", "time")
            raise DataError(
                f"{self.source}: row {chunk.start + idx[k] + 1}, column {name}: time must increase "
                "(--strict-recording)"
            )
        jump = np.where(back, prev - tf + self.dt, 0.0)
        offset = self._offset + np.cumsum(jump)
        clock[idx] = tf + offset
        reset[idx[back]] = True
        for j in np.flatnonzero(back).tolist():
            self.resets.append(
                Reset(chunk.start + int(idx[j]), float(prev[j]), float(tf[j]), float(clock[idx[j]]))
            )
        self._offset, self._last_t = float(offset[-1]), float(tf[-1])
        return clock, reset

    def _dropouts(self, start: int, bad: np.ndarray, badm: np.ndarray, clock: np.ndarray, chans) -> None:
        """Runs of bad rows, merged across chunks; their time span: from the last finite time at or
        before the first row to the first finite time at or after the last row (run clock)."""
        fin = np.isfinite(clock)
        idx = np.flatnonzero(fin)
        self._chans = chans
        # the last finite clock at or before each row (the previous chunk's last one carried in front)
        carried = np.concatenate([[self._last_clock], clock])
        where = np.where(np.concatenate([[True], fin]), np.arange(clock.size + 1), 0)
        last_finite = carried[np.maximum.accumulate(where)][1:]
        edges = np.flatnonzero(np.diff(np.concatenate([[False], bad, [False]]).astype(np.int8)))
        firsts, lasts = edges[::2], edges[1::2] - 1
        if idx.size:
            self._last_clock = float(clock[idx[-1]])
        if self._open is not None and not bad[0]:  # the previous chunk's dropout ended with it
            first, last, t0, t1, mask = self._open
            self._open = (first, last, t0, float(clock[0]) if np.isnan(t1) else t1, mask)
            self._close()
        for a, b in zip(firsts, lasts, strict=True):
            chans_bad = badm[a : b + 1].any(axis=0)
            if a == 0 and self._open is not None:
                first, _, t0, _, mask = self._open
                self._open = None
            else:
                first, t0, mask = start + int(a), float(last_finite[a]), np.zeros(len(chans), bool)
            k = np.searchsorted(idx, b)  # the first finite time at or after the run's last row
            t1 = float(clock[idx[k]]) if k < idx.size else np.nan  # NaN: in a later chunk
            self._open = (first, start + int(b), t0, t1, mask | chans_bad)
            if b + 1 < bad.size:
                self._close()
        if not bad[-1]:
            self._close()

    def _close(self) -> None:
        if self._open is None:
            return
        first, last, t0, t1, mask = self._open
        self._open = None
        t1 = self._last_clock if np.isnan(t1) else t1  # a dropout to the end: the last time known
        t0 = t1 if np.isnan(t0) else t0
        names = tuple(c for c, m in zip(self._chans, mask, strict=True) if m)
        self.dropouts.append(Dropout(first, last, (t0, t1), names))

    def finish(self) -> None:
        """Close a dropout that runs to the end of the recording."""
        self._close()
