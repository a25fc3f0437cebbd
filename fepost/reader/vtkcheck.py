"""Checks of VTK files before VTK reads them: declared sizes against the data, hostile XML.

VTK's readers trust a file's header: a piece declaring fewer cells than its
arrays hold is read as that many cells (a silently partial result), declared
sizes far beyond the data make them allocate without bound, and some
inconsistencies crash them. This module reads only the *structure* of a file
(tags, attributes, the length headers of binary arrays, token counts of ASCII
arrays; no array is decoded) and refuses a file whose header disagrees with
its data, before VTK sees it:

XML (``.vtu .vtp .vtm``)
    no DOCTYPE or ENTITY declarations (entity expansion), tags nested at most
    :data:`MAX_DEPTH` deep and balanced, the root type matching the suffix,
    ``NumberOfPoints``/``NumberOfCells`` (``NumberOf{Verts,Lines,Strips,Polys}``)
    non-negative and within :data:`MAX_COUNT`, every data array's length
    (from its binary header — plain or compressed blocks, inline base64 or
    appended raw/base64 — or its ASCII token count) equal to what the piece
    declares, and the bytes it announces present in the file. A ``.vtm``'s
    pieces are checked in turn (they must be VTK XML files that exist).
Legacy (``.vtk``, ASCII or binary, ``UNSTRUCTURED_GRID`` and ``POLYDATA``)
    every section's declared count (``POINTS``, ``CELLS``/``OFFSETS``/
    ``CONNECTIVITY``, ``CELL_TYPES``, ``POINT_DATA``/``CELL_DATA`` arrays,
    ``FIELD`` arrays) matches the values that follow: a section followed by
    more numbers than declared, or by fewer, is refused.

The structure is VTK's documented file format ("VTK File Formats", VTK User's
Guide); nothing here is used to *read* data, only to decide whether VTK may.
Corruption inside the data (a bad zlib block, wild connectivity) is left to
VTK's own errors, to the connectivity check after reading, and to the child
process the file is read in (:mod:`fepost.reader.isolate`).
"""

from __future__ import annotations

import base64
import binascii
import mmap
import re
import struct
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputFileError

#: Deepest XML nesting accepted (VTK files need about 6).
MAX_DEPTH = 32
#: Largest point, cell or value count accepted from a header.
MAX_COUNT = (1 << 31) - 1
#: Most nested .vtm files followed.
MAX_VTM_DEPTH = 4

_SIZES = {
    "Int8": 1,
    "UInt8": 1,
    "Int16": 2,
    "UInt16": 2,
    "Int32": 4,
    "UInt32": 4,
    "Int64": 8,
    "UInt64": 8,
    "Float32": 4,
    "Float64": 8,
}
_ROOT = {".vtu": "UnstructuredGrid", ".vtp": "PolyData", ".vtm": "vtkMultiBlockDataSet"}
_TAG = re.compile(
    rb"<!--.*?-->|<\?.*?\?>|<!\[CDATA\[.*?\]\]>|<(/?)([A-Za-z_][\w:.-]*)((?:[^>\"']|\"[^\"]*\"|'[^']*')*)>",
    re.S,
)
_ATTR = re.compile(rb"([A-Za-z_][\w:.-]*)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")


@dataclass
class Counts:
    """What a checked file declares, for the comparison after VTK has read it."""

    connectivity: list[int] = field(default_factory=list)  # values of each piece's connectivity arrays


def _bad(path: Path, what: str) -> InputFileError:
    """The one-line error for ``path``: refusals as they are, everything else as corrupt or truncated."""
    if what.startswith("refused: "):
        return InputFileError(f"{path}: refused {path.suffix} file ({what[len('refused: ') :]})")
    return InputFileError(f"{path}: corrupt or truncated {path.suffix} file ({what})")


def check_file(path: Path, depth: int = 0) -> Counts:
    """Check ``path`` (suffix-chosen); raise :class:`InputFileError` on any inconsistency."""
    suffix = path.suffix.lower()
    try:
        with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
            if suffix == ".vtk":
                return _Legacy(path, data[:]).check()
            return _Xml(path, data, depth).check()
    except InputFileError:
        raise
    except (OSError, ValueError) as exc:
        raise _bad(path, f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None


# ----------------------------------------------------------------------------- XML


def _int(path: Path, attrs: dict[str, str], key: str, default: int | None = None) -> int:
    if key not in attrs:
        if default is None:
            raise _bad(path, f"missing {key}")
        return default
    text = attrs[key].strip()
    if not re.fullmatch(r"[+-]?\d{1,20}", text):
        raise _bad(path, f"{key}={attrs[key]!r} is not an integer")
    value = int(text)
    if value < 0 or value > MAX_COUNT:
        raise _bad(path, f"{key}={value} is out of range")
    return value


@dataclass
class _Array:
    attrs: dict[str, str]
    section: str
    start: int  # inline content (ascii numbers or base64): data[start:end]
    end: int


@dataclass
class _Piece:
    attrs: dict[str, str]
    arrays: list[_Array] = field(default_factory=list)


class _Xml:
    def __init__(self, path: Path, data: bytes | mmap.mmap, depth: int):
        self.path, self.data, self.depth = path, data, depth

    def check(self) -> Counts:
        path, data = self.path, self.data
        suffix = path.suffix.lower()
        cut = data.find(b"<AppendedData")
        limit = len(data) if cut < 0 else cut
        first = data.find(b"<VTKFile", 0, limit)
        prologue = data[: first if first >= 0 else min(limit, 1 << 16)]
        if re.search(rb"<!(DOCTYPE|ENTITY)", prologue, re.I):
            raise _bad(
                path, "refused: XML with DOCTYPE/ENTITY declarations (not a VTK file; entity expansion)"
            )
        root, pieces, refs = self._scan(limit)
        want = _ROOT.get(suffix)
        if root.get("type") != want:
            raise _bad(path, f"not a VTK XML {want} file: VTKFile type={root.get('type')!r}")
        self.header_size = 8 if root.get("header_type", "UInt32") == "UInt64" else 4
        if root.get("header_type", "UInt32") not in ("UInt32", "UInt64"):
            raise _bad(path, f"header_type={root.get('header_type')!r}")
        self.endian = ">" if root.get("byte_order", "LittleEndian") == "BigEndian" else "<"
        self.compressed = bool(root.get("compressor"))
        self.appended = self._appended(cut)
        counts = Counts()
        if suffix == ".vtm":
            self._check_refs(refs)
            return counts
        for piece in pieces:
            counts.connectivity.append(self._piece(piece, suffix))
        return counts

    def _tags(self, limit: int):
        """The tags before ``limit``, found with bytes.find (array contents hold no '<')."""
        data, pos = self.data, 0
        while True:
            pos = data.find(b"<", pos, limit)
            if pos < 0:
                return
            m = _TAG.match(data, pos, limit)
            if m is None:
                raise _bad(self.path, "a '<' that opens no XML tag")
            yield m
            pos = m.end()

    def _scan(self, limit: int):
        data = self.data
        stack: list[bytes] = []
        root: dict[str, str] | None = None
        pieces: list[_Piece] = []
        refs: list[str] = []
        section = ""
        for m in self._tags(limit):
            closing, name, rest = m.group(1), m.group(2), m.group(3)
            if name is None:
                continue  # comment, processing instruction, CDATA
            selfclose = rest.rstrip().endswith(b"/")
            if closing:
                if not stack or stack[-1] != name:
                    raise _bad(self.path, f"unexpected XML tag </{name.decode('latin-1')}>")
                stack.pop()
                if name in (
                    b"Points",
                    b"Cells",
                    b"Verts",
                    b"Lines",
                    b"Strips",
                    b"Polys",
                    b"PointData",
                    b"CellData",
                ):
                    section = ""
                continue
            attrs = {
                k.decode("latin-1"): (a if a is not None else b or b"").decode("latin-1")
                for k, a, b in _ATTR.findall(rest)
            }
            if root is None:
                if name != b"VTKFile":
                    raise _bad(self.path, "no VTKFile element: not a VTK XML file")
                root = attrs
            if name == b"Piece":
                pieces.append(_Piece(attrs))
            elif name in (
                b"Points",
                b"Cells",
                b"Verts",
                b"Lines",
                b"Strips",
                b"Polys",
                b"PointData",
                b"CellData",
                b"FieldData",
            ):
                section = name.decode()
            elif name == b"DataArray" and pieces:
                end = data.find(b"<", m.end(), limit)
                end = m.end() if selfclose else (end if end >= 0 else limit)
                pieces[-1].arrays.append(_Array(attrs, section, m.end(), end))
            elif name == b"DataSet" and "file" in attrs:
                refs.append(attrs["file"])
            if not selfclose:
                stack.append(name)
                if len(stack) > MAX_DEPTH:
                    raise _bad(self.path, f"refused: XML nested more than {MAX_DEPTH} levels deep")
        if root is None:
            raise _bad(self.path, "no VTKFile element: not a VTK XML file")
        if stack and self.data.find(b"<AppendedData") < 0:
            raise _bad(self.path, f"XML element <{stack[-1].decode('latin-1')}> is not closed")
        return root, pieces, refs

    def _appended(self, cut: int) -> tuple[int, bool] | None:
        if cut < 0:
            return None
        close = self.data.find(b">", cut)
        if close < 0:
            raise _bad(self.path, "AppendedData element is not closed")
        attrs = dict(
            (k.decode("latin-1"), (a or b).decode("latin-1"))
            for k, a, b in _ATTR.findall(self.data[cut:close])
        )
        mark = self.data.find(b"_", close)
        if mark < 0:
            raise _bad(self.path, "AppendedData without its '_' marker")
        return mark + 1, attrs.get("encoding", "raw") == "base64"

    def _check_refs(self, refs: list[str]) -> None:
        if self.depth >= MAX_VTM_DEPTH:
            raise _bad(self.path, f"refused: multi-block files nested more than {MAX_VTM_DEPTH} deep")
        for ref in refs:
            sub = (self.path.parent / ref).resolve()
            if sub.suffix.lower() not in (".vtu", ".vtp", ".vtm"):
                raise _bad(self.path, f"multi-block piece {ref!r} is not a VTK XML file")
            if not sub.is_file():
                raise _bad(self.path, f"multi-block piece {ref!r} not found")
            if sub == self.path.resolve():
                raise _bad(self.path, "multi-block file refers to itself")
            check_file(sub, self.depth + 1)

    # -- array lengths --

    def _values(self, arr: _Array) -> int | None:
        """Number of values the array holds (None: a string array, not counted)."""
        a = arr.attrs
        dtype = a.get("type", "")
        if dtype == "String":
            if a.get("format", "ascii") == "ascii":  # the bytes of the strings, each ended by a 0
                return self.data[arr.start : arr.end].split().count(b"0")
            return None
        size = _SIZES.get(dtype)
        if size is None:
            raise _bad(self.path, f"unknown data type {dtype!r} of array {a.get('Name', '?')!r}")
        fmt = a.get("format", "ascii")
        name = a.get("Name", "?")
        if fmt == "ascii":
            return len(self.data[arr.start : arr.end].split())
        if fmt == "binary":
            nbytes, have = self._binary_size(arr.start, arr.end, name)
        elif fmt == "appended":
            if self.appended is None:
                raise _bad(self.path, f"array {name!r} is appended but the file has no AppendedData")
            off = _int(self.path, a, "offset")
            base, b64 = self.appended
            if b64:
                end = self.data.find(b"<", base)
                nbytes, have = self._binary_size(base + off, end if end >= 0 else len(self.data), name)
            else:
                nbytes, have = self._raw_size(base + off, name)
        else:
            raise _bad(self.path, f"format={fmt!r} of array {name!r}")
        if nbytes % size:
            raise _bad(self.path, f"array {name!r}: {nbytes} bytes is not a whole number of {dtype} values")
        return nbytes // size

    def _words(self, raw: bytes, n: int) -> tuple[int, ...]:
        fmt = self.endian + ("Q" if self.header_size == 8 else "I") * n
        return struct.unpack(fmt, raw[: self.header_size * n])

    def _decoded(self, start: int, end: int, nbytes: int, name: str) -> bytes:
        """The first ``nbytes`` of the base64 text data[start:end] (whitespace skipped)."""
        chars = -(-nbytes // 3) * 4
        head = b""
        pos = start
        while len(head) < chars and pos < end:
            chunk = self.data[pos : min(end, pos + max(4 * chars, 256))]
            head += re.sub(rb"\s+", b"", chunk)
            pos += len(chunk)
        head = head[:chars]
        try:
            return base64.b64decode(head + b"=" * (-len(head) % 4))
        except (binascii.Error, ValueError):
            raise _bad(self.path, f"array {name!r}: invalid base64 data") from None

    def _binary_size(self, start: int, end: int, name: str) -> tuple[int, int]:
        """(uncompressed bytes, bytes present at most) of a base64 array in data[start:end]."""
        h = self.header_size
        text_len = end - start  # whitespace included: an upper bound of the base64 characters
        if self.compressed:
            head = self._decoded(start, end, 3 * h, name)
            if len(head) < 3 * h:
                raise _bad(self.path, f"array {name!r}: truncated block header")
            nblocks, block, last = self._words(head, 3)
            if nblocks > MAX_COUNT // max(block, 1):
                raise _bad(self.path, f"array {name!r}: block header out of range")
            head = self._decoded(start, end, (3 + nblocks) * h, name)
            if len(head) < (3 + nblocks) * h:
                raise _bad(self.path, f"array {name!r}: truncated block header")
            csizes = self._words(head, 3 + nblocks)[3:]
            total = 0 if nblocks == 0 else (nblocks - 1) * block + (last or block)
            present = text_len * 3 // 4 - (3 + nblocks) * h
            if sum(csizes) > present + 3:
                raise _bad(
                    self.path, f"array {name!r}: compressed data shorter than its header says (truncated?)"
                )
            return total, present
        head = self._decoded(start, end, h, name)
        if len(head) < h:
            raise _bad(self.path, f"array {name!r}: truncated length header")
        (nbytes,) = self._words(head, 1)
        present = text_len * 3 // 4 - h
        if nbytes > present + 3:
            raise _bad(
                self.path, f"array {name!r}: {nbytes} bytes announced, {max(present, 0)} present (truncated?)"
            )
        return nbytes, present

    def _raw_size(self, pos: int, name: str) -> tuple[int, int]:
        h = self.header_size
        data = self.data
        if self.compressed:
            head = data[pos : pos + 3 * h]
            if len(head) < 3 * h:
                raise _bad(self.path, f"array {name!r}: truncated block header")
            nblocks, block, last = self._words(head, 3)
            if nblocks > MAX_COUNT // max(block, 1) or pos + (3 + nblocks) * h > len(data):
                raise _bad(self.path, f"array {name!r}: block header out of range (truncated?)")
            csizes = self._words(data[pos : pos + (3 + nblocks) * h], 3 + nblocks)[3:]
            present = len(data) - pos - (3 + nblocks) * h
            if sum(csizes) > present:
                raise _bad(
                    self.path, f"array {name!r}: compressed data shorter than its header says (truncated?)"
                )
            total = 0 if nblocks == 0 else (nblocks - 1) * block + (last or block)
            return total, present
        head = data[pos : pos + h]
        if len(head) < h:
            raise _bad(self.path, f"array {name!r}: truncated length header")
        (nbytes,) = self._words(head, 1)
        present = len(data) - pos - h
        if nbytes > present:
            raise _bad(self.path, f"array {name!r}: {nbytes} bytes announced, {present} present (truncated?)")
        return nbytes, present

    def _piece(self, piece: _Piece, suffix: str) -> int:
        path = self.path
        npts = _int(path, piece.attrs, "NumberOfPoints", 0)
        if suffix == ".vtu":
            sections = {"Cells": _int(path, piece.attrs, "NumberOfCells", 0)}
        else:
            sections = {
                s: _int(path, piece.attrs, f"NumberOf{s}", 0) for s in ("Verts", "Lines", "Strips", "Polys")
            }
        ncells = sum(sections.values())
        conn_total = 0
        seen_points = False
        for arr in piece.arrays:
            n = self._values(arr)
            if n is None:
                continue
            name = arr.attrs.get("Name", "?")
            ncomp = _int(path, arr.attrs, "NumberOfComponents", 1)
            if ncomp == 0:
                raise _bad(path, f"array {name!r} declares 0 components")
            if "NumberOfTuples" in arr.attrs and arr.section != "FieldData":
                if _int(path, arr.attrs, "NumberOfTuples") * ncomp != n:
                    raise _bad(path, f"array {name!r}: NumberOfTuples disagrees with its data")
            if arr.section == "Points":
                seen_points = True
                self._expect(n, 3 * npts, f"{npts} points", "the Points array", ncomp=3)
            elif arr.section in sections:
                count = sections[arr.section]
                if name in ("offsets", "types"):
                    if name == "types" and suffix != ".vtu":
                        continue
                    self._expect(
                        n,
                        count,
                        f"{count} {'cells' if suffix == '.vtu' else arr.section.lower()}",
                        f"its {name} array",
                    )
                elif name == "connectivity":
                    conn_total += n
            elif arr.section == "PointData":
                self._expect(n, npts * ncomp, f"{npts} points", f"point array {name!r}", ncomp=ncomp)
            elif arr.section == "CellData":
                self._expect(n, ncells * ncomp, f"{ncells} cells", f"cell array {name!r}", ncomp=ncomp)
        if npts and not seen_points:
            raise _bad(path, f"a piece of {npts} points has no Points array")
        return conn_total

    def _expect(self, have: int, want: int, declared: str, what: str, ncomp: int = 1) -> None:
        if have != want:
            held = f"{have} values" if ncomp == 1 else f"{have} values ({have / ncomp:g} tuples of {ncomp})"
            raise _bad(
                self.path,
                f"the header disagrees with the data: the piece declares {declared} but {what} holds {held}",
            )


# ----------------------------------------------------------------------------- legacy

_LEGACY_SIZES = {
    "bit": 0,
    "unsigned_char": 1,
    "char": 1,
    "unsigned_short": 2,
    "short": 2,
    "unsigned_int": 4,
    "int": 4,
    "unsigned_long": 8,
    "long": 8,
    "float": 4,
    "double": 8,
    "vtkidtype": 4,
    "vtktypeint64": 8,
    "vtktypeuint64": 8,
    "vtktypeint32": 4,
    "vtktypeuint32": 4,
}
_CELL_SECTIONS = (b"CELLS", b"POLYGONS", b"LINES", b"VERTICES", b"TRIANGLE_STRIPS")
_NUMBER = re.compile(rb"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:nan|inf|infinity)", re.I)


class _Legacy:
    """A walk over the sections of a legacy file, counting what follows each keyword."""

    def __init__(self, path: Path, data: bytes):
        self.path, self.data = path, data

    def bad(self, what: str) -> InputFileError:
        return _bad(self.path, what)

    def check(self) -> Counts:
        lines = self.data.split(b"\n", 4)
        if len(lines) < 5 or not lines[0].startswith(b"# vtk DataFile Version"):
            raise self.bad("no '# vtk DataFile Version' line: not a legacy VTK file")
        try:
            self.version = float(lines[0].split()[-1])
        except (ValueError, IndexError):
            self.version = 3.0
        mode = lines[2].strip().upper()
        dataset = lines[3].split()
        if mode not in (b"ASCII", b"BINARY") or len(dataset) != 2 or dataset[0].upper() != b"DATASET":
            raise self.bad("bad format or DATASET line in the legacy header")
        kind = dataset[1].upper()
        if kind not in (b"UNSTRUCTURED_GRID", b"POLYDATA"):
            return Counts()  # other data sets are left to VTK (and the child process)
        body_start = len(self.data) - len(lines[4])
        if mode == b"ASCII":
            return self._ascii(body_start)
        return self._binary(body_start)

    # the declared size of what follows a keyword line: (values, value type) per block
    def _sizes(self, words: list[bytes], counts: dict) -> list[tuple[int, str]] | None:
        key = words[0].upper()
        try:
            if key == b"POINTS":
                n = self._count(words[1])
                counts["points"] = n
                return [(3 * n, words[2].decode().lower())]
            if key in _CELL_SECTIONS:
                a, b = self._count(words[1]), self._count(words[2])
                counts["cells"] = counts.get("cells", 0) + (a - 1 if self.version >= 5 and a else a)
                if self.version >= 5:
                    counts.setdefault("v5", []).append((a, b))
                    return []
                return [(b, "int")]
            if key == b"OFFSETS":
                a, _ = counts["v5"][-1]
                return [(a, words[1].decode().lower())]
            if key == b"CONNECTIVITY":
                _, b = counts["v5"][-1]
                counts["conn"] = counts.get("conn", 0) + b
                return [(b, words[1].decode().lower())]
            if key == b"CELL_TYPES":
                n = self._count(words[1])
                if n != counts.get("cells", n):
                    raise self.bad(
                        f"the header disagrees with the data: CELL_TYPES {n} for {counts['cells']} cells"
                    )
                return [(n, "int")]
            if key in (b"POINT_DATA", b"CELL_DATA"):
                n = self._count(words[1])
                want = counts.get("points" if key == b"POINT_DATA" else "cells")
                if want is not None and n != want:
                    what = "points" if key == b"POINT_DATA" else "cells"
                    raise self.bad(
                        f"the header disagrees with the data: {key.decode()} {n} for {want} {what}"
                    )
                counts["attr"] = n
                return []
            n = int(counts.get("attr", 0))
            if key == b"SCALARS":
                ncomp = self._count(words[3]) if len(words) > 3 else 1
                counts["pending"] = (n * ncomp, words[2].decode().lower())
                return []  # the values follow the LOOKUP_TABLE line
            if key == b"LOOKUP_TABLE":
                if "pending" in counts:
                    return [counts.pop("pending")]
                return [(4 * self._count(words[2]), "float")] if len(words) > 2 else []
            if key in (b"VECTORS", b"NORMALS"):
                return [(3 * n, words[2].decode().lower())]
            if key == b"TENSORS":
                return [(9 * n, words[2].decode().lower())]
            if key == b"TENSORS6":
                return [(6 * n, words[2].decode().lower())]
            if key == b"TEXTURE_COORDINATES":
                return [(self._count(words[2]) * n, words[3].decode().lower())]
            if key == b"COLOR_SCALARS":
                return [(self._count(words[2]) * n, "unsigned_char" if self.mode_binary else "float")]
            if key in (b"GLOBAL_IDS", b"PEDIGREE_IDS"):
                return [(n, words[2].decode().lower())]
            if key == b"FIELD":
                counts["field"] = self._count(words[2])
                return []
        except (IndexError, KeyError, UnicodeDecodeError):
            raise self.bad(
                f"bad legacy section line {' '.join(w.decode('latin-1') for w in words)!r}"
            ) from None
        return None

    def _count(self, word: bytes) -> int:
        if not re.fullmatch(rb"\d{1,20}", word):
            raise self.bad(f"bad count {word.decode('latin-1')!r} in a legacy section line")
        n = int(word)
        if n > MAX_COUNT:
            raise self.bad(f"count {n} out of range in a legacy section line")
        return n

    def _field_array(self, words: list[bytes]) -> tuple[int, str]:
        if len(words) != 4:
            raise self.bad(f"bad FIELD array line {b' '.join(words).decode('latin-1')!r}")
        ncomp, ntup = self._count(words[1]), self._count(words[2])
        return ncomp * ntup, words[3].decode("latin-1").lower()

    def _ascii(self, pos: int) -> Counts:
        self.mode_binary = False
        text = self.data[pos:]
        # METADATA blocks (VTK >= 9 writes them) run to a blank line: not counted
        text = re.sub(rb"(?m)^\s*METADATA\s*$.*?(?:\n\s*\n|\Z)", b"\n", text, flags=re.S)
        tokens = text.split()
        counts: dict = {}
        i, n = 0, len(tokens)
        while i < n:
            words = [tokens[i]]
            key = tokens[i].upper()
            # keyword lines have a known number of words
            width = {
                b"POINTS": 3,
                b"CELL_TYPES": 2,
                b"POINT_DATA": 2,
                b"CELL_DATA": 2,
                b"VECTORS": 3,
                b"NORMALS": 3,
                b"TENSORS": 3,
                b"TENSORS6": 3,
                b"TEXTURE_COORDINATES": 4,
                b"COLOR_SCALARS": 3,
                b"GLOBAL_IDS": 3,
                b"PEDIGREE_IDS": 3,
                b"FIELD": 3,
                b"OFFSETS": 2,
                b"CONNECTIVITY": 2,
                **dict.fromkeys(_CELL_SECTIONS, 3),
            }.get(key)
            if key == b"SCALARS":
                width = 4 if i + 3 < n and re.fullmatch(rb"\d+", tokens[i + 3]) else 3
            elif key == b"LOOKUP_TABLE":
                width = 3 if "pending" not in counts else 2
            if width is None:
                if _NUMBER.fullmatch(tokens[i]):
                    raise self.bad(
                        "the header disagrees with the data: more values than the sections declare"
                    )
                return Counts()  # an unknown keyword: left to VTK
            words = tokens[i : i + width]
            i += width
            blocks = self._sizes(words, counts)
            if key == b"FIELD":
                for _ in range(counts.pop("field")):
                    if i + 4 > n:
                        raise self.bad("FIELD arrays end early")
                    size, _ = self._field_array(tokens[i : i + 4])
                    i += 4
                    i = self._skip_numbers(tokens, i, size)
                continue
            for size, _ in blocks or []:
                i = self._skip_numbers(tokens, i, size)
        return Counts([counts.get("conn", 0)])

    def _skip_numbers(self, tokens: list[bytes], i: int, size: int) -> int:
        end = i + size
        if end > len(tokens) or (size and not _NUMBER.fullmatch(tokens[end - 1])):
            raise self.bad(
                "the header disagrees with the data: fewer values than a section declares (truncated?)"
            )
        if size and not _NUMBER.fullmatch(tokens[i]):
            raise self.bad("the header disagrees with the data: a section holds no values")
        if end < len(tokens) and _NUMBER.fullmatch(tokens[end]):
            raise self.bad("the header disagrees with the data: more values than a section declares")
        return end

    def _binary(self, pos: int) -> Counts:
        self.mode_binary = True
        data = self.data
        counts: dict = {}
        n = len(data)
        while pos < n:
            while pos < n and data[pos : pos + 1] in (b"\n", b"\r", b" ", b"\t"):
                pos += 1
            if pos >= n:
                break
            eol = data.find(b"\n", pos)
            line = data[pos : eol if eol >= 0 else n]
            words = line.split()
            if not words or not re.fullmatch(rb"[A-Za-z_][A-Za-z0-9_]*", words[0]):
                raise self.bad(
                    "the header disagrees with the data: binary data where a section keyword belongs"
                )
            if words[0].upper() == b"METADATA":
                end = data.find(b"\n\n", pos)
                pos = n if end < 0 else end + 2
                continue
            blocks = self._sizes(words, counts)
            if blocks is None:
                return Counts()  # unknown keyword: left to VTK
            pos = (eol if eol >= 0 else n) + 1
            if words[0].upper() == b"FIELD":
                for _ in range(counts.pop("field")):
                    eol = data.find(b"\n", pos)
                    if eol < 0:
                        raise self.bad("FIELD arrays end early")
                    size, dtype = self._field_array(data[pos:eol].split())
                    pos = self._skip_bytes(eol + 1, size, dtype)
                continue
            for size, dtype in blocks:
                pos = self._skip_bytes(pos, size, dtype)
        return Counts([counts.get("conn", 0)])

    def _skip_bytes(self, pos: int, size: int, dtype: str) -> int:
        width = _LEGACY_SIZES.get(dtype)
        if width is None:
            raise self.bad(f"unknown data type {dtype!r}")
        nbytes = (size + 7) // 8 if width == 0 else size * width
        if pos + nbytes > len(self.data):
            raise self.bad(
                "the header disagrees with the data: fewer bytes than a section declares (truncated?)"
            )
        return pos + nbytes
