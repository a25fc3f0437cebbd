"""Checks of VTK files before VTK reads them: declared sizes against the data, hostile XML.

`check_file` dispatches to `xmlcheck` (XML) and `legacycheck` (legacy).

VTK's readers trust a file's header: a piece declaring fewer cells than its
arrays hold is read as that many cells (a silently partial result), declared
sizes far beyond the data make them allocate without bound, and some
inconsistencies crash them. This module reads only the *structure* of a file
(tags, attributes, the length headers of binary arrays, token counts of ASCII
arrays; no array is decoded) and refuses a file whose header disagrees with
its data, before VTK sees it:

XML (``.vtu .vtp .vtm .vts .vtr .pvtu .pvtp``)
    no DOCTYPE or ENTITY declarations (entity expansion), tags nested at most
    `MAX_DEPTH` deep and balanced, the root type matching the suffix,
    ``NumberOfPoints``/``NumberOfCells`` (``NumberOf{Verts,Lines,Strips,Polys}``)
    non-negative and within `MAX_COUNT`, every data array's length
    (from its binary header — plain or compressed blocks, inline base64 or
    appended raw/base64 — or its ASCII token count) equal to what the piece
    declares (structured grids: the counts of their ``Extent``), and the bytes it
    announces present in the file. The pieces of a ``.vtm``, ``.pvtu`` or ``.pvtp``
    are checked in turn: files of their kind that exist in the file's folder.
Legacy (``.vtk``, ASCII or binary, ``UNSTRUCTURED_GRID`` and ``POLYDATA``)
    every section's declared count (``POINTS``, ``CELLS``/``OFFSETS``/
    ``CONNECTIVITY``, ``CELL_TYPES``, ``POINT_DATA``/``CELL_DATA`` arrays,
    ``FIELD`` arrays, binary ones followed by METADATA blocks or not) matches the
    values that follow: a section followed by more numbers than declared, or by
    fewer, is refused.

The structure is VTK's documented file format ("VTK File Formats", VTK User's
Guide); nothing here is used to *read* data, only to decide whether VTK may.
Base64 text is checked as VTK's reader will decode it (`fepost.reader.b64text`:
a character outside the alphabet, padding inside a group, whitespace inside the
text or fewer bytes than the header announces would come out of VTK as zeros or
shifted values without an error). Other corruption inside the data (a bad zlib
block, wild connectivity) is left to VTK's own errors, to the connectivity check
after reading, and to the child process the file is read in (`fepost.reader.isolate`).
"""

from __future__ import annotations

import mmap
from pathlib import Path

from ..errors import InputFileError
from .checks import MAX_COUNT, MAX_DEPTH, MAX_VTM_DEPTH, Counts, bad_file
from .legacycheck import Legacy
from .xmlcheck import Xml

__all__ = ["MAX_COUNT", "MAX_DEPTH", "MAX_VTM_DEPTH", "Counts", "check_file"]


def check_file(path: Path) -> Counts:
    """Check ``path`` (suffix-chosen); raise `InputFileError` on any inconsistency."""
    suffix = path.suffix.lower()
    try:
        with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
            if suffix == ".vtk":
                return Legacy(path, data).check()
            return Xml(path, data, 0).check()
    except InputFileError:
        raise
    except (OSError, ValueError) as exc:
        raise bad_file(path, f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None
