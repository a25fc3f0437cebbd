"""The pieces of a VTK data set, as numpy arrays, turned into a `fepost.reader.raw.RawMesh`.

Both ways of reading a VTK file end here: VTK's own readers (`fepost.reader.vtkfile`
takes each data set's arrays out of VTK) and the direct decoder of serial XML files
(`fepost.reader.vtkdirect`). One assembly for both is what makes their results
identical: the same checks (finite coordinates, offsets against the connectivity,
node indices in range), the same grouping of cells by type into
`fepost.reader.raw.Block` s with the canonical node ordering of
`fepost.reader.cells`, the same refusals of cell types fepost cannot read.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from .cells import SPECS, VTK_TYPES, check_connectivity
from .raw import Block, RawMesh

#: VTK cell types without area that are passed over (named in the notes): they carry no contact pressure.
PASSED_OVER = {2: "poly-vertex", 4: "poly-line", 35: "cubic line", 68: "Lagrange curve", 75: "Bezier curve"}
#: VTK cell types with area that fepost cannot read: refused by name, so no load is dropped silently.
UNSUPPORTED = {
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
#: The cell sections of a polygonal data set, in VTK's order, with the cell type each stands for.
POLY_SECTIONS = (("Verts", 1), ("Lines", 3), ("Polys", 7), ("Strips", 6))


@dataclass
class Part:
    """One data set's content: ``points`` (n, 3); ``types`` (m,) VTK cell types, ``offsets``
    (m + 1) into ``conn``; named numeric point and cell arrays (first axis n or m) in file
    order; the component names of multi-component arrays, where the file gives any."""

    points: np.ndarray
    types: np.ndarray
    offsets: np.ndarray
    conn: np.ndarray
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)
    components: dict[str, tuple[str, ...]] = field(default_factory=dict)


#: Offsets per chunk of the offset checks (their temporaries stay in the cache, and a million
#: cells' checks allocate no array of the offsets' length).
CHECK_CHUNK = 1 << 16


def _decreasing(off: np.ndarray) -> bool:
    """Whether an offset is smaller than the one before it (``np.any(np.diff(off) < 0)``, in chunks)."""
    for start in range(0, len(off) - 1, CHECK_CHUNK):
        seg = off[start : start + CHECK_CHUNK + 1]
        if np.any(seg[1:] < seg[:-1]):
            return True
    return False


def _not_every(off: np.ndarray, k: int) -> bool:
    """Whether the offsets differ from 0, k, 2k, ... (``np.any(off != np.arange(0, k·len, k))``,
    in chunks)."""
    for start in range(0, len(off), CHECK_CHUNK):
        seg = off[start : start + CHECK_CHUNK]
        if np.any(seg != np.arange(k * start, k * (start + len(seg)), k)):
            return True
    return False


#: (types, offsets, connectivity) of a data set's cells.
Cells = tuple[np.ndarray, np.ndarray, np.ndarray]


def no_cells() -> Cells:
    """(types, offsets, connectivity) of a data set without cells."""
    return np.empty(0, np.uint8), np.zeros(1, np.int64), np.empty(0, np.int64)


def poly_cells(
    sections: list[tuple[int, np.ndarray, np.ndarray]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(types, offsets (m + 1), connectivity) of a polygonal data set's cell sections.

    ``sections`` holds (section type, offsets (k + 1), connectivity) in `POLY_SECTIONS`
    order, empty sections left out. Polygons of 3 and 4 nodes are triangles and
    quadrilaterals, lines of more than 2 nodes poly-lines, vertices of more than 1 poly-vertices.
    """
    parts = []
    for vtype, off, con in sections:
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
        return no_cells()
    types = np.concatenate([p[0] for p in parts])
    cons, offs, base = [], [np.zeros(1, np.int64)], 0
    for _, off, con in parts:
        offs.append(off[1:] + base)
        cons.append(con)
        base += len(con)
    return types, np.concatenate(offs), np.concatenate(cons)


def assemble(path: Path, parts: list[Part], fmt: str) -> RawMesh:
    """The `RawMesh` of ``parts`` (the pieces of one file, kept apart as bodies)."""
    blocks: list[Block] = []
    components: dict[str, tuple[str, ...]] = {}
    skipped: dict[str, int] = {}
    base = first_cell = conn_size = 0
    for piece, part in enumerate(parts):
        n = len(part.points)
        if not np.all(np.isfinite(part.points)):
            bad = int(np.sum(~np.isfinite(part.points).all(axis=1)))
            raise InputFileError(f"{path}: {bad} node coordinates are NaN or infinite")
        for name, names in part.components.items():
            components.setdefault(name, names)
        types, off, con = part.types, part.offsets, part.conn
        conn_size += len(con)
        if len(off) != len(types) + 1:
            raise InputFileError(f"{path}: cell offsets and cell types disagree in length (corrupt file)")
        if len(types):
            if off[0] != 0 or _decreasing(off) or off[-1] != len(con):
                raise InputFileError(
                    f"{path}: cell offsets are inconsistent with the connectivity (corrupt file)"
                )
            check_connectivity(con, n, str(path))
        where = f" of piece {piece + 1}" if len(parts) > 1 else ""
        for block in _blocks(path, part, base, first_cell, piece, where, skipped):
            blocks.append(block)
            first_cell += len(block.conn)
        base += n
    points = parts[0].points if len(parts) == 1 else np.concatenate([p.points for p in parts])
    raw = RawMesh(path=str(path), format=fmt, points=points, blocks=blocks, components=components)
    for name, arr in _join([p.point_data for p in parts], [len(p.points) for p in parts]).items():
        raw.point_data.add(name, arr)
    raw.skipped = skipped
    raw.connectivity_size = conn_size
    return raw


def _blocks(path: Path, part: Part, base: int, first_cell: int, piece: int, where: str, skipped):
    """The blocks of one part, one per cell type (types fepost passes over counted in ``skipped``)."""
    types, off, con = part.types, part.offsets, part.conn
    present = np.flatnonzero(np.bincount(types, minlength=256)) if len(types) else np.empty(0, np.int64)
    single = len(present) == 1
    for t in present:
        sel: np.ndarray | slice = slice(None) if single else np.flatnonzero(types == t)
        spec = VTK_TYPES.get(int(t))
        count = len(types) if isinstance(sel, slice) else len(sel)
        if spec is None:
            if int(t) in PASSED_OVER:
                skipped[PASSED_OVER[int(t)]] = skipped.get(PASSED_OVER[int(t)], 0) + count
                continue
            what = UNSUPPORTED.get(int(t), "an unknown type")
            raise InputFileError(
                f"{path}: {count} cell(s) of VTK type {int(t)} ({what}) cannot be read: "
                "convert them to triangles or quadrilaterals (or the file is corrupt)"
            )
        canon, perm = spec
        k = SPECS[canon].n_nodes
        if single and len(con) == k * count:
            # one cell type throughout: the offsets must step by k, the connectivity is a (m, k) view
            if _not_every(off, k):
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
        for name, arr in part.cell_data.items():
            block.cell_data.add(name, arr[sel])
        first_cell += count
        yield block


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


__all__ = ["PASSED_OVER", "POLY_SECTIONS", "UNSUPPORTED", "Part", "assemble", "no_cells", "poly_cells"]
