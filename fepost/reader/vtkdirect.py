"""Serial VTK XML files (``.vtu .vtp``) decoded with numpy, zlib and lzma instead of VTK.

Why fepost decodes these itself
-------------------------------
A contact field needs the points, the cells, the pressure and the displacement.
VTK's XML readers are general: on a 1.08 M-node surface ``.vtu`` (41 MB, zlib,
inline base64) importing them takes 0.38 s, asking for the arrays' names
(``UpdateInformation``) parses the whole inline file once (0.26 s) and the read
parses it again and inflates every block on one thread (0.80 s). The binary
layout of the format is small and documented ("VTK File Formats", VTK User's
Guide): a length header or a block table, then raw, zlib or LZMA blocks, inline
in base64 or appended raw or base64. Decoding only the arrays the field needs,
the base64 with ``pybase64`` (vectorised, it lets go of the GIL: 1.6 GB/s here
against 0.28 GB/s for ``binascii``) and the blocks inflated on two threads (zlib
and lzma release the GIL; zlib by ISA-L where ``isal`` is installed, `ZLIB`),
takes 0.24 s on that file (0.29 s with the standard zlib) and never imports VTK.
Text that is not strict base64 (line breaks) is decoded by ``binascii``'s lenient
decoder once it is known to hold only the alphabet, padding and whitespace; where
that stops short at padding inside the stream (a length header encoded on its own),
the text is decoded group by group as VTK reads it (`fepost.reader.b64text`).

What is decoded here, and what is not
-------------------------------------
The structure comes from the pre-read check (`fepost.reader.xmlcheck`), which
has already compared every array's length with what its piece declares. Taken:
one ``Piece``; every array binary (inline base64, appended raw or base64);
uncompressed, zlib or LZMA; ``UInt32``/``UInt64`` headers; either byte order.
Anything else — ASCII arrays, LZ4, several pieces, arrays that share a name,
cell types outside 0-255 — returns None and VTK reads the file as before.

The point arrays the field does not need are not decoded: they stay in the
`fepost.reader.raw.RawMesh` as loaders (the same choice as
`fepost.reader.vtkselect` makes for VTK). The arrays then go through the
assembly VTK's path uses (`fepost.reader.vtkassemble`), so both give identical
meshes (``tests/test_read_direct_vtk.py`` compares them on every writer's file).
A block that does not inflate to its declared size, damaged base64 (a character
outside the alphabet, padding inside a group, text that decodes to fewer bytes than
the header announces: VTK would read zeros there) or a file changed under a loader
is an `fepost.errors.InputFileError` naming the file and the array.
"""

from __future__ import annotations

import binascii
import importlib
import lzma
import mmap
import os
import struct
import zlib
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pybase64

from ..errors import InputFileError
from . import b64text
from .cells import SPECS, VTK_TYPES
from .checks import release
from .names import ArrayInfo, needed_point_arrays
from .raw import RawMesh, defer_point_arrays
from .transfer import fresh_array, reserve
from .vtkassemble import POLY_SECTIONS, Part, assemble, no_cells, poly_cells
from .xmlarrays import NUMPY_TYPES, DataArray, text_end
from .xmlcheck import Xml

#: Suffixes the direct decoder may take (serial unstructured grids and polygonal data).
DIRECT_SUFFIXES = (".vtu", ".vtp")


def _zlib_module():
    """ISA-L's zlib-compatible inflate (``isal``, in the ``fast`` extra) where installed: about
    twice the standard zlib's speed on these blocks and the same bytes; else the standard zlib."""
    try:
        return importlib.import_module("isal.isal_zlib")
    except ImportError:
        return zlib


#: The zlib inflater (`_zlib_module`).
ZLIB = _zlib_module()


def _zlib(block, limit: int) -> bytes:
    """A zlib block inflated to at most ``limit`` + 1 bytes (a block that inflates to more
    than its header says is refused without inflating it all: no zip bomb)."""
    return ZLIB.decompressobj().decompress(block, limit + 1)


def _lzma(block, limit: int) -> bytes:
    """An LZMA (xz) block inflated to at most ``limit`` + 1 bytes (see `_zlib`)."""
    return lzma.LZMADecompressor().decompress(block, max_length=limit + 1)


_INFLATE: dict[str, Callable[[Any, int], bytes]] = {
    "vtkZLibDataCompressor": _zlib,
    "vtkLZMADataCompressor": _lzma,
}
_FORMATS = {".vtu": "VTK XML (.vtu)", ".vtp": "VTK XML (.vtp)"}
#: Blocks inflated per thread task (a compressed array of more blocks is shared by two threads).
_BATCH = 64
#: Compressed blocks up to this size (bytes) are inflated once per distinct content (`_inflation`).
_SAME_MAX = 1024
_SPACE = b" \t\r\n"
_CELL_SECTIONS = ("Cells", *(name for name, _ in POLY_SECTIONS))


class _NotHere(Exception):
    """The file is valid but not one this decoder takes: VTK reads it."""


@dataclass(frozen=True)
class _Format:
    """What every array of a file shares: header word size, byte order, inflater, appended data."""

    path: Path
    header: int
    endian: Literal["<", ">"]
    inflate: Callable[[Any, int], bytes] | None
    appended: tuple[int, bool] | None  # (first byte, base64?) of the AppendedData
    text_end: Callable[[int], int] | None = None  # where an appended base64 array's text ends


def read_direct(path: Path, *, field: str | None = None, displacement: str | None = "auto") -> RawMesh | None:
    """The `RawMesh` of a serial ``.vtu``/``.vtp`` file, or None where VTK must read it.

    ``field`` and ``displacement`` choose the point arrays decoded now (as in
    `fepost.reader.read_contact`); the others are decoded when asked for.

    Raises
    ------
    InputFileError
        The file fails the pre-read check or its data does not decode.
    """
    suffix = path.suffix.lower()
    stamp = _stamp(path)
    with open(path, "rb") as fh:
        data = _mapped(fh)
        try:
            xml = Xml(path, data, 0, verify=False)
            try:
                xml.check()
            except InputFileError:
                raise
            except (OSError, ValueError) as exc:
                raise InputFileError(f"{path}: cannot read ({exc})") from None
            try:
                fmt = _format(xml)
                piece = _piece(xml)
                part, lazy = _decode_piece(fmt, data, piece, suffix, field, displacement)
            except _NotHere:
                return None
        finally:
            _unmap(data)
    if len(part.points) == 0:
        raise InputFileError(f"{path}: the file holds no mesh (0 nodes or 0 cells)")
    reserve(_answer_size(part))  # the answer's memory allocated while the mesh is assembled
    raw = assemble(path, [part], _FORMATS[suffix])
    if lazy:
        _add_lazy(raw, fmt, piece, lazy, stamp)
    return raw


def _answer_size(part: Part) -> int:
    """About the bytes a reading child answers with for ``part`` (`fepost.reader.transfer.reserve`):
    a surface mesh's points, connectivity and decoded arrays; 0 for a mesh with cells of
    another dimension (a volume mesh's answer is its boundary, a small part of it)."""
    present = np.flatnonzero(np.bincount(part.types, minlength=256)).tolist() if len(part.types) else []
    if any(t not in VTK_TYPES or SPECS[VTK_TYPES[t][0]].dim != 2 for t in present):
        return 0
    arrays = [*part.point_data.values(), *part.cell_data.values()]
    return part.points.nbytes + part.conn.nbytes + sum(a.nbytes for a in arrays)


def _mapped(fh) -> mmap.mmap:
    """The whole file mapped read-only. Its pages are not mapped ahead (``MAP_POPULATE``):
    a solver's file is mostly arrays that are never decoded, and mapped pages count in the
    process's memory."""
    return mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)


def _unmap(data: mmap.mmap) -> None:
    """Close the map; while an error's traceback still holds views of it, leave that to the
    garbage collector (every decoded array is a copy: nothing returned views the map)."""
    try:
        data.close()
    except BufferError:
        pass


def _stamp(path: Path) -> tuple[int, int]:
    st = os.stat(path)
    return st.st_size, st.st_mtime_ns


def _format(xml: Xml) -> _Format:
    compressor = xml.root.get("compressor", "")
    if compressor and compressor not in _INFLATE:
        raise _NotHere  # LZ4 and unknown compressors: VTK's
    endian: Literal["<", ">"] = ">" if xml.endian == ">" else "<"
    ends = None
    if xml.appended is not None:  # plain numbers only: the format travels with the lazy loaders
        ends = partial(text_end, xml.appended[0], xml.offsets, xml.stream_end)
    return _Format(xml.path, xml.header_size, endian, _INFLATE.get(compressor), xml.appended, ends)


def _piece(xml: Xml):
    if len(xml.pieces) != 1:
        raise _NotHere
    piece = xml.pieces[0]
    for arr in piece.arrays:
        if arr.section != "FieldData" and arr.attrs.get("format", "ascii") not in ("binary", "appended"):
            raise _NotHere  # ASCII arrays: VTK's
    return piece


def _named(piece, section: str) -> dict[str, DataArray]:
    """The numeric arrays of ``section`` by name, in file order (strings and unnamed ones passed over)."""
    out: dict[str, DataArray] = {}
    for arr in piece.arrays:
        if arr.section != section:
            continue
        name = arr.attrs.get("Name", "")
        if not name or arr.attrs.get("type") == "String":
            continue
        if name in out:
            raise _NotHere  # two arrays of one name: VTK's rule decides
        out[name] = arr
    return out


def _components(arr: DataArray) -> tuple[int, tuple[str, ...]]:
    """(component count, component names as VTK gives them: none unless some are set)."""
    ncomp = int(arr.attrs.get("NumberOfComponents", "1") or 1)
    names = [arr.attrs.get(f"ComponentName{k}", "") for k in range(ncomp)] if ncomp > 1 else []
    return ncomp, tuple(names) if any(names) else ()


def _decode_piece(fmt, data, piece, suffix, field, displacement) -> tuple[Part, dict]:
    points_arrays = [a for a in piece.arrays if a.section == "Points"]
    npts = int(piece.attrs.get("NumberOfPoints", "0") or 0)
    if len(points_arrays) != (1 if npts else 0):
        raise _NotHere
    point_arrays, cell_arrays = _named(piece, "PointData"), _named(piece, "CellData")
    keep = _chosen(fmt.path, point_arrays, cell_arrays, field, displacement)
    with ThreadPoolExecutor(2) as pool:
        wanted = [a for a in piece.arrays if a.section in _CELL_SECTIONS or a.section == "Points"]
        wanted += [a for n, a in point_arrays.items() if keep is None or n in keep]
        wanted += list(cell_arrays.values())
        jobs = {id(a): _Job(fmt, data, a, lead=_is_offsets(a)) for a in wanted}
        for job in sorted(jobs.values(), key=lambda j: -len(j.out)):
            job.start(pool)  # the largest first: the two threads finish together

        def decode(arr: DataArray, lead: bool = False) -> np.ndarray | None:
            return jobs[id(arr)].led() if lead else jobs[id(arr)].result()

        points = decode(points_arrays[0]) if npts else np.empty(0)
        points = np.asarray(points, float).reshape(npts, 3)
        types, off, con = _vtu_cells(piece, decode) if suffix == ".vtu" else _vtp_cells(piece, decode)
        components: dict[str, tuple[str, ...]] = {}
        point_data = _arrays(point_arrays, npts, decode, components, keep)
        cell_data = _arrays(cell_arrays, len(types), decode, components, None)
    lazy = {name: arr for name, arr in point_arrays.items() if name not in point_data}
    return Part(points, types, off, con, point_data, cell_data, components), lazy


def _chosen(path, point_arrays, cell_arrays, field, displacement) -> set[str] | None:
    """The point arrays to decode now (None: all of them, as when the choice needs the data)."""
    catalogue = [ArrayInfo(n, "point", *_components(a)) for n, a in point_arrays.items()]
    catalogue += [
        ArrayInfo(n, "cell", *_components(a)) for n, a in cell_arrays.items() if n not in point_arrays
    ]
    return needed_point_arrays(str(path), catalogue, field, displacement)


def _arrays(arrays, n, decode, components, keep) -> dict[str, np.ndarray]:
    out = {}
    for name, arr in arrays.items():
        ncomp, names = _components(arr)
        if names:
            components.setdefault(name, names)
        if keep is not None and name not in keep:
            continue
        values = decode(arr)
        out[name] = values if ncomp == 1 else values.reshape(n, ncomp)
    return out


def _section(piece, section: str) -> dict[str, DataArray]:
    return {a.attrs.get("Name", ""): a for a in piece.arrays if a.section == section}


def _is_offsets(arr: DataArray) -> bool:
    """Whether ``arr`` is the offsets array of a cell section (decoded after a 0: `_Job`)."""
    return arr.section in _CELL_SECTIONS and arr.attrs.get("Name") == "offsets"


def _cell_arrays(piece, section: str, decode, count: int) -> tuple[np.ndarray, np.ndarray]:
    """(offsets (count + 1), connectivity) of one cell section."""
    arrays = _section(piece, section)
    if "offsets" not in arrays or "connectivity" not in arrays:
        raise _NotHere
    led = decode(arrays["offsets"], lead=True)  # 64-bit offsets: inflated after a 0, no copy
    if led is not None and led.dtype == np.int64 and len(led) == count + 1:
        return led, np.asarray(decode(arrays["connectivity"]), np.int64)
    ends = np.asarray(decode(arrays["offsets"]), np.int64)
    off = np.empty(count + 1, np.int64)
    off[0] = 0
    off[1:] = ends
    return off, np.asarray(decode(arrays["connectivity"]), np.int64)


def _vtu_cells(piece, decode):
    count = int(piece.attrs.get("NumberOfCells", "0") or 0)
    if count == 0:
        return no_cells()
    arrays = _section(piece, "Cells")
    if "types" not in arrays:
        raise _NotHere
    types = decode(arrays["types"])
    if types.dtype != np.uint8 and len(types) and (types.min() < 0 or types.max() > 255):
        raise _NotHere  # VTK would wrap them to unsigned char
    off, con = _cell_arrays(piece, "Cells", decode, count)
    return types.astype(np.uint8, copy=False), off, con


def _vtp_cells(piece, decode):
    sections = []
    for name, vtype in POLY_SECTIONS:
        count = int(piece.attrs.get(f"NumberOf{name}", "0") or 0)
        if count:
            sections.append((vtype, *_cell_arrays(piece, name, decode, count)))
    return poly_cells(sections)


# ----------------------------------------------------------------------------- decoding one array


class _Job:
    """One binary array being decoded: the header read and the base64 decoded when made, the
    blocks inflated by `start` (on a thread pool or at once), `result` waits for them.

    The base64 of every array is decoded before any block is inflated (a small share of the
    time), then the largest arrays' blocks go first so that the two threads finish together;
    starting each array's blocks as soon as its base64 was decoded measured no faster.
    """

    def __init__(self, fmt: _Format, data, arr: DataArray, lead: bool = False):
        self.fmt, self.name = fmt, arr.attrs.get("Name") or arr.section or "?"
        self.dtype = np.dtype(NUMPY_TYPES[arr.attrs["type"]]).newbyteorder(fmt.endian)
        # ``lead``: one zero value before the array's own, where that needs no conversion (the
        # cell offsets of an XML file are the ends of the cells: VTK's offsets start with 0)
        self.lead = self.dtype.itemsize if lead and self.dtype.isnative else 0
        words, body = self._payload(data, arr)
        self.tasks: list = []
        self.runs: list = []
        if fmt.inflate is None:
            self.full = _plain(fmt, words, body, self.name, self.lead)
        else:
            self.full, self.runs = _inflation(fmt, words, body, self.name, self.lead)
        self.out = self.full[self.lead :]

    def start(self, pool: ThreadPoolExecutor | None = None) -> _Job:
        """Inflate the blocks: on ``pool``, or here and now without one."""
        runs, self.runs = self.runs, []
        if pool is None:
            for run in runs:
                run()
        else:
            self.tasks = [pool.submit(run) for run in runs]
        return self

    def _payload(self, data, arr: DataArray) -> tuple[tuple[int, ...], memoryview]:
        fmt = self.fmt
        if arr.attrs.get("format") != "appended":
            start, end = arr.start, arr.end
        elif fmt.appended is None:
            raise InputFileError(
                f"{fmt.path}: array {self.name!r} is appended but the file has no AppendedData"
            )
        else:
            base, b64 = fmt.appended
            start = base + int(arr.attrs["offset"])
            if not b64:
                return _raw_payload(fmt, data, start, self.name)
            assert fmt.text_end is not None
            end = fmt.text_end(int(arr.attrs["offset"]))
        while start < end and data[start] in _SPACE:
            start += 1
        while end > start and data[end - 1] in _SPACE:
            end -= 1
        text = memoryview(data)[start:end]
        try:
            return _base64_payload(fmt, text, self.name, inline=arr.attrs.get("format") != "appended")
        finally:
            del text
            release(data, start, end)  # decoded: the text's pages are not needed again

    def result(self) -> np.ndarray:
        """The values, 1-D, native byte order, writable."""
        for task in self.tasks:
            task.result()
        out = self.out
        if len(out) % self.dtype.itemsize:
            raise InputFileError(
                f"{self.fmt.path}: array {self.name!r}: {len(out)} bytes is not a whole number of values"
            )
        values = out.view(self.dtype)
        return values if self.dtype.isnative else values.astype(self.dtype.newbyteorder("="))

    def led(self) -> np.ndarray | None:
        """0 and then the values (`result` checked), or None when the job was made without
        room for the 0 (``lead``)."""
        self.result()
        return self.full.view(self.dtype) if self.lead else None


def _values(fmt: _Format, data, arr: DataArray) -> np.ndarray:
    """The values of one binary array (decoded on the calling thread)."""
    return _Job(fmt, data, arr).start().result()


def _words(fmt: _Format, raw, n: int) -> tuple[int, ...]:
    return struct.unpack(fmt.endian + ("Q" if fmt.header == 8 else "I") * n, bytes(raw[: fmt.header * n]))


def _b64(fmt: _Format, text, name: str) -> bytes:
    """The bytes of base64 ``text``: strict base64 by pybase64, anything else by binascii's
    lenient decoder (which skips line breaks and stops at padding) once the text is known to
    hold nothing but the alphabet, padding and whitespace (binascii would skip anything else)."""
    try:
        return pybase64.b64decode(text, validate=True)
    except ValueError:
        pass  # not strict base64: decoded leniently below (the same bytes where both decode)
    chunk = bytes(text)
    if chunk.translate(None, b64text.ALPHABET + b"=" + _SPACE):
        raise _damaged(fmt, name, b64text.Damaged(b64text.describe(chunk, skip=_SPACE)))
    try:
        return binascii.a2b_base64(chunk)
    except (binascii.Error, ValueError):
        raise InputFileError(f"{fmt.path}: array {name!r}: invalid base64 data") from None


def _damaged(fmt: _Format, name: str, exc: b64text.Damaged) -> InputFileError:
    return InputFileError(f"{fmt.path}: array {name!r}: damaged base64 data ({exc})")


def _groups(fmt: _Format, text, name: str, want: int, inline: bool) -> bytes:
    """The array's whole text decoded group by group as VTK reads it (padding inside the
    stream: a length header encoded on its own), at least ``want`` bytes, or the error
    naming the damage."""
    chunk = bytes(text).translate(None, _SPACE) if inline else bytes(text)
    try:
        decoded = b64text.decode_groups(chunk)
    except b64text.Damaged as exc:
        raise _damaged(fmt, name, exc) from None
    if len(decoded) < want:
        raise _damaged(
            fmt,
            name,
            b64text.Damaged(f"it decodes to {len(decoded)} bytes, its header announces {want}"),
        )
    return decoded


def _chars(nbytes: int) -> int:
    """Base64 characters that encode ``nbytes`` bytes (padding included)."""
    return b64text.chars(nbytes)


def _spaced(text) -> bool:
    """True when the (short) base64 text holds whitespace."""
    chunk = bytes(text)
    return len(chunk.translate(None, _SPACE)) != len(chunk)


def _base64_payload(fmt: _Format, text, name: str, inline: bool) -> tuple[tuple[int, ...], memoryview]:
    """(header words, the bytes after the header) of a base64 array.

    Compressed: the block table is encoded on its own, the blocks follow in one stream.
    Not compressed: the length word and the values are one stream (as VTK reads them).
    The header is found by counting characters, so text broken into lines before its
    end is first joined; after it, ``a2b_base64`` passes whitespace over (inline arrays
    run to the end of their element; appended ones by count).
    """
    h = fmt.header
    head = _chars(h if fmt.inflate is None else 3 * h)
    if _spaced(text[:head]):
        text = bytes(text).translate(None, _SPACE)
    if fmt.inflate is None:
        nbytes = _words(fmt, _b64(fmt, text[:head], name), 1)[0] if len(text) >= head else 0
        decoded = _b64(fmt, text if inline else text[: _chars(h + nbytes)], name)
        if len(decoded) < h + nbytes:  # padding inside the stream (the length encoded on its own), or damage
            decoded = _groups(fmt, text, name, h + nbytes, inline)
        return (nbytes,), memoryview(decoded)[h : h + nbytes]
    first = _b64(fmt, text[:head], name)
    if len(first) < 3 * h:
        raise InputFileError(f"{fmt.path}: array {name!r}: truncated block header")
    nblocks = _words(fmt, first, 1)[0]
    chars = _chars((3 + nblocks) * h)
    if _spaced(text[:chars]):
        text = bytes(text).translate(None, _SPACE)
    words = _words(fmt, _b64(fmt, text[:chars], name), 3 + nblocks)
    need = sum(words[3:])
    body = _b64(fmt, text[chars:] if inline else text[chars : chars + _chars(need)], name)
    if len(body) < need:  # padding inside the stream, or damage
        body = _groups(fmt, text[chars:], name, need, inline)
    return words, memoryview(body)


def _raw_payload(fmt: _Format, data, start: int, name: str) -> tuple[tuple[int, ...], memoryview]:
    """(header words, the bytes after the header) of an appended raw array."""
    h = fmt.header
    nblocks = _words(fmt, data[start : start + h], 1)[0]
    if fmt.inflate is None:
        return (nblocks,), memoryview(data)[start + h : start + h + nblocks]
    words = _words(fmt, data[start : start + (3 + nblocks) * h], 3 + nblocks)
    body = start + (3 + nblocks) * h
    return words, memoryview(data)[body : body + sum(words[3:])]


def _plain(fmt: _Format, words: tuple[int, ...], body: memoryview, name: str, lead: int = 0) -> np.ndarray:
    """The buffer of an uncompressed array: ``lead`` zero bytes, then its ``words[0]`` bytes."""
    if len(body) < words[0]:
        raise InputFileError(f"{fmt.path}: array {name!r}: truncated data")
    out = fresh_array(lead + words[0], np.uint8)
    out[lead:] = np.frombuffer(body, np.uint8, count=words[0])
    return out


def _inflation(fmt: _Format, words: tuple[int, ...], body: memoryview, name: str, lead: int = 0):
    """(the output buffer, ``lead`` zero bytes and then the inflated bytes, and the functions
    that inflate the blocks into it, `_BATCH` blocks each)."""
    nblocks, block, last = words[0], words[1], words[2]
    sizes = words[3:]
    total = 0 if nblocks == 0 else (nblocks - 1) * block + (last or block)
    whole = fresh_array(lead + total, np.uint8)  # a forked reader's pages are all new: huge pages
    out = whole[lead:]
    starts = np.concatenate(([0], np.cumsum(sizes, dtype=np.int64))).tolist()
    if starts[-1] > len(body):
        raise InputFileError(f"{fmt.path}: array {name!r}: compressed data shorter than its header says")
    inflate = fmt.inflate
    assert inflate is not None
    # inflating is a function of the compressed bytes: a small compressed block (a run of one
    # value, as the cell types of a mesh of one cell type) met again is copied, not inflated
    seen: dict[tuple[bytes, int], np.ndarray] = {}

    def run(first: int, stop: int) -> None:
        for i in range(first, stop):
            want = block if i < nblocks - 1 or not last else last
            key = (bytes(body[starts[i] : starts[i + 1]]), want) if sizes[i] <= _SAME_MAX else None
            again = seen.get(key) if key is not None else None
            if again is not None:
                out[i * block : i * block + want] = again
                continue
            try:
                got = inflate(body[starts[i] : starts[i + 1]], want)
            except (zlib.error, ZLIB.error, lzma.LZMAError, ValueError, EOFError):
                raise InputFileError(
                    f"{fmt.path}: array {name!r}: block {i + 1} does not decompress"
                ) from None
            if len(got) != want:
                held = f"more than {want}" if len(got) > want else f"{len(got)}"
                raise InputFileError(
                    f"{fmt.path}: array {name!r}: block {i + 1} inflates to {held} bytes, "
                    f"its header says {want}"
                )
            out[i * block : i * block + want] = np.frombuffer(got, np.uint8)
            if key is not None:
                seen[key] = np.frombuffer(got, np.uint8)

    return whole, [partial(run, i, min(i + _BATCH, nblocks)) for i in range(0, nblocks, _BATCH)]


# ----------------------------------------------------------------------------- arrays decoded later


def _add_lazy(raw: RawMesh, fmt: _Format, piece, lazy: dict[str, DataArray], stamp) -> None:
    """Put the point arrays not decoded back into ``raw``, in file order, as loaders."""
    n = len(raw.points)
    deferred = {}
    for name, arr in lazy.items():
        ncomp, names = _components(arr)
        deferred[name] = (partial(_load, fmt, arr, n, ncomp, stamp), ncomp, names)
    defer_point_arrays(raw, list(_named(piece, "PointData")), deferred)


def _load(fmt: _Format, arr: DataArray, n: int, ncomp: int, stamp) -> np.ndarray:
    """One point array decoded on demand (refused if the file changed since it was read)."""
    name = arr.attrs.get("Name", "?")
    try:
        if _stamp(fmt.path) != stamp:
            raise InputFileError(f"{fmt.path}: point array {name!r}: the file changed after it was read")
        with open(fmt.path, "rb") as fh:
            data = _mapped(fh)
            try:
                values = _values(fmt, data, arr)
            finally:
                _unmap(data)
    except OSError as exc:
        raise InputFileError(
            f"{fmt.path}: cannot read point array {name!r} ({exc.strerror or exc})"
        ) from None
    except _NotHere:
        raise InputFileError(f"{fmt.path}: cannot decode point array {name!r}") from None
    return values if ncomp == 1 else values.reshape(n, ncomp)


__all__ = ["DIRECT_SUFFIXES", "read_direct"]
