"""Numeric CSV tables with named columns: the one reader of fepost's CSV inputs.

The measured rig data of ``fepost diagnose`` (`fepost.diagnose.measured`)
and the kinematics of ``fepost predict`` (`fepost.friction.predict`) are
the same kind of file: a header row naming the columns, then one row of numbers
per point; blank lines and lines whose first non-blank character is ``#`` are
skipped (before and after the header), columns the format does not read are
ignored, and a UTF-8 byte-order mark is dropped. A `CsvFormat` says
which columns a format needs and how its messages name it; `parse_table`
and `read_table` read every such format alike.

Every problem is one `DataError` of one line naming the
file and, where there is one, the line and the column: an unreadable, binary
or over-large file, a line the csv module cannot split or a cell longer than
`MAX_CELL` characters, a header without a required column or with a
column read twice, a row too short for a column read, a cell that is not a
finite number, no data rows.

Own code rather than ``numpy.loadtxt`` or pandas: those stop at the first bad
cell without naming the file, line and column together, and neither skips
comment lines that stand between data rows while ignoring unread columns that
may hold text.
"""

from __future__ import annotations

import csv
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ._arrays import frozen
from .errors import DataError

#: Longest cell (characters): the csv module's default field limit, 128 kB.
MAX_CELL = 131072


@dataclass(frozen=True)
class CsvFormat:
    """One numeric CSV format: its columns and the words its messages use.

    Parameters
    ----------
    required, optional
        Names of the columns read; a file without one of ``required`` is refused.
    what
        The data in words, e.g. ``"measured data"``: "cannot read the measured data".
    kind
        The file in words, e.g. ``"CSV file"``: "is a folder, not a CSV file".
    max_rows, too_many_rows
        At most this many data rows are read (None: no limit); the message of a
        longer file is "<n> data rows: <too_many_rows>". Counted before any row
        is parsed.
    max_bytes, too_large
        Largest file read (bytes; None: no limit), checked before it is read;
        the message is "<size> MB is too large for <too_large>".
    """

    required: tuple[str, ...]
    optional: tuple[str, ...] = ()
    what: str = "CSV data"
    kind: str = "CSV file"
    max_rows: int | None = None
    too_many_rows: str = ""
    max_bytes: int | None = None
    too_large: str = ""

    @property
    def columns(self) -> tuple[str, ...]:
        """Every column read, required first."""
        return self.required + self.optional


@dataclass(frozen=True)
class CsvTable:
    """The columns read from one CSV table.

    ``values`` maps each column of the format that the file has to a read-only
    float array, one entry per data row; ``lines`` are the 1-based line numbers
    of those rows; ``source`` names the file in messages ("" for text).
    """

    values: Mapping[str, np.ndarray]
    lines: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", MappingProxyType({k: frozen(v) for k, v in self.values.items()}))
        object.__setattr__(self, "lines", frozen(self.lines, dtype=int))

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[name]

    def get(self, name: str) -> np.ndarray | None:
        """The column ``name``, or None where the file does not have it."""
        return self.values.get(name)

    def where(self, i: int) -> str:
        """'<source>: line <n>' of data row ``i`` (0-based), for messages."""
        src = f"{self.source}: " if self.source else ""
        return f"{src}line {int(self.lines[i])}"

    def __len__(self) -> int:
        return int(self.lines.size)


def _number(text: str, where: str, column: str) -> float:
    cell = text.strip()
    try:
        value = float(cell)
    except ValueError:
        shown = cell if cell else "an empty cell"
        raise DataError(f"{where}, column {column}: not a number: {shown!r}") from None
    if not np.isfinite(value):
        raise DataError(f"{where}, column {column}: not a finite number: {cell!r}")
    return value


def _rows(lines: list[str], src: str) -> list[tuple[int, list[str]]]:
    """(line number, cells) of every line that is neither blank nor a comment."""
    rows = []
    for lineno, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        try:
            cells = next(csv.reader([line]))
        except csv.Error as exc:
            if "field limit" in str(exc):
                raise DataError(f"{src}line {lineno}: a cell is longer than {MAX_CELL} characters") from None
            raise DataError(f"{src}line {lineno}: not a CSV line ({exc})") from None
        if any(len(c) > MAX_CELL for c in cells):
            raise DataError(f"{src}line {lineno}: a cell is longer than {MAX_CELL} characters")
        rows.append((lineno, cells))
    return rows


def parse_table(text: str, fmt: CsvFormat, source: str = "") -> CsvTable:
    """Read the CSV ``text`` in the format ``fmt``; ``source`` names it in messages.

    Raises
    ------
    DataError
        One line naming ``source`` and the line and column at fault (module docstring).
    """
    src = f"{source}: " if source else ""
    lines_all = text.splitlines()
    if fmt.max_rows is not None:
        count = sum(1 for line in lines_all if line.strip() and not line.lstrip().startswith("#")) - 1
        if count > fmt.max_rows:
            raise DataError(f"{src}{count} data rows: {fmt.too_many_rows}")
    rows = _rows(lines_all, src)
    if not rows:
        raise DataError(f"{src}no header row: the file is empty or only comments")
    head_line, header = rows[0]
    names = [h.strip() for h in header]
    index: dict[str, int] = {}
    for j, name in enumerate(names):
        if name in index and name in fmt.columns:
            raise DataError(f"{src}line {head_line}: column {name!r} appears twice in the header")
        index.setdefault(name, j)
    missing = [c for c in fmt.required if c not in index]
    if missing:
        got = ", ".join(repr(n) for n in names if n) or "none"
        raise DataError(f"{src}missing column(s) {', '.join(missing)} in the header (found {got})")
    wanted = [c for c in fmt.columns if c in index]
    values: dict[str, list[float]] = {c: [] for c in wanted}
    lines = []
    for lineno, cells in rows[1:]:
        where = f"{src}line {lineno}"
        short = [c for c in wanted if index[c] >= len(cells)]
        if short:
            raise DataError(
                f"{where}, column {short[0]}: missing ({len(cells)} fields, the header has {len(names)})"
            )
        for c in wanted:
            values[c].append(_number(cells[index[c]], where, c))
        lines.append(lineno)
    if not lines:
        raise DataError(f"{src}no data rows after the header")
    return CsvTable(
        values={c: np.asarray(v, float) for c, v in values.items()}, lines=np.asarray(lines), source=source
    )


def read_table(path, fmt: CsvFormat) -> CsvTable:
    """Read the CSV file ``path`` in the format ``fmt`` (UTF-8, with or without a BOM).

    Raises
    ------
    DataError
        One line naming the file: missing, a folder, unreadable, larger than
        ``fmt.max_bytes``, not text (NUL bytes), or any problem of `parse_table`.
    """
    path = Path(path)
    try:
        size = path.stat().st_size
        if path.is_dir():
            raise DataError(f"{path}: is a folder, not a {fmt.kind}")
        if fmt.max_bytes is not None and size > fmt.max_bytes:
            raise DataError(f"{path}: {size / 2**20:.0f} MB is too large for {fmt.too_large}")
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise DataError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise DataError(f"{path}: is a folder, not a {fmt.kind}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"{path}: cannot read the {fmt.what} ({exc.__class__.__name__})") from None
    if "\x00" in text:
        raise DataError(f"{path}: not a text CSV file (binary data)")
    return parse_table(text, fmt, source=str(path))
