"""A rigid body on its supports: the body JSON contract and the supports' statics loads.

`load_body` reads and validates a body file (the "body JSON" of the command-line contract): the mass
(kg), gravity (m/s²), the centre of mass and the reference point ([x, y], m, body
frame), and either three point supports (``supports``, each a disc of radius
``support_radius``) or a flat base (``base``, a simple polygon). The optional
``log`` block says how a logger recorded the body's pushes (``format``
``planar-push``, the force sensor's 2×2 ``sensor_to_world`` matrix, the body
frame's origin in the motion-capture frame ``body_origin_in_mocap`` in the log's
length units, and ``length_unit``, m). Other keys are kept in `Body.extra`.

`support_loads` gives the normal loads of three point supports from statics:
the sum of the loads carries the weight, and their moments about the x and y
axes balance the weight's moments at the centre of mass. That is the 3×3
linear system

    [1   1   1 ] [N1]   [W    ]
    [x1  x2  x3] [N2] = [W x_c]
    [y1  y2  y3] [N3]   [W y_c]

whose matrix is singular when the supports are collinear. A centre of mass
outside the supports' triangle gives a negative load: the body would tip over,
and the file is refused. The loads are the barycentric coordinates of the centre
of mass in the triangle, times the weight.

Every error is one line naming the file and the key.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from .errors import DataError, InputFileError, ScaleError
from .jsonobject import read_json_object

#: Log formats `load_body` knows (the ``log.format`` key).
LOG_FORMATS = ("planar-push",)
#: Largest body coordinate (m) taken as plausible; beyond it the file is probably in mm.
MAX_COORDINATE = 10.0
#: Largest body file read (bytes).
MAX_BYTES = 1_000_000
#: Relative tolerance of the geometric checks (collinear supports, a load on an edge).
GEOMETRY_RTOL = 1e-9

_Point = tuple[float, float]


@dataclass(frozen=True)
class LogFormat:
    """How a logger recorded the body's pushes (the body file's ``log`` block).

    Attributes
    ----------
    format : str
        The log's format, ``"planar-push"``.
    sensor_to_world : tuple of two (float, float)
        Rows of the 2×2 matrix taking the sensor's (fx, fy) to world axes.
    body_origin_in_mocap : (float, float, float)
        Where the body frame's origin is in the motion-capture body frame, in log units.
    length_unit : float
        The log's length unit in metres (0.001 for mm).
    """

    format: str
    sensor_to_world: tuple[_Point, _Point]
    body_origin_in_mocap: tuple[float, float, float]
    length_unit: float

    def matrix(self) -> np.ndarray:
        """`sensor_to_world` as a read-only 2×2 array."""
        m = np.array(self.sensor_to_world, dtype=float)
        m.flags.writeable = False
        return m


@dataclass(frozen=True)
class Body:
    """A rigid body resting on three point supports or on a flat base (SI units, body frame).

    Attributes
    ----------
    path : str
        The file it was read from (named in errors).
    name : str
        The file's ``name`` key, or the file's stem.
    mass, gravity : float
        kg and m/s².
    centre_of_mass, reference_point : (float, float)
        m, in the body frame.
    supports : tuple of (float, float), or None
        The three point supports (m), or None for a flat base.
    support_radius : float or None
        The radius of each support's contact disc (m).
    base : tuple of (float, float), or None
        The base polygon's vertices (m), or None for point supports.
    log : LogFormat or None
        The logger's description, when the file has one.
    extra : mapping
        The file's other keys, read-only.
    """

    path: str
    name: str
    mass: float
    gravity: float
    centre_of_mass: _Point
    reference_point: _Point
    supports: tuple[_Point, ...] | None = None
    support_radius: float | None = None
    base: tuple[_Point, ...] | None = None
    log: LogFormat | None = None
    extra: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    @property
    def weight(self) -> float:
        """mass × gravity (N): the normal load the support carries."""
        return self.mass * self.gravity

    @property
    def kind(self) -> str:
        """``"supports"`` (point supports) or ``"base"`` (a flat base)."""
        return "supports" if self.supports is not None else "base"

    def base_area(self) -> float:
        """The base polygon's area (m²); raises `DataError` for a body on point supports."""
        if self.base is None:
            raise DataError(f"{self.path}: the body stands on point supports, it has no 'base'")
        return abs(signed_area(np.array(self.base)))

    def to_dict(self) -> dict:
        """The body as plain JSON values (the contract's keys)."""
        out: dict[str, Any] = {
            "name": self.name,
            "mass": self.mass,
            "gravity": self.gravity,
            "centre_of_mass": list(self.centre_of_mass),
            "reference_point": list(self.reference_point),
        }
        if self.supports is not None:
            out["supports"] = [list(p) for p in self.supports]
            out["support_radius"] = self.support_radius
        if self.base is not None:
            out["base"] = [list(p) for p in self.base]
        if self.log is not None:
            out["log"] = {
                "format": self.log.format,
                "sensor_to_world": [list(r) for r in self.log.sensor_to_world],
                "body_origin_in_mocap": list(self.log.body_origin_in_mocap),
                "length_unit": self.log.length_unit,
            }
        return {**dict(self.extra), **out}


def load_body(path) -> Body:
    """Read and validate a body JSON file.

    Parameters
    ----------
    path : str or Path
        The body file.

    Returns
    -------
    Body

    Raises
    ------
    InputFileError
        Missing, unreadable or not a JSON object.
    DataError
        A key missing or of the wrong shape, a number not finite or out of range, both or neither
        of ``supports`` and ``base``, collinear supports or a centre of mass outside them, a base
        polygon that crosses itself or does not hold the centre of mass, an unknown log format.
    ScaleError
        Coordinates of more than `MAX_COORDINATE` m (a file in millimetres?).
    """
    p = Path(path)
    data = _read_object(p)
    where = str(p)
    mass = _positive(where, data, "mass")
    gravity = _positive(where, data, "gravity")
    com = _point(where, data, "centre_of_mass")
    ref = _point(where, data, "reference_point")
    has_supports, has_base = "supports" in data, "base" in data
    if has_supports == has_base:
        raise DataError(
            f"{where}: give either 'supports' (point supports) or 'base' (a flat base), "
            f"not {'both' if has_base else 'neither'}"
        )
    supports = radius = base = None
    if has_supports:
        supports = _points(where, data, "supports", exactly=3)
        radius = _positive(where, data, "support_radius")
    else:
        base = _points(where, data, "base", at_least=3)
    for key, pts in (
        ("centre_of_mass", [com]),
        ("reference_point", [ref]),
        ("supports", supports),
        ("base", base),
    ):
        _check_scale(where, key, pts or [])
    log = _log(where, data["log"]) if "log" in data else None
    name = data.get("name")
    known = {
        "name",
        "mass",
        "gravity",
        "centre_of_mass",
        "reference_point",
        "supports",
        "support_radius",
        "base",
        "log",
    }
    body = Body(
        path=where,
        name=name if isinstance(name, str) else p.stem,
        mass=mass,
        gravity=gravity,
        centre_of_mass=com,
        reference_point=ref,
        supports=supports,
        support_radius=radius,
        base=base,
        log=log,
        extra=MappingProxyType({k: v for k, v in data.items() if k not in known}),
    )
    if supports is not None:
        support_loads(body)  # refuses collinear supports and a body that would tip
        _check_radius(where, supports, radius)
    else:
        _check_base(where, np.array(base), com)
    return body


def support_loads(body: Body) -> np.ndarray:
    """The statics normal loads (N) of a body's three point supports, in the order of `Body.supports`.

    Solves the balance of the vertical forces and of the moments about the x and y axes,
    with the weight at the centre of mass (see the module docstring).

    Parameters
    ----------
    body : Body
        A body on three point supports.

    Returns
    -------
    numpy.ndarray
        Three loads, read-only, summing to `Body.weight`, each ≥ 0.

    Raises
    ------
    DataError
        The body has a base, not point supports; the supports are collinear; the centre of mass
        lies outside their triangle (a negative load: the body would tip).
    """
    if body.supports is None:
        raise DataError(
            f"{body.path}: key 'supports': the body lies on a flat base, it has no point supports"
        )
    pts = np.array(body.supports, dtype=float)
    if pts.shape != (3, 2):
        raise DataError(
            f"{body.path}: key 'supports': statics gives the loads of exactly 3 supports, got {len(pts)}"
        )
    size = float(np.max(np.ptp(pts, axis=0)))
    area2 = signed_area(pts) * 2.0
    if size == 0.0 or abs(area2) <= GEOMETRY_RTOL * size * size:
        raise DataError(
            f"{body.path}: key 'supports': the three supports are collinear, statics cannot share the load"
        )
    a = np.vstack([np.ones(3), pts[:, 0], pts[:, 1]])
    w = body.weight
    b = np.array([w, w * body.centre_of_mass[0], w * body.centre_of_mass[1]])
    loads = np.linalg.solve(a, b)
    worst = int(np.argmin(loads))
    if loads[worst] < -GEOMETRY_RTOL * w:
        raise DataError(
            f"{body.path}: key 'centre_of_mass': {list(body.centre_of_mass)} lies outside the supports' "
            "triangle "
            f"(support {worst + 1} would carry {loads[worst]:.4g} N): the body would tip"
        )
    loads = np.clip(loads, 0.0, None)
    loads.flags.writeable = False
    return loads


def _read_object(p: Path) -> dict:
    try:
        return read_json_object(p, "body JSON", MAX_BYTES)
    except FileNotFoundError:
        raise InputFileError(f"{p}: body file not found") from None


def _number(where: str, key: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise DataError(f"{where}: key '{key}' must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise DataError(f"{where}: key '{key}' is not finite ({value!r})")
    return x


def _require(where: str, data: Mapping, key: str, prefix: str = ""):
    if key not in data:
        raise DataError(f"{where}: missing key '{prefix}{key}'")
    return data[key]


def _positive(where: str, data: Mapping, key: str, prefix: str = "") -> float:
    x = _number(where, prefix + key, _require(where, data, key, prefix))
    if x <= 0.0:
        raise DataError(f"{where}: key '{prefix}{key}' must be positive, got {x:g}")
    return x


def _vector(where: str, key: str, value, n: int) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n:
        raise DataError(f"{where}: key '{key}' must be a list of {n} numbers, got {value!r}")
    return tuple(_number(where, f"{key}[{i}]", v) for i, v in enumerate(value))


def _point(where: str, data: Mapping, key: str) -> _Point:
    x, y = _vector(where, key, _require(where, data, key), 2)
    return (x, y)


def _points(
    where: str, data: Mapping, key: str, *, exactly: int = 0, at_least: int = 0
) -> tuple[_Point, ...]:
    value = data[key]
    n = len(value) if isinstance(value, list) else -1
    if n < 0 or (exactly and n != exactly) or n < at_least:
        want = f"{exactly}" if exactly else f"at least {at_least}"
        raise DataError(f"{where}: key '{key}' must be a list of {want} [x, y] points, got {value!r}"[:300])
    out = []
    for i, v in enumerate(value):
        x, y = _vector(where, f"{key}[{i}]", v, 2)
        out.append((x, y))
    return tuple(out)


def _check_scale(where: str, key: str, pts) -> None:
    for p in pts:
        if max(abs(p[0]), abs(p[1])) > MAX_COORDINATE:
            raise ScaleError(
                f"{where}: key '{key}': a coordinate of {max(abs(p[0]), abs(p[1])):g} m "
                f"(over {MAX_COORDINATE:g} m): are the lengths in metres?"
            )


def _check_radius(where: str, supports, radius) -> None:
    pts = np.array(supports)
    gap = min(float(np.hypot(*(pts[i] - pts[j]))) for i in range(3) for j in range(i + 1, 3))
    if 2.0 * radius >= gap:
        raise DataError(
            f"{where}: key 'support_radius': {radius:g} m makes the supports' discs overlap "
            f"(closest supports {gap:g} m apart)"
        )


def signed_area(pts: np.ndarray) -> float:
    """The shoelace area (m²) of the polygon ``pts`` (n, 2): positive counter-clockwise."""
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _check_base(where: str, poly: np.ndarray, com: _Point) -> None:
    size = float(np.max(np.ptp(poly, axis=0)))
    if size == 0.0 or abs(signed_area(poly)) <= GEOMETRY_RTOL * size * size:
        raise DataError(f"{where}: key 'base': the polygon has no area")
    n = len(poly)
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue
            if _segments_cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n]):
                raise DataError(f"{where}: key 'base': edges {i + 1} and {j + 1} of the polygon cross")
    if not _inside(poly, np.array(com)):
        raise DataError(
            f"{where}: key 'centre_of_mass': {list(com)} lies outside the base polygon: the body would tip"
        )


def _cross(o, a, b) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _segments_cross(p1, p2, q1, q2) -> bool:
    d1, d2 = _cross(q1, q2, p1), _cross(q1, q2, p2)
    d3, d4 = _cross(p1, p2, q1), _cross(p1, p2, q2)
    return (d1 * d2 < 0.0) and (d3 * d4 < 0.0)


def _inside(poly: np.ndarray, pt: np.ndarray) -> bool:
    """Even-odd rule; a point on the boundary counts as inside."""
    n = len(poly)
    inside = False
    for i in range(n):
        a, b = poly[i], poly[(i + 1) % n]
        if abs(_cross(a, b, pt)) <= 1e-12 * max(1.0, float(np.hypot(*(b - a))) ** 2) and (
            min(a[0], b[0]) - 1e-15 <= pt[0] <= max(a[0], b[0]) + 1e-15
            and min(a[1], b[1]) - 1e-15 <= pt[1] <= max(a[1], b[1]) + 1e-15
        ):
            return True
        if (a[1] > pt[1]) != (b[1] > pt[1]):
            x = a[0] + (pt[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            if x > pt[0]:
                inside = not inside
    return inside


def _log(where: str, block) -> LogFormat:
    if not isinstance(block, dict):
        raise DataError(f"{where}: key 'log' must be a JSON object, got {block!r}")
    fmt = _require(where, block, "format", "log.")
    if fmt not in LOG_FORMATS:
        raise DataError(f"{where}: key 'log.format' must be one of {', '.join(LOG_FORMATS)}, got {fmt!r}")
    rows = _require(where, block, "sensor_to_world", "log.")
    if not isinstance(rows, list) or len(rows) != 2:
        raise DataError(
            f"{where}: key 'log.sensor_to_world' must be a 2x2 matrix (two rows of two numbers), got {rows!r}"
        )
    r0 = _vector(where, "log.sensor_to_world[0]", rows[0], 2)
    r1 = _vector(where, "log.sensor_to_world[1]", rows[1], 2)
    det = r0[0] * r1[1] - r0[1] * r1[0]
    scale = max(map(abs, r0 + r1))
    if scale == 0.0 or abs(det) <= GEOMETRY_RTOL * scale * scale:
        raise DataError(f"{where}: key 'log.sensor_to_world' is singular (determinant {det:g})")
    origin = _vector(
        where, "log.body_origin_in_mocap", _require(where, block, "body_origin_in_mocap", "log."), 3
    )
    unit = _positive(where, block, "length_unit", "log.")
    return LogFormat(
        format=fmt,
        sensor_to_world=((r0[0], r0[1]), (r1[0], r1[1])),
        body_origin_in_mocap=(origin[0], origin[1], origin[2]),
        length_unit=unit,
    )
