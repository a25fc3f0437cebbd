"""Checks of legacy VTK files (``.vtk``, ASCII or binary) before VTK reads them (see `vtkcheck`)."""

from __future__ import annotations

import mmap
import re
from pathlib import Path

from ..errors import InputFileError
from .checks import MAX_COUNT, Counts, bad_file, refuse_netcdf

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
    "signed_char": 1,
}
#: Array types whose values are not fixed-size numbers (strings, variants): a FIELD block holding
#: one is left to VTK from there on (the child process still guards the read).
_UNCOUNTED = ("string", "utf8_string", "variant", "unicode_string")
_CELL_SECTIONS = (b"CELLS", b"POLYGONS", b"LINES", b"VERTICES", b"TRIANGLE_STRIPS")
_NUMBER = re.compile(rb"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:nan|inf|infinity)", re.I)


class Legacy:
    """A walk over the sections of a legacy file, counting what follows each keyword."""

    def __init__(self, path: Path, data: bytes | mmap.mmap):
        self.path, self.data = path, data

    def bad(self, what: str) -> InputFileError:
        return bad_file(self.path, what)

    def check(self) -> Counts:
        refuse_netcdf(self.path, self.data)
        lines, pos = [], 0
        for _ in range(4):  # the four header lines, found without copying the body
            eol = self.data.find(b"\n", pos)
            if eol < 0:
                break
            lines.append(self.data[pos:eol])
            pos = eol + 1
        if len(lines) < 4 or not lines[0].startswith(b"# vtk DataFile Version"):
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
        body_start = pos
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
                    if i < n and tokens[i] == b"NULL_ARRAY":
                        i += 1
                        continue
                    if i + 4 > n:
                        raise self.bad("FIELD arrays end early")
                    size, dtype = self._field_array(tokens[i : i + 4])
                    if dtype in _UNCOUNTED:
                        return Counts()  # strings are not numbers: left to VTK
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
            pos = self._gap(pos)
            if pos >= n:
                break
            eol = data.find(b"\n", pos)
            line = data[pos : eol if eol >= 0 else n]
            words = line.split()
            if not words or not re.fullmatch(rb"[A-Za-z_][A-Za-z0-9_]*", words[0]):
                raise self.bad(
                    "the header disagrees with the data: binary data where a section keyword belongs"
                )
            blocks = self._sizes(words, counts)
            if blocks is None:
                return Counts()  # unknown keyword: left to VTK
            pos = (eol if eol >= 0 else n) + 1
            if words[0].upper() == b"FIELD":
                for _ in range(counts.pop("field")):
                    # each array's binary values end with a newline, and may be followed by METADATA
                    pos = self._gap(pos)
                    eol = data.find(b"\n", pos)
                    if eol < 0:
                        raise self.bad("FIELD arrays end early")
                    words = data[pos:eol].split()
                    if words == [b"NULL_ARRAY"]:
                        pos = eol + 1
                        continue
                    size, dtype = self._field_array(words)
                    if dtype in _UNCOUNTED:
                        return Counts()  # strings are not numbers: left to VTK
                    pos = self._skip_bytes(eol + 1, size, dtype)
                continue
            for size, dtype in blocks:
                pos = self._skip_bytes(pos, size, dtype)
        return Counts([counts.get("conn", 0)])

    def _gap(self, pos: int) -> int:
        """The position after the whitespace and METADATA blocks (text up to a blank line) at ``pos``."""
        data, n = self.data, len(self.data)
        while True:
            while pos < n and data[pos : pos + 1] in (b"\n", b"\r", b" ", b"\t"):
                pos += 1
            if data[pos : pos + 8].upper() != b"METADATA":
                return pos
            end = data.find(b"\n\n", pos)
            pos = n if end < 0 else end + 2

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
