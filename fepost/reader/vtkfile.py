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
from .raw import RawMesh
from .suffixes import VTK_SUFFIXES
from .vtkassemble import POLY_SECTIONS, Part, assemble, no_cells, poly_cells

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
    from . import vtkdirect
    from .pieces import join_pieces
    from .vtkcheck import check_file
    from .vtkselect import SELECTABLE, plan

    suffix = path.suffix.lower()
    if select and suffix in SELECTABLE and suffix in vtkdirect.DIRECT_SUFFIXES:
        direct = vtkdirect.read_direct(path, field=field, displacement=displacement)
        if direct is not None:
            return direct
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
    fmt = f"{_FORMAT_NAMES.get(suffix, 'VTK XML')} ({suffix})"
    raw = assemble(path, [_part(path, leaf) for leaf in leaves], fmt)
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

    from .raw import defer_point_arrays

    n = len(raw.points)
    deferred = {
        name: (partial(_read_one, path, name, n), ncomp, names)
        for name, (ncomp, names) in chosen.skipped.items()
    }
    defer_point_arrays(raw, chosen.order, deferred)


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
        sections = []
        for name, vtype in POLY_SECTIONS:
            ca = getattr(ds, f"Get{name}")()
            if ca is None or ca.GetNumberOfCells() == 0:
                continue
            off = np.asarray(_np(ca.GetOffsetsArray()), np.int64)
            sections.append((vtype, off, np.asarray(_np(ca.GetConnectivityArray()), np.int64)))
        return poly_cells(sections)
    cells = ds.GetCells()
    if cells is None or ds.GetNumberOfCells() == 0:
        return no_cells()
    # GetCellTypes returns the array from VTK 9.6 on (GetCellTypesArray is deprecated there)
    getter = ds.GetCellTypes if _vtk_at_least(9, 6) else ds.GetCellTypesArray
    types = np.asarray(_np(getter()), np.uint8)
    off = np.asarray(_np(cells.GetOffsetsArray()), np.int64)
    con = np.asarray(_np(cells.GetConnectivityArray()), np.int64)
    return types, off, con


def _part(path: Path, leaf) -> Part:
    """One VTK data set's content as numpy arrays."""
    ds = _as_unstructured(leaf)
    n = int(ds.GetNumberOfPoints())
    pts = np.asarray(_np(ds.GetPoints().GetData()), float).reshape(n, 3)
    components: dict[str, tuple[str, ...]] = {}
    point_data = _data_arrays(path, ds.GetPointData(), n, "point", components)
    types, off, con = _cells(ds)
    cell_data = _data_arrays(path, ds.GetCellData(), len(types), "cell", components)
    return Part(pts, types, off, con, point_data, cell_data, components)


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


__all__ = ["PARALLEL_SUFFIXES", "VTK_SUFFIXES", "read_vtk"]
