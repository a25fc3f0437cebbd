"""The contact patch: loaded region, ground plane, frame and circularity check.

Definitions (docs/theory.md, "The contact patch and its frame")
---------------------------------------------------------------
* **Loaded**: an element face is loaded when the FE pressure exceeds the
  threshold somewhere on it: for nodal data when one of its nodes does, for
  face data when its value does. The threshold is ``threshold`` × the peak
  pressure (default `DEFAULT_THRESHOLD` = 1e-6, i.e. essentially
  "non-zero"). Steep faces that touch the contact only where flat loaded faces
  do (the sides of the loaded body) are not part of the patch
  (`fepost.facegroups.drop_edge_faces`).
* **Faces**: linear triangles as they are; bilinear and quadratic faces are cut
  into triangles with their own shape functions, finer until the triangles
  carry the element load to `REFINE_TOL` (``N_fe`` is always the exact
  integral over the element faces, `fepost.reader.quadratic`).
* **Plane**: least-squares plane through the nodes with pressure above the
  threshold (SVD). Its normal is the road normal z, oriented to have a
  positive component along the global axis it is closest to (z-up and y-up
  models both come out with z pointing up).
* **Frame**: origin = static centre of pressure (exact integral over the FE
  faces), x = the rolling axis projected on the plane (default: global x; when
  global x is normal to the patch, the global axis closest to the plane, with a
  warning), y = z × x.
* **R** = ``r_max``: largest in-plane distance from the origin of a node of a
  loaded face (the support of the FE field). ``r_equiv`` = √(area/π) with the
  area of the loaded faces.
* **Circularity**: best-fit ellipse from the second area moments of the
  loaded faces (a uniform ellipse of semi-axes a ≥ b has moments a²/4, b²/4).
  ``circular`` is true when ``aspect`` = a/b ≤ 1 + `ASPECT_TOL` and
  r_max/r_equiv ≤ `RMAX_TOL` (a square, aspect 1, has 1.25).

Rejected (`PatchError` / `PressureError`
/ `DimensionError` / `ScaleError`):
all-zero pressure, NaN inside the patch, negative nodal pressures below −1 % of
the peak, several patches each carrying more than 1 % of the load (side by side,
or on parallel surfaces), a patch whose RMS distance from its plane exceeds
`PLANARITY_TOL` × R (R = r_max, as documented), loaded nodes on one line (a line contact), and
implausible scales (`fepost.reader.units.check_scale`).
Repaired with a warning: NaN away from the patch and small negative values
(set to zero), fragments under 1 % of the load (dropped).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ._arrays import frozen, sealed
from .errors import ArgumentError, DimensionError, PatchError, PressureError, PressureWarning
from .facegroups import STEEP_DEG, drop_edge_faces, loaded_groups
from .facesums import FaceSums, PolarSums, load_outside, triangle_areas
from .field import ContactField
from .frame import Frame, farthest_from_plane, fit_plane, patch_axes

# the patch rules' tolerances, documented here
from .patchfaces import REFINE_MAX_TRIANGLES as REFINE_MAX_TRIANGLES
from .patchfaces import REFINE_TOL as REFINE_TOL
from .patchfaces import cut_faces, drop_fragments, patch_load
from .reader.names import DISPLACEMENT_NAMES, norm
from .reader.units import check_scale
from .regions import GAP_FRACTION as GAP_FRACTION
from .regions import check_single_surface

DEFAULT_THRESHOLD = 1e-6
ASPECT_TOL = 0.10
RMAX_TOL = 1.15
PLANARITY_TOL = 0.02
NEGATIVE_TOL = 0.01
#: Loaded nodes spanning less than this fraction of their length across are on a line.
LINE_TOL = 1e-6


@dataclass(frozen=True)
class Patch:
    """A contact patch in its own frame.

    ``xy`` (k, 2) are the in-plane coordinates (m) of the nodes of the loaded
    faces ``triangles`` (m, 3); ``values`` the pressure (Pa) per node or face.
    Lengths in m, areas in m², forces in N.
    """

    source: str
    field: str
    location: str
    frame: Frame
    xy: np.ndarray
    height: np.ndarray
    triangles: np.ndarray
    values: np.ndarray
    threshold: float
    N_fe: float
    centre_of_pressure: tuple[float, float]
    area: float
    r_max: float
    r_equiv: float
    ellipse_axes: tuple[float, float]
    ellipse_angle: float
    ellipse_centre: tuple[float, float]
    aspect: float
    load_outside: float
    planarity_rms: float
    circular: bool
    reaction_z: float | None = None
    dropped_fragments: int = 0
    max_edge: float = float("nan")  # longest edge of a loaded face (m): the mesh size
    notes: tuple[str, ...] = ()
    n_element_faces: int = 0  # loaded element faces (before the cut into triangles)
    face_types: tuple[str, ...] = ()
    refine_level: int = 0  # 0: linear triangles as read
    refine_error: float = 0.0  # load of the triangles / exact element load − 1
    dropped_edge_faces: int = 0
    body: str = ""
    #: the face pass's terms of the polar-moment enclosure, about their origin in this frame
    #: (`fepost.facesums.PolarSums`; None: no enclosure), for `fepost.refine`
    polar: PolarSums | None = None

    def __post_init__(self) -> None:
        for name in ("xy", "height", "values"):
            object.__setattr__(self, name, frozen(getattr(self, name)))
        object.__setattr__(self, "triangles", frozen(self.triangles, dtype=np.int64))

    @property
    def R(self) -> float:
        return self.r_max

    def node_values(self) -> np.ndarray:
        """Pressure per node (face data spread to nodes by area)."""
        if self.location == "point":
            return self.values
        area = triangle_areas(self.xy, self.triangles)
        num = np.zeros(len(self.xy))
        den = np.zeros(len(self.xy))
        for k in range(3):
            np.add.at(num, self.triangles[:, k], area * self.values)
            np.add.at(den, self.triangles[:, k], area)
        return np.divide(num, den, out=np.zeros_like(num), where=den > 0)

    def to_dict(self) -> dict:
        o = self.frame.origin
        return {
            "centre": [float(o[0]), float(o[1]), float(o[2])],
            "normal": [float(v) for v in self.frame.axes[2]],
            "x_axis": [float(v) for v in self.frame.axes[0]],
            "r_equiv": self.r_equiv,
            "r_max": self.r_max,
            "area": self.area,
            "aspect": self.aspect,
            "ellipse_semi_axes": list(self.ellipse_axes),
            "ellipse_angle_deg": float(np.degrees(self.ellipse_angle)),
            "ellipse_centre": list(self.ellipse_centre),
            "load_outside_r_equiv": self.load_outside,
            "planarity_rms": self.planarity_rms,
            "circular": bool(self.circular),
            "circular_rule": f"aspect <= {1 + ASPECT_TOL:.2f} and r_max/r_equiv <= {RMAX_TOL:.2f}",
            "threshold_pa": self.threshold,
            "n_nodes": int(len(self.xy)),
            "n_faces": int(len(self.triangles)),
            "field": self.field,
            "location": self.location,
            "source": self.source,
            "dropped_fragments": self.dropped_fragments,
            "dropped_edge_faces": self.dropped_edge_faces,
            "n_element_faces": self.n_element_faces,
            "face_types": list(self.face_types),
            "refinement": {"level": self.refine_level, "load_error": self.refine_error},
            "body": self.body,
            "notes": list(self.notes),
        }


def _validate_values(fld: ContactField) -> tuple[np.ndarray, float]:
    """The pressure values checked and, where allowed, repaired (a new array only then)."""
    v = fld.values
    finite = np.isfinite(v)
    all_finite = bool(finite.all())
    if v.size == 0 or (not all_finite and not finite.any()):
        raise PressureError(f"{fld.source}: pressure array {fld.field!r} holds no finite values")
    peak = float(np.max(v) if all_finite else np.max(v[finite]))
    if peak <= 0.0:
        raise PressureError(
            f"{fld.source}: pressure array {fld.field!r} is zero or negative everywhere (no contact)"
        )
    if not all_finite:
        bad = ~finite
        vz = np.where(finite, v, 0.0)
        if fld.location == "point":
            inside = np.zeros(v.size, bool)
            for _, conn, _ in fld.face_groups():
                face_loaded = np.any(vz[conn] > 0, axis=1)
                inside[conn[face_loaded].ravel()] = True
            inside &= bad
        else:
            hot_nodes = np.zeros(fld.n_points, bool)
            groups = list(fld.face_groups())
            for _, conn, sl in groups:
                hot_nodes[conn[vz[sl] > 0].ravel()] = True
            inside = np.zeros(v.size, bool)
            for _, conn, sl in groups:
                inside[sl] = bad[sl] & np.any(hot_nodes[conn], axis=1)
        if inside.any():
            raise PressureError(
                f"{fld.source}: {int(inside.sum())} NaN/inf pressure values inside the contact "
                f"patch (array {fld.field!r})"
            )
        warnings.warn(
            f"{fld.source}: {int(bad.sum())} NaN/inf pressure values outside the contact patch "
            "were set to zero",
            PressureWarning,
            stacklevel=3,
        )
        v = vz
    vmin = float(v.min())
    if vmin < -NEGATIVE_TOL * peak:
        n = int(np.sum(v < -NEGATIVE_TOL * peak))
        raise PressureError(
            f"{fld.source}: negative contact pressure down to {vmin:.4g} Pa at {n} "
            f"{'nodes' if fld.location == 'point' else 'faces'} (array {fld.field!r}); "
            "is the sign convention tension-positive?"
        )
    if vmin < 0.0:
        warnings.warn(
            f"{fld.source}: {int(np.sum(v < 0))} small negative pressures (>= {vmin:.3g} Pa, "
            f"under {NEGATIVE_TOL:.0%} of the peak) were set to zero",
            PressureWarning,
            stacklevel=3,
        )
        v = np.clip(v, 0.0, None)
    return (v if v is fld.values else sealed(v)), peak


class _Plane(NamedTuple):
    """The base frame of the patch: fitted (origin on the plane) or given."""

    frame: Frame
    flat: bool  # every loaded node on the plane to round-off
    note: str  # why the default rolling axis was replaced ("" when it was not)


def _hot_nodes(fld: ContactField, values: np.ndarray, thr: float, groups) -> np.ndarray:
    """Nodes loaded above the threshold (face data: the nodes of the loaded faces)."""
    if fld.location == "point":
        return values > thr
    hot = np.zeros(fld.n_points, bool)
    for g in groups:
        hot[g.conn.ravel()] = True
    return hot


def _fit_frame(fld: ContactField, *, values: np.ndarray, thr: float, groups, rolling_axis) -> _Plane:
    """The plane of the loaded nodes (their pressure as weights) and its axes."""
    src, points = fld.source, fld.points
    if len(groups) == 1 and len(groups[0].conn) == len(fld.triangles) and fld.location == "point":
        sel = None  # every face loaded: weigh all nodes (zero weight off the patch)
    else:
        mask = np.zeros(fld.n_points, bool)
        for g in groups:
            mask[g.conn.ravel()] = True
        sel = np.flatnonzero(mask)
    pts_sel = points if sel is None else points[sel]
    if fld.location == "point":
        vs = values if sel is None else values[sel]
        w = np.where(vs > thr, vs, 0.0)
    else:
        w = np.ones(len(pts_sel))
    if np.count_nonzero(w) < 3:
        raise PatchError(f"{src}: the contact patch has fewer than 3 loaded nodes")
    c, normal, var = fit_plane(pts_sel, w)
    flat = bool(farthest_from_plane(pts_sel, w, c, normal) <= 1e-9 * np.sqrt(var[2]))
    if var[1] <= LINE_TOL**2 * var[2]:
        raise DimensionError(
            f"{src}: the loaded nodes lie on one line: the contact is a line, not a patch "
            "(a 2-D plane or axisymmetric model written as 3-D?); fepost needs a contact area"
        )
    axes, axis_note = patch_axes(normal, rolling_axis, src)
    return _Plane(Frame(origin=c, axes=axes), flat, axis_note)


class _Ellipse(NamedTuple):
    semi: np.ndarray  # major, minor semi-axis (m)
    angle: float  # of the major axis to x, in (−π/2, π/2]
    aspect: float


def _ellipse(sums: FaceSums) -> _Ellipse:
    """The best-fit ellipse: the same second moments of area as the loaded faces."""
    evals, evecs = np.linalg.eigh(sums.covariance())
    evals = np.clip(evals, 0.0, None)
    semi = 2.0 * np.sqrt(evals[::-1])  # major, minor
    major = evecs[:, 1]
    angle = float(np.arctan2(major[1], major[0]))
    angle = (angle + np.pi / 2) % np.pi - np.pi / 2
    aspect = float(semi[0] / semi[1]) if semi[1] > 0 else np.inf
    return _Ellipse(semi, angle, aspect)


def _not_planar_hint(fld: ContactField, *, given_frame: bool) -> str:
    """What a non-planar patch most likely means, from what the reader did with displacements."""
    if fld.displacement is None:
        named = [a for a in fld.arrays if norm(a) in DISPLACEMENT_NAMES]
        if named:
            return f"are the coordinates undeformed? try --displacement {named[0]}"
        done = "the file has no displacement array to apply"
    else:
        done = f"the displacements {fld.displacement!r} were applied"
    if given_frame:
        return (
            f"{done}: is the rolling map at the static map's deflection, in the same coordinates, "
            "on a flat road?"
        )
    return (
        f"{done}: the contact surface itself is curved (e.g. a cylindrical interface); fepost needs "
        "a flat tire-road contact patch"
    )


def _check_planar(fld: ContactField, *, rms: float, r_max: float, given_frame: bool, groups, hot) -> None:
    """Refuse a patch farther from its plane than `PLANARITY_TOL` × R (R = r_max, the
    documented patch radius); loaded faces on several surfaces are named as such first."""
    if rms <= PLANARITY_TOL * r_max:
        return
    check_single_surface(fld, groups, hot, fld.points)
    plane = "the given frame's plane (the static patch's)" if given_frame else "its best-fit plane"
    raise PatchError(
        f"{fld.source}: the contact patch is not planar (RMS distance from {plane} "
        f"{rms:.3g} m = {rms / r_max:.1%} of R = r_max {r_max:.4g} m, limit {PLANARITY_TOL:.0%}); "
        + _not_planar_hint(fld, given_frame=given_frame)
    )


def _in_frame(xy: np.ndarray, *, cop: np.ndarray, centroid: np.ndarray, base: Frame, given: bool):
    """(frame, in-plane coordinates, centre of pressure, centroid) in the patch frame: a fitted
    base frame moves to the centre of pressure; a given frame stays (the centre of pressure is
    then reported relative to it)."""
    if given:
        return base, xy, (float(cop[0]), float(cop[1])), centroid
    fr = Frame(origin=base.to_global(cop[None, :])[0], axes=base.axes)  # on the plane: local z = 0
    xy -= cop  # in place: the projection's array, which nothing else holds
    return fr, xy, (0.0, 0.0), centroid - cop


def build_patch(
    fld: ContactField,
    *,
    threshold: float = DEFAULT_THRESHOLD,
    rolling_axis=None,
    frame: Frame | None = None,
) -> Patch:
    """Find the loaded region of ``fld`` and describe it in the patch frame.

    Parameters
    ----------
    fld : ContactField
        The FE contact-pressure field (``fepost.reader.read_contact``).
    threshold : float
        Relative pressure threshold (fraction of the peak) that defines "loaded".
    rolling_axis : 3-vector, optional
        Global direction projected on the plane to give x (default global x).
    frame : Frame, optional
        Use this frame (e.g. the static patch's, for a rolling map) instead of
        fitting one; the centre of pressure is then reported relative to it.

    Returns
    -------
    Patch
        The loaded region in its frame, with R = r_max, N_fe and the circularity check.
    """
    if not (0.0 <= threshold < 1.0):
        raise ArgumentError(f"threshold must be a fraction of the peak pressure in [0, 1), got {threshold!r}")
    src = fld.source
    v, peak = _validate_values(fld)
    thr = threshold * peak
    groups = loaded_groups(fld, v, thr)
    if not groups:
        raise PatchError(f"{src}: no element face carries pressure above the threshold")
    hot = _hot_nodes(fld, v, thr, groups)
    if frame is None:
        plane = _fit_frame(fld, values=v, thr=thr, groups=groups, rolling_axis=rolling_axis)
    else:
        plane = _Plane(frame, False, "")
    base = plane.frame
    groups, n_edge = drop_edge_faces(groups, fld.points, hot, base.axes[2], fld.location, flat=plane.flat)
    cut = cut_faces(fld, values=v, thr=thr, groups=groups, base=base)
    cut = drop_fragments(fld, cut=cut, values=v, thr=thr, base=base)
    N, cop, refine_err, load_notes = patch_load(cut, location=fld.location)
    _, tri_local, nvals, xy, height, weights, sums = cut.geo
    fr, xy, cop_rel, cen = _in_frame(xy, cop=cop, centroid=sums.centroid, base=base, given=frame is not None)
    xy = sealed(xy)
    height = sealed(height)
    x, y = xy[:, 0], xy[:, 1]
    ellipse = _ellipse(sums)
    r2 = x * x
    r2 += y * y
    r_max = float(np.sqrt(np.max(r2)))
    r_equiv = float(np.sqrt(sums.A / np.pi))
    rms = float(np.sqrt((weights @ (height * height)) / weights.sum()))
    _check_planar(fld, rms=rms, r_max=r_max, given_frame=frame is not None, groups=cut.groups, hot=hot)
    check_scale(src, r_max, peak, fld.units)
    outside = load_outside(x, y, tri_local, nvals, fld.location, r_equiv, sums, r2=r2)
    circular = bool(ellipse.aspect <= 1.0 + ASPECT_TOL and r_max / r_equiv <= RMAX_TOL)
    notes = [*fld.notes, *([plane.note] if plane.note else []), *_edge_note(n_edge), *load_notes]
    if not circular:
        notes.append(
            f"patch is not circular (aspect {ellipse.aspect:.3f}, r_max/r_equiv {r_max / r_equiv:.3f}); "
            "the paper's closed forms assume a circle"
        )
    return Patch(
        source=src,
        field=fld.field,
        location=fld.location,
        frame=fr,
        xy=xy,
        height=height,
        triangles=tri_local,
        values=nvals,
        threshold=thr,
        N_fe=N,
        centre_of_pressure=cop_rel,
        area=float(sums.A),
        r_max=r_max,
        r_equiv=r_equiv,
        ellipse_axes=(float(ellipse.semi[0]), float(ellipse.semi[1])),
        ellipse_angle=ellipse.angle,
        ellipse_centre=(float(cen[0]), float(cen[1])),
        aspect=ellipse.aspect,
        load_outside=outside,
        planarity_rms=rms,
        circular=circular,
        reaction_z=fld.reaction_z,
        dropped_fragments=cut.dropped,
        max_edge=sums.max_edge,
        notes=tuple(notes),
        n_element_faces=sum(len(g.conn) for g in cut.groups),
        face_types=tuple(sorted({g.ftype for g in cut.groups})),
        refine_level=0 if cut.exact is None else cut.level,
        refine_error=refine_err,
        dropped_edge_faces=n_edge,
        body=fld.body,
        polar=_moved(sums.polar, xy_shift=None if frame is not None else cop),
    )


def _moved(polar: PolarSums | None, *, xy_shift) -> PolarSums | None:
    """``polar`` with its origin in the patch frame: the base frame's origin, at −(centre of
    pressure) once the frame moved there (``xy_shift``: what `_in_frame` took from xy)."""
    if polar is None or xy_shift is None:
        return polar
    return polar._replace(origin=(-float(xy_shift[0]), -float(xy_shift[1])))


def _edge_note(n_edge: int) -> tuple[str, ...]:
    if not n_edge:
        return ()
    return (
        f"{n_edge} loaded face(s) steeper than {STEEP_DEG:g} deg to the patch plane, touching the "
        "contact only at its edge (sides of the loaded body), are not part of the patch",
    )
