"""Checks of XDMF files (``.xdmf`` + heavy data in ``.h5``) before meshio reads them.

An XDMF file is XML that names arrays: inline (``Format="XML"``), in an HDF5 file
(``Format="HDF"``, ``file.h5:/group/dataset``) or in a raw binary file
(``Format="Binary"``). meshio trusts all of it: it opens whatever HDF5 path the
text names, reads raw files relative to the *working directory*, and reshapes
arrays to the declared ``Dimensions`` (an error deep inside numpy when they
disagree). This module refuses, before meshio sees the file:

* ENTITY declarations (entity expansion; a DOCTYPE without them, as dolfinx
  writes, is read), nesting deeper than
  `MAX_DEPTH`, XML that does not parse, a root other than ``Xdmf``;
* ``xi:include`` of another file (an ``href``: only includes inside the file,
  as dolfinx writes them, are read);
* ``Dimensions`` that are not positive integers within `MAX_COUNT`;
* inline arrays whose value count differs from their ``Dimensions``;
* ``Format="Binary"`` arrays (raw bytes named relative to the working
  directory: not read; write HDF5);
* inline values that are not numbers of the item's type (named with the item);
* HDF5 references to files outside the XDMF file's folder, to files that do
  not exist, are not regular files (a FIFO is never opened) or are not HDF5
  (signature), to datasets the file does not hold, or to datasets whose size
  differs from the declared ``Dimensions``; HDF5 links are followed one by one and
  an external link, a virtual dataset's source or external raw storage outside
  the folder is refused (h5py would follow it anywhere).

The HDF5 files are opened with h5py for their structure only (no array is
read). Like every check here it runs in the reading child (`fepost.reader.isolate`).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputFileError
from .checks import MAX_COUNT, MAX_DEPTH, bad_file, inside_folder, regular_file

#: The 8 bytes an HDF5 file starts with (at offset 0, 512, 1024, 2048, ... after a user block).
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
#: Largest XDMF (XML) file read: the heavy data belongs in the HDF5 file.
MAX_XML_BYTES = 256 << 20
_XINCLUDE = tuple(
    f"{{{scheme}://www.w3.org/{year}/XInclude}}include"
    for scheme in ("http", "https")
    for year in (2001, 2003)
)


@dataclass
class XdmfLayout:
    """What a checked XDMF file holds: its version and whether it is a time series."""

    version: str
    temporal: int = 0  # number of Temporal collections (one per function in dolfinx files)
    heavy: list[Path] = field(default_factory=list)  # the HDF5 files it reads
    datasets: list[tuple[str, Path, str]] = field(default_factory=list)  # (as named, file, dataset)


def _hdf5(path: Path, target: Path, ref: str) -> None:
    with open(target, "rb") as fh:
        head = fh.read(8)
        offset = 512
        size = target.stat().st_size
        while head != HDF5_SIGNATURE and offset + 8 <= size:
            fh.seek(offset)
            head = fh.read(8)
            offset *= 2
    if head != HDF5_SIGNATURE:
        raise bad_file(path, f"heavy-data file {ref!r} is not an HDF5 file")


def _dims(path: Path, item: ET.Element) -> int:
    text = item.get("Dimensions", "")
    words = text.split()
    if not words or not all(re.fullmatch(r"\d{1,12}", w) for w in words):
        raise bad_file(path, f"DataItem Dimensions={text!r} is not a list of integers")
    total = 1
    for w in words:
        total *= int(w)
        if total > MAX_COUNT:
            raise bad_file(path, f"DataItem Dimensions={text!r} is out of range")
    return total


class _Heavy:
    """The HDF5 files an XDMF file names, each opened once (structure only)."""

    def __init__(self, path: Path):
        self.path = path
        self.folder = path.parent.resolve()
        self.files: dict[Path, Any] = {}
        self.datasets: list[tuple[str, Path, str]] = []  # (as named, file, dataset) of every HDF item

    def size(self, ref: str, dataset: str) -> int:
        import h5py

        target = inside_folder(self.path, ref, "heavy-data file")
        if target not in self.files:
            regular_file(self.path, target, ref, "heavy-data file")
            _hdf5(self.path, target, ref)
            try:
                self.files[target] = h5py.File(target, "r")
            except (OSError, ValueError):
                raise bad_file(
                    self.path, f"heavy-data file {ref!r} is damaged: HDF5 cannot open it (its superblock)"
                ) from None
        try:
            node = self._follow(self.files[target], dataset, ref)
        except InputFileError:
            raise
        except (OSError, KeyError, RuntimeError, ValueError):
            raise bad_file(
                self.path, f"heavy-data file {ref!r}: dataset {dataset!r} is damaged (its HDF5 metadata)"
            ) from None
        if not isinstance(node, h5py.Dataset):
            raise bad_file(self.path, f"heavy-data file {ref!r} holds no dataset {dataset!r}")
        self._stored_inside(node, ref, dataset)
        self.datasets.append((ref, target, dataset))
        return int(node.size)

    def _outside(self, ref: str, dataset: str, how: str, name: str):
        return bad_file(
            self.path,
            f"refused: heavy-data file {ref!r}: dataset {dataset!r} reaches {name!r} through {how}, "
            "which lies outside the file's folder",
        )

    def _follow(self, h5, dataset: str, ref: str, hops: int = 0, named: str = ""):
        """The object at ``dataset`` in the open file ``h5``, its HDF5 links followed one by one:
        an external link must name a regular file inside the XDMF file's folder (HDF5 would open
        any file it names), soft links are followed from the root (at most `MAX_LINKS` hops)."""
        import h5py

        named = named or dataset
        if hops > MAX_LINKS:
            raise bad_file(
                self.path,
                f"refused: heavy-data file {ref!r}: dataset {dataset!r}: more than {MAX_LINKS} links",
            )
        node = h5["/"]
        parts = [part for part in dataset.split("/") if part]
        for k, part in enumerate(parts):
            if not isinstance(node, h5py.Group):
                return None
            link = node.get(part, getlink=True)
            if link is None:
                return None
            if isinstance(link, h5py.SoftLink):
                rest = "/".join([link.path.rstrip("/"), *parts[k + 1 :]])
                return self._follow(node.file, rest, ref, hops + 1, named)
            if isinstance(link, h5py.ExternalLink):
                base = Path(node.file.filename).parent
                target = (base / link.filename).resolve()
                if not target.is_relative_to(self.folder):
                    raise self._outside(ref, named, "an HDF5 external link", link.filename)
                regular_file(self.path, target, link.filename, "heavy-data file (external link)")
                _hdf5(self.path, target, link.filename)
                hops += 1
            node = node[part]
            opened = Path(node.file.filename).resolve()
            if not opened.is_relative_to(self.folder):
                raise self._outside(ref, named, "an HDF5 link", str(opened))
        return node

    def _stored_inside(self, node, ref: str, dataset: str) -> None:
        """Refuse a dataset whose values live in other files: external raw storage or the
        sources of a virtual dataset outside the folder."""
        base = Path(node.file.filename).parent
        for name, *_ in node.external or ():
            raw = name.decode("utf-8", "replace") if isinstance(name, bytes) else str(name)
            if not (base / raw).resolve().is_relative_to(self.folder):
                raise self._outside(ref, dataset, "external raw storage", raw)
        if node.is_virtual:
            for source in node.virtual_sources():
                if source.file_name != "." and not (base / source.file_name).resolve().is_relative_to(
                    self.folder
                ):
                    raise self._outside(ref, dataset, "a virtual dataset", source.file_name)

    def close(self) -> None:
        for f in self.files.values():
            f.close()


#: Most HDF5 links followed from an XDMF item to its dataset.
MAX_LINKS = 16


def _label(item: ET.Element, parents: dict[ET.Element, ET.Element]) -> str:
    """The DataItem as a reader finds it: its name, or the element it belongs to."""
    if item.get("Name"):
        return f"DataItem {item.get('Name')!r}"
    owner = parents.get(item)
    if owner is None:
        return "a DataItem"
    named = f" {owner.get('Name')!r}" if owner.get("Name") else ""
    return f"the DataItem of {owner.tag}{named}"


def _inline_values(path: Path, item: ET.Element, text: str, label: str) -> None:
    """Refuse inline values that are not numbers of the item's type (meshio would stop at the
    first and fail to reshape: a message that names neither the item nor the token)."""
    kind = item.get("DataType") or item.get("NumberType") or "Float"
    integer = kind in ("Int", "UInt", "Char", "UChar")
    words = text.split()
    try:
        np.array(words, dtype=np.int64 if integer else np.float64)
        return
    except (ValueError, OverflowError):
        pass
    for word in words:
        try:
            int(word) if integer else float(word)
        except ValueError:
            raise bad_file(path, f"{label}: inline value {word[:40]!r} is not a {kind} number") from None


def _item(path: Path, item: ET.Element, heavy: _Heavy, label: str) -> None:
    if "Reference" in item.attrib:
        return  # a reference to another DataItem of this file
    want = _dims(path, item)
    fmt = item.get("Format", "XML")
    text = (item.text or "").strip()
    if fmt == "XML":
        have = len(text.split())
        if have != want:
            raise bad_file(
                path,
                f"the header disagrees with the data: {label} of Dimensions "
                f"{item.get('Dimensions')!r} holds {have} values",
            )
        _inline_values(path, item, text, label)
    elif fmt == "HDF":
        ref, sep, dataset = text.partition(":")
        if not sep or not ref or not dataset.strip() or ":" in dataset:
            raise bad_file(path, f"HDF DataItem {text[:80]!r} is not 'file.h5:/dataset'")
        have = heavy.size(ref, dataset.strip())
        if have != want:
            raise bad_file(
                path,
                f"the header disagrees with the data: {ref}:{dataset.strip()} holds {have} values, "
                f"the DataItem declares Dimensions {item.get('Dimensions')!r}",
            )
    elif fmt == "Binary":
        raise bad_file(
            path, 'refused: Format="Binary" data (a raw file named from the working directory); write HDF5'
        )
    else:
        raise bad_file(path, f"DataItem Format={fmt!r} is not XML, HDF or Binary")


def _tree(path: Path) -> ET.Element:
    size = path.stat().st_size
    if size > MAX_XML_BYTES:
        raise bad_file(
            path, f"refused: {size} bytes of XML (at most {MAX_XML_BYTES}; heavy data goes to HDF5)"
        )
    data = path.read_bytes()
    first = data.find(b"<Xdmf")
    prologue = data[: first if first >= 0 else 1 << 16]
    # dolfinx writes <!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>: a DOCTYPE is fine, entity declarations are not
    if re.search(rb"<!ENTITY", prologue, re.I):
        raise bad_file(path, "refused: XML with ENTITY declarations (entity expansion)")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise bad_file(path, f"not well-formed XML ({exc})") from None
    stack = [(root, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise bad_file(path, f"refused: XML nested more than {MAX_DEPTH} levels deep")
        stack.extend((child, depth + 1) for child in node)
    if root.tag != "Xdmf":
        raise bad_file(path, f"not an XDMF file (root element <{root.tag[:40]}>)")
    return root


def check_xdmf(path: Path) -> XdmfLayout:
    """Check the XDMF file ``path`` and the HDF5 files it names; raise `InputFileError` if it fails."""
    try:
        root = _tree(path)
    except OSError as exc:
        raise bad_file(path, f"cannot read ({exc.strerror or exc})") from None
    version = root.get("Version", "")
    if not re.fullmatch(r"[23](\.\d+)*", version):
        raise bad_file(path, f"XDMF Version={version!r} (versions 2 and 3 are read)")
    heavy = _Heavy(path)
    parents = {child: node for node in root.iter() for child in node}
    try:
        for node in root.iter():
            if node.tag in _XINCLUDE and node.get("href"):
                raise bad_file(path, f"refused: xi:include of another file ({node.get('href')!r})")
            if node.tag == "DataItem":
                _item(path, node, heavy, _label(node, parents))
        layout = XdmfLayout(version, heavy=list(heavy.files), datasets=heavy.datasets)
    finally:
        heavy.close()
    domain = root.find("Domain")
    if domain is None:
        raise bad_file(path, "no Domain element")
    layout.temporal = sum(
        1
        for g in domain.findall("Grid")
        if g.get("GridType") == "Collection" and g.get("CollectionType") == "Temporal"
    )
    return layout


__all__ = ["HDF5_SIGNATURE", "MAX_XML_BYTES", "XdmfLayout", "check_xdmf"]
