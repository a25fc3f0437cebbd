"""The pieces of a parallel VTK file (``.pvtu``, ``.pvtp``) joined into one mesh.

A parallel writer cuts one mesh into pieces; every node on a cut is written
once in each piece that uses it. Read piece by piece and laid end to end, those
nodes would be counted twice or three times, and the faces of a volume mesh
along a cut would look like boundary faces. `join_pieces` therefore merges them:

* by global node ids, when the pieces carry them (the point array VTK marks as
  global ids, or one named ``GlobalNodeIds``/``GlobalPointIds``/``vtkGlobalIds``):
  equal ids are one node;
* otherwise by position: nodes of *different* pieces at exactly the same
  coordinates (as written) are one node. A node that has a twin at the same
  position inside its own piece is never merged: coincident nodes within a piece
  are two bodies in contact, which fepost keeps apart (as for every other format).

The ghost cells a writer adds around each piece (``vtkGhostType``) are dropped
before the join by `fepost.reader.vtkfile`. Written with numpy rather than VTK's
point-merging filters, because those merge every coincident pair, also the
nodes of two bodies in contact within one piece.
"""

from __future__ import annotations

import numpy as np

from .raw import RawMesh

#: Names of point arrays read as global node ids.
GLOBAL_ID_NAMES = ("globalnodeids", "globalpointids", "vtkglobalids", "globalids")


def _global_ids(raw: RawMesh) -> np.ndarray | None:
    for name in raw.point_data:
        if name.lower().replace("_", "") in GLOBAL_ID_NAMES:
            ids = np.asarray(raw.point_data[name])
            if ids.ndim == 1 and ids.dtype.kind in "iu":
                return ids.astype(np.int64)
    return None


def _by_position(points: np.ndarray, piece: np.ndarray, npieces: int) -> np.ndarray:
    """For each node, the node it is merged into (itself when it is kept)."""
    n = len(points)
    target = np.arange(n)
    if n == 0:
        return target
    _, group, count = np.unique(points, axis=0, return_inverse=True, return_counts=True)
    group = group.ravel()
    idx = np.flatnonzero(count[group] > 1)
    if not len(idx):
        return target
    g = group[idx]
    key = g * npieces + piece[idx]
    keys, per_key = np.unique(key, return_counts=True)
    twin_groups = np.unique(keys[per_key > 1] // npieces)  # coincident nodes inside one piece
    ok = ~np.isin(g, twin_groups)
    idx, g = idx[ok], g[ok]
    first = np.full(len(count), n)
    np.minimum.at(first, g, idx)
    target[idx] = first[g]
    return target


def join_pieces(raw: RawMesh, sizes: list[int]) -> tuple[RawMesh, int]:
    """``raw`` with the nodes shared by its pieces merged (``sizes``: nodes per piece, in order).

    Returns the joined mesh and the number of nodes merged away. The blocks become
    one body (the pieces of one data set); their connectivity is renumbered, point
    arrays keep the value of each node's first occurrence.
    """
    points = np.asarray(raw.points, float)
    piece = np.repeat(np.arange(len(sizes)), sizes)
    ids = _global_ids(raw)
    if ids is not None:
        _, first, inverse = np.unique(ids, return_index=True, return_inverse=True)
        target = first[inverse.ravel()]
    else:
        target = _by_position(points, piece, len(sizes))
    keep = target == np.arange(len(points))
    merged = int(len(points) - keep.sum())
    new_index = np.cumsum(keep) - 1
    remap = new_index[target]
    out = RawMesh(
        path=raw.path,
        format=raw.format,
        points=points[keep],
        blocks=raw.blocks,
        components=raw.components,
        skipped=raw.skipped,
        connectivity_size=raw.connectivity_size,
    )
    for block in out.blocks:
        block.conn = remap[block.conn]
        block.body = 0
    for name in raw.point_data:
        out.point_data.add(name, np.asarray(raw.point_data[name])[keep])
    return out, merged


__all__ = ["GLOBAL_ID_NAMES", "join_pieces"]
