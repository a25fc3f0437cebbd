"""The sweep's inputs: files, folders and globs expanded into FE exports.

Every INPUT yields at least one `Source`. An input that names nothing
(a missing file or folder, a glob without matches, a folder without FE exports)
is a usage error (`ArgumentError`, exit status 2), raised before anything is
written: a typo never leaves an output folder behind.

* a file: itself, whatever its suffix (the reader names an unknown format);
* a folder: the FE exports directly inside it (by suffix, sorted by name;
  hidden files skipped); use a glob for sub-folders;
* a glob (``*``, ``?``, ``[...]``; ``**`` spans folders): the FE exports it
  matches, sorted.

A file reached twice (the same resolved path) is kept once, at its first place.
The pieces of a parallel file (the ``.vtu``/``.vtp`` files a ``.pvtu``/``.pvtp``
among the inputs names) are read through it, never as cases of their own.

One case written in several formats (files of one folder with the same stem,
``static_100.vtu`` and ``static_100.e``) is one source: the file whose suffix
comes first in `PREFERENCE` is read, the others are noted in its
``also`` (the table's ``also_as`` column). Exodus comes first because it holds
every time step (``--steps all``) and the side sets; then VTK XML, then legacy
VTK, then any other format in the reader's order.
"""

from __future__ import annotations

import glob
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import ArgumentError

_MAGIC = ("*", "?", "[")
#: Parallel VTK files, whose pieces are read through them.
PARALLEL_SUFFIXES = (".pvtu", ".pvtp")
#: Most bytes of a parallel file looked at for its pieces' names (the files are a few lines).
_PIECES_HEAD = 1 << 20
_PIECE_SOURCE = re.compile(rb"<Piece\b[^>]*?\bSource\s*=\s*[\"']([^\"']+)[\"']")
#: Suffixes in the order a case written in several formats is read (the first present wins).
PREFERENCE = (".e", ".exo", ".ex2", ".exii", ".vtu", ".vtp", ".vtk")


@dataclass(frozen=True)
class Source:
    """One FE export of the sweep (or an input that names none).

    Attributes
    ----------
    given : str
        The path as the user wrote it, or as the folder/glob it came from
        produced it (``folder/name``); the table's ``source`` column.
    path : str or None
        Absolute path read by the workers; None when ``error`` is set.
    error : str or None
        One-line reason why the input gives no file.
    also : tuple of str
        Other files of the same case (same folder and stem, other formats),
        as given; they are not read.
    """

    given: str
    path: str | None
    error: str | None = None
    also: tuple[str, ...] = ()


def fe_suffixes() -> tuple[str, ...]:
    """Suffixes of the FE exports the reader accepts (lower case, with the dot)."""
    from ..reader import supported_suffixes

    return tuple(s.lower() for s in supported_suffixes())


def _is_export(p: Path, suffixes: tuple[str, ...]) -> bool:
    return p.is_file() and p.suffix.lower() in suffixes and not p.name.startswith(".")


def _expand_one(given: str, suffixes: tuple[str, ...]) -> list[Source]:
    p = Path(given)
    if p.is_dir():
        found = sorted(c for c in p.iterdir() if _is_export(c, suffixes))
        if not found:
            raise ArgumentError(f"{given}: folder holds no FE exports ({' '.join(suffixes)})")
        return [Source(os.path.join(given, c.name), str(c.resolve())) for c in found]
    if p.exists():
        return [Source(given, str(p.resolve()))]
    if not any(ch in given for ch in _MAGIC):
        raise ArgumentError(f"{given}: no such file or folder")
    hits = sorted(h for h in glob.glob(given, recursive=True) if _is_export(Path(h), suffixes))
    if not hits:
        raise ArgumentError(f"{given}: no FE export matches this pattern")
    return [Source(h, str(Path(h).resolve())) for h in hits]


def _rank(path: str) -> tuple[int, int]:
    """Sort key of a format: `PREFERENCE` first, then the reader's order."""
    suffix = Path(path).suffix.lower()
    if suffix in PREFERENCE:
        return (0, PREFERENCE.index(suffix))
    known = fe_suffixes()
    return (1, known.index(suffix) if suffix in known else len(known))


def one_per_case(sources: Iterable[Source]) -> list[Source]:
    """One source per case: files of one folder with the same stem are one case.

    The preferred format (`PREFERENCE`) is kept, at the place of the
    case's first file; the others are listed in its ``also``.
    """
    sources = list(sources)
    cases: dict[tuple[str, str], list[Source]] = {}
    for src in sources:
        if src.path is not None:
            p = Path(src.path)
            cases.setdefault((str(p.parent), p.stem), []).append(src)
    out: list[Source] = []
    placed: set[tuple[str, str]] = set()
    for src in sources:
        if src.path is None:
            out.append(src)
            continue
        case = (str(Path(src.path).parent), Path(src.path).stem)
        if case in placed:
            continue
        placed.add(case)
        members = sorted(cases[case], key=lambda s: _rank(s.path or ""))
        best = members[0]
        out.append(replace(best, also=tuple(m.given for m in members[1:])))
    return out


def piece_paths(path: str | os.PathLike) -> set[str]:
    """Resolved paths of the pieces a parallel file (``.pvtu``/``.pvtp``) names.

    Only the names are looked at (the first `_PIECES_HEAD` bytes); the file itself
    is checked and read by the reader. An unreadable file names no pieces.
    """
    p = Path(path)
    try:
        with open(p, "rb") as fh:
            head = fh.read(_PIECES_HEAD)
    except OSError:
        return set()
    return {str((p.parent / m.decode("utf-8", "replace")).resolve()) for m in _PIECE_SOURCE.findall(head)}


def without_pieces(sources: list[Source]) -> list[Source]:
    """``sources`` less the pieces of the parallel files among them."""
    pieces: set[str] = set()
    for src in sources:
        if src.path is not None and Path(src.path).suffix.lower() in PARALLEL_SUFFIXES:
            pieces |= piece_paths(src.path)
    return [s for s in sources if s.path is None or s.path not in pieces]


def expand_inputs(inputs: Iterable[str | os.PathLike]) -> list[Source]:
    """Expand files, folders and globs into `Source` items, in the order given,
    one per case (`one_per_case`).

    Raises
    ------
    ArgumentError
        An input names no file: missing, a glob without matches, a folder without exports.
    """
    suffixes = fe_suffixes()
    seen: set[str] = set()
    out: list[Source] = []
    for item in inputs:
        for src in _expand_one(os.fspath(item), suffixes):
            if src.path is not None:
                if src.path in seen:
                    continue
                seen.add(src.path)
            out.append(src)
    return one_per_case(without_pieces(out))
