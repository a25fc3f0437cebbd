"""A push's friction wrench and twist direction, formed from the logged force, finger and block poses.

What the rig measures and what it does not: the finger's force (a two-axis sensor on the
robot's tool, sampled at about 100 Hz), the finger's pose (about 33 Hz) and the block's
pose only before and after the push (motion capture). The pushes are slow (a few mm/s),
so the block is in quasi-static balance: the support's friction wrench on the block is
minus the finger's wrench on it. `form_push` forms one push's wrench and twist so:

1. **The sensor's zero.** The sensor is not zeroed. Before the finger touches the block
   it carries no load, so the force of the quiet samples before the impact (from the
   first sample up to `Settings.zero_guard` s before the impact) is the offset; the
   authors took the first sample alone. Within a log the offset drifts by 0.01-0.03 N
   over 50 pushes (the checks report it), but a few pushes start loaded: the finger
   already pressing (up to 1 N at the first sample) or touching lightly before the
   impact. A push whose own zero lies more than `Settings.zero_tolerance` from its
   log's median zero takes the median instead (`fepost.pushes.table.read_pushes`;
   counted and named by the checks), which is right to the drift, 1 % of the force.
2. **Sensor to world.** The body file's ``log.sensor_to_world`` matrix S takes the
   sensor's (fx, fy) to the robot tool's axes, and the tool's yaw ψ (from the finger's
   logged quaternion, interpolated to each force sample) turns those into the world:
   R(ψ) S f. Without R(ψ) the measured force lies about 90° off the push direction at
   random; with it, it lies 22-25° (median; at most 32-38°) from the inward normal of the
   block's edge the finger touches, on all five hardboard logs: the finger's own friction
   cone, the finger sliding along the edge. The force of the finger on the block is minus
   that (the sensor reads the block's reaction on the finger).
3. **The finger's impact.** The force rises from noise to its sliding level within a
   few samples when the finger reaches the block. The impact is the first sample whose
   zero-corrected force exceeds `Settings.impact_level` times the push's plateau (the
   median force of its second half). Samples before it are dropped, and so are those of
   the next `Settings.settle` s (the impact's spike and the block breaking loose:
   static to kinetic friction); the authors dropped a fixed first 30 % of the samples,
   which the checks compare with the impact found.
4. **Low-force samples.** After the impact, samples below `Settings.low_level` times the
   plateau (the finger losing contact) are dropped.
5. **The block's pose within the push.** Only its poses before and after are logged. It
   stands still until the impact and moves until the last sample; in between its
   reference point's position and its yaw are interpolated linearly in time. The
   logged pose is that of the motion-capture frame; the body frame's origin is at
   ``body_origin_in_mocap`` (log units) in it, axes parallel: a body point b (m) is the
   mocap point ``body_origin_in_mocap + b / length_unit``. On the hardboard logs the
   mocap frame's origin is the block's right-angle corner, as the body files' frame: the
   finger's mean contact point of every push lies within 2 mm (median 0.5-0.7 mm, about
   its tip's radius) of the edge x = 0, y = 0 or x + y = 150 mm.
6. **The wrench of a sample.** The finger's contact point is its tip's centre, from its
   logged (x, y) interpolated to the sample's time. Its torque about the reference point
   is r × F with r from the interpolated reference point. (The contact lies 1 mm, the
   tip's radius, from the centre along the contact normal; the force is within the
   finger's friction cone of that normal, so the torque's error is below
   1 mm · |F| · sin 38°, 4 mN·m at the largest force, 6 N, against a median |Mz| of
   0.06-0.13 N·m per log.) The support's friction wrench is minus the finger's:
   (Fx, Fy) = −F and Mz = −r × F.
7. **The push's wrench** is the mean of its kept samples' wrenches, with the force
   turned into the block's frame at the start of the push.
8. **The twist direction** is the block's net displacement over the push in that same
   frame: (dx, dy) of the reference point and dθ (wrapped to ±π). Both use the start
   frame on purpose: for a push that turns the block steadily by Δθ, the chord of the
   reference point's path is the body-frame velocity turned by Δθ/2, and the mean of
   the body-frame force seen from the start frame is turned by the same Δθ/2, so the
   angle between wrench and twist is kept to first order. (The turn itself reaches
   0.11-0.37 rad per log, median 0.07-0.16 rad; the displacement's magnitude is
   immaterial, only its direction is a twist.)

A push that cannot give a wrench is left out with the reason (`LeftOut`): fewer than
`Settings.min_samples` kept samples, no force (a plateau under `Settings.min_force`),
or a displacement too small to give a direction (under `Settings.min_motion` m at
the patch radius R: |(dx, dy)| and R·|dθ| both).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._arrays import sealed
from ..body import Body, LogFormat
from ..errors import DataError
from .log import RawPush


@dataclass(frozen=True)
class Settings:
    """The thresholds of `form_push` (see the module docstring).

    Attributes
    ----------
    impact_level : float
        The impact: the force's first rise above this fraction of the plateau.
    settle : float
        Seconds after the impact whose samples are dropped.
    zero_guard : float
        Seconds before the impact left out of the zero.
    low_level : float
        Samples after the settling below this fraction of the plateau are dropped.
    min_force : float
        N; a push whose plateau is below it has no contact force.
    min_samples : int
        Fewest kept samples that give a wrench.
    min_motion : float
        m; a push that moved less, at the patch radius, gives no twist direction.
    zero_tolerance : float
        N; a push's zero this far from its log's median zero was loaded, and is replaced by it.
    """

    impact_level: float = 0.5
    settle: float = 0.3
    zero_guard: float = 0.05
    low_level: float = 0.5
    min_force: float = 0.1
    min_samples: int = 20
    min_motion: float = 1e-3
    zero_tolerance: float = 0.05


@dataclass(frozen=True)
class Push:
    """One push's friction wrench and displacement, with what the checks need.

    Attributes
    ----------
    log : str
    index, line : int
        The push's number in its log (from 1) and its first line.
    wrench : numpy.ndarray
        (Fx, Fy, Mz): the support's friction wrench on the block, N and N·m, in the block's frame
        at the start of the push, torque about the reference point.
    displacement : numpy.ndarray
        (dx, dy, dθ): the reference point's displacement (m) in that frame, and the turn (rad).
    samples, kept : int
        Force samples logged and kept.
    zero, first : numpy.ndarray
        The sensor's offset used (mean of the quiet samples, or the log's) and its first sample
        (N, sensor frame).
    zero_from_log : bool
        Whether the offset is the log's median zero (the push's own was loaded).
    impact_time : float
        s after the first force sample.
    impact_fraction : float
        The impact's sample index over the sample count.
    impact_peak : float
        The largest force of the settling window over the plateau (1 without a spike).
    scatter : float
        Standard deviation of the kept samples' |F| over their mean.
    contact : numpy.ndarray
        The finger's mean contact point in the body frame (m).
    tilt : float
        The block's largest tilt from the board's plane in its two poses (rad).
    """

    log: str
    index: int
    line: int
    wrench: np.ndarray
    displacement: np.ndarray
    samples: int
    kept: int
    zero: np.ndarray
    zero_from_log: bool
    first: np.ndarray
    impact_time: float
    impact_fraction: float
    impact_peak: float
    scatter: float
    contact: np.ndarray
    tilt: float


@dataclass(frozen=True)
class LeftOut:
    """A push that gives no wrench or no twist direction, and why."""

    log: str
    index: int
    line: int
    reason: str


def rotation(angle) -> np.ndarray:
    """2×2 rotation matrices by ``angle`` (rad; a scalar gives (2, 2), an array (..., 2, 2))."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def quaternion_matrix(q) -> np.ndarray:
    """The 3×3 rotation matrix of the unit quaternion ``q`` = (w, x, y, z)."""
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def yaw(q) -> np.ndarray:
    """The yaw (rad) of unit quaternions (w, x, y, z), last axis: the turned x axis's angle in the plane."""
    q = np.asarray(q, float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def wrap(angle: float) -> float:
    """``angle`` wrapped to (−π, π]."""
    a = math.remainder(angle, 2 * math.pi)
    return math.pi if a == -math.pi else a


def block_pose(body: Body, pose) -> tuple[np.ndarray, float, float]:
    """(the reference point's world position (m, x y), the yaw (rad), the tilt (rad)) of a logged pose.

    The body frame's origin is ``log.body_origin_in_mocap`` (log units) in the mocap frame, axes
    parallel, so the reference point is at ``body_origin_in_mocap + reference_point / length_unit``.
    """
    log = log_format(body)
    r = quaternion_matrix(pose[3:])
    ref = np.array([*body.reference_point, 0.0]) / log.length_unit + np.asarray(log.body_origin_in_mocap)
    point = (np.asarray(pose[:3]) + r @ ref) * log.length_unit
    tilt = math.acos(min(1.0, max(-1.0, r[2, 2])))
    return point[:2], math.atan2(r[1, 0], r[0, 0]), tilt


def patch_radius(body: Body) -> float:
    """R (m): the radius of the smallest circle about the reference point that holds the support."""
    ref = np.asarray(body.reference_point)
    if body.supports is not None:
        d = np.hypot(*(np.asarray(body.supports) - ref).T)
        return float(d.max()) + float(body.support_radius or 0.0)
    return float(np.hypot(*(np.asarray(body.base) - ref).T).max())


def log_format(body: Body) -> LogFormat:
    """The body's ``log`` block; a `DataError` naming the file when it has none."""
    if body.log is None:
        raise DataError(f"{body.path}: missing key 'log' (how the push logs were recorded)")
    return body.log


def form_push(
    raw: RawPush, body: Body, settings: Settings | None = None, *, zero: np.ndarray | None = None
) -> Push | LeftOut:
    """The friction wrench and displacement of one push, or why it gives none (module docstring).

    Parameters
    ----------
    raw : RawPush
        The push as logged.
    body : Body
        The block, with its ``log`` block.
    settings : Settings, optional
        The thresholds (default `Settings()`).
    zero : numpy.ndarray, optional
        The sensor's offset (fx, fy) to use instead of the push's own quiet samples (the log's
        median zero, when the push's own is not unloaded: `fepost.pushes.table.read_pushes`).

    Returns
    -------
    Push or LeftOut
    """
    settings = settings or Settings()
    if len(raw.force) < settings.min_samples:
        return LeftOut(
            raw.log,
            raw.index,
            raw.line,
            f"{len(raw.force)} force samples (fewer than {settings.min_samples})",
        )
    if len(raw.finger) < 1:
        return LeftOut(raw.log, raw.index, raw.line, "no finger pose")
    t = raw.force[:, 0] - raw.force[0, 0]
    sensor = raw.force[:, 1:3]
    to_world = _to_world(raw, body)
    given = zero is not None
    impact = _impact(t, to_world(sensor - (zero if zero is not None else sensor[0])), settings, given=given)
    if isinstance(impact, str):
        return LeftOut(raw.log, raw.index, raw.line, impact)
    i0, plateau = impact
    if zero is None:
        quiet = t <= t[i0] - settings.zero_guard
        quiet[0] = True
        zero = sensor[quiet].mean(axis=0)
    on_block = -to_world(sensor - zero)  # the finger's force on the block, world axes
    size = np.hypot(*on_block.T)
    keep = (t >= t[i0] + settings.settle) & (size >= settings.low_level * plateau)
    if keep.sum() < settings.min_samples:
        return LeftOut(
            raw.log,
            raw.index,
            raw.line,
            f"{int(keep.sum())} samples after the impact (fewer than {settings.min_samples})",
        )
    p0, th0, tilt0 = block_pose(body, raw.before)
    p1, th1, tilt1 = block_pose(body, raw.after)
    turn = wrap(th1 - th0)
    d_world = p1 - p0
    start = rotation(th0)
    disp = np.array([*(start.T @ d_world), turn])
    radius = patch_radius(body)
    if max(math.hypot(disp[0], disp[1]), radius * abs(turn)) < settings.min_motion:
        return LeftOut(
            raw.log,
            raw.index,
            raw.line,
            f"hardly moved ({1e3 * math.hypot(disp[0], disp[1]):.2g} mm, {turn:.2g} rad)",
        )
    s = np.clip((t - t[i0]) / max(t[-1] - t[i0], 1e-12), 0.0, 1.0)[keep]
    ref = p0 + s[:, None] * d_world
    theta = th0 + s * turn
    finger = _finger_xy(raw, body, raw.force[keep, 0])
    r = finger - ref
    f = on_block[keep]
    torque = r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]
    force_start = f @ start  # each row turned into the start frame: (Rᵀ f)ᵀ = fᵀ R
    local = np.einsum("nji,nj->ni", rotation(theta), r)
    kept_size = size[keep]
    late = (t >= t[i0]) & (t < t[i0] + settings.settle)
    return Push(
        log=raw.log,
        index=raw.index,
        line=raw.line,
        wrench=sealed(-np.array([*force_start.mean(axis=0), torque.mean()])),
        displacement=sealed(disp),
        samples=len(t),
        kept=int(keep.sum()),
        zero=sealed(np.array(zero, dtype=float)),
        zero_from_log=given,
        first=sealed(np.array(raw.force[0, 1:])),
        impact_time=float(t[i0]),
        impact_fraction=i0 / len(t),
        impact_peak=float(size[late].max() / plateau) if late.any() else 1.0,
        scatter=float(kept_size.std() / kept_size.mean()),
        contact=sealed(local.mean(axis=0) + np.asarray(body.reference_point)),
        tilt=max(tilt0, tilt1),
    )


def _to_world(raw: RawPush, body: Body):
    """The map of sensor readings (n, 2) to world axes, R(ψ) S f, ψ the tool's yaw at each force sample."""
    psi = np.unwrap(yaw(raw.finger[:, 4:8]))
    turn = rotation(np.interp(raw.force[:, 0], raw.finger[:, 0], psi))
    s = log_format(body).matrix()

    def to_world(f: np.ndarray) -> np.ndarray:
        return np.einsum("nij,nj->ni", turn, f @ s.T)

    return to_world


def _finger_xy(raw: RawPush, body: Body, times: np.ndarray) -> np.ndarray:
    """The finger's (x, y) in the world (m) at ``times``, linear between its logged poses."""
    unit = log_format(body).length_unit
    x = np.interp(times, raw.finger[:, 0], raw.finger[:, 1])
    y = np.interp(times, raw.finger[:, 0], raw.finger[:, 2])
    return np.column_stack([x, y]) * unit


def _impact(t: np.ndarray, rel: np.ndarray, settings: Settings, *, given: bool) -> tuple[int, float] | str:
    """(the impact's sample index, the plateau force N), or why there is none."""
    size = np.hypot(*rel.T)
    plateau = float(np.median(size[len(size) // 2 :]))
    if plateau < settings.min_force:
        return f"no contact force (plateau {plateau:.2g} N, under {settings.min_force:g} N)"
    above = np.flatnonzero(size >= settings.impact_level * plateau)
    i0 = int(above[0])
    if i0 == 0 and not given:
        return "the force is already up at the first sample (no unloaded zero)"
    return i0, plateau
