"""The sweep table: its columns, units, and how it is written (Parquet and CSV).

One row per (input file, time step). The coefficient columns are copied from
the ``fepost coefficients --json`` document of that row's analysis
(`fepost.analysis.Analysis.to_dict`), so a row equals the single-file
result number for number.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..output import atomic_path, write_text_atomic


@dataclass(frozen=True)
class Column:
    """A table column: name, type (``str``, ``int``, ``float``, ``bool``), unit, meaning."""

    name: str
    kind: str
    unit: str
    meaning: str


#: Every column of the table, in order.
COLUMNS: tuple[Column, ...] = (
    Column("source", "str", "", "FE export, path as given (or as the folder/glob produced it)"),
    Column("rolling", "str", "", "rolling map paired with it, empty when none"),
    Column(
        "role", "str", "", "static (a load point) or rolling (an unpaired rolling map, not in the trends)"
    ),
    Column("also_as", "str", "", "other files of the same case (same stem, other formats), not read"),
    Column("rolling_also_as", "str", "", "other files of the rolling map's case (other formats), not read"),
    Column("step", "int", "", "Exodus time step read (0-based); empty for files without time steps"),
    Column("time", "float", "s", "time value of that step (the solver's time unit)"),
    Column("status", "str", "", "ok or error"),
    Column("error", "str", "", "one-line error message, empty when ok"),
    Column("N", "float", "N", "normal load (polar-grid integral)"),
    Column("R", "float", "m", "patch radius r_max about the static centre of pressure"),
    Column("F0", "float", "N", "sliding friction force f N"),
    Column("M0", "float", "N m", "spin friction torque"),
    Column("a", "float", "1", "coupling coefficient a (with R as given)"),
    Column("m", "float", "1", "coupling coefficient m (with R as given)"),
    Column("b", "float", "1", "b = m/4"),
    Column("b1", "float", "N m", "b1 = M0/2"),
    Column("f", "float", "1", "friction coefficient used"),
    Column("aspect", "float", "1", "best-fit ellipse length/width of the patch"),
    Column("circular", "bool", "", "patch taken as circular (aspect and r_max/r_equiv rule)"),
    Column("k_x", "float", "1", "rolling pressure-shift coefficient; empty without a rolling map"),
    Column("x_c", "float", "m", "rolling centre-of-pressure shift; empty without a rolling map"),
    Column("N_fe", "float", "N", "normal load, exact integral over the FE faces"),
    Column("N_rolling", "float", "N", "normal load of the rolling map (polar grid); empty without one"),
    Column(
        "load_mismatch_allowed",
        "bool",
        "",
        "the rolling map's load differs from the static one's by more than 3 % and this was allowed",
    ),
    Column("r_equiv", "float", "m", "sqrt(area/pi) of the loaded region"),
    Column("aR2", "float", "m^2", "a R^2 (independent of the choice of R)"),
    Column("m_over_R2", "float", "1/m^2", "m / R^2 (independent of the choice of R)"),
    Column("case", "str", "", "case name from the sidecar <case>.json"),
    Column("load", "float", "N", "load from the sidecar (load, else reaction_z)"),
    Column("deflection", "float", "m", "deflection from the sidecar"),
    Column("inflation_pressure", "float", "Pa", "inflation pressure from the sidecar"),
    Column("warnings", "str", "", "fepost warnings of the analysis, joined by ' | '"),
    Column("seconds", "float", "s", "wall time of the row's analysis on its worker"),
)
NAMES: tuple[str, ...] = tuple(c.name for c in COLUMNS)
#: Keys copied from the top level of the coefficients JSON document.
FROM_JSON = (
    "N", "R", "F0", "M0", "a", "m", "b", "b1", "f", "k_x", "x_c", "N_fe", "N_rolling", "aR2", "m_over_R2",
)  # fmt: skip
#: Keys copied from its ``patch`` object.
FROM_PATCH = ("aspect", "circular", "r_equiv")


def coefficient_columns(doc: Mapping) -> dict:
    """The table's coefficient columns from a ``fepost coefficients --json`` document."""
    row = {k: doc.get(k) for k in FROM_JSON}
    patch = doc.get("patch") or {}
    row.update({k: patch.get(k) for k in FROM_PATCH})
    rolling = doc.get("rolling") or {}
    ratio = rolling.get("load_ratio")
    beyond = ratio is not None and abs(ratio - 1.0) > rolling.get("load_tolerance", 0.0)
    row["load_mismatch_allowed"] = bool(beyond and rolling.get("load_mismatch_allowed")) if rolling else None
    return row


def one_line(message: str, limit: int = 400) -> str:
    """``message`` on one line (whitespace runs collapsed), at most ``limit`` characters."""
    text = " ".join(str(message).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def normalise(row: Mapping) -> dict:
    """A row with every column, in order, values of the column's type (None when empty)."""
    out = {}
    for c in COLUMNS:
        v = row.get(c.name)
        if v is None or (isinstance(v, float) and math.isnan(v)):
            v = "" if c.name in ("error", "warnings", "rolling", "also_as", "rolling_also_as") else None
        elif c.kind == "float":
            v = float(v)
        elif c.kind == "int":
            v = int(v)
        elif c.kind == "bool":
            v = bool(v)
        else:
            v = str(v)
        out[c.name] = v
    return out


def _csv_cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ""
    return str(v)


def csv_text(rows: Iterable[Mapping]) -> str:
    """The table as CSV text: header row, floats written to round-trip exactly."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(NAMES)
    for row in rows:
        w.writerow([_csv_cell(row[n]) for n in NAMES])
    return buf.getvalue()


def arrow_schema():
    import pyarrow as pa

    types = {"str": pa.string(), "int": pa.int64(), "float": pa.float64(), "bool": pa.bool_()}
    fields = [
        pa.field(c.name, types[c.kind], metadata={"unit": c.unit, "meaning": c.meaning}) for c in COLUMNS
    ]
    return pa.schema(fields, metadata={"fepost": "sweep table"})


def write_table(rows: Sequence[Mapping], folder: Path) -> tuple[Path, Path]:
    """Write ``coefficients.parquet`` and ``coefficients.csv`` into ``folder``, each atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = [normalise(r) for r in rows]
    table = pa.Table.from_pylist(rows, schema=arrow_schema())
    parquet = folder / "coefficients.parquet"
    with atomic_path(parquet) as tmp:  # created by pyarrow with the umask's mode, as documented
        pq.write_table(table, tmp)
    return parquet, write_text_atomic(folder / "coefficients.csv", csv_text(rows))


def read_table(path: str | Path) -> list[dict]:
    """Rows of a sweep table written by `write_table` (``.parquet`` or ``.csv``)."""
    path = Path(path)
    if path.suffix.lower() == ".parquet":
        import pyarrow.parquet as pq

        return pq.read_table(path).to_pylist()
    kinds = {c.name: c.kind for c in COLUMNS}
    out = []
    with path.open(newline="") as fh:
        for rec in csv.DictReader(fh):
            row: dict = {}
            for k, v in rec.items():
                kind = kinds.get(k, "str")
                if v == "" and kind != "str":
                    row[k] = None
                elif kind == "float":
                    row[k] = float(v)
                elif kind == "int":
                    row[k] = int(v)
                elif kind == "bool":
                    row[k] = v == "true"
                else:
                    row[k] = v
            out.append(row)
    return out
