"""Measured rig data: the friction CSV (docs/diagnose.md), read and validated.

Columns (SI, header row, one row per test point; other columns are ignored):

=========== ==========================================================
``vx, vy``  sliding velocity of the patch origin against the road, m/s
``wz``      spin about the road normal, rad/s
``Fx, Fy``  friction force of the road on the tire, N (patch frame)
``Mz``      friction torque on the tire about the patch origin, N·m
``N``       optional normal load of the point, N (default: the simulation's)
``roll``    optional −1, 0 or +1 (default 0): which pressure map applies
``time``    optional: when the point was measured (s, or any increasing run
            index); the run-order test uses it besides the row order
=========== ==========================================================

Blank lines and lines whose first non-blank character is ``#`` are skipped
(before and after the header). The file is read by `fepost.csvtable`, as
the kinematics of ``fepost predict`` are: every problem is a one-line
`DataError` naming the file, the line and the column.

Limits: at most `MAX_ROWS` test points (a rig programme has hundreds;
diagnose takes 1–4 ms per point on a 2-core machine, 7 s for 5000 points, see
``benchmarks/bench_diagnose.py``) and
files of at most `MAX_BYTES`; both are refused before the rows are parsed,
so a table of a million rows is turned away in a second rather than diagnosed for
an hour. Long data with a ``time`` column are rig recordings, read in chunks and
reduced to their steady holds instead (`fepost.diagnose.inputs`). A cell longer
than `fepost.csvtable.MAX_CELL` characters is an error.

`check_plausible` compares the data with the simulation (units, dead
channels, a test programme in which nothing varies, rolling rows without a
rolling map) once f, N and R are known.
"""

from __future__ import annotations

import io
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._arrays import frozen
from ..csvtable import CsvFormat, CsvTable, parse_table, read_table
from ..errors import DataError, FepostWarning
from ..output import write_text_atomic

REQUIRED = ("vx", "vy", "wz", "Fx", "Fy", "Mz")
OPTIONAL = ("N", "roll", "time")
CHANNELS = ("Fx", "Fy", "Mz")

#: Fewest test points diagnose accepts: 5-fold cross-validation keeps ≥ 4 points
#: per held-out fold, and the richest candidate (f + 3 offsets + 3 channel
#: variances = 7 parameters) is then fitted to ≥ 48 observations (16 rows × 3).
MIN_ROWS = 20
#: Fewest distinct test points (vx, vy, wz, N, roll): the joint models of two
#: causes have up to 6 parameters of the mean.
MIN_DISTINCT = 6
#: Most test points diagnose accepts (see the module docstring).
MAX_ROWS = 5000
#: Largest measured-data file read (bytes): 5000 rows of a dozen numbers are ~1 MB.
MAX_BYTES = 64 * 1024 * 1024

#: |F|/(f·N) above this is not a friction force in N (kN given as N, or N·m in
#: a force column): error. The largest physical value is about 1 (α ≤ 2 allows 2).
UNITS_ERROR_RATIO = 4.0
#: max |F|/(f·N) below this over the rows that slide: forces look like kN: warning.
UNITS_SMALL_RATIO = 0.02


class UnitsWarning(FepostWarning):
    """Measured values are implausible in size for SI units."""


@dataclass(frozen=True)
class MeasuredData:
    """Rig test points (SI). Arrays have one entry per row; ``N`` is None when absent.

    ``lines`` are the 1-based line numbers of the rows in the source file;
    ``time`` (optional) when each point was measured.
    """

    vx: np.ndarray
    vy: np.ndarray
    wz: np.ndarray
    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray
    N: np.ndarray | None = None
    roll: np.ndarray | None = None
    lines: np.ndarray | None = None
    source: str = ""
    time: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = np.size(self.vx)
        for name in ("vx", "vy", "wz", "Fx", "Fy", "Mz", "N", "time"):
            value = getattr(self, name)
            if value is None:
                continue
            arr = frozen(np.ravel(value))
            if arr.size != n:
                raise DataError(f"{name} must have {n} entries like vx, got {arr.size}")
            if not np.all(np.isfinite(arr)):
                raise DataError(f"{name} must be finite, got a non-finite entry")
            object.__setattr__(self, name, arr)
        roll = np.zeros(n, int) if self.roll is None else np.ravel(self.roll)
        if roll.size != n:
            raise DataError(f"roll must have {n} entries like vx, got {roll.size}")
        if not np.all(np.isin(roll, (-1, 0, 1))):
            raise DataError(f"roll must be -1, 0 or +1, got {sorted(set(roll.tolist()) - {-1, 0, 1})}")
        object.__setattr__(self, "roll", frozen(roll, dtype=int))
        lines = np.arange(1, n + 1) if self.lines is None else np.ravel(self.lines)
        object.__setattr__(self, "lines", frozen(lines, dtype=int))
        if self.N is not None and np.any(self.N <= 0):
            i = int(np.flatnonzero(self.N <= 0)[0])
            raise DataError(
                f"{self._where(i)}, column N: load must be positive (N), got {float(self.N[i])!r}"
            )

    def _where(self, i: int) -> str:
        src = f"{self.source}: " if self.source else ""
        line = i + 1 if self.lines is None else int(self.lines[i])
        return f"{src}line {line}"

    def __len__(self) -> int:
        return int(self.vx.size)

    @property
    def forces(self) -> np.ndarray:
        """(n, 3) array of the measured Fx, Fy (N) and Mz (N·m)."""
        return np.column_stack([self.Fx, self.Fy, self.Mz])

    def loads(self, default: float) -> np.ndarray:
        """Per-row normal load (N): the ``N`` column, or ``default`` where absent."""
        return np.full(len(self), float(default)) if self.N is None else np.array(self.N)

    def to_dict(self) -> dict:
        d = {name: getattr(self, name).tolist() for name in ("vx", "vy", "wz", "Fx", "Fy", "Mz", "roll")}
        d["N"] = None if self.N is None else self.N.tolist()
        d["time"] = None if self.time is None else self.time.tolist()
        d["source"] = self.source
        return d


#: The measured-data CSV format (module docstring).
MEASURED = CsvFormat(
    required=REQUIRED,
    optional=OPTIONAL,
    what="measured data",
    kind="measured-data CSV file",
    max_rows=MAX_ROWS,
    too_many_rows=(
        f"diagnose takes at most {MAX_ROWS} test points "
        "(a rig programme has hundreds; average replicates or split the file)"
    ),
    max_bytes=MAX_BYTES,
    too_large=f"measured data (at most {MAX_BYTES // 2**20} MB and {MAX_ROWS} test points)",
)


def _measured(table: CsvTable) -> MeasuredData:
    roll = table.get("roll")
    if roll is not None:
        bad = ~np.isin(roll, (-1.0, 0.0, 1.0))
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise DataError(f"{table.where(i)}, column roll: must be -1, 0 or 1, got {roll[i]:g}")
    return MeasuredData(
        vx=table["vx"], vy=table["vy"], wz=table["wz"],
        Fx=table["Fx"], Fy=table["Fy"], Mz=table["Mz"],
        N=table.get("N"), roll=None if roll is None else roll.astype(int), lines=table.lines,
        source=table.source, time=table.get("time"),
    )  # fmt: skip


def parse_csv(text: str, source: str = "") -> MeasuredData:
    """Parse the CSV ``text`` (see the module docstring); ``source`` names it in messages."""
    return _measured(parse_table(text, MEASURED, source))


def read_measured(path) -> MeasuredData:
    """Read a measured-friction CSV file (see the module docstring)."""
    return _measured(read_table(path, MEASURED))


def write_csv(data: MeasuredData, path, comment: str = "") -> None:
    """Write ``data`` in the measured-data CSV format (``#`` comment lines first), atomically."""
    path = Path(path)
    out = io.StringIO()
    for line in comment.splitlines():
        out.write(f"# {line}\n")
    cols = ["vx", "vy", "wz", "Fx", "Fy", "Mz"] + (["N"] if data.N is not None else []) + ["roll"]
    cols += ["time"] if data.time is not None else []
    out.write(",".join(cols) + "\n")
    arrays = [getattr(data, c) for c in cols]
    for i in range(len(data)):
        out.write(
            ",".join(
                f"{a[i]:.10g}" if c != "roll" else str(int(a[i])) for c, a in zip(cols, arrays, strict=True)
            )
            + "\n"
        )
    write_text_atomic(path, out.getvalue())


def point_keys(data: MeasuredData) -> np.ndarray:
    """One integer label per row: rows with equal vx, vy, wz, N and roll share it."""
    cols = [data.vx, data.vy, data.wz, np.asarray(data.roll, float)]
    if data.N is not None:
        cols.append(data.N)
    table = np.column_stack(cols)
    _, labels = np.unique(table, axis=0, return_inverse=True)
    return np.asarray(labels).ravel()


def distinct_points(data: MeasuredData) -> int:
    """Number of distinct test points (vx, vy, wz, N, roll) in ``data``."""
    return int(np.unique(point_keys(data)).size)


def check_plausible(
    data: MeasuredData, *, friction: float, load: float, radius: float, has_rolling: bool
) -> None:
    """Reject or flag data that cannot be compared with the simulation.

    ``friction`` is the nominal f, ``load`` the simulation's N (N), ``radius``
    its R (m). Errors (`DataError`), in this order: fewer than
    `MIN_ROWS` rows; no row that slides or spins; fewer than
    `MIN_DISTINCT` distinct test points (nothing varies); a channel that is
    zero in every row (dead sensor); roll = ±1 rows when no rolling map was given
    (the static map would silently stand in for it); |Fx|, |Fy| above
    ``UNITS_ERROR_RATIO``·f·N or |Mz| above that times f·N·R in any row (wrong
    units); a channel with one value in every row (dead sensor). Warning
    (`UnitsWarning`): the largest force of the sliding rows is below
    ``UNITS_SMALL_RATIO``·f·N (kN given as N?).
    """
    src = f"{data.source}: " if data.source else ""
    n = len(data)
    if n < MIN_ROWS:
        raise DataError(
            f"{src}{n} test points are too few: the candidate models and the 5-fold check "
            f"need at least {MIN_ROWS}"
        )
    if not np.any((data.vx != 0) | (data.vy != 0) | (data.wz != 0)):
        raise DataError(f"{src}columns vx, vy, wz are zero in every row: nothing slides or spins")
    points = distinct_points(data)
    if points < MIN_DISTINCT:
        what = "every row is the same test point" if points == 1 else f"only {points} distinct test points"
        raise DataError(
            f"{src}columns vx, vy, wz: {what}; nothing varies enough to tell causes apart "
            f"(at least {MIN_DISTINCT} are needed)"
        )
    for c in CHANNELS:
        if np.all(getattr(data, c) == 0.0):
            raise DataError(f"{src}column {c} is zero in every row: a dead channel cannot be diagnosed")
    rolling_rows = int(np.count_nonzero(data.roll != 0))
    if rolling_rows and not has_rolling:
        raise DataError(
            f"{src}column roll: {rolling_rows} rows have roll = ±1 but no rolling map was given (--rolling)"
        )
    loads = data.loads(load)
    fn = friction * loads
    for c, scale, unit in (("Fx", fn, "f·N"), ("Fy", fn, "f·N"), ("Mz", fn * radius, "f·N·R")):
        ratio = np.abs(getattr(data, c)) / scale
        i = int(np.argmax(ratio))
        if ratio[i] > UNITS_ERROR_RATIO:
            line = i + 1 if data.lines is None else int(data.lines[i])
            raise DataError(
                f"{src}line {line}, column {c}: |{c}| is {ratio[i]:.3g} x {unit} "
                f"(f = {friction:g}, N = {loads[i]:.6g} N, R = {radius:.4g} m): wrong units?"
            )
    for c in CHANNELS:
        values = getattr(data, c)
        if np.all(values == values[0]):
            raise DataError(
                f"{src}column {c} has the same value in every row: a dead channel cannot be diagnosed"
            )
    sliding = np.hypot(data.vx, data.vy) > 0
    if np.any(sliding):
        top = float(np.max(np.hypot(data.Fx, data.Fy)[sliding] / fn[sliding]))
        if top < UNITS_SMALL_RATIO:
            warnings.warn(
                f"{src}columns Fx, Fy: the largest sliding force is {top:.3g} x f·N: "
                "forces in kN rather than N, or the wrong load?",
                UnitsWarning,
                stacklevel=2,
            )
