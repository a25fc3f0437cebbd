"""The planar-push log, read as the logger wrote it: one push at a time, every line numbered.

The format (the rig's README, beside the logs) is whitespace-separated text::

    n_pushes
    then, for each push:
      x y z qw qx qy qz              the block's pose before the push (log length unit; unit quaternion)
      x y z qw qx qy qz              the block's pose after the push
      n_ft
      n_ft lines:    t fx fy         time (s), the finger's force in the sensor's frame (N, not zeroed)
      n_robot
      n_robot lines: t x y z qw qx qy qz   the finger's pose

`read_log` is a generator of `RawPush`: it holds one push in memory at a time and
checks each line as it reads it. Blank lines are skipped. Anything else that is not
what the format says at that place is a `DataError` of one line naming the file, the
push and the line: a line with the wrong count of numbers, a word that is not a finite
number, a sample count that is not a whole number (or runs past the file's end: a
truncated log), a quaternion whose norm is not 1 (beyond `QUATERNION_TOLERANCE`, the
logger's 3- to 6-digit rounding), sample times that go back, data after the last push,
an empty file. The quaternions are returned normalised.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._arrays import sealed
from ..errors import DataError, InputFileError

#: Largest |‖q‖ − 1| of a logged quaternion (the finger's is rounded to 3 digits: ‖q‖ ≈ 0.9996).
QUATERNION_TOLERANCE = 0.01
#: Most pushes and most samples per push accepted from a header (a count beyond is a damaged number).
MAX_PUSHES = 100_000
MAX_SAMPLES = 10_000_000


@dataclass(frozen=True)
class RawPush:
    """One push as logged (arrays read-only; lengths in the log's unit).

    Attributes
    ----------
    log : str
        The log file.
    index : int
        The push's number in the log, from 1.
    line : int
        The line of its first pose.
    before, after : numpy.ndarray
        The block's pose before and after the push: x, y, z, qw, qx, qy, qz (normalised).
    force : numpy.ndarray
        (n_ft, 3): t (s), fx, fy (N, sensor frame, not zeroed).
    finger : numpy.ndarray
        (n_robot, 8): t (s), x, y, z, qw, qx, qy, qz (normalised).
    force_line, finger_line : int
        The lines of the first force sample and of the first finger sample (0 when there is none).
    """

    log: str
    index: int
    line: int
    before: np.ndarray
    after: np.ndarray
    force: np.ndarray
    finger: np.ndarray
    force_line: int
    finger_line: int

    def where(self, row: int | None = None, *, finger: bool = False) -> str:
        """``"<log>: push <k>, line <n>"``: the push's first line, or that of a force (or finger) sample."""
        if row is None:
            line = self.line
        else:
            line = (self.finger_line if finger else self.force_line) + row
        return f"{self.log}: push {self.index}, line {line}"


class _Lines:
    """The log's non-blank lines with their numbers; one-line errors naming push and line."""

    def __init__(self, path: str, handle) -> None:
        self.path = path
        self._lines = enumerate(handle, 1)
        self.push = 0
        self.number = 0

    def where(self) -> str:
        push = f"push {self.push}, " if self.push else ""
        return f"{self.path}: {push}line {self.number}"

    def next(self) -> list[str] | None:
        """The next non-blank line's words, or None at the end of the file."""
        for number, text in self._lines:
            self.number = number
            words = text.split()
            if words:
                return words
        return None

    def need(self, what: str) -> list[str]:
        words = self.next()
        if words is None:
            push = f"in push {self.push} " if self.push else ""
            raise DataError(
                f"{self.path}: the log ends {push}after line {self.number}: expected {what} (truncated?)"
            )
        return words

    def numbers(self, what: str, count: int) -> list[float]:
        words = self.need(what)
        if len(words) != count:
            raise DataError(f"{self.where()}: expected {count} numbers ({what}), got {len(words)}")
        out = []
        for w in words:
            try:
                x = float(w)
            except ValueError:
                raise DataError(f"{self.where()}: {w[:40]!r} is not a number ({what})") from None
            if not math.isfinite(x):
                raise DataError(f"{self.where()}: {w[:40]!r} is not a finite number ({what})")
            out.append(x)
        return out

    def count(self, what: str, limit: int, words: list[str] | None = None) -> int:
        words = self.need(what) if words is None else words
        if len(words) != 1:
            raise DataError(f"{self.where()}: expected one whole number ({what}), got {len(words)} words")
        try:
            n = int(words[0])
        except ValueError:
            raise DataError(f"{self.where()}: {words[0][:40]!r} is not a whole number ({what})") from None
        if not 0 <= n <= limit:
            raise DataError(f"{self.where()}: {what} {n} is out of range (0 to {limit})")
        return n


def _unit_quaternion(lines: _Lines, q: list[float], what: str) -> list[float]:
    norm = math.sqrt(sum(c * c for c in q))
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        raise DataError(
            f"{lines.where()}: the quaternion of the {what} has norm {norm:.4g}, "
            "not 1 (an impossible rotation)"
        )
    return [c / norm for c in q]


def _pose(lines: _Lines, what: str) -> np.ndarray:
    v = lines.numbers(f"{what}: x y z qw qx qy qz", 7)
    return sealed(np.array(v[:3] + _unit_quaternion(lines, v[3:], what)))


def _samples(lines: _Lines, n: int, width: int, what: str, *, quaternion: bool) -> tuple[np.ndarray, int]:
    out = np.empty((n, width))
    first = 0
    previous = -math.inf
    for i in range(n):
        row = lines.numbers(what, width)
        first = first or lines.number
        if row[0] < previous:
            raise DataError(f"{lines.where()}: time {row[0]!r} goes back (previous sample {previous!r})")
        previous = row[0]
        if quaternion:
            row[4:] = _unit_quaternion(lines, row[4:], "finger's pose")
        out[i] = row
    return sealed(out), first


def _push(lines: _Lines, path: str, index: int) -> RawPush:
    lines.push = index
    before = _pose(lines, "block's pose before the push")
    line = lines.number
    after = _pose(lines, "block's pose after the push")
    n_ft = lines.count("the number of force samples, n_ft", MAX_SAMPLES)
    force, force_line = _samples(lines, n_ft, 3, "force sample: t fx fy", quaternion=False)
    n_robot = lines.count("the number of finger poses, n_robot", MAX_SAMPLES)
    finger, finger_line = _samples(lines, n_robot, 8, "finger pose: t x y z qw qx qy qz", quaternion=True)
    return RawPush(
        log=path,
        index=index,
        line=line,
        before=before,
        after=after,
        force=force,
        finger=finger,
        force_line=force_line,
        finger_line=finger_line,
    )


def read_log(path) -> Iterator[RawPush]:
    """The pushes of a planar-push log, one at a time (module docstring).

    Parameters
    ----------
    path : str or Path
        The log file.

    Yields
    ------
    RawPush

    Raises
    ------
    InputFileError
        The file is missing or unreadable.
    DataError
        The log is empty, damaged or truncated: one line naming the file, the push and the line.
    """
    p = Path(path)
    name = str(path)
    try:
        handle = p.open("r", encoding="utf-8", errors="strict")
    except FileNotFoundError:
        raise InputFileError(f"{name}: push log not found") from None
    except OSError as exc:
        raise InputFileError(f"{name}: cannot read the push log ({exc.strerror or exc})") from None
    with handle:
        lines = _Lines(name, handle)
        try:
            first = lines.next()
            if first is None:
                raise DataError(f"{name}: the push log is empty")
            n = lines.count("the number of pushes", MAX_PUSHES, first)
            for k in range(1, n + 1):
                yield _push(lines, name, k)
            lines.push = 0
            if lines.next() is not None:
                raise DataError(
                    f"{lines.where()}: data after the last of the {n} pushes the first line announces"
                )
        except UnicodeDecodeError:
            raise DataError(f"{lines.where()}: not a text log (bytes that are not UTF-8)") from None
        except IsADirectoryError:
            raise InputFileError(f"{name}: is a folder, not a push log") from None
