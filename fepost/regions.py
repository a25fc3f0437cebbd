"""How many contact patches the loaded faces make: side by side in the plane, or on different surfaces.

The regions side by side are counted on a small raster (`loaded_regions`),
dilated and labelled here with numpy (`dilate`, `label`) rather
than with ``scipy.ndimage``, whose import alone (~0.3-0.6 s) would be a quarter
of a million-node ``fepost coefficients`` run; the two agree cell for cell
(tests/test_regions.py).
"""

from __future__ import annotations

import numpy as np

from ._chunks import map_chunks, slices
from .components import item_parts
from .errors import PatchError
from .facegroups import FaceGroup
from .facesums import FaceSums
from .field import ContactField
from .reader.quadratic import face_surface_loads

#: Regions closer than this fraction of √area belong to one patch (tread grooves).
GAP_FRACTION = 0.05
#: Nodes per chunk of the raster's pass over the nodes (two threads share the chunks).
NODE_CHUNK = 1 << 16
#: Largest raster side, cells.
RASTER_MAX = 2048
#: Loaded regions carrying more than this share of the load are patches (smaller ones: fragments).
FRAGMENT_SHARE = 0.01


def dilate(occupied: np.ndarray) -> np.ndarray:
    """Binary dilation of a 2-D boolean raster by a 3 × 3 square (cells beyond the border are empty)."""
    rows = occupied.copy()
    rows[1:] |= occupied[:-1]
    rows[:-1] |= occupied[1:]
    out = rows.copy()
    out[:, 1:] |= rows[:, :-1]
    out[:, :-1] |= rows[:, 1:]
    return out


def label(occupied: np.ndarray) -> tuple[np.ndarray, int]:
    """8-connected regions of a 2-D boolean raster: (labels, count), numbered as ``scipy.ndimage.label``.

    Labels are 1..count in the order each region first appears in a row-major
    scan (0: empty cells). Runs of cells along a row start joined; the runs are
    then merged across the rows by hooking each tree's root under the smaller
    root of a neighbouring tree and halving paths until nothing changes: every
    round at least halves the number of trees that still have a neighbour, and
    the root left in each region is its first cell.
    """
    shape = occupied.shape
    flat = occupied.ravel()
    cells = np.flatnonzero(flat)
    k = cells.size
    labels = np.zeros(shape, np.int32)
    if k == 0:
        return labels, 0
    ny = shape[1]
    index = np.full(flat.size, -1, np.int32)  # a raster holds at most RASTER_MAX² cells
    rank = np.arange(k, dtype=np.int32)
    index[cells] = rank
    grid = index.reshape(shape)
    # a run along a row: a cell whose left neighbour is occupied joins its run's first cell
    starts = np.ones(k, bool)
    starts[1:] = (cells[1:] != cells[:-1] + 1) | (cells[1:] % ny == 0)
    parent = np.maximum.accumulate(np.where(starts, rank, 0))
    a_parts, b_parts = [], []
    for dj in (-1, 0, 1):  # the row below: down-left, down, down-right
        lo, hi = max(0, -dj), ny - max(0, dj)
        a = grid[:-1, lo:hi]
        b = grid[1:, lo + dj : hi + dj]
        both = (a >= 0) & (b >= 0)
        a_parts.append(a[both])
        b_parts.append(b[both])
    a, b = np.concatenate(a_parts), np.concatenate(b_parts)
    while True:
        ra, rb = parent[a], parent[b]
        differ = ra != rb
        if not differ.any():
            break
        a, b, ra, rb = a[differ], b[differ], ra[differ], rb[differ]
        np.minimum.at(parent, np.maximum(ra, rb), np.minimum(ra, rb))
        while True:  # every cell straight to its root
            up = parent[parent]
            if np.array_equal(up, parent):
                break
            parent = up
    is_root = parent == rank
    number = np.cumsum(is_root, dtype=np.int32)  # roots are first cells: numbered in scan order
    labels.ravel()[cells] = number[parent]
    return labels, int(number[-1])


def loaded_regions(x: np.ndarray, y: np.ndarray, tri: np.ndarray, sums: FaceSums) -> tuple[int, np.ndarray]:
    """Separate loaded regions of a patch in its plane: (count, label per face).

    Parameters
    ----------
    x, y : ndarray, shape (n,)
        In-plane coordinates of the nodes.
    tri : ndarray, shape (m, 3)
        The loaded triangles (node indices).
    sums : FaceSums
        Their area and longest loaded edge (``fepost.facesums``).

    Returns
    -------
    count : int
        Number of separate regions.
    labels : ndarray of int, shape (m,)
        Region of each triangle, 0 to count − 1.

    Notes
    -----
    Regions closer than a gap of about `GAP_FRACTION` × √area (tread
    grooves, sparse contact at the edge) belong to one patch; regions farther
    apart (dual wheels) are separate. The nodes are binned on a raster of cell
    h = max(GAP_FRACTION·√area, longest loaded edge), so faces that share a node
    always fall in touching cells; one dilation closes gaps narrower than ~h.
    """
    h = max(GAP_FRACTION * np.sqrt(sums.A), sums.max_edge)
    chunks = slices(len(x), NODE_CHUNK)
    ends = np.array(map_chunks(lambda sl: (x[sl].min(), y[sl].min(), x[sl].max(), y[sl].max()), chunks))
    lo = ends[:, :2].min(axis=0)
    ext = ends[:, 2:].max(axis=0) - lo
    n = np.floor(ext / h).astype(int) + 3
    if n.max() > RASTER_MAX:  # a very sparse region: coarsen the raster
        h *= n.max() / RASTER_MAX
        n = np.floor(ext / h).astype(int) + 3
    occupied = np.zeros(tuple(n), bool)
    flat = occupied.ravel()

    def cells(sl: slice) -> tuple[np.ndarray, np.ndarray]:
        # coordinates are >= lo, so truncation is the floor
        i = ((x[sl] - lo[0]) * (1.0 / h)).astype(np.int32)
        i += 1
        j = ((y[sl] - lo[1]) * (1.0 / h)).astype(np.int32)
        j += 1
        return i, j

    def mark(sl: slice) -> None:
        i, j = cells(sl)
        i *= int(n[1])
        i += j
        flat[i] = True  # a flat index: 2-D fancy assignment is slower (the same True from either thread)

    map_chunks(mark, chunks)  # the nodes' cells, in chunks shared by two threads
    labels, count = label(dilate(occupied))
    if count == 1:
        return 1, np.zeros(len(tri), np.int64)
    i, j = cells(slice(0, len(x)))
    first = tri[:, 0]
    return int(count), labels[i[first], j[first]] - 1


def check_single_surface(fld: ContactField, groups: list[FaceGroup], hot: np.ndarray, points) -> None:
    """Raise a `PatchError` when the loaded faces form several patches (e.g. on parallel surfaces).

    Parameters
    ----------
    fld : ContactField
        The field (its values and source name).
    groups : list of FaceGroup
        The faces of the contact surface, by type.
    hot : ndarray of bool
        Nodes loaded above the threshold.
    points : ndarray, shape (n, 3)
        Node coordinates.

    Notes
    -----
    Patches carrying less than `FRAGMENT_SHARE` of the load are fragments, not
    patches. Faces are connected when they share a node loaded above the threshold, so a
    side face touching two patches at its unloaded middle does not join them.
    """
    rows, cols, loads = [], [], []
    start = 0
    for g in groups:
        m = len(g.conn)
        fid = np.repeat(np.arange(start, start + m), g.conn.shape[1])
        nodes = g.conn.ravel()
        sel = hot[nodes]
        rows.append(fid[sel])
        cols.append(nodes[sel])
        vals = np.nan_to_num(fld.values if fld.location == "point" else np.asarray(g.values))
        loads.append(face_surface_loads(g.ftype, points, g.conn, vals, fld.location))
        start += m
    _, lab = item_parts(np.concatenate(rows), np.concatenate(cols), start)
    share = np.bincount(lab, weights=np.concatenate(loads))
    share = share / share.sum()
    big = np.sort(share[share > FRAGMENT_SHARE])[::-1]
    if big.size > 1:
        parts = ", ".join(f"{s:.0%}" for s in big)
        raise PatchError(
            f"{fld.source}: {big.size} separate contact patches (load shares {parts}) on different "
            "surfaces (not one plane); fepost analyses one patch at a time: crop the mesh (in an Exodus "
            "file: choose one side set or block with --surface)"
        )
