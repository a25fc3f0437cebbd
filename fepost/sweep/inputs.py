"""The sweep's inputs: files, folders and globs expanded into FE exports.

Every INPUT yields at least one :class:`Source`. An input that names nothing
(a missing file, a glob without matches, a folder without FE exports) is a
:class:`Source` with an ``error``: it becomes one error row of the table, so a
typo is reported beside the results rather than silently dropped.

* a file: itself, whatever its suffix (the reader names an unknown format);
* a folder: the FE exports directly inside it (by suffix, sorted by name;
  hidden files skipped); use a glob for sub-folders;
* a glob (``*``, ``?``, ``[...]``; ``**`` spans folders): the FE exports it
  matches, sorted.

A file reached twice (the same resolved path) is kept once, at its first place.
"""

from __future__ import annotations

import glob
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

_MAGIC = ("*", "?", "[")


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
    """

    given: str
    path: str | None
    error: str | None = None


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
            return [Source(given, None, f"{given}: folder holds no FE exports ({' '.join(suffixes)})")]
        return [Source(os.path.join(given, c.name), str(c.resolve())) for c in found]
    if p.exists() or not any(ch in given for ch in _MAGIC):
        return [Source(given, str(p.resolve()))]
    hits = sorted(h for h in glob.glob(given, recursive=True) if _is_export(Path(h), suffixes))
    if not hits:
        return [Source(given, None, f"{given}: no FE export matches this pattern")]
    return [Source(h, str(Path(h).resolve())) for h in hits]


def expand_inputs(inputs: Iterable[str | os.PathLike]) -> list[Source]:
    """Expand files, folders and globs into :class:`Source` items, in the order given.

    A missing plain file is kept as a source (its row reports "no such file"
    from the reader, like ``fepost coefficients`` would).
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
    return out
