"""XDMF files (``.xdmf`` + ``.h5``, as FEniCS/dolfinx and meshio write them) read with meshio.

Two layouts are read, after the checks of `fepost.reader.xdmfcheck`:

* one grid (``meshio.write("x.xdmf", mesh)``): read with ``meshio.read``;
* a time series: the mesh once, then one ``Temporal`` collection per function whose
  grids include the mesh and carry the function at each time (dolfinx's
  ``XDMFFile.write_function``, meshio's ``TimeSeriesWriter``): read with meshio's
  ``TimeSeriesReader``. Every collection's step k is one state; the last is read
  by default (``--step N`` as for Exodus), and the collections must agree on the
  times.

The cells are grouped by type into `fepost.reader.raw.Block` s through the VTK
node orderings of `fepost.reader.cells` (meshio and dolfinx write XDMF cells in
VTK's order).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from .cells import SPECS, VTK_TYPES, check_connectivity
from .exodus import choose_step
from .raw import Block, RawMesh
from .suffixes import XDMF_SUFFIXES
from .xdmfcheck import XdmfLayout, check_xdmf

#: meshio cell type → VTK cell type (meshio keeps VTK's node order).
MESHIO_TO_VTK = {
    "vertex": 1,
    "line": 3,
    "triangle": 5,
    "quad": 9,
    "tetra": 10,
    "hexahedron": 12,
    "wedge": 13,
    "pyramid": 14,
    "line3": 21,
    "triangle6": 22,
    "quad8": 23,
    "tetra10": 24,
    "hexahedron20": 25,
    "wedge15": 26,
    "pyramid13": 27,
    "quad9": 28,
    "hexahedron27": 29,
    "triangle7": 34,
}
#: What meshio raises on malformed files it was handed (after the checks).
_MESHIO_ERRORS: tuple[type[BaseException], ...] = (
    KeyError,
    ValueError,
    IndexError,
    TypeError,
    AttributeError,
    OSError,
    RuntimeError,
    AssertionError,
)


def _meshio_errors() -> tuple[type[BaseException], ...]:
    from meshio import ReadError

    return (ReadError, *_MESHIO_ERRORS)


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0][:200]}" if text else type(exc).__name__


def _series(path: Path, step: int | None):
    """(points, cells, point data, cell data, times, chosen step) of a time series."""
    from meshio.xdmf import TimeSeriesReader

    with TimeSeriesReader(path) as reader:
        points, cells = reader.read_points_cells()
        collections = [
            g
            for g in reader.domain
            if g.tag == "Grid" and g.get("GridType") == "Collection" and g.get("CollectionType") == "Temporal"
        ]
        sizes = {len(list(g)) for g in collections}
        if len(sizes) != 1:
            raise InputFileError(f"{path}: the time series hold different numbers of steps ({sorted(sizes)})")
        n = sizes.pop()
        times = _times(path, collections)
        chosen = choose_step(path, step, n)
        point_data: dict = {}
        cell_data: dict = {}
        for g in collections:
            reader.collection = list(g)
            _, pd, cd = reader.read_data(chosen)
            point_data.update(pd)
            cell_data.update(cd)
    return points, cells, point_data, cell_data, times, chosen


def _times(path: Path, collections: list) -> tuple[float, ...]:
    """The time of every step, the same in every collection, each a finite number."""
    series = []
    for g in collections:
        values = []
        for k, grid in enumerate(g):
            node = grid.find("Time")
            try:
                t = float(node.get("Value")) if node is not None else float("nan")
            except (TypeError, ValueError):
                t = float("nan")
            if not np.isfinite(t):
                raise InputFileError(f"{path}: time value of step {k} is not a finite number ({t})")
            values.append(t)
        series.append(tuple(values))
    if any(s != series[0] for s in series):
        raise InputFileError(f"{path}: the time series of the file's functions have different times")
    return series[0]


def read_steps(path: Path) -> tuple[float, ...]:
    """The time value of every step of an XDMF time series (empty for a single grid)."""
    import xml.etree.ElementTree as ET

    layout = check_xdmf(path)
    if not layout.temporal:
        return ()
    domain = ET.parse(path).getroot().find("Domain")
    collections = [g for g in (domain if domain is not None else []) if g.get("GridType") == "Collection"]
    return _times(path, collections)


#: Environment variables that make HDF5 look for linked, virtual-source and raw-storage files
#: in other folders first (the checks follow HDF5's search without them): unset while reading.
HDF5_PREFIXES = ("HDF5_EXT_PREFIX", "HDF5_VDS_PREFIX", "HDF5_EXTFILE_PREFIX")


@contextmanager
def _own_folder() -> Iterator[None]:
    """HDF5 without the search prefixes of `HDF5_PREFIXES` (restored afterwards)."""
    saved = {name: os.environ.pop(name) for name in HDF5_PREFIXES if name in os.environ}
    try:
        yield
    finally:
        os.environ.update(saved)


def read_xdmf(path: Path, step: int | None) -> RawMesh:
    """Read an XDMF file into a `fepost.reader.raw.RawMesh` (``step``: of a time series)."""
    with _own_folder():
        return _read_xdmf(path, step)


def _read_xdmf(path: Path, step: int | None) -> RawMesh:
    layout = check_xdmf(path)
    times: tuple[float, ...] = ()
    chosen = None
    try:
        if layout.temporal:
            points, cells, point_data, cell_data, times, chosen = _series(path, step)
        else:
            if step is not None:
                raise InputFileError(f"{path}: --step applies to time series; this XDMF file holds one grid")
            import meshio

            mesh = meshio.read(path, file_format="xdmf")
            points, cells, point_data, cell_data = mesh.points, mesh.cells, mesh.point_data, mesh.cell_data
    except InputFileError:
        raise
    except _meshio_errors() as exc:
        damaged = _damaged_dataset(path, layout)
        if damaged is not None:
            raise damaged from None
        raise InputFileError(f"{path}: cannot read XDMF file ({_one_line(exc)})") from None
    raw = _raw(path, np.asarray(points), cells, point_data, cell_data)
    raw.steps, raw.step = times, chosen
    return raw


def _damaged_dataset(path: Path, layout: XdmfLayout) -> InputFileError | None:
    """The error naming the first HDF5 dataset whose values do not read (damaged chunks or
    filters), or None: looked for only after meshio failed, each dataset read on its own."""
    import h5py

    for ref, target, dataset in layout.datasets:
        try:
            with h5py.File(target, "r") as h5:
                h5[dataset][()]
        except (OSError, KeyError, RuntimeError, ValueError, TypeError):
            return InputFileError(
                f"{path}: heavy-data file {ref!r}: the values of dataset {dataset!r} cannot be read "
                "(damaged HDF5 data)"
            )
    return None


def _raw(path: Path, points: np.ndarray, cells, point_data: dict, cell_data: dict) -> RawMesh:
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputFileError(f"{path}: node coordinates of shape {points.shape} (expected n × 2 or n × 3)")
    dim = points.shape[1]
    if dim == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    points = np.asarray(points, float)
    if not np.all(np.isfinite(points)):
        bad = int(np.sum(~np.isfinite(points).all(axis=1)))
        raise InputFileError(f"{path}: {bad} node coordinates are NaN or infinite")
    n = len(points)
    raw = RawMesh(path=str(path), format="XDMF (meshio)", points=points, blocks=[], dim=dim)
    first = 0
    for k, block in enumerate(cells):
        vtk = MESHIO_TO_VTK.get(block.type)
        if vtk is None:
            raise InputFileError(f"{path}: {len(block.data)} cells of type {block.type!r} cannot be read")
        canon, perm = VTK_TYPES[vtk]
        conn = np.asarray(block.data, np.int64)
        if conn.ndim != 2 or conn.shape[1] != SPECS[canon].n_nodes:
            raise InputFileError(f"{path}: {block.type} cells with {conn.shape[-1]} nodes (corrupt file)")
        check_connectivity(conn, n, str(path))
        if perm is not None:
            conn = conn[:, list(perm)]
        b = Block(f"{canon.upper()} cells of block {k + 1} ({len(conn)})", canon, conn, first)
        for name, arrays in cell_data.items():
            a = np.asarray(arrays[k])
            if len(a) != len(conn):
                raise InputFileError(f"{path}: cell array {name!r} has {len(a)} values for {len(conn)} cells")
            b.cell_data.add(name, a[:, 0] if a.ndim == 2 and a.shape[1] == 1 else a)
        raw.blocks.append(b)
        first += len(conn)
    for name, a in point_data.items():
        a = np.asarray(a)
        if len(a) != n:
            raise InputFileError(f"{path}: point array {name!r} has {len(a)} values for {n} nodes")
        raw.point_data.add(name, a[:, 0] if a.ndim == 2 and a.shape[1] == 1 else a)
    return raw


__all__ = ["MESHIO_TO_VTK", "XDMF_SUFFIXES", "read_steps", "read_xdmf"]
