"""The loaded element faces of a contact field, grouped by face type, on their way to triangles.

The patch step works on linear triangles (`fepost.facesums`,
`fepost.locate`); element faces of other types are cut into triangles by
`refine`, with their exact load kept aside (`exact_load`) to check
the cut. Faces whose normal is steep to the patch plane and which touch the
contact only where flat loaded faces do are the sides of the loaded body, not
contact surface: `drop_edge_faces` removes them (a side face of a block
whose bottom edge is in contact would otherwise carry half the edge pressure
up its height).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._arrays import sealed
from ._chunks import map_chunks, slices
from .field import ContactField
from .reader import quadratic

#: A face is steep when its normal makes more than this angle with the patch normal (degrees). The
#: faces at the rim of the sample tire patches lean up to 14 deg; the sides of a block, 90 deg; the
#: slanted face of a corner tetrahedron, 55 deg.
STEEP_DEG = 45.0
#: Faces per chunk of the loaded-face test (its temporaries stay in the cache).
ROW_CHUNK = 1 << 16


@dataclass(frozen=True)
class FaceGroup:
    """Faces of one type.

    ``conn`` (m, k); ``values`` per face (face data) or None; ``face_ids`` (m,) face
    ids, or a ``range`` of consecutive ones (made an array only when `ids` is asked for:
    linear triangles never need theirs); ``partial`` (m,) true where some node is not
    loaded (the rim of the patch).
    """

    ftype: str
    conn: np.ndarray
    values: np.ndarray | None
    face_ids: np.ndarray | range
    partial: np.ndarray

    @property
    def ids(self) -> np.ndarray:
        """The face ids as an (m,) array."""
        r = self.face_ids
        return np.arange(r.start, r.stop) if isinstance(r, range) else r

    def subset(self, keep: np.ndarray) -> FaceGroup:
        return FaceGroup(
            self.ftype,
            self.conn[keep],
            None if self.values is None else self.values[keep],
            self.ids[keep],
            self.partial[keep],
        )

    def corners(self) -> np.ndarray:
        return self.conn[:, : (3 if self.ftype.startswith("tri") else 4)]


def loaded_groups(fld: ContactField, v: np.ndarray, thr: float) -> list[FaceGroup]:
    """The faces of ``fld`` with pressure above ``thr`` at a node (nodal data) or on the face."""
    out = []
    hot = v > thr if fld.location == "point" else None
    for ftype, conn, sl in fld.face_groups():
        if hot is not None:
            loaded, partial = _loaded_rows(hot, conn)
            fv = None
        else:
            fv = v[sl]
            loaded = fv > thr
            partial = np.ones(len(conn), bool)
        if loaded.all():
            out.append(FaceGroup(ftype, conn, fv, range(sl.start, sl.stop), partial))
        elif loaded.any():
            sub = None if fv is None else fv[loaded]
            ids = np.flatnonzero(loaded) + sl.start
            # a new array no caller holds: sealed, so the patch shares it instead of copying
            out.append(FaceGroup(ftype, sealed(conn[loaded]), sub, ids, partial[loaded]))
    return out


def _loaded_rows(hot: np.ndarray, conn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(some node hot, not every node hot) per face of ``conn``, in chunks of `ROW_CHUNK`
    faces shared by two threads (`fepost._chunks`)."""

    def chunk(sl: slice) -> tuple[np.ndarray, np.ndarray]:
        c = conn[sl]
        h = hot[c[:, 0]]
        loaded, full = h.copy(), h
        for k in range(1, c.shape[1]):
            h = hot[c[:, k]]
            loaded |= h
            full &= h
        return loaded, ~full

    parts = map_chunks(chunk, slices(len(conn), ROW_CHUNK))
    if len(parts) <= 1:
        return parts[0] if parts else (np.zeros(0, bool), np.zeros(0, bool))
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _steep(points: np.ndarray, corners: np.ndarray, normal: np.ndarray, cos_max: float) -> np.ndarray:
    """True where a face's normal makes more than arccos(``cos_max``) with ``normal`` (and for
    degenerate faces, which have no normal). ``corners``: (m, 3) triangles or (m, 4) quadrilaterals
    (the normal of a quadrilateral is that of its diagonals)."""
    p = points.take(corners, axis=0)  # (m, corners, 3): one gather of whole rows
    uv = p[:, 1:] - p[:, :1] if corners.shape[1] == 3 else p[:, 2:] - p[:, :2]
    u, v = uv[:, 0].T, uv[:, 1].T
    # n = u × v by components (np.cross is several times slower on long arrays)
    nx = u[1] * v[2] - u[2] * v[1]
    ny = u[2] * v[0] - u[0] * v[2]
    nz = u[0] * v[1] - u[1] * v[0]
    along = np.abs(nx * normal[0] + ny * normal[1] + nz * normal[2])
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    return (along < cos_max * norm) | (norm == 0)


def drop_edge_faces(
    groups: list[FaceGroup],
    points: np.ndarray,
    hot: np.ndarray,
    normal: np.ndarray,
    location: str,
    flat: bool = False,
) -> tuple[list[FaceGroup], int]:
    """Remove steep faces that meet the contact only at nodes of flat loaded faces.

    ``hot`` marks the nodes loaded above the threshold. For nodal data a steep
    face is dropped when every loaded node of it is a node of a flat loaded
    face; for face data (no nodal values) when it shares two or more corners
    with flat loaded faces. ``flat``: the loaded nodes lie in the plane (to
    round-off), so only faces with an unloaded node can be steep and the others
    are not examined. Returns the groups kept and the count dropped.
    """
    cos_max = np.cos(np.radians(STEEP_DEG))
    steep = []
    for g in groups:
        s = np.zeros(len(g.conn), bool)
        look = np.flatnonzero(g.partial) if flat else np.arange(len(g.conn))
        if look.size:
            s[look] = _steep(points, g.corners()[look], normal, cos_max)
        steep.append(s)
    if not any(s.any() for s in steep):
        return groups, 0
    flat_nodes = np.zeros(len(points), bool)
    for g, s in zip(groups, steep, strict=True):
        flat_nodes[g.conn[~s].ravel()] = True
    out, dropped = [], 0
    for g, s in zip(groups, steep, strict=True):
        if not s.any():
            out.append(g)
            continue
        c = g.conn[s]
        if location == "point":
            own = hot[c] & ~flat_nodes[c]
            edge = ~own.any(axis=1)
        else:
            edge = flat_nodes[g.corners()[s]].sum(axis=1) >= 2
        drop = np.zeros(len(g.conn), bool)
        drop[np.flatnonzero(s)[edge]] = True
        dropped += int(drop.sum())
        if not drop.all():
            out.append(g.subset(~drop) if drop.any() else g)
    return out, dropped


#: First refinement level per face type (see `fepost.reader.quadratic.refine`).
START_LEVEL = {"tri3": 0, "quad4": 1, "tri6": 4, "tri7": 4, "quad8": 4, "quad9": 4}


def refine(
    groups: list[FaceGroup], points: np.ndarray, values: np.ndarray, location: str, level: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Triangles of the groups: (points, triangles, values, face id per triangle, linear flag per triangle).

    Linear triangles keep their nodes; a ``quad4`` at ``level`` 1 is split
    along its diagonal (0, 2) on its own nodes; other faces are cut at
    ``level`` × their `START_LEVEL` into triangles whose new nodes
    follow ``points`` (nodal values interpolated with the shape functions;
    face values repeated per triangle). The linear flag marks triangles whose
    field cannot dip below its nodal values (linear and bilinear faces).
    """
    pts_parts = [points]
    tri_parts: list[Any] = []
    val_parts: list[Any] = []
    id_parts: list[Any] = []
    lin_parts: list[Any] = []
    nvals_parts: list[Any] = [values] if location == "point" else []
    base = len(points)
    for g in groups:
        if g.ftype == "tri3" or (g.ftype == "quad4" and level == 1):
            if g.ftype == "tri3":
                t, ids, fv = g.conn, g.ids, g.values
            else:
                t = np.concatenate([g.conn[:, [0, 1, 2]], g.conn[:, [0, 2, 3]]])
                ids = np.concatenate([g.ids, g.ids])
                fv = None if g.values is None else np.concatenate([g.values, g.values])
            tri_parts.append(t)
            id_parts.append(ids)
            lin_parts.append(np.ones(len(t), bool))
            if location == "cell":
                val_parts.append(fv)
            continue
        lv = START_LEVEL[g.ftype] * level
        p, t, nv = quadratic.refine(g.ftype, points, g.conn, values if location == "point" else None, lv)
        per = quadratic.triangles_per_face(g.ftype, lv)
        pts_parts.append(p)
        tri_parts.append(t + base)
        id_parts.append(np.repeat(g.ids, per))
        lin_parts.append(np.full(len(t), g.ftype == "quad4"))
        if location == "point":
            nvals_parts.append(nv)
        else:
            val_parts.append(np.repeat(np.asarray(g.values), per))
        base += len(p)
    pts = pts_parts[0] if len(pts_parts) == 1 else np.concatenate(pts_parts)
    tri = np.concatenate(tri_parts) if tri_parts else np.empty((0, 3), np.int64)
    if location == "point":
        vals = nvals_parts[0] if len(nvals_parts) == 1 else np.concatenate(nvals_parts)
    else:
        vals = np.concatenate(val_parts) if val_parts else np.empty(0)
    ids = np.concatenate(id_parts) if id_parts else np.empty(0, np.int64)
    return pts, tri, vals, ids, np.concatenate(lin_parts) if lin_parts else np.empty(0, bool)


def exact_load(groups: list[FaceGroup], xy: np.ndarray, values: np.ndarray, location: str) -> np.ndarray:
    """Exact (N, ∬σx, ∬σy) of the faces with their own shape functions, in the plane of ``xy``."""
    tot = np.zeros(3)
    for g in groups:
        vals = values if location == "point" else np.asarray(g.values)
        tot += quadratic.face_moments(g.ftype, xy, g.conn, vals, location).sum(axis=0)
    return tot


def folded_faces(groups: list[FaceGroup], xy: np.ndarray) -> int:
    """How many faces (other than linear triangles) fold over in the plane of ``xy``."""
    return sum(int(quadratic.folded(g.ftype, xy, g.conn).sum()) for g in groups if g.ftype != "tri3")


def next_triangles(groups: list[FaceGroup], level: int) -> int:
    """Triangles the cut at ``level`` makes of the faces other than linear triangles."""
    return sum(
        len(g.conn) * quadratic.triangles_per_face(g.ftype, START_LEVEL[g.ftype] * level)
        for g in groups
        if g.ftype != "tri3"
    )


def only_triangles(groups: list[FaceGroup]) -> bool:
    return all(g.ftype == "tri3" for g in groups)
