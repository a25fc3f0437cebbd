"""Checks of VTK XML files before VTK reads them (see `vtkcheck`).

Serial files (``.vtu .vtp``), structured grids (``.vts .vtr``: the counts follow from
the piece's ``Extent``), multi-block files (``.vtm``) and parallel files (``.pvtu
.pvtp``). The files a ``.vtm`` or a parallel file points at must lie in its folder (or
below), be regular files, have the suffix of their kind and pass these same checks; a
parallel file may not list a piece twice. Attribute values are decoded in the encoding
of the XML declaration (UTF-8 without one), as VTK's XML parser decodes them. The
arrays' lengths (and their base64 text) are read by `fepost.reader.xmlarrays`.
"""

from __future__ import annotations

import codecs
import mmap
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputFileError
from .checks import (
    MAX_COUNT,
    MAX_DEPTH,
    MAX_VTM_DEPTH,
    RELEASE_STEP,
    Counts,
    bad_file,
    inside_folder,
    refuse_netcdf,
    regular_file,
    release,
)
from .xmlarrays import ArrayLengths, DataArray, int_attr

_ROOT = {
    ".vtu": "UnstructuredGrid",
    ".vtp": "PolyData",
    ".vtm": "vtkMultiBlockDataSet",
    ".vts": "StructuredGrid",
    ".vtr": "RectilinearGrid",
    ".pvtu": "PUnstructuredGrid",
    ".pvtp": "PPolyData",
}
#: The suffix of the pieces of a parallel file.
_PIECE_SUFFIX = {".pvtu": ".vtu", ".pvtp": ".vtp"}
#: Most pieces a parallel file may list.
MAX_PIECES = 4096
#: The tag after which raw bytes may follow: the tag scan ends there.
_APPENDED = b"<AppendedData"
_TAG = re.compile(
    rb"<!--.*?-->|<\?.*?\?>|<!\[CDATA\[.*?\]\]>|<(/?)([A-Za-z_][\w:.-]*)((?:[^>\"']|\"[^\"]*\"|'[^']*')*)>",
    re.S,
)
#: Elements that label the DataArrays inside them with their name, up to their end tag.
#: FieldData labels the arrays after it too (they are not checked against a piece's
#: counts), but its end tag does not clear the label.
_SECTIONS = frozenset(
    {b"Points", b"Cells", b"Verts", b"Lines", b"Strips", b"Polys", b"PointData", b"CellData", b"Coordinates"}
)
_ATTR = re.compile(rb"([A-Za-z_][\w:.-]*)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")


_DECLARED = re.compile(rb"<\?xml[^>]*?encoding\s*=\s*[\"']([A-Za-z][A-Za-z0-9._-]{0,39})[\"']")


def _encoding(path: Path, prologue: bytes) -> str:
    """The encoding the XML declaration names (UTF-8 without one)."""
    m = _DECLARED.search(prologue[:1024])
    name = m.group(1).decode("ascii") if m else "utf-8"
    try:
        return codecs.lookup(name).name
    except LookupError:
        raise bad_file(path, f"the XML declaration names the unknown encoding {name!r}") from None


@dataclass
class Piece:
    """A ``Piece`` tag: its attributes and its data arrays in file order."""

    attrs: dict[str, str]
    arrays: list[DataArray] = field(default_factory=list)


class Xml(ArrayLengths):
    """The structure of one VTK XML file, checked by `check`.

    ``verify``: also check every base64 array's text as VTK's reader will decode it
    (`fepost.reader.b64text`: damaged text would come out of VTK as zeros or shifted
    values without an error). The direct decoder, which checks the text as it decodes
    it, passes False.
    """

    def __init__(self, path: Path, data: bytes | mmap.mmap, depth: int, verify: bool = True):
        self.path, self.data, self.depth, self.verify = path, data, depth, verify

    def check(self) -> Counts:
        path, data = self.path, self.data
        refuse_netcdf(path, data)
        suffix = path.suffix.lower()
        # one walk over the file: the tag scan stops at <AppendedData (raw bytes may follow)
        first = data.find(b"<VTKFile")
        prologue = data[: first if first >= 0 else min(len(data), 1 << 16)]
        if re.search(rb"<!(DOCTYPE|ENTITY)", prologue, re.I):
            raise bad_file(
                path, "refused: XML with DOCTYPE/ENTITY declarations (not a VTK file; entity expansion)"
            )
        self.encoding = _encoding(path, prologue)
        root, pieces, refs, cut = self._scan(len(data))
        self.root, self.pieces = root, pieces  # the structure, for the direct decoder (`vtkdirect`)
        want = _ROOT.get(suffix)
        if root.get("type") != want:
            raise bad_file(path, f"not a VTK XML {want} file: VTKFile type={root.get('type')!r}")
        self.header_size = 8 if root.get("header_type", "UInt32") == "UInt64" else 4
        if root.get("header_type", "UInt32") not in ("UInt32", "UInt64"):
            raise bad_file(path, f"header_type={root.get('header_type')!r}")
        self.endian = ">" if root.get("byte_order", "LittleEndian") == "BigEndian" else "<"
        self.compressed = bool(root.get("compressor"))
        self.appended = self._appended(cut)
        self.offsets, self.stream_end = self._stream(pieces)
        counts = Counts()
        if suffix == ".vtm":
            self._check_refs(refs, (".vtu", ".vtp", ".vtm"), "multi-block piece")
            return counts
        if suffix in _PIECE_SUFFIX:
            if not pieces:
                raise bad_file(path, "a parallel file that lists no pieces")
            if len(pieces) > MAX_PIECES:
                raise bad_file(path, f"refused: {len(pieces)} pieces (at most {MAX_PIECES})")
            sources = [p.attrs.get("Source", "") for p in pieces]
            if not all(sources):
                raise bad_file(path, "a Piece without its Source file")
            return self._check_refs(sources, (_PIECE_SUFFIX[suffix],), "piece")
        for piece in pieces:
            counts.connectivity.append(self._piece(piece, suffix))
        return counts

    def _tags(self, limit: int):
        """(position, match) of the tags before ``limit``, found with bytes.find (array contents
        hold no '<'); the match is None for an unclosed AppendedData tag. The pages walked are
        let go every `RELEASE_STEP` bytes, those of the last stretch kept: the decoder reads
        them next."""
        data, pos = self.data, 0
        behind = 0  # the pages before this were let go
        while True:
            pos = data.find(b"<", pos, limit)
            if pos < 0:
                return
            if pos - behind > RELEASE_STEP:
                release(data, behind, pos)
                behind = pos
            m = _TAG.match(data, pos, limit)
            if m is None and data[pos : pos + len(_APPENDED)] != _APPENDED:
                raise bad_file(self.path, "a '<' that opens no XML tag")
            yield pos, m
            if m is None:
                return
            pos = m.end()

    def _scan(self, limit: int):
        data = self.data
        stack: list[bytes] = []
        root: dict[str, str] | None = None
        pieces: list[Piece] = []
        refs: list[str] = []
        section = ""
        cut = -1
        for pos, m in self._tags(limit):
            if m is None or (m.group(2) == b"AppendedData" and not m.group(1)):
                cut = pos  # raw bytes may follow (holding a '<'): the structure ends here
                break
            closing, name, rest = m.group(1), m.group(2), m.group(3)
            if name is None:
                continue  # comment, processing instruction, CDATA
            selfclose = rest.rstrip().endswith(b"/")
            if closing:
                if not stack or stack[-1] != name:
                    raise bad_file(self.path, f"unexpected XML tag </{name.decode('latin-1')}>")
                stack.pop()
                if name in _SECTIONS:
                    section = ""
                continue
            attrs = {
                k.decode("latin-1"): self._text(a if a is not None else b or b"")
                for k, a, b in _ATTR.findall(rest)
            }
            if root is None:
                if name != b"VTKFile":
                    raise bad_file(self.path, "no VTKFile element: not a VTK XML file")
                root = attrs
            if name == b"Piece":
                pieces.append(Piece(attrs))
            elif name in _SECTIONS or name == b"FieldData":
                section = name.decode()
            elif name == b"DataArray" and pieces:
                end = data.find(b"<", m.end(), limit)
                end = m.end() if selfclose else (end if end >= 0 else limit)
                pieces[-1].arrays.append(DataArray(attrs, section, m.end(), end))
            elif name == b"DataSet" and "file" in attrs:
                refs.append(attrs["file"])
            if not selfclose:
                stack.append(name)
                if len(stack) > MAX_DEPTH:
                    raise bad_file(self.path, f"refused: XML nested more than {MAX_DEPTH} levels deep")
        if root is None:
            raise bad_file(self.path, "no VTKFile element: not a VTK XML file")
        if stack and cut < 0:
            raise bad_file(self.path, f"XML element <{stack[-1].decode('latin-1')}> is not closed")
        return root, pieces, refs, cut

    def _text(self, raw: bytes) -> str:
        """An attribute's value in the file's encoding (UTF-8 unless its XML declaration says
        otherwise, as for VTK's XML parser); bytes that are not in it as Latin-1."""
        try:
            return raw.decode(self.encoding)
        except UnicodeDecodeError:
            return raw.decode("latin-1")

    def _appended(self, cut: int) -> tuple[int, bool] | None:
        if cut < 0:
            return None
        close = self.data.find(b">", cut)
        if close < 0:
            raise bad_file(self.path, "AppendedData element is not closed")
        attrs = dict(
            (k.decode("latin-1"), (a or b).decode("latin-1"))
            for k, a, b in _ATTR.findall(self.data[cut:close])
        )
        mark = self.data.find(b"_", close)
        if mark < 0:
            raise bad_file(self.path, "AppendedData without its '_' marker")
        return mark + 1, attrs.get("encoding", "raw") == "base64"

    def _stream(self, pieces: list[Piece]) -> tuple[tuple[int, ...], int]:
        """(the appended arrays' offsets, sorted; the end of the base64 AppendedData text)."""
        if self.appended is None or not self.appended[1]:
            return (), len(self.data)
        offsets = {
            int(a.attrs["offset"])
            for p in pieces
            for a in p.arrays
            if a.attrs.get("format") == "appended" and a.attrs.get("offset", "").strip().isdigit()
        }
        end = self.data.find(b"<", self.appended[0])
        return tuple(sorted(offsets)), end if end >= 0 else len(self.data)

    def _check_refs(self, refs: list[str], suffixes: tuple[str, ...], what: str) -> Counts:
        if self.depth >= MAX_VTM_DEPTH:
            raise bad_file(self.path, f"refused: multi-block files nested more than {MAX_VTM_DEPTH} deep")
        counts = Counts()
        seen: set[Path] = set()
        for ref in refs:
            sub = inside_folder(self.path, ref, what)
            if sub.suffix.lower() not in suffixes:
                kind = "VTK XML" if len(suffixes) > 1 else suffixes[0]
                raise bad_file(self.path, f"{what} {ref!r} is not a {kind} file")
            if sub == self.path.resolve():
                whole = "multi-block" if what.startswith("multi") else "parallel"
                raise bad_file(self.path, f"{whole} file refers to itself")
            if what == "piece" and sub in seen:
                raise bad_file(
                    self.path, f"refused: piece {ref!r} is listed twice; its nodes would count twice"
                )
            seen.add(sub)
            regular_file(self.path, sub, ref, what)
            try:
                counts.connectivity += check_xml(sub, self.depth + 1).connectivity
            except InputFileError as exc:
                raise InputFileError(f"{self.path}: {what} {ref!r} refused: {exc}") from None
        return counts

    # -- array lengths --

    def _extent(self, attrs: dict[str, str]) -> tuple[int, int, int]:
        """Points along each axis of a structured piece, from its ``Extent``."""
        words = attrs.get("Extent", "").split()
        if len(words) != 6 or not all(re.fullmatch(r"[+-]?\d{1,10}", w) for w in words):
            raise bad_file(self.path, f"Extent={attrs.get('Extent')!r} is not six integers")
        lo, hi = [int(w) for w in words[0::2]], [int(w) for w in words[1::2]]
        dims = tuple(b - a + 1 for a, b in zip(lo, hi, strict=True))
        if min(dims) < 1 or dims[0] * dims[1] * dims[2] > MAX_COUNT:
            raise bad_file(self.path, f"Extent={attrs['Extent']!r} is out of range")
        return dims  # type: ignore[return-value]

    def _piece(self, piece: Piece, suffix: str) -> int:
        path = self.path
        dims: tuple[int, int, int] | None = None
        if suffix in (".vts", ".vtr"):
            dims = self._extent(piece.attrs)
            npts = dims[0] * dims[1] * dims[2]
            sections = {"Cells": max(dims[0] - 1, 1) * max(dims[1] - 1, 1) * max(dims[2] - 1, 1)}
        elif suffix == ".vtu":
            npts = int_attr(path, piece.attrs, "NumberOfPoints", 0)
            sections = {"Cells": int_attr(path, piece.attrs, "NumberOfCells", 0)}
        else:
            npts = int_attr(path, piece.attrs, "NumberOfPoints", 0)
            sections = {
                s: int_attr(path, piece.attrs, f"NumberOf{s}", 0)
                for s in ("Verts", "Lines", "Strips", "Polys")
            }
        ncells = sum(sections.values())
        conn_total = 0
        seen_points = dims is not None and suffix == ".vtr"  # a rectilinear grid has Coordinates
        axis = 0
        for arr in piece.arrays:
            n = self._values(arr)
            if n is None:
                continue
            name = arr.attrs.get("Name", "?")
            ncomp = int_attr(path, arr.attrs, "NumberOfComponents", 1)
            if ncomp == 0:
                raise bad_file(path, f"array {name!r} declares 0 components")
            if "NumberOfTuples" in arr.attrs and arr.section != "FieldData":
                if int_attr(path, arr.attrs, "NumberOfTuples") * ncomp != n:
                    raise bad_file(path, f"array {name!r}: NumberOfTuples disagrees with its data")
            if arr.section == "Points":
                seen_points = True
                self._expect(n, 3 * npts, f"{npts} points", "the Points array", ncomp=3)
            elif arr.section == "Coordinates" and dims is not None:
                if axis > 2:
                    raise bad_file(path, "a rectilinear piece with more than 3 Coordinates arrays")
                want = dims[axis]
                self._expect(n, want, f"{want} points along axis {axis}", f"coordinate array {name!r}")
                axis += 1
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
            raise bad_file(path, f"a piece of {npts} points has no Points array")
        if dims is not None and suffix == ".vtr" and axis != 3:
            raise bad_file(path, f"a rectilinear piece with {axis} Coordinates arrays instead of 3")
        return conn_total

    def _expect(self, have: int, want: int, declared: str, what: str, ncomp: int = 1) -> None:
        if have != want:
            held = f"{have} values" if ncomp == 1 else f"{have} values ({have / ncomp:g} tuples of {ncomp})"
            raise bad_file(
                self.path,
                f"the header disagrees with the data: the piece declares {declared} but {what} holds {held}",
            )


def check_xml(path: Path, depth: int = 0) -> Counts:
    """Check the VTK XML file ``path`` (its suffix says which kind); raise `InputFileError` if it fails."""
    try:
        with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
            return Xml(path, data, depth).check()
    except InputFileError:
        raise
    except (OSError, ValueError) as exc:
        raise bad_file(path, f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None
