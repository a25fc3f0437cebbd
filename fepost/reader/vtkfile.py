"""VTK files read with VTK's own readers.

XML ``.vtu .vtp .vtm``, structured XML grids ``.vts .vtr`` (turned into hexahedra
or quadrilaterals, whose boundary is then taken as for any volume mesh), parallel
XML ``.pvtu .pvtp`` (read piece by piece by VTK's parallel readers, ghost cells
dropped, then joined by `fepost.reader.pieces`) and legacy ``.vtk``.

VTK's readers are used directly (``vtkmodules``, not pyvista: the same
readers, a third of the import time). Each file is first checked by
`fepost.reader.vtkcheck` (declared sizes against the data, hostile XML);
VTK's error messages are collected through a string output window and any
error fails the read (VTK goes on after many errors and returns partial data).
The cells are grouped by type into `fepost.reader.raw.Block` s with the
canonical node ordering of `fepost.reader.cells`; the pieces of a
multi-block file are kept apart (never merged: two bodies in contact share
node positions).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputFileError
from .cells import SPECS, VTK_TYPES, check_connectivity
from .raw import Block, RawMesh

VTK_SUFFIXES = (".vtu", ".vtp", ".vtk", ".vtm", ".vts", ".vtr", ".pvtu", ".pvtp")
#: Parallel files: pieces read one by one and joined.
PARALLEL_SUFFIXES = (".pvtu", ".pvtp")
_XML_READERS = {
    ".vtu": "vtkXMLUnstructuredGridReader",
    ".vtp": "vtkXMLPolyDataReader",
    ".vtm": "vtkXMLMultiBlockDataReader",
    ".vts": "vtkXMLStructuredGridReader",
    ".vtr": "vtkXMLRectilinearGridReader",
    ".pvtu": "vtkXMLPUnstructuredGridReader",
    ".pvtp": "vtkXMLPPolyDataReader",
}
_FORMAT_NAMES = {
    ".vtk": "VTK legacy",
    ".vts": "VTK XML structured grid",
    ".vtr": "VTK XML rectilinear grid",
    ".pvtu": "VTK parallel XML",
    ".pvtp": "VTK parallel XML",
}
#: VTK cell types without area that are passed over (named in the notes): they carry no contact pressure.
_PASSED_OVER = {2: "poly-vertex", 4: "poly-line", 35: "cubic line", 68: "Lagrange curve", 75: "Bezier curve"}
#: VTK cell types with area that fepost cannot read: refused by name, so no load is dropped silently.
_UNSUPPORTED = {
    6: "triangle-strip",
    7: "polygon",
    42: "polyhedron",
    69: "Lagrange triangle",
    70: "Lagrange quadrilateral",
    71: "Lagrange tetrahedron",
    72: "Lagrange hexahedron",
    73: "Lagrange wedge",
    74: "Lagrange pyramid",
}


class _ErrorWindow:
    """Route VTK's messages into a string for the duration of a read."""

    def __enter__(self):
        from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow

        self._old = vtkOutputWindow.GetInstance()
        self.window = vtkStringOutputWindow()
        vtkOutputWindow.SetInstance(self.window)
        return self

    def __exit__(self, *exc):
        from vtkmodules.vtkCommonCore import vtkOutputWindow

        vtkOutputWindow.SetInstance(self._old)
        return False

    def errors(self) -> list[str]:
        text = self.window.GetOutput() or ""
        out = []
        lines = text.splitlines()
        for i, ln in enumerate(lines):
            if ln.strip().startswith("ERROR"):
                # the message follows on the next line ("vtkXMLReader (0x..): message")
                msg = lines[i + 1].strip() if i + 1 < len(lines) else ln.strip()
                if "):" in msg:
                    msg = msg.split("):", 1)[1].strip()
                out.append(msg or ln.strip())
        return out


def _reader_for(suffix: str):
    if suffix in _XML_READERS:
        from vtkmodules import vtkIOXML

        return getattr(vtkIOXML, _XML_READERS[suffix])()
    from vtkmodules.vtkIOLegacy import vtkDataSetReader

    r = vtkDataSetReader()
    r.ReadAllScalarsOn()
    r.ReadAllVectorsOn()
    r.ReadAllNormalsOn()
    r.ReadAllTensorsOn()
    r.ReadAllFieldsOn()
    r.ReadAllColorScalarsOn()
    return r


def _leaves(obj) -> list:
    from vtkmodules.vtkCommonDataModel import vtkMultiBlockDataSet

    if obj is None:
        return []
    if isinstance(obj, vtkMultiBlockDataSet):
        out = []
        for i in range(obj.GetNumberOfBlocks()):
            out += _leaves(obj.GetBlock(i))
        return out
    return [obj]


def _pieces(reader) -> tuple[list, bool]:
    """The pieces of a parallel file, one data set each, ghost cells removed (and whether any were)."""
    reader.UpdateInformation()
    n = reader.GetNumberOfPieces()
    out, ghosts = [], False
    for i in range(n):
        reader.UpdatePiece(i, n, 0)
        got = reader.GetOutputDataObject(0)
        ds = got.NewInstance()
        ds.DeepCopy(got)
        if ds.GetCellData().GetArray("vtkGhostType") is not None:
            before = ds.GetNumberOfCells()
            ds.RemoveGhostCells()
            ghosts = ghosts or ds.GetNumberOfCells() != before
        out.append(ds)
    return out, ghosts


def read_vtk(
    path: Path, *, field: str | None = None, displacement: str | None = "auto", select: bool = True
) -> RawMesh:
    """Read a VTK file into a `fepost.reader.raw.RawMesh`.

    ``field`` and ``displacement`` are `fepost.reader.read_contact`'s: with ``select``
    (the default) a serial XML file's point arrays that they do not choose are not
    decoded (`fepost.reader.vtkselect`); they are read on demand if asked for.
    """
    from .pieces import join_pieces
    from .vtkcheck import check_file
    from .vtkselect import SELECTABLE, plan

    suffix = path.suffix.lower()
    counts = check_file(path)
    reader = _reader_for(suffix)
    ghosts = False
    pieces: list = []
    chosen = None
    with _ErrorWindow() as win:
        reader.SetFileName(str(path))
        if suffix in PARALLEL_SUFFIXES:
            pieces, ghosts = _pieces(reader)
            out = None
        else:
            if select and suffix in SELECTABLE:
                chosen = plan(path, reader, field, displacement)
            reader.Update()
            out = reader.GetOutputDataObject(0)
    errors = win.errors()
    if errors:
        raise InputFileError(f"{path}: corrupt or truncated {suffix} file ({errors[0]})")
    if reader.GetErrorCode():
        from vtkmodules.vtkCommonCore import vtkErrorCode  # type: ignore[attr-defined]

        raise InputFileError(
            f"{path}: cannot read {suffix} file "
            f"({vtkErrorCode.GetStringFromErrorCode(reader.GetErrorCode())})"
        )
    leaves = _leaves(out) if out is not None else pieces
    leaves = [leaf for leaf in leaves if leaf is not None and leaf.GetNumberOfPoints() > 0]
    if not leaves:
        raise InputFileError(f"{path}: the file holds no mesh (0 nodes or 0 cells)")
    raw = _assemble(path, leaves, f"{_FORMAT_NAMES.get(suffix, 'VTK XML')} ({suffix})")
    declared = sum(counts.connectivity)
    if declared and suffix != ".vtm" and not ghosts and declared != raw.connectivity_size:
        raise InputFileError(
            f"{path}: the header disagrees with the data: the connectivity holds {declared} values, "
            f"the declared cells use {raw.connectivity_size}"
        )
    if suffix in PARALLEL_SUFFIXES:
        raw, merged = join_pieces(raw, [int(leaf.GetNumberOfPoints()) for leaf in leaves])
        raw.notes = [f"{len(leaves)} pieces joined ({merged} nodes shared by pieces merged)"]
    if chosen is not None:
        _add_skipped(raw, path, chosen)
    return raw


def _add_skipped(raw: RawMesh, path: Path, chosen) -> None:
    """Put the point arrays left out of the read back into ``raw``, in file order, as loaders."""
    from functools import partial

    from .raw import LazyArrays

    data = LazyArrays()
    for name in chosen.order:
        if name in chosen.skipped:
            ncomp, names = chosen.skipped[name]
            data.add(name, partial(_read_one, path, name, len(raw.points)))
            raw.ncomp[name] = ncomp
            if names:
                raw.components.setdefault(name, names)
        else:
            data.add(name, raw.point_data[name])
    raw.point_data = data


def _read_one(path: Path, name: str, n: int) -> np.ndarray:
    """One point array of a serial XML file, read on its own (a file read whole but for the other arrays)."""
    reader = _reader_for(path.suffix.lower())
    with _ErrorWindow() as win:
        reader.SetFileName(str(path))
        reader.UpdateInformation()
        sel = reader.GetPointDataArraySelection()
        sel.DisableAllArrays()
        sel.EnableArray(name)
        reader.GetCellDataArraySelection().DisableAllArrays()
        reader.Update()
    if win.errors() or reader.GetErrorCode():
        raise InputFileError(f"{path}: cannot read point array {name!r} (corrupt or changed file)")
    ds = _as_unstructured(reader.GetOutputDataObject(0))
    got = _data_arrays(path, ds.GetPointData(), n, "point", {})
    if name not in got:
        raise InputFileError(f"{path}: point array {name!r} is gone (the file changed while read)")
    return got[name]


def _as_unstructured(ds):
    from vtkmodules.vtkCommonDataModel import vtkPolyData, vtkUnstructuredGrid

    if isinstance(ds, vtkUnstructuredGrid | vtkPolyData):
        return ds
    from vtkmodules.vtkFiltersCore import vtkAppendFilter

    f = vtkAppendFilter()
    f.AddInputData(ds)
    f.Update()
    return f.GetOutput()


def _vtk_at_least(major: int, minor: int) -> bool:
    from vtkmodules.vtkCommonCore import vtkVersion

    return (vtkVersion.GetVTKMajorVersion(), vtkVersion.GetVTKMinorVersion()) >= (major, minor)


def _np(arr) -> np.ndarray:
    from vtkmodules.util.numpy_support import vtk_to_numpy

    return vtk_to_numpy(arr)


def _cells(ds) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(types, offsets (m + 1), connectivity) of all cells of a data set."""
    from vtkmodules.vtkCommonDataModel import vtkPolyData

    if isinstance(ds, vtkPolyData):
        parts = []
        for getter, vtype in ((ds.GetVerts, 1), (ds.GetLines, 3), (ds.GetPolys, 7), (ds.GetStrips, 6)):
            ca = getter()
            if ca is None or ca.GetNumberOfCells() == 0:
                continue
            off = np.asarray(_np(ca.GetOffsetsArray()), np.int64)
            con = np.asarray(_np(ca.GetConnectivityArray()), np.int64)
            size = np.diff(off)
            t = np.full(len(size), vtype, np.uint8)
            if vtype == 7:
                t[size == 3] = 5
                t[size == 4] = 9
            elif vtype == 3:
                t[size != 2] = 4
            elif vtype == 1:
                t[size != 1] = 2
            parts.append((t, off, con))
        if not parts:
            return np.empty(0, np.uint8), np.zeros(1, np.int64), np.empty(0, np.int64)
        types = np.concatenate([p[0] for p in parts])
        cons, offs, base = [], [np.zeros(1, np.int64)], 0
        for _, off, con in parts:
            offs.append(off[1:] + base)
            cons.append(con)
            base += len(con)
        return types, np.concatenate(offs), np.concatenate(cons)
    cells = ds.GetCells()
    if cells is None or ds.GetNumberOfCells() == 0:
        return np.empty(0, np.uint8), np.zeros(1, np.int64), np.empty(0, np.int64)
    # GetCellTypes returns the array from VTK 9.6 on (GetCellTypesArray is deprecated there)
    getter = ds.GetCellTypes if _vtk_at_least(9, 6) else ds.GetCellTypesArray
    types = np.asarray(_np(getter()), np.uint8)
    off = np.asarray(_np(cells.GetOffsetsArray()), np.int64)
    con = np.asarray(_np(cells.GetConnectivityArray()), np.int64)
    return types, off, con


def _assemble(path: Path, leaves: list, fmt: str) -> RawMesh:
    pts_parts: list[np.ndarray] = []
    blocks: list[Block] = []
    point_pieces: list[dict[str, np.ndarray]] = []
    sizes: list[int] = []
    components: dict[str, tuple[str, ...]] = {}
    skipped: dict[str, int] = {}
    base = 0
    first_cell = 0
    conn_size = 0
    for piece, leaf in enumerate(leaves):
        ds = _as_unstructured(leaf)
        n = int(ds.GetNumberOfPoints())
        pts = np.asarray(_np(ds.GetPoints().GetData()), float).reshape(n, 3)
        if not np.all(np.isfinite(pts)):
            bad = int(np.sum(~np.isfinite(pts).all(axis=1)))
            raise InputFileError(f"{path}: {bad} node coordinates are NaN or infinite")
        pts_parts.append(pts)
        point_pieces.append(_data_arrays(path, ds.GetPointData(), n, "point", components))
        sizes.append(n)
        types, off, con = _cells(ds)
        conn_size += len(con)
        if len(off) != len(types) + 1:
            raise InputFileError(f"{path}: cell offsets and cell types disagree in length (corrupt file)")
        if len(types):
            if off[0] != 0 or np.any(np.diff(off) < 0) or off[-1] != len(con):
                raise InputFileError(
                    f"{path}: cell offsets are inconsistent with the connectivity (corrupt file)"
                )
            check_connectivity(con, n, str(path))
        cdata = _data_arrays(path, ds.GetCellData(), len(types), "cell", components)
        where = f" of piece {piece + 1}" if len(leaves) > 1 else ""
        present = np.flatnonzero(np.bincount(types, minlength=256)) if len(types) else np.empty(0, np.int64)
        single = len(present) == 1
        for t in present:
            sel: np.ndarray | slice = slice(None) if single else np.flatnonzero(types == t)
            spec = VTK_TYPES.get(int(t))
            count = len(types) if isinstance(sel, slice) else len(sel)
            if spec is None:
                if int(t) in _PASSED_OVER:
                    skipped[_PASSED_OVER[int(t)]] = skipped.get(_PASSED_OVER[int(t)], 0) + count
                    continue
                what = _UNSUPPORTED.get(int(t), "an unknown type")
                raise InputFileError(
                    f"{path}: {count} cell(s) of VTK type {int(t)} ({what}) cannot be read: "
                    "convert them to triangles or quadrilaterals (or the file is corrupt)"
                )
            canon, perm = spec
            k = SPECS[canon].n_nodes
            if single and len(con) == k * count:
                # one cell type throughout: the offsets must step by k, the connectivity is a (m, k) view
                if np.any(off != np.arange(0, k * count + 1, k)):
                    raise InputFileError(
                        f"{path}: cell offsets are inconsistent with {canon} cells (corrupt file)"
                    )
                conn = con.reshape(count, k)
            else:
                idx = sel if isinstance(sel, np.ndarray) else np.arange(len(types))
                size = off[idx + 1] - off[idx]
                if np.any(size != k):
                    raise InputFileError(
                        f"{path}: {canon} cells with {int(size[size != k][0])} nodes instead of {k} "
                        "(corrupt file)"
                    )
                conn = con[off[idx][:, None] + np.arange(k)[None, :]]
            if perm is not None:
                conn = conn[:, list(perm)]
            if base:
                conn = conn + base
            block = Block(f"{canon.upper()} cells{where} ({count})", canon, conn, first_cell, piece)
            for name, arr in cdata.items():
                block.cell_data.add(name, arr[sel])
            blocks.append(block)
            first_cell += count
        base += n
    points = pts_parts[0] if len(pts_parts) == 1 else np.concatenate(pts_parts)
    raw = RawMesh(path=str(path), format=fmt, points=points, blocks=blocks, components=components)
    for name, arr in _join(point_pieces, sizes).items():
        raw.point_data.add(name, arr)
    raw.skipped = skipped
    raw.connectivity_size = conn_size
    return raw


def _numeric(arr) -> bool:
    from vtkmodules.vtkCommonCore import vtkDataArray

    return isinstance(arr, vtkDataArray)


def _data_arrays(path, data, n: int, where: str, components) -> dict[str, np.ndarray]:
    """The named numeric arrays of a point or cell ``data`` object, each checked to have ``n`` values.

    ``where`` is ``"point"`` or ``"cell"`` (the arrays' ``n`` are nodes or cells). Component
    names of multi-component arrays go into ``components`` (the first piece's are kept).
    """
    counted = "nodes" if where == "point" else "cells"
    out = {}
    for i in range(data.GetNumberOfArrays()):
        arr = data.GetAbstractArray(i)
        name = arr.GetName() if arr is not None else None
        if not name or not _numeric(arr):
            continue  # string and unnamed arrays carry no field values
        a = np.asarray(_np(arr))
        if a.shape[0] != n:
            raise InputFileError(f"{path}: {where} array {name!r} has {a.shape[0]} values for {n} {counted}")
        if arr.GetNumberOfComponents() > 1:
            names = tuple(arr.GetComponentName(k) or "" for k in range(arr.GetNumberOfComponents()))
            if any(names):
                components.setdefault(name, names)
        out[name] = a
    return out


def _join(pieces: list[dict[str, np.ndarray]], sizes: list[int]) -> dict[str, np.ndarray]:
    """Point arrays of several pieces end to end; a piece without an array gets zeros there."""
    if len(pieces) == 1:
        return pieces[0]
    shapes: dict[str, tuple] = {}
    for p in pieces:
        for name, a in p.items():
            shapes.setdefault(name, a.shape[1:])
    out = {}
    for name, tail in shapes.items():
        parts: list[np.ndarray] = []
        for p, n in zip(pieces, sizes, strict=True):
            got = p.get(name)
            parts.append(got if got is not None and got.shape[1:] == tail else np.zeros((n, *tail)))
        out[name] = np.concatenate(parts)
    return out


__all__ = ["PARALLEL_SUFFIXES", "VTK_SUFFIXES", "read_vtk"]
