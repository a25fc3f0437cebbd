"""The lengths of the data arrays of a VTK XML file, read from their headers (`xmlcheck`).

Each binary array starts with a length word or a table of compressed blocks, inline in
base64 or appended raw or base64; an ASCII array is counted by its tokens. Nothing is
decoded but those header words; with ``verify`` the base64 text is checked as VTK's
reader will decode it (`fepost.reader.b64text`). `ArrayLengths` is the part of
`fepost.reader.xmlcheck.Xml` that does this; `text_end` says where an appended array's
text ends (the direct decoder, `fepost.reader.vtkdirect`, uses it too).
"""

from __future__ import annotations

import base64
import binascii
import bisect
import mmap
import re
import struct
from dataclasses import dataclass
from pathlib import Path

from . import b64text
from .checks import MAX_COUNT, bad_file

#: The numpy type code of each numeric ``type`` attribute (`vtkdirect` decodes with it) ...
NUMPY_TYPES = {
    "Int8": "i1",
    "UInt8": "u1",
    "Int16": "i2",
    "UInt16": "u2",
    "Int32": "i4",
    "UInt32": "u4",
    "Int64": "i8",
    "UInt64": "u8",
    "Float32": "f4",
    "Float64": "f8",
}
#: ... and its size in bytes.
_SIZES = {name: int(code[1]) for name, code in NUMPY_TYPES.items()}


def int_attr(path: Path, attrs: dict[str, str], key: str, default: int | None = None) -> int:
    if key not in attrs:
        if default is None:
            raise bad_file(path, f"missing {key}")
        return default
    text = attrs[key].strip()
    if not re.fullmatch(r"[+-]?\d{1,20}", text):
        raise bad_file(path, f"{key}={attrs[key]!r} is not an integer")
    value = int(text)
    if value < 0 or value > MAX_COUNT:
        raise bad_file(path, f"{key}={value} is out of range")
    return value


@dataclass
class DataArray:
    """A ``DataArray`` tag: its attributes, the element it sits in, where its inline content lies."""

    attrs: dict[str, str]
    section: str
    start: int  # inline content (ascii numbers or base64): data[start:end]
    end: int


class ArrayLengths:
    """Array lengths from their headers; the file's state (``path``, ``data``, ``header_size``,
    ``endian``, ``compressed``, ``appended``, ``offsets``, ``stream_end``, ``verify``) is set by
    the check that uses it."""

    path: Path
    data: bytes | mmap.mmap
    header_size: int
    endian: str
    compressed: bool
    appended: tuple[int, bool] | None
    offsets: tuple[int, ...]
    stream_end: int
    verify: bool

    def text_end(self, offset: int) -> int:
        """Where the base64 text of the appended array at ``offset`` ends: at the next array's
        offset, or at the end of the AppendedData text."""
        assert self.appended is not None
        return text_end(self.appended[0], self.offsets, self.stream_end, offset)

    def _values(self, arr: DataArray) -> int | None:
        """Number of values the array holds (None: a string array, not counted)."""
        a = arr.attrs
        dtype = a.get("type", "")
        if dtype == "String":
            if a.get("format", "ascii") == "ascii":  # the bytes of the strings, each ended by a 0
                return self.data[arr.start : arr.end].split().count(b"0")
            return None
        size = _SIZES.get(dtype)
        if size is None:
            raise bad_file(self.path, f"unknown data type {dtype!r} of array {a.get('Name', '?')!r}")
        fmt = a.get("format", "ascii")
        name = a.get("Name", "?")
        if fmt == "ascii":
            return len(self.data[arr.start : arr.end].split())
        if fmt == "binary":
            nbytes, have = self._binary_size(arr.start, arr.end, name)
        elif fmt == "appended":
            if self.appended is None:
                raise bad_file(self.path, f"array {name!r} is appended but the file has no AppendedData")
            off = int_attr(self.path, a, "offset")
            base, b64 = self.appended
            if b64:
                nbytes, have = self._binary_size(base + off, self.text_end(off), name)
            else:
                nbytes, have = self._raw_size(base + off, name)
        else:
            raise bad_file(self.path, f"format={fmt!r} of array {name!r}")
        if nbytes % size:
            raise bad_file(
                self.path, f"array {name!r}: {nbytes} bytes is not a whole number of {dtype} values"
            )
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
            raise bad_file(self.path, f"array {name!r}: invalid base64 data") from None

    def _binary_size(self, start: int, end: int, name: str) -> tuple[int, int]:
        """(uncompressed bytes, bytes present at most) of a base64 array in data[start:end]."""
        h = self.header_size
        text_len = end - start  # whitespace included: an upper bound of the base64 characters
        if self.compressed:
            head = self._decoded(start, end, 3 * h, name)
            if len(head) < 3 * h:
                raise bad_file(self.path, f"array {name!r}: truncated block header")
            nblocks, block, last = self._words(head, 3)
            if nblocks > MAX_COUNT // max(block, 1):
                raise bad_file(self.path, f"array {name!r}: block header out of range")
            head = self._decoded(start, end, (3 + nblocks) * h, name)
            if len(head) < (3 + nblocks) * h:
                raise bad_file(self.path, f"array {name!r}: truncated block header")
            csizes = self._words(head, 3 + nblocks)[3:]
            total = 0 if nblocks == 0 else (nblocks - 1) * block + (last or block)
            present = text_len * 3 // 4 - (3 + nblocks) * h
            if sum(csizes) > present + 3:
                raise bad_file(
                    self.path, f"array {name!r}: compressed data shorter than its header says (truncated?)"
                )
            self._verify(start, end, (3 + nblocks) * h + sum(csizes), name)
            return total, present
        head = self._decoded(start, end, h, name)
        if len(head) < h:
            raise bad_file(self.path, f"array {name!r}: truncated length header")
        (nbytes,) = self._words(head, 1)
        present = text_len * 3 // 4 - h
        if nbytes > present + 3:
            raise bad_file(
                self.path, f"array {name!r}: {nbytes} bytes announced, {max(present, 0)} present (truncated?)"
            )
        self._verify(start, end, h + nbytes, name)
        return nbytes, present

    def _verify(self, start: int, end: int, need: int, name: str) -> None:
        """Refuse base64 text VTK's reader would decode to other bytes than it holds (`verify`)."""
        if not self.verify:
            return
        why = b64text.problem(self.data, start, end, need)
        if why is not None:
            raise bad_file(self.path, f"array {name!r}: damaged base64 data ({why})")

    def _raw_size(self, pos: int, name: str) -> tuple[int, int]:
        h = self.header_size
        data = self.data
        if self.compressed:
            head = data[pos : pos + 3 * h]
            if len(head) < 3 * h:
                raise bad_file(self.path, f"array {name!r}: truncated block header")
            nblocks, block, last = self._words(head, 3)
            if nblocks > MAX_COUNT // max(block, 1) or pos + (3 + nblocks) * h > len(data):
                raise bad_file(self.path, f"array {name!r}: block header out of range (truncated?)")
            csizes = self._words(data[pos : pos + (3 + nblocks) * h], 3 + nblocks)[3:]
            present = len(data) - pos - (3 + nblocks) * h
            if sum(csizes) > present:
                raise bad_file(
                    self.path, f"array {name!r}: compressed data shorter than its header says (truncated?)"
                )
            total = 0 if nblocks == 0 else (nblocks - 1) * block + (last or block)
            return total, present
        head = data[pos : pos + h]
        if len(head) < h:
            raise bad_file(self.path, f"array {name!r}: truncated length header")
        (nbytes,) = self._words(head, 1)
        present = len(data) - pos - h
        if nbytes > present:
            raise bad_file(
                self.path, f"array {name!r}: {nbytes} bytes announced, {present} present (truncated?)"
            )
        return nbytes, present


def text_end(base: int, offsets: tuple[int, ...], stream_end: int, offset: int) -> int:
    """Where the text of the appended array at ``offset`` ends (``base``: the first byte of the
    AppendedData text, ``offsets``: every appended array's, sorted; ``stream_end``: its end)."""
    k = bisect.bisect_right(offsets, offset)
    return min(base + offsets[k], stream_end) if k < len(offsets) else stream_end


__all__ = ["NUMPY_TYPES", "ArrayLengths", "DataArray", "int_attr", "text_end"]
