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

A rolling map is never a static load point. Without ``--rolling-pairs`` (and for
the inputs a given rule or CSV leaves unpaired), an input recognised as a
rolling map (`is_rolling_map`: ``rolling`` in its file name, or a sidecar
with a ``rolling_standin`` block) is paired with the input named like it with
``rolling`` replaced by ``static`` (``rolling_100.vtu`` → ``static_100.vtu``);
without such an input it stays a row of its own with the role ``rolling``,
listed apart and left out of the load trends.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ArgumentError, InputFileError
from ..reader.sidecar import read_sidecar
from .inputs import Source

#: Roles of a row: a static load point, or a rolling map left unpaired.
STATIC, ROLLING = "static", "rolling"
_ROLLING_WORD = re.compile("rolling", re.IGNORECASE)


@dataclass(frozen=True)
class Pairing:
    """A source and its rolling map (absolute path and as written), if any.

    ``role`` is `STATIC` (a load point) or `ROLLING` (an unpaired
    rolling map: a row of its own, not a load point); ``rolling_also`` the
    rolling map's other formats, not read.
    """

    static: Source
    rolling: str | None = None
    rolling_given: str | None = None
    role: str = STATIC
    rolling_also: tuple[str, ...] = ()


def is_rolling_map(path: str) -> bool:
    """Whether the export ``path`` is a rolling map: ``rolling`` in its file name, or a
    sidecar ``<stem>.json`` with a ``rolling_standin`` block (as the shipped samples have)."""
    if _ROLLING_WORD.search(Path(path).name):
        return True
    try:
        side = read_sidecar(Path(path))
    except InputFileError:
        return False  # the row's own analysis reports the sidecar
    return side is not None and "rolling_standin" in side


def _static_name(name: str) -> str:
    """``name`` with every ``rolling`` replaced by ``static`` in the same case."""

    def swap(m: re.Match) -> str:
        word = m.group(0)
        return "STATIC" if word.isupper() else "Static" if word[0].isupper() else "static"

    return _ROLLING_WORD.sub(swap, name)


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


def _default_partners(sources: Sequence[Source], taken: set[str]) -> dict[str, tuple[str, str]]:
    """{static path: (rolling path, as given)} for the rolling maps among ``sources`` whose
    static partner (``rolling`` → ``static`` in the name) is an input too."""
    by_path = {s.path: s for s in sources if s.path is not None}
    by_case = {(str(Path(p).parent), Path(p).stem): p for p in by_path}
    out: dict[str, tuple[str, str]] = {}
    for src in sources:
        path = src.path
        if path is None or path in taken or not is_rolling_map(path):
            continue
        p = Path(path)
        static = by_case.get((str(p.parent), _static_name(p.stem)))
        if static is not None and static != path and static not in out and static not in taken:
            out[static] = (path, src.given)
    return out


def pair_sources(sources: Sequence[Source], pairs: RollingPairs | None) -> list[Pairing]:
    """Attach rolling maps to the static sources; drop the rolling maps that were paired;
    mark the rolling maps left unpaired with the role `ROLLING`."""
    found = [(s, pairs.partner(s) if pairs is not None else None) for s in sources]
    partners = {p[0] for _, p in found if p is not None}
    if (
        pairs is not None
        and pairs.rule is not None
        and not partners
        and any(s.path is not None for s in sources)
    ):
        old, new = pairs.rule
        raise ArgumentError(
            f"--rolling-pairs {pairs.spec}: no input has a rolling partner (no file named like an "
            f"input with {old!r} replaced by {new!r})"
        )
    paired = {s.path for s, p in found if p is not None and s.path is not None}
    default = _default_partners(sources, partners | paired)
    partners |= {rolling for rolling, _ in default.values()}
    also = {s.path: s.also for s in sources if s.path is not None}
    out = []
    for src, p in found:
        if src.path is not None and src.path in partners and p is None:
            continue  # this file is another input's rolling map
        p = p if p is not None else default.get(src.path or "")
        if p is not None:
            out.append(Pairing(src, *p, rolling_also=also.get(p[0], ())))
        elif src.path is not None and is_rolling_map(src.path):
            out.append(Pairing(src, role=ROLLING))
        else:
            out.append(Pairing(src))
    return out
