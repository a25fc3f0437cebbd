"""Read only the point arrays a contact field needs from a serial VTK XML file.

Solver exports carry many nodal arrays (stresses, strains, velocities) beside the
contact pressure and the displacement; VTK's XML readers decode every enabled
array. Before the read, `plan` asks the reader for the arrays' names and
component counts (``UpdateInformation``: the XML structure only, no data
decoded), takes the component names from the file's ``DataArray`` tags, and
chooses the pressure and the displacement exactly as `fepost.reader.contact`
will (`fepost.reader.names.pick_field`, `fepost.reader.names.pick_displacement`
on the same catalogue). Every other point array is disabled; it stays in the
result's `fepost.reader.raw.RawMesh.point_data` as a loader that reads it (a
full read with that one array enabled) if anything ever asks for it, and its
component count is known from the header, so choosing the arrays never loads it.

Cell arrays are all read (the catalogue needs their shapes). Where the choice
cannot be made from the header (no candidate, several, a name not in the file,
string arrays, several pieces), `plan` returns None and the file is read whole:
the general path then gives the same choice and the same error as ever.

The component names are read from the XML tags (found with ``find``, tag to
tag, up to ``<AppendedData>``, where raw bytes begin): VTK's information keys
give names and counts but not component names.
"""

from __future__ import annotations

import mmap
import re
from dataclasses import dataclass
from pathlib import Path

from .names import ArrayInfo, needed_point_arrays

#: Serial XML suffixes whose point arrays are selected before the read. Structured grids
#: (``.vts .vtr``) are not: their conversion to cells (VTK's append filter) reorders the
#: arrays, and the order of the names a field lists must not depend on the path taken.
SELECTABLE = (".vtu", ".vtp")
#: VTK array types read as numbers (VTK's type ids: char ... unsigned long long, id type).
_NUMERIC = {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 15, 16, 17}
_TAG = re.compile(rb"<(/?)(PointData|CellData|DataArray|Piece|AppendedData)\b([^>]*)>")
_ATTR = re.compile(rb'([A-Za-z_][\w.-]*)\s*=\s*"([^"]*)"')


@dataclass(frozen=True)
class Plan:
    """The point arrays left out of a read: name → (component count, component names), in file order."""

    order: tuple[str, ...]
    skipped: dict[str, tuple[int, tuple[str, ...]]]


def _header_tags(path: Path) -> tuple[dict[tuple[str, str], tuple[str, ...]], int]:
    """Component names of every array ((section, name) → names) and the number of pieces."""
    names: dict[tuple[str, str], tuple[str, ...]] = {}
    pieces = 0
    section = ""
    with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
        pos = data.find(b"<")
        while pos >= 0:
            # memchr from tag to tag: inline base64 and ASCII arrays hold no "<"
            m = _TAG.match(data, pos)
            pos = data.find(b"<", pos + 1)
            if m is None:
                continue
            closing, tag, body = m.group(1), m.group(2), m.group(3)
            if tag == b"AppendedData":
                break
            if tag == b"Piece" and not closing:
                pieces += 1
            elif tag in (b"PointData", b"CellData"):
                section = "" if closing or body.rstrip().endswith(b"/") else tag.decode()
            elif tag == b"DataArray" and not closing and section:
                attrs = {k.decode(): v.decode("utf-8", "replace") for k, v in _ATTR.findall(body)}
                comps = [(int(k[13:]), v) for k, v in attrs.items() if re.fullmatch(r"ComponentName\d+", k)]
                if comps and "Name" in attrs:
                    ncomp = max(k for k, _ in comps) + 1
                    out = [""] * ncomp
                    for k, v in comps:
                        out[k] = v
                    names.setdefault((section, attrs["Name"]), tuple(out))
    return names, pieces


def _infos(reader, key) -> list[tuple[str, int, int]]:
    """(name, components, VTK type) of the arrays the reader's information lists under ``key``."""
    from vtkmodules.vtkCommonDataModel import vtkDataObject

    vec = reader.GetOutputInformation(0).Get(key)
    out: list[tuple[str, int, int]] = []
    if vec is None:
        return out
    for i in range(vec.GetNumberOfInformationObjects()):
        o = vec.GetInformationObject(i)
        out.append(
            (
                o.Get(vtkDataObject.FIELD_NAME()) or "",
                int(o.Get(vtkDataObject.FIELD_NUMBER_OF_COMPONENTS()) or 1),
                int(o.Get(vtkDataObject.FIELD_ARRAY_TYPE())),
            )
        )
    return out


def _padded(names: tuple[str, ...] | None, ncomp: int) -> tuple[str, ...]:
    """Component names as VTK gives them: one per component, none for a scalar or when all are empty."""
    if not names or ncomp < 2 or not any(names[:ncomp]):
        return ()
    return tuple(names[:ncomp]) + ("",) * max(0, ncomp - len(names))


def plan(path: Path, reader, field: str | None, displacement: str | None) -> Plan | None:
    """Disable the point arrays of ``reader`` that the contact field does not need.

    ``reader`` is a serial VTK XML reader whose file name is set; `UpdateInformation`
    is called here. Returns what was left out, or None (nothing disabled: read it all).
    """
    from vtkmodules.vtkCommonDataModel import vtkDataObject

    reader.UpdateInformation()
    points = _infos(reader, vtkDataObject.POINT_DATA_VECTOR())
    cells = _infos(reader, vtkDataObject.CELL_DATA_VECTOR())
    if not points or any(not n or t not in _NUMERIC for n, _, t in points + cells):
        return None  # unnamed or string arrays: the general path passes them over itself
    if len({n for n, _, _ in points}) != len(points):
        return None
    comps, pieces = _header_tags(path)
    if pieces != 1:
        return None
    catalogue = [ArrayInfo(n, "point", k, _padded(comps.get(("PointData", n)), k)) for n, k, _ in points]
    seen = {n for n, _, _ in points}
    for n, k, _ in cells:
        if n not in seen:
            seen.add(n)
            catalogue.append(ArrayInfo(n, "cell", k, _padded(comps.get(("CellData", n)), k)))
    keep = needed_point_arrays(str(path), catalogue, field, displacement)
    if keep is None:
        return None  # the general path raises the same error, with the same catalogue
    sel = reader.GetPointDataArraySelection()
    skipped = {}
    for a in catalogue[: len(points)]:
        if a.name not in keep:
            sel.DisableArray(a.name)
            skipped[a.name] = (a.ncomp, a.components)
    return Plan(tuple(n for n, _, _ in points), skipped)


__all__ = ["SELECTABLE", "Plan", "plan"]
