"""The loaded faces of a patch as triangles: cut, projected, integrated, fragments dropped.

The steps of `fepost.patch.build_patch` between the plane and the patch's shape:

* `cut_faces` – the loaded element faces as triangles in the patch's base
  frame: linear triangles as they are; bilinear and quadratic faces cut with
  their own shape functions, finer until the triangles carry the element load
  to `REFINE_TOL` (while that converges, within `REFINE_MAX_TRIANGLES`);
* `drop_fragments` – small loaded regions beside the patch left out (with a
  warning), several large ones refused;
* `patch_load` – N and the centre of pressure: the exact element integrals
  where faces were cut (``fepost.facegroups.exact_load``), else the
  triangles' own sums.

`project_faces` compacts, projects and integrates one set of triangles (`Geometry`).
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from ._arrays import sealed
from .errors import PatchError, PatchWarning
from .facegroups import exact_load, folded_faces, next_triangles, only_triangles, refine
from .facesums import FaceSums, face_loads, face_sums
from .field import ContactField
from .frame import Frame, frame_rows
from .regions import FRAGMENT_SHARE, loaded_regions

#: Largest |load of the triangles / exact element load − 1| before the faces are cut finer.
REFINE_TOL = 1e-4
#: Most triangles the cut of curved faces may make (the finest level stays within it).
REFINE_MAX_TRIANGLES = 4_000_000
#: Sidecar key by which a map declares that it holds this many separate contact patches on
#: purpose (a body on point supports, `fepost.bodymap`): exactly that many regions are kept
#: together; any other count is refused as for every other map.
DECLARED_PATCHES_KEY = "separate_patches"


class Geometry(NamedTuple):
    points: np.ndarray
    triangles: np.ndarray
    values: np.ndarray
    xy: np.ndarray  # (n, 2) in-plane coordinates in the base frame (m)
    z: np.ndarray  # distance from the base plane (m)
    weights: np.ndarray  # per node: the pressure where loaded, else 0 (face data: 1)
    sums: FaceSums


def project_faces(source, points, tri, vals, location, thr, base: Frame) -> Geometry:
    """Compact the nodes of ``tri``, project them into ``base`` and integrate."""
    used_mask = np.zeros(len(points), bool)
    used_mask[tri.ravel()] = True
    if used_mask.all():
        pts, tri_local, nvals = points, tri, vals
    else:
        used = np.flatnonzero(used_mask)
        remap = np.cumsum(used_mask) - 1
        tri_local = sealed(remap[tri])  # new here: the patch shares it
        pts = points[used]
        nvals = vals[used] if location == "point" else vals
    w = np.where(nvals > thr, nvals, 0.0) if location == "point" else np.ones(len(pts))
    rows = frame_rows(pts, base)  # patch coordinates as rows: x and y columns of xy contiguous
    xy, z = rows[:2].T, rows[2]
    sums = face_sums(xy[:, 0], xy[:, 1], tri_local, nvals, location)
    if not sums.N > 0:
        raise PatchError(f"{source}: the contact patch carries no load")
    return Geometry(pts, tri_local, nvals, xy, z, w, sums)


class Cut(NamedTuple):
    """The loaded faces as triangles, projected and integrated."""

    geo: Geometry
    groups: list  # the loaded face groups (``FaceGroup``)
    parent: np.ndarray | None  # element face of each triangle (None: linear triangles as read)
    exact: np.ndarray | None  # exact element load and its first moments (None: linear triangles)
    level: int  # the cut's level (1: no subdivision)
    xy_native: np.ndarray | None  # in-plane coordinates of every node (element faces only)
    dropped: int = 0  # small loaded fragments left out


def _triangles(fld: ContactField, *, values: np.ndarray, thr: float, groups, level: int):
    """The loaded faces as triangles: (points, triangles, values, parent face of each triangle
    or None for linear triangles as read)."""
    points = fld.points
    if only_triangles(groups):
        tri = groups[0].conn if len(groups) == 1 else np.concatenate([g.conn for g in groups])
        if fld.location == "point":
            return points, tri, values, None
        fv = groups[0].values if len(groups) == 1 else np.concatenate([g.values for g in groups])
        return points, tri, fv, None
    pts, tri, vals, ids, linear = refine(groups, points, values, fld.location, level)
    if fld.location == "point":
        # a linear or bilinear piece with no node above the threshold carries (almost) nothing:
        # leave it out of the loaded area, as for linear triangles
        hot_t = (vals > thr)[tri]
        keep = ~linear | hot_t[:, 0] | hot_t[:, 1] | hot_t[:, 2]
        if not keep.all():
            tri, ids = tri[keep], ids[keep]
    return pts, tri, vals, ids


def cut_faces(fld: ContactField, *, values: np.ndarray, thr: float, groups, base: Frame) -> Cut:
    """Cut the loaded faces into triangles, finer until they carry the element load."""
    src, points = fld.source, fld.points
    xy_native = None
    if not only_triangles(groups):
        xy_native = points @ base.axes[:2].T - base.origin @ base.axes[:2].T
        bad = folded_faces(groups, xy_native)
        if bad:
            raise PatchError(
                f"{src}: {bad} loaded element face(s) fold over in the patch plane (repeated or "
                "crossed corner nodes): corrupt or inverted elements"
            )
    level = 1
    exact = None
    previous = np.inf
    while True:
        pts, tri, vals, parent = _triangles(fld, values=values, thr=thr, groups=groups, level=level)
        geo = project_faces(src, pts, tri, vals, fld.location, thr, base)
        if parent is None or xy_native is None:  # linear triangles as read (then both are None)
            break
        exact = exact_load(groups, xy_native, values, fld.location)
        err = abs(geo.sums.N / exact[0] - 1.0)
        # finer until the triangles carry the element load, while that converges (error / 4 per level)
        if (
            err <= REFINE_TOL
            or next_triangles(groups, 2 * level) > REFINE_MAX_TRIANGLES
            or err > 0.5 * previous
        ):
            break
        previous = err
        level *= 2
    return Cut(geo, groups, parent, exact, level, xy_native)


def drop_fragments(fld: ContactField, *, cut: Cut, values: np.ndarray, thr: float, base: Frame) -> Cut:
    """The cut without the small loaded fragments beside the patch (refused when several
    regions each carry more than `FRAGMENT_SHARE` of the load)."""
    src, geo = fld.source, cut.geo
    ncomp, labels = loaded_regions(geo.xy[:, 0], geo.xy[:, 1], geo.triangles, geo.sums)
    if ncomp <= 1 or ncomp == declared_patches(fld):
        return cut
    loads = face_loads(geo.xy, geo.triangles, geo.values, fld.location)
    share = np.bincount(labels, weights=loads, minlength=ncomp) / geo.sums.N
    big = np.flatnonzero(share > FRAGMENT_SHARE)
    if big.size > 1:
        parts = ", ".join(f"{s:.0%}" for s in sorted(share[big], reverse=True))
        raise PatchError(
            f"{src}: {big.size} separate contact patches (load shares {parts}); "
            "dual wheels or a split patch? fepost analyses one patch at a time: crop the mesh"
        )
    main = int(np.argmax(share))
    keep = labels == main
    dropped = int(ncomp - 1)
    warnings.warn(
        f"{src}: dropped {dropped} small loaded fragment(s) carrying {1 - share[main]:.2%} of the load",
        PatchWarning,
        stacklevel=3,
    )
    tri_kept = geo.triangles[keep]
    vals_kept = geo.values if fld.location == "point" else geo.values[keep]
    groups, exact = cut.groups, cut.exact
    if cut.parent is not None:
        kept_ids = np.unique(cut.parent[np.flatnonzero(keep)])  # compaction keeps the order
        groups = [g.subset(np.isin(g.ids, kept_ids)) for g in groups]
        groups = [g for g in groups if len(g.conn)]
    geo = project_faces(src, geo.points, tri_kept, vals_kept, fld.location, thr, base)
    if cut.parent is not None and cut.xy_native is not None:
        exact = exact_load(groups, cut.xy_native, values, fld.location)
    return cut._replace(geo=geo, groups=groups, exact=exact, dropped=dropped)


def declared_patches(fld: ContactField) -> int:
    """The number of separate patches ``fld``'s sidecar declares (`DECLARED_PATCHES_KEY`, an
    integer >= 2), else 1."""
    n = (fld.sidecar or {}).get(DECLARED_PATCHES_KEY)
    return n if isinstance(n, int) and not isinstance(n, bool) and n >= 2 else 1


def patch_load(cut: Cut, *, location: str) -> tuple[float, np.ndarray, float, tuple[str, ...]]:
    """N, the centre of pressure (base frame), the cut's load error and notes: the exact
    element integrals where faces were cut, else the triangles' own sums."""
    sums = cut.geo.sums
    if cut.exact is None:
        return sums.N, sums.centre_of_pressure, 0.0, ()
    exact = cut.exact
    N, cop = float(exact[0]), exact[1:] / exact[0]
    refine_err = float(sums.N / exact[0] - 1.0)
    notes = []
    if abs(refine_err) > REFINE_TOL:
        notes.append(
            f"element faces cut into triangles carry {refine_err:+.2e} of the exact element load "
            f"(finest cut within {REFINE_MAX_TRIANGLES:,} triangles)"
        )
    geo = cut.geo
    lobes = -float(face_loads(geo.xy, geo.triangles, np.minimum(geo.values, 0.0), location).sum()) / N
    if location == "point" and lobes > 1e-4:
        notes.append(
            f"the quadratic interpolation dips below zero between nodes ({lobes:.2%} of the load): "
            "kept, as the element's own field (not a sign error)"
        )
    return N, cop, refine_err, tuple(notes)
