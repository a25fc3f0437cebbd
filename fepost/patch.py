"""The contact patch: loaded region, ground plane, frame and circularity check.

Definitions (THEORY.md §1)
--------------------------
* **Loaded**: a face is loaded when the FE pressure exceeds the threshold
  somewhere on it: for nodal data when one of its nodes does, for face data
  when its value does. The threshold is ``threshold`` × the peak pressure
  (default :data:`DEFAULT_THRESHOLD` = 1e-6, i.e. essentially "non-zero").
* **Plane**: least-squares plane through the nodes with pressure above the
  threshold (SVD). Its normal is the road normal z, oriented to have a
  positive component along the global axis it is closest to (z-up and y-up
  models both come out with z pointing up).
* **Frame**: origin = static centre of pressure (exact integral over the FE
  faces), x = the rolling axis projected on the plane (default: global x),
  y = z × x.
* **R** = ``r_max``: largest in-plane distance from the origin of a node of a
  loaded face (the support of the FE field). ``r_equiv`` = √(area/π) with the
  area of the loaded faces.
* **Circularity**: best-fit ellipse from the second area moments of the
  loaded faces (a uniform ellipse of semi-axes a ≥ b has moments a²/4, b²/4).
  ``circular`` is true when ``aspect`` = a/b ≤ 1 + :data:`ASPECT_TOL` and
  r_max/r_equiv ≤ :data:`RMAX_TOL` (a square, aspect 1, has 1.25).

Rejected (:class:`~fepost.errors.PatchError` / :class:`~fepost.errors.PressureError`):
all-zero pressure, NaN inside the patch, negative pressures below −1 % of the
peak, several patches each carrying more than 1 % of the load, a patch whose
RMS distance from its plane exceeds :data:`PLANARITY_TOL` × r_equiv.
Repaired with a warning: NaN away from the patch and small negative values
(set to zero), fragments under 1 % of the load (dropped).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy import ndimage

from ._arrays import frozen, sealed
from .errors import ArgumentError, PatchError, PatchWarning, PressureError, PressureWarning
from .facesums import FaceSums, face_loads, face_sums, load_outside, triangle_areas
from .field import ContactField

DEFAULT_THRESHOLD = 1e-6
ASPECT_TOL = 0.10
RMAX_TOL = 1.15
PLANARITY_TOL = 0.02
NEGATIVE_TOL = 0.01
FRAGMENT_SHARE = 0.01
GAP_FRACTION = 0.05
RASTER_MAX = 2048


@dataclass(frozen=True)
class Frame:
    """Patch frame: ``origin`` (3,) in global coordinates (m); ``axes`` rows are x, y, z."""

    origin: np.ndarray
    axes: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", frozen(self.origin))
        object.__setattr__(self, "axes", frozen(self.axes))

    def to_local(self, points) -> np.ndarray:
        """Global (n, 3) points → patch coordinates (n, 3), m."""
        return (np.asarray(points, float) - self.origin) @ self.axes.T

    def to_global(self, local) -> np.ndarray:
        """Patch coordinates (n, 2 or 3) → global (n, 3), m."""
        local = np.asarray(local, float)
        if local.shape[-1] == 2:
            local = np.concatenate([local, np.zeros(local.shape[:-1] + (1,))], axis=-1)
        return local @ self.axes + self.origin


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
        }


def _validate_values(fld: ContactField) -> tuple[np.ndarray, float]:
    """The pressure values checked and, where allowed, repaired (a new array only then)."""
    v = fld.values
    finite = np.isfinite(v)
    if not finite.any():
        raise PressureError(f"{fld.source}: pressure array {fld.field!r} holds no finite values")
    peak = float(np.max(v[finite]))
    if peak <= 0.0:
        raise PressureError(
            f"{fld.source}: pressure array {fld.field!r} is zero or negative everywhere (no contact)"
        )
    if not finite.all():
        bad = ~finite
        if fld.location == "point":
            loaded_nodes = np.zeros(v.size, bool)
            face_loaded = np.any(np.where(finite[fld.triangles], v[fld.triangles], 0.0) > 0, axis=1)
            loaded_nodes[fld.triangles[face_loaded].ravel()] = True
            inside = bad & loaded_nodes
        else:
            tri_nodes_loaded = np.zeros(fld.n_points, bool)
            tri_nodes_loaded[fld.triangles[finite & (np.where(finite, v, 0) > 0)].ravel()] = True
            inside = bad & np.any(tri_nodes_loaded[fld.triangles], axis=1)
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
        v = np.where(finite, v, 0.0)
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


def _loaded_faces(fld: ContactField, v: np.ndarray, thr: float) -> np.ndarray:
    if fld.location == "point":
        hot = (v > thr)[fld.triangles]
        return hot[:, 0] | hot[:, 1] | hot[:, 2]
    return v > thr


def _components(x: np.ndarray, y: np.ndarray, tri: np.ndarray, sums: FaceSums) -> tuple[int, np.ndarray]:
    """Separate loaded regions: (count, label per face).

    Regions closer than a gap of about :data:`GAP_FRACTION` × √area (tread
    grooves, sparse contact at the edge) belong to one patch; regions farther
    apart (dual wheels) are separate. The nodes are binned on a raster of cell
    h = max(GAP_FRACTION·√area, longest loaded edge), so faces that share a node
    always fall in touching cells; one dilation closes gaps narrower than ~h.
    """
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


def _plane(points: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted least-squares plane through ``points`` (n, 3): (centroid, unit normal).

    The second moments are accumulated column by column (one (n,) temporary)
    about a node of the patch, so large global offsets cost no precision.
    """
    w = weights / weights.sum()
    ref = points[int(np.argmax(weights))]
    c = w @ points - ref
    m = np.empty((3, 3))
    buf = np.empty(len(points))
    cols = [points[:, k] for k in range(3)]
    for a in range(3):
        np.subtract(cols[a], ref[a], out=buf)
        buf *= w
        for b in range(a, 3):
            m[a, b] = m[b, a] = buf @ cols[b] - ref[b] * buf.sum()
    cov = m - np.outer(c, c)
    _, vecs = np.linalg.eigh(cov)
    n = vecs[:, 0]
    k = int(np.argmax(np.abs(n)))
    if n[k] < 0:
        n = -n
    return c + ref, n


def _axes(normal: np.ndarray, rolling_axis) -> np.ndarray:
    if rolling_axis is None:
        rolling_axis = (1.0, 0.0, 0.0)
    ax = np.asarray(rolling_axis, float)
    if ax.shape != (3,) or not np.all(np.isfinite(ax)) or np.linalg.norm(ax) == 0:
        raise ArgumentError(f"rolling_axis must be a non-zero 3-vector, got {rolling_axis!r}")
    ax = ax / np.linalg.norm(ax)
    x = ax - (ax @ normal) * normal
    if np.linalg.norm(x) < 0.1:
        raise ArgumentError(
            f"rolling_axis {tuple(np.round(ax, 3))} is (nearly) normal to the patch plane "
            f"(normal {tuple(np.round(normal, 3))}); give an in-plane rolling axis"
        )
    x /= np.linalg.norm(x)
    y = np.cross(normal, x)
    return np.vstack([x, y, normal])


class _Geometry(NamedTuple):
    points: np.ndarray
    triangles: np.ndarray
    values: np.ndarray
    base: Frame
    xy: np.ndarray  # (n, 2) in-plane coordinates in the base frame (m)
    z: np.ndarray  # distance from the base plane (m)
    weights: np.ndarray  # per node: the pressure where loaded, else 0 (face data: 1)
    sums: FaceSums


def _geometry(fld, tri, fvals, v, thr, frame, rolling_axis) -> _Geometry:
    """Compact the loaded faces, fit the plane (unless ``frame``) and integrate."""
    used_mask = np.zeros(fld.n_points, bool)
    used_mask[tri.ravel()] = True
    if used_mask.all():
        pts, tri_local, nvals = fld.points, tri, (v if fld.location == "point" else fvals)
    else:
        used = np.flatnonzero(used_mask)
        remap = np.cumsum(used_mask) - 1
        tri_local = remap[tri]
        pts = fld.points[used]
        nvals = v[used] if fld.location == "point" else fvals
    w = np.where(nvals > thr, nvals, 0.0) if fld.location == "point" else np.ones(len(pts))
    if frame is None:
        if np.count_nonzero(w) < 3:
            raise PatchError(f"{fld.source}: the contact patch has fewer than 3 loaded nodes")
        c, normal = _plane(pts, w)
        base = Frame(origin=c, axes=_axes(normal, rolling_axis))
    else:
        base = frame
    # patch coordinates: (pts − o)·e_k = pts·e_k − o·e_k
    xy = pts @ base.axes[:2].T
    xy -= base.origin @ base.axes[:2].T
    z = pts @ base.axes[2]
    z -= base.origin @ base.axes[2]
    sums = face_sums(xy[:, 0], xy[:, 1], tri_local, nvals, fld.location)
    if not sums.N > 0:
        raise PatchError(f"{fld.source}: the contact patch carries no load")
    return _Geometry(pts, tri_local, nvals, base, xy, z, w, sums)


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
    threshold : float
        Relative pressure threshold (fraction of the peak) that defines "loaded".
    rolling_axis : 3-vector, optional
        Global direction projected on the plane to give x (default global x).
    frame : Frame, optional
        Use this frame (e.g. the static patch's, for a rolling map) instead of
        fitting one; the centre of pressure is then reported relative to it.
    """
    if not (0.0 <= threshold < 1.0):
        raise ArgumentError(f"threshold must be a fraction of the peak pressure in [0, 1), got {threshold!r}")
    v, peak = _validate_values(fld)
    thr = threshold * peak
    loaded = _loaded_faces(fld, v, thr)
    if loaded.all():
        tri, fvals = fld.triangles, v
    else:
        tri = fld.triangles[loaded]
        fvals = v[loaded] if fld.location == "cell" else v

    geo = _geometry(fld, tri, fvals, v, thr, frame, rolling_axis)
    ncomp, labels = _components(geo.xy[:, 0], geo.xy[:, 1], geo.triangles, geo.sums)
    dropped = 0
    if ncomp > 1:
        loads = face_loads(geo.xy, geo.triangles, geo.values, fld.location)
        share = np.bincount(labels, weights=loads, minlength=ncomp) / geo.sums.N
        big = np.flatnonzero(share > FRAGMENT_SHARE)
        if big.size > 1:
            parts = ", ".join(f"{s:.0%}" for s in sorted(share[big], reverse=True))
            raise PatchError(
                f"{fld.source}: {big.size} separate contact patches (load shares {parts}); "
                "dual wheels or a split patch? fepost analyses one patch at a time: crop the mesh"
            )
        main = int(np.argmax(share))
        keep = labels == main
        dropped = int(ncomp - 1)
        warnings.warn(
            f"{fld.source}: dropped {dropped} small loaded fragment(s) carrying "
            f"{1 - share[main]:.2%} of the load",
            PatchWarning,
            stacklevel=2,
        )
        tri = tri[keep]
        if fld.location == "cell":
            fvals = fvals[keep]
        geo = _geometry(fld, tri, fvals, v, thr, frame, rolling_axis)
    pts, tri_local, nvals, base, xy, height, weights, sums = geo
    N = sums.N
    cop = sums.centre_of_pressure
    if frame is None:
        origin = base.to_global(cop[None, :])[0]  # on the plane: local z = 0
        fr = Frame(origin=origin, axes=base.axes)
        xy -= cop  # the geometry's own array: shifted in place
        cop_rel = (0.0, 0.0)
        cen = sums.centroid - cop
    else:
        fr = frame
        cop_rel = (float(cop[0]), float(cop[1]))
        cen = sums.centroid
    xy = sealed(xy)
    height = sealed(height)
    x, y = xy[:, 0], xy[:, 1]
    area = sums.A
    evals, evecs = np.linalg.eigh(sums.covariance())
    evals = np.clip(evals, 0.0, None)
    semi = 2.0 * np.sqrt(evals[::-1])  # major, minor
    major = evecs[:, 1]
    angle = float(np.arctan2(major[1], major[0]))
    angle = (angle + np.pi / 2) % np.pi - np.pi / 2
    aspect = float(semi[0] / semi[1]) if semi[1] > 0 else np.inf
    r2 = x * x + y * y
    r_max = float(np.sqrt(np.max(r2)))
    r_equiv = float(np.sqrt(area / np.pi))
    rms = float(np.sqrt((weights @ (height * height)) / weights.sum()))
    if rms > PLANARITY_TOL * r_equiv:
        plane = "its best-fit plane" if frame is None else "the given frame's plane (the static patch's)"
        raise PatchError(
            f"{fld.source}: the contact patch is not planar (RMS distance from {plane} "
            f"{rms:.3g} m = {rms / r_equiv:.1%} of its radius, limit {PLANARITY_TOL:.0%}); "
            "are the coordinates undeformed? try --displacement NAME"
        )
    outside = load_outside(x, y, tri_local, nvals, fld.location, r_equiv, sums, r2=r2)
    circular = bool(aspect <= 1.0 + ASPECT_TOL and r_max / r_equiv <= RMAX_TOL)
    notes = []
    if not circular:
        notes.append(
            f"patch is not circular (aspect {aspect:.3f}, r_max/r_equiv {r_max / r_equiv:.3f}); "
            "the paper's closed forms assume a circle"
        )
    return Patch(
        source=fld.source,
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
        area=float(area),
        r_max=r_max,
        r_equiv=r_equiv,
        ellipse_axes=(float(semi[0]), float(semi[1])),
        ellipse_angle=angle,
        ellipse_centre=(float(cen[0]), float(cen[1])),
        aspect=aspect,
        load_outside=outside,
        planarity_rms=rms,
        circular=circular,
        reaction_z=fld.reaction_z,
        dropped_fragments=dropped,
        max_edge=sums.max_edge,
        notes=tuple(notes),
    )
