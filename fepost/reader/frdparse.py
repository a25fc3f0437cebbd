"""The records of a CalculiX ``.frd`` result file: nodes, elements, nodal result blocks.

Layout (CalculiX GraphiX manual, "Result Format"; CalculiX's writer ``frd.c``
and ``frdheader.c``): text header lines ``    1C``/``    1U…``/``    1P…``, then

* ``    2C`` nodes: ``count`` and a format flag (1 ASCII, 3 binary). ASCII
  records ``-1`` I10 node, 3 × E12.5, closed by `` -3``; binary records
  int32 node + 3 float64, no closing line.
* ``    3C`` elements: ``count``, flag (1 ASCII, 2 binary). ASCII: a ``-1`` line
  (I10 element, I5 type, I5 group, I5 material) and ``-2`` lines of I10 nodes;
  binary: 4 int32 and the nodes as int32. The node count follows the type.
* ``  100C`` a nodal result block of one increment: the time (columns 12–24),
  the node count (24–36), the increment counter ``kode`` (58–63), the format
  (column 74: 1 ASCII, 2 binary float32, 3 binary float64); a ``-4`` line (name,
  number of ``-5`` lines) and the ``-5`` component lines (``IEXIST = 1`` marks a
  derived component such as ``ALL`` that has no values); records: ASCII ``-1``
  I10 node + E12.5 values (six a line, ``-2`` lines for more), closed by ``-3``;
  binary int32 node + values.
* ``    1PSTEP`` before each result block: increment and step of the analysis.
* `` 9999`` the end.

CalculiX writes ASCII with ``*NODE FILE`` / ``*EL FILE`` / ``*CONTACT FILE``
and binary with ``*NODE OUTPUT`` / ``*ELEMENT OUTPUT`` / ``*CONTACT OUTPUT``
(machine byte order: little-endian on every platform CalculiX is built for).

The file is memory-mapped and walked once; every count is checked against the
bytes left before anything is allocated, and result blocks are only located
here (their values are read on demand by `block_values`).
A block's records must hold exactly the values its ``-5`` lines declare stored
(ASCII: the values of each record are counted; binary: the records must end where
the next line starts): a wrong ``IEXIST`` flag would otherwise shift every column.
Whether the closing ``9999`` line was found is kept (`FrdFile.complete`): a file
cut off while written ends without it.
"""

from __future__ import annotations

import mmap
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputFileError

#: Nodes per element of each frd element type (1 he8 … 12 be3).
NODES_PER_TYPE = {1: 8, 2: 6, 3: 4, 4: 20, 5: 15, 6: 10, 7: 3, 8: 6, 9: 4, 10: 8, 11: 2, 12: 3}
#: Longest text line accepted (frd lines are at most ~130 characters).
MAX_LINE = 1024
_FORTRAN_EXP = re.compile(rb"([0-9.])([+-])(\d{2,3})$")
#: How the line after a binary block's records starts (``    1PSTEP``, ``  100C``, `` 9999`` ...).
_LINE_START = re.compile(rb" {0,4}\d{1,4}(?:[A-Z ]|\r?\n|$)")


@dataclass(frozen=True)
class ResultBlock:
    """One nodal result block: where its records are and what they hold."""

    name: str
    components: tuple[str, ...]
    count: int
    fmt: int  # 1 ASCII, 2 binary float32, 3 binary float64
    start: int  # first byte of the records
    end: int  # one past the last byte of the records (ASCII: before the -3 line)
    kode: int  # increment counter of the file
    time: float
    step: int  # analysis step (1PSTEP), 0 when not given


@dataclass
class FrdFile:
    """The parsed mesh and the located result blocks of an ``.frd`` file."""

    path: str
    binary: bool
    node_ids: np.ndarray  # (n,) as in the file
    coords: np.ndarray  # (n, 3)
    elem_types: np.ndarray  # (m,) frd element types
    elem_nodes: dict[int, np.ndarray]  # frd type -> (k, nodes) node ids, in file order per type
    blocks: list[ResultBlock] = field(default_factory=list)
    data: mmap.mmap | bytes = b""
    complete: bool = True  # the closing ``9999`` line was found (False: cut off while written?)


def _show(raw: bytes) -> str:
    """Bytes of the file quoted for a message (non-printable characters escaped)."""
    return repr(raw.decode("latin-1"))


def _bad(path: str, what: str) -> InputFileError:
    return InputFileError(f"{path}: corrupt or truncated .frd file ({what})")


def open_frd(path: Path) -> mmap.mmap:
    """The file mapped read-only (an empty file is refused before)."""
    with open(path, "rb") as fh:
        try:
            return mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)
        except (OSError, ValueError) as exc:
            raise InputFileError(f"{path}: cannot map the file ({exc})") from None


def _int(path: str, text: bytes, what: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise _bad(path, f"{what} {_show(text.strip()[:20])} is not a number") from None


def _floats(path: str, cols: np.ndarray) -> np.ndarray:
    """Fixed-width number fields (an array of bytes) as floats; Fortran ``1.0-100`` accepted."""
    try:
        return cols.astype(np.float64)
    except ValueError:
        out = np.empty(cols.shape)
        for i, txt in enumerate(cols.ravel()):
            t = txt.strip()
            try:
                out.flat[i] = float(t)
            except ValueError:
                try:
                    out.flat[i] = float(_FORTRAN_EXP.sub(rb"\1e\2\3", t))
                except ValueError:
                    raise _bad(path, f"value {_show(t[:20])} is not a number") from None
        return out


def _columns(lines: list[bytes], starts: list[int], width: int) -> list[np.ndarray] | None:
    """Fixed-width fields of equally long lines as byte-string arrays (None when lengths differ)."""
    if not lines or not starts:
        return [np.empty(0, f"S{width}") for _ in starts]
    length = len(lines[0])
    if any(len(ln) != length for ln in lines) or starts[-1] + width > length:
        return None
    table = np.frombuffer(b"".join(lines), np.uint8).reshape(len(lines), length)
    return [np.ascontiguousarray(table[:, s : s + width]).view(f"S{width}").ravel() for s in starts]


def _text_lines(data, start: int, end: int) -> list[bytes]:
    if end <= start:
        return []
    return [ln.rstrip(b"\r") for ln in bytes(data[start:end]).split(b"\n") if ln.strip()]


def _ascii_end(path: str, data, pos: int, what: str) -> tuple[int, int]:
    """(end of the records, start of the next line) of an ASCII block starting at ``pos``."""
    if data[pos : pos + 3] == b" -3":
        stop = pos
    else:
        stop = data.find(b"\n -3", max(pos - 1, 0))
        if stop < 0:
            raise _bad(path, f"{what} is not closed by a -3 line")
        stop += 1
    nxt = data.find(b"\n", stop)
    return stop, (len(data) if nxt < 0 else nxt + 1)


def _ascii_records(path: str, lines: list[bytes], nvals: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Node ids and values of ASCII result or coordinate records (six values a line)."""
    if nvals <= 6 and all(ln[:3] == b" -1" for ln in lines):
        ids = _columns(lines, [3], 10)
        vals = _columns(lines, [13 + 12 * k for k in range(nvals)], 12)
        if ids is not None and vals is not None and lines:
            if (len(lines[0]) - 13) // 12 > nvals:
                raise _bad(path, _too_many(what, (len(lines[0]) - 13) // 12, nvals))
            values = np.column_stack([_floats(path, v) for v in vals]) if vals else np.empty((len(lines), 0))
            return _ids(path, ids[0], what), values
    return _slow_records(path, lines, nvals, what)


def _ids(path: str, col: np.ndarray, what: str) -> np.ndarray:
    try:
        return col.astype(np.int64)
    except ValueError:
        bad = next(b for b in col if not b.strip().lstrip(b"-").isdigit())
        raise _bad(path, f"{what}: node number {_show(bad.strip()[:20])}") from None


def _too_many(what: str, held: int, nvals: int) -> str:
    return (
        f"{what}: a record holds {held} values, its -5 lines declare {nvals} stored components "
        "(a component flagged as derived, IEXIST = 1, that has values?)"
    )


def _slow_records(path: str, lines: list[bytes], nvals: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    ids: list[int] = []
    rows: list[list[bytes]] = []
    for ln in lines:
        tag = ln[:3]
        if tag == b" -1":
            ids.append(_int(path, ln[3:13], f"{what}: node"))
            rows.append([ln[13 + 12 * k : 25 + 12 * k] for k in range((len(ln) - 13) // 12)])
        elif tag == b" -2" and rows:
            rows[-1] += [ln[13 + 12 * k : 25 + 12 * k] for k in range((len(ln) - 13) // 12)]
        else:
            raise _bad(path, f"{what}: unexpected line {_show(ln[:40])}")
    if any(len(r) < nvals for r in rows):
        raise _bad(path, f"{what}: a record holds fewer than {nvals} values")
    if any(len(r) > nvals for r in rows):
        raise _bad(path, _too_many(what, max(len(r) for r in rows), nvals))
    cols = np.array([r[:nvals] for r in rows], dtype="S12").reshape(len(rows), nvals)
    return np.array(ids, np.int64), _floats(path, cols)


def _need(path: str, data, pos: int, nbytes: int, what: str) -> None:
    if nbytes < 0 or pos + nbytes > len(data):
        raise _bad(path, f"{what} needs {nbytes} bytes, {len(data) - pos} are left")


def _nodes(path: str, data, pos: int, count: int, fmt: int) -> tuple[np.ndarray, np.ndarray, int]:
    if fmt in (2, 3):
        size = 4 + 3 * (4 if fmt == 2 else 8)
        _need(path, data, pos, count * size, f"the node block ({count} nodes)")
        real = "<f4" if fmt == 2 else "<f8"
        rec = np.frombuffer(data, np.dtype([("id", "<i4"), ("x", real, 3)]), count=count, offset=pos)
        return rec["id"].astype(np.int64), np.array(rec["x"], np.float64), pos + count * size
    if fmt != 1:
        raise InputFileError(f"{path}: .frd node block in format {fmt}, which fepost cannot read")
    _need(path, data, pos, count * 13, f"the node block ({count} nodes)")
    stop, nxt = _ascii_end(path, data, pos, "the node block")
    lines = _text_lines(data, pos, stop)
    if len(lines) != count:
        raise _bad(path, f"the node block declares {count} nodes and holds {len(lines)}")
    ids, xyz = _ascii_records(path, lines, 3, "node block")
    return ids, xyz, nxt


def _elements(path: str, data, pos: int, count: int, fmt: int):
    """(types, flat node ids, next position) of the element block."""
    if fmt == 2:
        _need(path, data, pos, count * 20, f"the element block ({count} elements)")
        ints = np.frombuffer(data, "<i4", count=(len(data) - pos) // 4, offset=pos)
        types, flat, used = _binary_elements(path, ints, count)
        return types, flat, pos + 4 * used
    if fmt != 1:
        raise InputFileError(f"{path}: .frd element block in format {fmt}, which fepost cannot read")
    _need(path, data, pos, count * 28, f"the element block ({count} elements)")
    stop, nxt = _ascii_end(path, data, pos, "the element block")
    lines = _text_lines(data, pos, stop)
    heads = [ln for ln in lines if ln[:3] == b" -1"]
    body = [ln[3:] for ln in lines if ln[:3] == b" -2"]
    if len(heads) + len(body) != len(lines):
        odd = next(ln for ln in lines if ln[:3] not in (b" -1", b" -2"))
        raise _bad(path, f"element block: unexpected line {_show(odd[:40])}")
    if len(heads) != count:
        raise _bad(path, f"the element block declares {count} elements and holds {len(heads)}")
    types = np.array([_int(path, h[13:18], "element type") for h in heads], np.int64)
    unknown = sorted(set(types.tolist()) - set(NODES_PER_TYPE))
    if unknown:
        raise _bad(path, f"element type {unknown[0]} is unknown")
    if any(len(b) % 10 for b in body):
        raise _bad(path, "element block: a node line is not made of 10-character fields")
    joined = b"".join(body)
    flat = _ids(path, np.frombuffer(joined, "S10"), "element block") if joined else np.empty(0, np.int64)
    need = int(sum(NODES_PER_TYPE[int(t)] for t in types))
    if len(flat) != need:
        raise _bad(path, f"the element block lists {len(flat)} nodes for elements needing {need}")
    return types, flat, nxt


def _binary_elements(path: str, ints: np.ndarray, count: int):
    """(types, flat node ids, int32 words used) of ``count`` binary element records."""
    k0 = NODES_PER_TYPE.get(int(ints[1])) if count and len(ints) > 1 else None
    if k0 is not None and count * (4 + k0) <= len(ints):
        rec = ints[: count * (4 + k0)].reshape(count, 4 + k0)
        if np.all(rec[:, 1] == rec[0, 1]):  # one element type throughout: regular records
            flat = np.array(rec[:, 4:], np.int64).ravel()
            return rec[:, 1].astype(np.int64), flat, count * (4 + k0)
    types = np.empty(count, np.int64)
    starts = np.empty(count, np.int64)
    i = 0
    for e in range(count):
        if i + 4 > len(ints):
            raise _bad(path, f"the element block ends after {e} of {count} elements")
        t = int(ints[i + 1])
        k = NODES_PER_TYPE.get(t)
        if k is None:
            raise _bad(path, f"element {int(ints[i])} has the unknown type {t}")
        types[e], starts[e] = t, i + 4
        i += 4 + k
    if i > len(ints):
        raise _bad(path, f"the element block ({count} elements) runs past the end of the file")
    sizes = np.array([NODES_PER_TYPE[int(t)] for t in types], np.int64)
    flat = (
        np.array(ints[np.repeat(starts, sizes) + _ramp(sizes)], np.int64) if count else np.empty(0, np.int64)
    )
    return types, flat, i


def _ramp(sizes: np.ndarray) -> np.ndarray:
    """0, 1, …, s−1 for each s in ``sizes``, end to end."""
    ends = np.cumsum(sizes)
    return np.arange(int(ends[-1]) if len(ends) else 0) - np.repeat(ends - sizes, sizes)


def _group(types: np.ndarray, flat: np.ndarray) -> dict[int, np.ndarray]:
    """frd type → (k, nodes) node ids of its elements, in file order."""
    sizes = np.array([NODES_PER_TYPE[int(t)] for t in types], np.int64)
    starts = np.cumsum(sizes) - sizes
    out = {}
    for t in np.unique(types):
        sel = np.flatnonzero(types == t)
        out[int(t)] = flat[starts[sel][:, None] + np.arange(NODES_PER_TYPE[int(t)])[None, :]]
    return out


def _header_line(path: str, data, pos: int) -> tuple[bytes, int]:
    eol = data.find(b"\n", pos, pos + MAX_LINE)
    if eol < 0:
        raise _bad(path, "a result block header is cut off")
    return bytes(data[pos:eol]).rstrip(b"\r"), eol + 1


def _result_header(path: str, data, pos: int, head: bytes, step: int) -> tuple[ResultBlock, int]:
    """Parse a ``100C`` block from its header line ``head``; ``pos`` is just after it."""
    count = _int(path, head[24:36], "result block node count")
    kode = _int(path, head[58:63] or b"0", "increment counter") if len(head) > 58 else 0
    fmt = _int(path, head[74:75], "result format") if len(head) > 74 else 1
    try:
        time = float(head[12:24])
    except ValueError:
        time = float("nan")
    if not np.isfinite(time):
        raise _bad(path, f"result block time {_show(head[12:24].strip())} is not a finite number")
    minus4, pos = _header_line(path, data, pos)
    if minus4[:3] != b" -4":
        raise _bad(path, f"result block header: expected a -4 line, found {_show(minus4[:40])}")
    name = minus4[5:13].decode("latin-1").strip()
    ncomp = _int(path, minus4[13:18], "result block component count")
    if not 0 <= ncomp <= 1000:
        raise _bad(path, f"result block {name} with {ncomp} components")
    comps: list[str] = []
    for _ in range(ncomp):
        ln, pos = _header_line(path, data, pos)
        if ln[:3] != b" -5":
            raise _bad(path, f"result block {name}: expected a -5 line, found {_show(ln[:40])}")
        if ln[33:38].strip() != b"1":  # IEXIST = 1: derived (ALL), no values stored
            comps.append(ln[5:13].decode("latin-1").strip())
    if count < 0:
        raise _bad(path, f"result block {name} declares {count} nodes")
    if fmt in (2, 3):
        size = 4 + len(comps) * (4 if fmt == 2 else 8)
        _need(path, data, pos, count * size, f"result block {name} ({count} nodes)")
        end = nxt = pos + count * size
        if end < len(data) and not _LINE_START.match(data, end, min(len(data), end + 12)):
            raise _bad(
                path,
                f"result block {name}: its records do not end where its -5 lines say ({count} nodes, "
                f"{len(comps)} stored components of {size // len(comps) if comps else 0} bytes each): "
                "a component flagged as derived (IEXIST = 1) that has values, or the reverse?",
            )
    elif fmt == 1:
        _need(path, data, pos, count * 13, f"result block {name} ({count} nodes)")
        end, nxt = _ascii_end(path, data, pos, f"result block {name}")
    else:
        raise InputFileError(f"{path}: .frd result block {name} in format {fmt}, which fepost cannot read")
    return ResultBlock(name, tuple(comps), count, fmt, pos, end, kode, time, step), nxt


def block_values(frd: FrdFile, block: ResultBlock) -> tuple[np.ndarray, np.ndarray]:
    """(node ids (m,), values (m, c)) of a result block."""
    nv = len(block.components)
    if block.fmt in (2, 3):
        real = "<f4" if block.fmt == 2 else "<f8"
        dt = np.dtype([("id", "<i4"), ("v", real, (nv,))])
        rec = np.frombuffer(frd.data, dt, count=block.count, offset=block.start)
        return rec["id"].astype(np.int64), np.array(rec["v"], np.float64).reshape(block.count, nv)
    lines = _text_lines(frd.data, block.start, block.end)
    ids, vals = _ascii_records(frd.path, lines, nv, f"result block {block.name}")
    if len(ids) != block.count:
        raise _bad(frd.path, f"result block {block.name} declares {block.count} nodes and holds {len(ids)}")
    return ids, vals


def scan(path: Path, data) -> FrdFile:
    """Walk the file: parse nodes and elements, locate the result blocks."""
    where = str(path)
    pos, n = 0, len(data)
    nodes = elems = None
    frd = FrdFile(where, False, np.empty(0, np.int64), np.empty((0, 3)), np.empty(0, np.int64), {}, data=data)
    step = 0
    complete = False
    while pos < n:
        eol = data.find(b"\n", pos, pos + MAX_LINE)
        if eol < 0:
            if n - pos >= MAX_LINE:
                raise _bad(where, f"no line break within {MAX_LINE} bytes at byte {pos}")
            eol = n
        line = bytes(data[pos:eol]).rstrip(b"\r")
        pos = eol + 1
        key = line[:5].strip()
        if key == b"1":
            if line[5:10] == b"PSTEP" and len(line) >= 60:
                step = _int(where, line[48:60], "step number")
        elif key == b"2" and line[5:6] == b"C":
            if nodes is not None:
                raise _bad(where, "a second node block")
            count, fmt = _count_fmt(where, line, "node")
            frd.binary = fmt != 1
            ids, xyz, pos = _nodes(where, data, pos, count, fmt)
            nodes = (ids, xyz)
        elif key == b"3" and line[5:6] == b"C":
            if elems is not None:
                raise _bad(where, "a second element block")
            count, fmt = _count_fmt(where, line, "element")
            elems = _elements(where, data, pos, count, fmt)
            pos = elems[2]
        elif key == b"100" and line[5:6] == b"C":
            block, pos = _result_header(where, data, pos, line, step)
            frd.blocks.append(block)
        elif key == b"9999":
            complete = True
            break
        elif line.strip():
            raise _bad(where, f"unexpected line {_show(line[:40])} at byte {pos - len(line) - 1}")
    if nodes is None:
        raise InputFileError(f"{where}: not a CalculiX .frd result file (no node block '2C')")
    frd.node_ids, frd.coords = nodes
    frd.complete = complete
    if elems is not None:
        frd.elem_types, frd.elem_nodes = elems[0], _group(elems[0], elems[1])
    return frd


def _count_fmt(path: str, line: bytes, what: str) -> tuple[int, int]:
    fields = line[6:].split()
    if not fields:
        raise _bad(path, f"the {what} block header gives no count")
    count = _int(path, fields[0], f"{what} count")
    fmt = _int(path, fields[-1], f"{what} block format") if len(fields) > 1 else 1
    if count < 0:
        raise _bad(path, f"the {what} block declares {count} {what}s")
    return count, fmt
