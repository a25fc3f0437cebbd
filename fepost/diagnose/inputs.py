"""Measured data in: a table of test points, or a rig recording reduced to its steady holds.

`load_measured` decides. ``layout="points"``: the measured-data CSV of
test points (`fepost.diagnose.measured`), exactly as always.
``layout="recording"``: a time series (`fepost.diagnose.recording`,
`fepost.diagnose.holds`). ``layout="auto"`` (the default): a recording
when the file is Parquet, MATLAB or TYDEX, when a column mapping, a unit or a
point column is given, or when a CSV has more than
`fepost.diagnose.measured.MAX_ROWS` data rows (counted without parsing,
and only up to that limit); otherwise a table of test points.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ArgumentError
from .holds import HoldRule, Holds, find_holds
from .measured import MAX_ROWS, MeasuredData, read_measured
from .recording import ALIASES, Columns

LAYOUTS = ("auto", "points", "recording")


def _more_rows_than(path: Path, limit: int) -> bool:
    """Whether the text file has more than ``limit`` lines that are neither blank nor comments."""
    count = 0
    with path.open("rb") as fh:
        for line in fh:
            s = line.strip()
            if s and not s.startswith(b"#"):
                count += 1
                if count > limit + 1:  # the header row and more than ``limit`` data rows
                    return True
    return False


def is_recording(path, columns: Columns | None, rule: HoldRule | None) -> bool:
    """``layout="auto"``'s rule (module docstring)."""
    path = Path(path)
    if path.suffix.lower() not in (".csv", ".txt"):
        return True
    if columns is not None and (columns.names or columns.units):
        return True
    if rule is not None and rule.use_point:
        return True
    return _more_rows_than(path, MAX_ROWS) and _has_time(path, columns)


def _has_time(path: Path, columns: Columns | None) -> bool:
    """Whether the CSV's header names a time column (a table of points without one is refused as before)."""
    if columns is not None and "time" in columns.names:
        return True
    with path.open("r", encoding="utf-8", errors="replace") as fh:
        for line in fh:
            s = line.strip()
            if s and not s.startswith("#"):
                names = {c.strip().strip('"').strip().lower() for c in s.split(",")}
                return bool(names & {"time", *ALIASES["time"]})
    return False


def load_measured(
    measured, *, columns: Columns | None = None, hold_rule: HoldRule | None = None, layout: str = "auto"
) -> tuple[MeasuredData, Holds | None]:
    """(test points, the holds they came from or None) for ``measured`` (module docstring).

    ``measured``: a path, `MeasuredData` or `Holds`.
    """
    if layout not in LAYOUTS:
        raise ArgumentError(f"layout must be one of {', '.join(LAYOUTS)}, got {layout!r}")
    if isinstance(measured, MeasuredData):
        return measured, None
    if isinstance(measured, Holds):
        return measured.data, measured
    if not isinstance(measured, (str, Path)):
        raise ArgumentError(f"measured must be a path, MeasuredData or Holds, got {type(measured).__name__}")
    path = Path(measured)
    if not path.is_file():
        return read_measured(path), None  # the table reader's own message (no such file, a folder, ...)
    recording = layout == "recording" or (layout == "auto" and is_recording(path, columns, hold_rule))
    if not recording:
        return read_measured(path), None
    holds = find_holds(path, columns, hold_rule)
    return holds.data, holds
