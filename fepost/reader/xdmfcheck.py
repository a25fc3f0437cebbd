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
  differs from the declared ``Dimensions``. The dataset path is split as meshio
  splits it and its HDF5 links are followed one by one as HDF5 follows them
  (soft links from their group or the root, external links next to the file
  that holds them); then every HDF5 file opened is scanned whole: an external
  link, a virtual dataset's source or external raw storage anywhere in it that
  names a file outside the folder, absolute or relative, is refused, naming the
  link, and so is one naming a file that is not there (HDF5 would then look for
  it in the working directory). The files reached are scanned in turn.

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
    """The HDF5 files an XDMF file names, each opened once (structure only).

    The heavy data are found next to the XDMF file's real path (symbolic links resolved, as
    meshio does) and nothing may lead out of that folder. Every HDF5 file opened is scanned
    whole: an external link, a virtual dataset's source or external raw storage anywhere in it
    must name a file inside the folder, as HDF5 resolves it (a link or source that is not
    there is refused too: HDF5 would then look for it in the working directory), whatever
    path the XDMF file names; the files those reach are scanned in turn.
    """

    def __init__(self, path: Path):
        self.path = path
        self.folder = path.resolve().parent
        self.files: dict[Path, Any] = {}
        self.scanned: set[Path] = set()
        self.refs: dict[Path, tuple[str, bool]] = {}  # (the XDMF file's name for it, named there?)
        self.seen = 0  # links and objects visited by the scans
        self.datasets: list[tuple[str, Path, str]] = []  # (as named, file, dataset) of every HDF item

    def size(self, ref: str, dataset: str) -> int:
        import h5py

        target = inside_folder(self.path, ref, "heavy-data file", folder=self.folder)
        # the keys meshio walks: one leading '/' dropped, the rest split at every '/'
        keys = (dataset[1:] if dataset.startswith("/") else dataset).split("/")
        if not all(keys):
            raise bad_file(self.path, f"HDF DataItem dataset {dataset!r} has an empty name in its path")
        try:
            self._open(target, ref, ref)
            node = self._follow(self.files[target], keys, ref, dataset)
            if isinstance(node, h5py.Dataset):
                self._stored_inside(node, ref, f"dataset {dataset!r}")
        except InputFileError:
            raise
        except (OSError, KeyError, RuntimeError, ValueError):
            raise bad_file(
                self.path, f"heavy-data file {ref!r}: dataset {dataset!r} is damaged (its HDF5 metadata)"
            ) from None
        if not isinstance(node, h5py.Dataset):
            raise bad_file(self.path, f"heavy-data file {ref!r} holds no dataset {dataset!r}")
        self.datasets.append((ref, target, dataset))
        return int(node.size)

    def _open(self, target: Path, name: str, ref: str) -> None:
        """Open ``target`` (named ``name``), a regular HDF5 file inside the folder, once."""
        import h5py

        if target in self.files:
            return
        self.refs[target] = (ref, name == ref)
        what = "heavy-data file" if name == ref else f"heavy-data file {ref!r}: linked file"
        regular_file(self.path, target, name, what)
        _hdf5(self.path, target, name)
        try:
            self.files[target] = h5py.File(target, "r")
        except (OSError, ValueError):
            raise bad_file(
                self.path, f"{what} {name!r} is damaged: HDF5 cannot open it (its superblock)"
            ) from None

    def _outside(self, ref: str, subject: str, how: str, name: str):
        """The refusal of ``subject`` (a dataset or a link, named) reaching ``name`` outside the folder."""
        return bad_file(
            self.path,
            f"refused: heavy-data file {ref!r}: {subject} reaches {name!r} through {how}, "
            "which lies outside the file's folder",
        )

    def _linked(self, holder: str, name: str, ref: str, subject: str, how: str) -> Path:
        """The file an external link or a virtual dataset's source ``name`` in the HDF5 file
        ``holder`` opens: HDF5 looks next to ``holder`` first (an absolute name as it is); it
        must lie inside the folder and be there (else HDF5 looks in the working directory)."""
        if "%" in name:  # a virtual source's pattern (%b: the file's own base name)
            raise self._outside(ref, subject, f"{how} named by a pattern", name)
        target = (Path(holder).parent / name).resolve()
        if not target.is_relative_to(self.folder):
            raise self._outside(ref, subject, how, name)
        if not target.exists():
            raise bad_file(
                self.path,
                f"refused: heavy-data file {ref!r}: {subject} reaches {name!r} through {how}, "
                "which is not in the file's folder (HDF5 would look for it in the working directory)",
            )
        return target

    def _follow(self, h5, keys: list[str], ref: str, dataset: str):
        """The object at the path ``keys`` in the open file ``h5``, its HDF5 links followed one by
        one as HDF5 does (soft links from the root or from their group, external links from
        the target file's root; at most `MAX_LINKS` hops); None where nothing is there."""
        import h5py

        node, todo, hops = h5["/"], list(keys), 0
        while todo:
            part = todo.pop(0)
            if part in ("", "."):
                continue
            if not isinstance(node, h5py.Group):
                return None
            link = node.get(part, getlink=True)
            if link is None:
                return None
            if isinstance(link, (h5py.SoftLink, h5py.ExternalLink)):
                hops += 1
                if hops > MAX_LINKS:
                    raise bad_file(
                        self.path,
                        f"refused: heavy-data file {ref!r}: dataset {dataset!r}: more than {MAX_LINKS} links",
                    )
                if isinstance(link, h5py.ExternalLink):
                    how = "an HDF5 external link"
                    subject = f"dataset {dataset!r}"
                    target = self._linked(node.file.filename, link.filename, ref, subject, how)
                    self._open(target, link.filename, ref)
                    node = self.files[target]["/"]
                elif link.path.startswith("/"):
                    node = node.file["/"]
                todo[:0] = link.path.split("/")
                continue
            node = node[part]
        return node

    def _stored_inside(self, node, ref: str, subject: str) -> None:
        """Refuse a dataset whose values live in other files outside the folder: external raw
        storage (HDF5 reads it from the working directory) or a virtual dataset's sources."""
        for name, *_ in node.external or ():
            raw = name.decode("utf-8", "replace") if isinstance(name, bytes) else str(name)
            target = _raw_storage(raw)
            if not target.is_relative_to(self.folder):
                raise self._outside(ref, subject, "external raw storage (from the working directory)", raw)
            regular_file(self.path, target, raw, f"heavy-data file {ref!r}: external raw storage")
        if node.is_virtual:
            for source in node.virtual_sources():
                if source.file_name != ".":
                    how = "a virtual dataset"
                    target = self._linked(node.file.filename, source.file_name, ref, subject, how)
                    self._open(target, source.file_name, ref)

    def scan(self) -> None:
        """Scan every open file not yet scanned (and the files it reaches) for links, virtual
        sources and raw storage outside the folder (see the class); after the XDMF file's
        datasets were followed (their own links are refused naming the dataset)."""
        import h5py

        while todo := [f for f in self.files if f not in self.scanned]:
            for target in todo:
                self.scanned.add(target)
                h5 = self.files[target]
                ref, named = self.refs[target]
                inner = "" if named else f"{target.relative_to(self.folder)}:"
                links: list[tuple[str, h5py.ExternalLink]] = []
                datasets: list[h5py.Dataset] = []

                # the callbacks must not raise inside h5py's iteration: they stop it (a value)
                def link(name: str, lk: Any, links: list = links) -> bool | None:
                    self.seen += 1
                    if isinstance(lk, h5py.ExternalLink):
                        links.append((name, lk))
                    return True if self.seen > MAX_OBJECTS else None

                def item(_: str, obj: Any, datasets: list = datasets) -> bool | None:
                    self.seen += 1
                    if isinstance(obj, h5py.Dataset):
                        datasets.append(obj)
                    return True if self.seen > MAX_OBJECTS else None

                h5.visititems_links(link)
                h5.visititems(item)
                if self.seen > MAX_OBJECTS:
                    raise bad_file(
                        self.path, f"refused: heavy data of more than {MAX_OBJECTS} HDF5 objects and links"
                    )
                for name, lk in links:
                    how = "an HDF5 external link"
                    linked = self._linked(h5.filename, lk.filename, ref, f"link {inner + '/' + name!r}", how)
                    self._open(linked, lk.filename, ref)
                for obj in datasets:
                    self._stored_inside(obj, ref, f"dataset {inner + obj.name!r}")

    def close(self) -> None:
        for f in self.files.values():
            f.close()


def _raw_storage(name: str) -> Path:
    """The file external raw storage ``name`` is read from: HDF5 reads a relative name from the
    working directory (unless HDF5_EXTFILE_PREFIX is set: unset while fepost reads)."""
    return (Path.cwd() / name).resolve()


#: Most HDF5 links followed from an XDMF item to its dataset.
MAX_LINKS = 16
#: Most HDF5 objects and links the scans of one XDMF file's heavy data visit.
MAX_OBJECTS = 1_000_000


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
        ref, sep, dataset = text.partition(":")  # as meshio splits it: no space stripped
        if not sep or not ref or not dataset.strip() or ":" in dataset:
            raise bad_file(path, f"HDF DataItem {text[:80]!r} is not 'file.h5:/dataset'")
        have = heavy.size(ref, dataset)
        if have != want:
            raise bad_file(
                path,
                f"the header disagrees with the data: {ref}:{dataset} holds {have} values, "
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
        try:
            heavy.scan()
        except InputFileError:
            raise
        except (OSError, KeyError, RuntimeError, ValueError):
            raise bad_file(path, "heavy data damaged (its HDF5 metadata)") from None
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
