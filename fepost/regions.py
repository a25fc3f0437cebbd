"""How many contact patches the loaded faces make: side by side in the plane, or on different surfaces."""

from __future__ import annotations

import numpy as np

from .errors import PatchError
from .facegroups import FaceGroup
from .facesums import FaceSums
from .field import ContactField
from .reader.quadratic import face_surface_loads

#: Regions closer than this fraction of √area belong to one patch (tread grooves).
GAP_FRACTION = 0.05
#: Largest raster side, cells.
RASTER_MAX = 2048
#: Loaded regions carrying more than this share of the load are patches (smaller ones: fragments).
FRAGMENT_SHARE = 0.01


def warm_up() -> None:
    """Import what the patch step needs beyond numpy (scipy.ndimage, ~0.3 s), e.g. while a file is read."""
    from scipy import ndimage  # noqa: F401


def _components(x: np.ndarray, y: np.ndarray, tri: np.ndarray, sums: FaceSums) -> tuple[int, np.ndarray]:
    """Separate loaded regions: (count, label per face).

    Regions closer than a gap of about :data:`GAP_FRACTION` × √area (tread
    grooves, sparse contact at the edge) belong to one patch; regions farther
    apart (dual wheels) are separate. The nodes are binned on a raster of cell
    h = max(GAP_FRACTION·√area, longest loaded edge), so faces that share a node
    always fall in touching cells; one dilation closes gaps narrower than ~h.
    """
    from scipy import ndimage

    h = max(GAP_FRACTION * np.sqrt(sums.A), sums.max_edge)
    lo = np.array([x.min(), y.min()])
    ext = np.array([x.max(), y.max()]) - lo
    n = np.floor(ext / h).astype(int) + 3
    if n.max() > RASTER_MAX:  # a very sparse region: coarsen the raster
        h *= n.max() / RASTER_MAX
        n = np.floor(ext / h).astype(int) + 3
    # coordinates are >= lo, so truncation is the floor
    i = ((x - lo[0]) * (1.0 / h)).astype(np.int32) + 1
    j = ((y - lo[1]) * (1.0 / h)).astype(np.int32) + 1
    occupied = np.zeros(tuple(n), bool)
    occupied[i, j] = True
    occupied = ndimage.binary_dilation(occupied, structure=np.ones((3, 3), bool))
    labels, count = ndimage.label(occupied, structure=np.ones((3, 3), bool))
    if count == 1:
        return 1, np.zeros(len(tri), np.int64)
    first = tri[:, 0]
    return int(count), labels[i[first], j[first]] - 1


def _separate_surfaces(fld: ContactField, groups: list[FaceGroup], hot: np.ndarray, points) -> None:
    """Raise when the loaded faces form several patches (e.g. on parallel surfaces).

    Faces are connected when they share a node loaded above the threshold, so a
    side face touching two patches at its unloaded middle does not join them.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

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
    nf = start
    r, c = np.concatenate(rows), np.concatenate(cols)
    g = coo_matrix((np.ones(len(r), np.int8), (r, nf + c)), shape=(nf + len(points), nf + len(points)))
    count, labels = connected_components(g, directed=False)
    lab = labels[:nf]
    _, lab = np.unique(lab, return_inverse=True)
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
