"""A body's contact-pressure map: point supports as loaded discs, a flat base as a uniform map.

The map is the support's contact pressure (Pa) on planar triangles, nodal
values linear on each triangle, in the **map frame**: the body frame moved to
the body's ``reference_point`` (x, y along the body's axes, z up, m). It is
written as an FE-style ``.vtu`` (`fepost.bodymap.write_map`) that fepost reads
as any FE export.

Point supports
--------------
Each support is a disc of radius ``support_radius`` carrying the load statics
gives it (`fepost.body.support_loads`). Its pressure profile is Hertz-like,
p = p0·√(1 − (r/a)²), by default: a leg's rounded foot pressed into an elastic
board makes a Hertzian contact, and the profile falls to zero at the rim, so a
polar grid that samples the map converges on it without the jump of a uniform
disc. The choice hardly matters to friction: a disc of radius a at distance d
from the reference point adds about ⟨ρ²⟩/(4d) to the mean lever arm, with
⟨ρ²⟩ = a²/2 (uniform) or 2a²/5 (Hertz), a difference of a²/(40d) (1e-4 of d for
a = 2 mm, d = 28 mm); ``profile="uniform"`` gives the other one to measure it.
Each disc's nodal values are scaled so that the linear interpolant carries the
statics load exactly (`fepost.bodymap.mesh.linear_load`), and the disc mesh is
rotationally symmetric, so its centre of pressure is the support to round-off.

A flat base
-----------
A uniform pressure N/A over the base polygon (N = m g). The centre of
pressure is the polygon's centroid: statics puts it at the centre of mass,
which `fepost.body.load_body` only requires inside the polygon, so a
centroid off the centre of mass is recorded in the map's notes (a uniform
pressure is then not in equilibrium with the weight).

Several supports in one map
---------------------------
fepost refuses a map whose loaded faces make several separate patches (dual
wheels, a cut-up mesh). A map of point supports holds them on purpose and
says so in its sidecar: ``separate_patches`` = the number of supports
(`fepost.patchfaces.DECLARED_PATCHES_KEY`); the patch step keeps exactly that
many regions together and still refuses any other count.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import frozen
from ..body import Body, support_loads
from ..errors import ArgumentError
from .mesh import disc_mesh, linear_load, polygon_mesh, triangle_areas

#: Disc pressure profiles of point supports (module docstring).
PROFILES = ("hertz", "uniform")
#: Edge length of a flat base's triangles, as a fraction of the polygon's size.
BASE_DIVISIONS = 40
#: The map frame, as written in the sidecar.
FRAME = "body frame moved to reference_point: x, y along the body's axes, z up (normal of the board); m"


@dataclass(frozen=True)
class BodyMap:
    """A body's contact-pressure map in the map frame (module docstring).

    Attributes
    ----------
    kind : str
        ``"supports"``, ``"base"`` or ``"board"`` (the base on an elastic board, solved by CalculiX).
    xy : ndarray (n, 2)
        Node coordinates, m, map frame.
    triangles : ndarray (m, 3)
        Triangles (node indices).
    pressure : ndarray (n,)
        Contact pressure at the nodes, Pa (linear on each triangle).
    load : float
        ∬ p dA, N (exact for the linear field).
    centre_of_pressure : (float, float)
        m, map frame.
    info : dict
        What the sidecar records (loads, profile, board, solver's reaction, notes).
    """

    kind: str
    xy: np.ndarray
    triangles: np.ndarray
    pressure: np.ndarray
    load: float
    centre_of_pressure: tuple[float, float]
    info: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "xy", frozen(self.xy))
        object.__setattr__(self, "triangles", frozen(self.triangles, dtype=np.int64))
        object.__setattr__(self, "pressure", frozen(self.pressure))

    @property
    def separate_patches(self) -> int:
        """How many separate loaded regions the map holds on purpose (1 but for point supports)."""
        return int(self.info.get("separate_patches", 1))

    def peak(self) -> float:
        """The largest nodal pressure, Pa."""
        return float(self.pressure.max())

    def mean_pressure(self) -> float:
        """load / loaded area, Pa (the area of the triangles with any node loaded)."""
        loaded = np.any(self.pressure[self.triangles] > 0, axis=1)
        area = np.abs(triangle_areas(self.xy, self.triangles[loaded]))
        return self.load / float(area.sum())


def _map_frame(body: Body, xy) -> np.ndarray:
    return np.asarray(xy, float) - np.asarray(body.reference_point, float)


def common_info(body: Body, contact: str) -> dict[str, Any]:
    """What every map's sidecar says about the body, its frame and its reaction (statics)."""
    com = _map_frame(body, body.centre_of_mass)
    return {
        "kind": "body map",
        "contact": contact,
        "frame": FRAME,
        "body": body.path,
        "name": body.name,
        "mass": body.mass,
        "gravity": body.gravity,
        "weight": body.weight,
        "reference_point": list(body.reference_point),
        "centre_of_mass": [float(com[0]), float(com[1])],
        "reaction_z": body.weight,
        "reaction_source": "statics: the supports carry the weight",
        "notes": [],
    }


def _checked_profile(profile: str) -> str:
    if profile not in PROFILES:
        raise ArgumentError(f"profile must be one of {', '.join(PROFILES)}, got {profile!r}")
    return profile


def support_map(body: Body, *, profile: str = "hertz") -> BodyMap:
    """The map of a body on point supports: a loaded disc per support (module docstring).

    Parameters
    ----------
    body : Body
        A body with ``supports`` (`fepost.body.load_body`).
    profile : str
        ``"hertz"`` (default) or ``"uniform"``: each disc's pressure profile.

    Returns
    -------
    BodyMap
        Kind ``"supports"``; ``info["supports"]`` lists each disc's centre (map frame),
        radius and load; ``info["separate_patches"]`` is their number.
    """
    _checked_profile(profile)
    if body.supports is None or body.support_radius is None:
        raise ArgumentError(f"{body.path}: the body lies on a flat base, not on point supports")
    loads = support_loads(body)
    a = float(body.support_radius)
    pts, tris, vals, rows = [], [], [], []
    count = 0
    for centre, load in zip(_map_frame(body, body.supports), loads, strict=True):
        xy, tri, rho = disc_mesh(centre, a)
        shape = np.sqrt(np.clip(1.0 - rho * rho, 0.0, None)) if profile == "hertz" else np.ones_like(rho)
        unit, _ = linear_load(xy, tri, shape)
        p = shape * (float(load) / unit)
        pts.append(xy)
        tris.append(tri + count)
        vals.append(p)
        count += len(xy)
        rows.append({"centre": [float(centre[0]), float(centre[1])], "radius": a, "load": float(load)})
    xy, tri, p = np.vstack(pts), np.vstack(tris), np.concatenate(vals)
    load, first = linear_load(xy, tri, p)
    info = common_info(body, "point supports")
    info.update(supports=rows, profile=profile, separate_patches=len(rows))
    return BodyMap("supports", xy, tri, p, load, (float(first[0] / load), float(first[1] / load)), info)


def base_map(body: Body) -> BodyMap:
    """The map of a body on a flat base: a uniform pressure m g / area over the polygon.

    Parameters
    ----------
    body : Body
        A body with a ``base`` polygon (`fepost.body.load_body`).

    Returns
    -------
    BodyMap
        Kind ``"base"``; ``info["pressure"]`` is the uniform pressure (Pa).
    """
    if body.base is None:
        raise ArgumentError(f"{body.path}: the body stands on point supports, it has no flat base")
    poly = _map_frame(body, body.base)
    size = float(np.max(np.ptp(poly, axis=0)))
    xy, tri = polygon_mesh(poly, size / BASE_DIVISIONS, where=body.path)
    unit, first = linear_load(xy, tri, np.ones(len(xy)))
    p = np.full(len(xy), body.weight / unit)
    load = body.weight
    cop = (float(first[0] / unit), float(first[1] / unit))
    info = common_info(body, "flat base, uniform pressure")
    info.update(pressure=body.weight / unit, area=unit)
    com = info["centre_of_mass"]
    off = float(np.hypot(cop[0] - com[0], cop[1] - com[1]))
    if off > 1e-9 * size:
        info["notes"].append(
            f"the base's centroid is {off:.4g} m from the centre of mass: a uniform pressure does not "
            "balance the weight's moment (statics puts the centre of pressure at the centre of mass)"
        )
    return BodyMap("base", xy, tri, p, load, cop, info)


def body_map(body: Body, *, profile: str = "hertz") -> BodyMap:
    """`support_map` or `base_map`, as the body stands."""
    return support_map(body, profile=profile) if body.supports is not None else base_map(body)
