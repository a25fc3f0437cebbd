"""``--rolling-pairs``: which rolling map goes with which static map.

Two ways to say it:

* a **naming rule** ``STATIC=ROLLING``: the rolling map of an input whose file
  name contains ``STATIC`` is the file beside it with every ``STATIC`` in the
  name replaced by ``ROLLING`` (``case_150kN_static.e`` →
  ``case_150kN_rolling.e`` with ``static=rolling``). An input without
  ``STATIC`` in its name, or whose partner does not exist, is a static-only
  row (a load sweep often has a rolling run at one load only); a rule that
  pairs no input at all is refused as a likely typo.
* a **CSV file** (``*.csv``) with a header row naming the columns ``static``
  and ``rolling`` (others ignored; blank lines and ``#`` comments allowed);
  relative paths are taken from the CSV's folder. Inputs not listed are
  static-only rows.

A rolling map that is paired with an input is not a row of its own, even when
a folder or glob also matched it.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ArgumentError
from .inputs import Source


@dataclass(frozen=True)
class Pairing:
    """A static source and its rolling map (absolute path and as written), if any."""

    static: Source
    rolling: str | None = None
    rolling_given: str | None = None


@dataclass(frozen=True)
class RollingPairs:
    """A parsed ``--rolling-pairs`` value: a naming rule or a table of pairs."""

    spec: str
    rule: tuple[str, str] | None = None
    table: Mapping[str, str] = field(default_factory=dict)

    def partner(self, src: Source) -> tuple[str, str] | None:
        """(absolute path, path as written) of the rolling map of ``src``, or None."""
        if src.path is None:
            return None
        if self.rule is not None:
            old, new = self.rule
            name = Path(src.path).name
            if old not in name:
                return None
            partner = Path(src.path).with_name(name.replace(old, new))
            if not partner.is_file():
                return None
            given = Path(src.given)
            return str(partner), str(given.with_name(given.name.replace(old, new)))
        hit = self.table.get(src.path)
        return (hit, hit) if hit is not None else None


def parse_rolling_pairs(spec: str) -> RollingPairs:
    """Parse ``--rolling-pairs``: ``STATIC=ROLLING`` or the path of a CSV of pairs.

    Raises
    ------
    ArgumentError
        A rule with an empty or path-like side, or a CSV that is missing or malformed.
    """
    if spec.lower().endswith(".csv"):
        return RollingPairs(spec, table=_read_pairs_csv(Path(spec)))
    if "=" in spec:
        old, _, new = spec.partition("=")
        if not old or not new or old == new or any(s in old + new for s in ("/", "\\", "=")):
            raise ArgumentError(
                f"--rolling-pairs {spec!r}: a naming rule is STATIC=ROLLING, two different "
                "non-empty parts of a file name (e.g. static=rolling)"
            )
        return RollingPairs(spec, rule=(old, new))
    raise ArgumentError(
        f"--rolling-pairs {spec!r}: expected a naming rule STATIC=ROLLING or a CSV file (*.csv) "
        "with columns static,rolling"
    )


def _read_pairs_csv(path: Path) -> dict[str, str]:
    try:
        text = path.read_text()
    except OSError as exc:
        raise ArgumentError(f"--rolling-pairs {path}: cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise ArgumentError(f"--rolling-pairs {path}: not a text CSV file") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(lines))))
    if not rows:
        raise ArgumentError(f"--rolling-pairs {path}: empty CSV (expected columns static,rolling)")
    header = [h.strip().lower() for h in rows[0]]
    if "static" not in header or "rolling" not in header:
        raise ArgumentError(
            f"--rolling-pairs {path}: the header must name the columns static and rolling, got {rows[0]}"
        )
    i_s, i_r = header.index("static"), header.index("rolling")
    base = path.parent
    table: dict[str, str] = {}
    for n, row in enumerate(rows[1:], start=2):
        if len(row) <= max(i_s, i_r) or not row[i_s].strip() or not row[i_r].strip():
            raise ArgumentError(f"--rolling-pairs {path}: data row {n - 1} lacks a static or rolling path")
        static = (base / row[i_s].strip()).resolve()
        rolling = (base / row[i_r].strip()).resolve()
        if not static.is_file():
            raise ArgumentError(f"--rolling-pairs {path}: data row {n - 1}: no such static file {static}")
        key = str(static)
        if key in table and table[key] != str(rolling):
            raise ArgumentError(f"--rolling-pairs {path}: {static} is paired twice")
        table[key] = str(rolling)
    return table


def pair_sources(sources: Sequence[Source], pairs: RollingPairs | None) -> list[Pairing]:
    """Attach rolling maps to the static sources; drop the rolling maps that were paired."""
    if pairs is None:
        return [Pairing(s) for s in sources]
    found = [(s, pairs.partner(s)) for s in sources]
    partners = {p[0] for _, p in found if p is not None}
    if pairs.rule is not None and not partners and any(s.path is not None for s in sources):
        old, new = pairs.rule
        raise ArgumentError(
            f"--rolling-pairs {pairs.spec}: no input has a rolling partner (no file named like an "
            f"input with {old!r} replaced by {new!r})"
        )
    out = []
    for src, p in found:
        if src.path is not None and src.path in partners and p is None:
            continue  # this file is another input's rolling map
        out.append(Pairing(src, *p) if p is not None else Pairing(src))
    return out
