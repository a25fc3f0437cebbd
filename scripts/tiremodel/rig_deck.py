"""CalculiX decks of the slide/spin rig: the small tire sector slid and spun on a fixed rigid road.

Steps (all quasi-static, NLGEOM):

1. inflation (as the static case);
2. vertical rim travel (as the static case);
3. the rim (the bead nodes) moves rigidly in the road plane so that every
   tire point has, relative to the road, the constant velocity field of a
   sliding velocity (vx, vy) of the static patch origin c plus a spin wz about
   the road normal; the road stays put.

The road is one rigid body (``*RIGID BODY``) whose reference node (at c) and
rotation node are held: their reactions are the road's total force and moment.
The sector's cut faces keep the condition of the static case (their
circumferential displacement is the rim's: the rest of the tire moves with the
rim), each against its own reference node that follows the rim's rigid motion
at that point. Why the tire moves and not the road: with a turning road (the master surface
of the contact) CalculiX 2.20 turned the friction traction away from the slip
direction by about the road's rotation angle (a uniform -10.5 degrees after an
11 degree turn, the force direction drifting with the path); with the road
fixed the traction is along the slip (median deviation about 1 degree over the
loaded nodes of a test run).

Steps 1 and 2 are the same for every run: they are solved once (the "base"
deck, which writes a CalculiX restart file) and each run restarts from the end
of step 2 (``*RESTART, READ``) with its own slide.

Kinematics. The relative sliding velocity of the tire point x against the road
is (THEORY section 3) ``w(x) = (vx - wz (y - cy), vy + wz (x - cx))``, in the
tire's own (moving) frame. For wz != 0 that is a rotation at the rate wz about
the point P = c + (-vy/wz, vx/wz) where w = 0 (the instantaneous centre of
rotation), fixed in the tire and on the road; for wz = 0 a translation by
(vx, vy) t. The rim is turned about the vertical axis through P by wz t. The
forces measured on the road are in the road's frame; the tire's frame is
turned by wz t, and the patch origin has moved to P + Rot(wz t) (c - P):
``fepost rig`` turns the forces into the tire's frame and takes the torque
about the moved origin (the sidecar records both).

Quasi-static. There is no inertia and no rate in the material or the friction
law, so the "velocities" are displacements per unit of the step's pseudo-time
T = 1: only the direction of the sliding velocity and the ratio of spin to
sliding (wz R / |v|) matter for rigid-slip Coulomb friction, not their size.

Road reactions. The reference node's RF is the total force of the road on the
tire (the constraint holds the road against the tire's push), the rotation
node's RF the moment about the reference node; both are printed per increment.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import ccxdeck as cx
from . import deck as dk
from .geometry import TireMesh
from .meshing import face_lookup

INFLATION_TIME = 0.2  # time of the inflation ramp in a one-step base (the vertical travel takes 1)
FIRST_SLIDE_INC = 1e-4  # first increment of a one-step slide (pseudo-time)
SLIDE_PATH = 0.06  # m, reference sliding path of a run: |v| T + |wz| R_REF T combined in quadrature
R_REF = 0.10  # m, reference patch radius used to scale the spin


@dataclass(frozen=True)
class RigTire:
    """What differs between the tires on the rig; the steps and the rig itself are shared.

    ``model_lines(mesh, title, road, cut_refs)``: the deck lines before the
    boundary conditions (nodes, elements, sets ``BEAD``, ``ROADN``, ``TIREN``,
    materials, the cut faces' equations against the ``CUTREF`` nodes, the
    contact pair); ``road()``: the road block; ``controls``: lines added to
    every step (relaxed convergence criteria); ``slide_path`` and ``r_ref``:
    the reference path of a run and the radius that scales the spin (m).
    """

    name: str
    model_lines: Callable
    road: Callable[[], cx.Road]
    pressure: float  # Pa
    deflection: float  # m, rim travel beyond the inflated tread's first contact
    slide_path: float = SLIDE_PATH
    r_ref: float = R_REF
    inflation_inc: str = "0.25, 1.0, 1e-5, 0.5"
    vertical_inc: str = "0.05, 1.0, 1e-6, 0.1"
    controls: tuple[str, ...] = ()
    friction: float = dk.FRICTION
    one_step: bool = False  # base and slide each one step, driven by amplitudes (below)
    timeout: float = 1800.0  # s, wall time allowed to one CalculiX run
    # the slides' lines instead of ``controls`` (None: the same as the base's)
    slide_controls: tuple[str, ...] | None = None

    @property
    def slide_start(self) -> float:
        """Total time at the start of the slide (the end of the base)."""
        return 1.0 + INFLATION_TIME if self.one_step else 2.0


#: the small stand-in tire (homogeneous, 200 kPa, 29 mm deflection)
SMALL = RigTire(
    name="small",
    model_lines=dk.model_lines,
    road=cx.build_road,
    pressure=dk.PRESSURE,
    deflection=0.029,
)


@dataclass(frozen=True)
class Kinematics:
    """Sliding velocity (vx, vy) of the static patch origin relative to the road and spin wz.

    Units: m and rad per unit pseudo-time (the slide step lasts T = 1).
    """

    vx: float
    vy: float
    wz: float

    def pivot(self, origin: tuple[float, float]) -> tuple[float, float] | None:
        """The instantaneous centre of rotation P (m), None for pure sliding."""
        if self.wz == 0.0:
            return None
        return origin[0] - self.vy / self.wz, origin[1] + self.vx / self.wz


def kinematics(
    direction_deg: float, spin_angle_deg: float, spin_sign: int, tire: RigTire = SMALL
) -> Kinematics:
    """Kinematics of one run with the tire's reference path S (``SLIDE_PATH`` for the small tire).

    ``spin_angle_deg``: 0 = pure sliding, 90 = pure spin; |v| = S cos(a),
    |wz| R_ref = S sin(a). ``direction_deg``: direction of the sliding velocity
    from +x towards +y. ``spin_sign``: sign of wz.
    """
    a = math.radians(spin_angle_deg)
    d = math.radians(direction_deg)
    v = tire.slide_path * math.cos(a)
    wz = spin_sign * tire.slide_path * math.sin(a) / tire.r_ref
    vx, vy = v * math.cos(d), v * math.sin(d)
    # exact zeros where they belong (pure spin, axis directions): the deck stays clean
    r = 12
    return Kinematics(round(vx, r) + 0.0, round(vy, r) + 0.0, round(wz, r) + 0.0)


@dataclass(frozen=True)
class RigNodes:
    ref: int  # 1-based CalculiX node number of the rigid body's reference node
    rot: int  # ... of its rotation node
    ref_xy: tuple[float, float]  # m, reference position of the reference node (z = 0)


def _static(w, tire: RigTire, inc: str, slide: bool = False) -> None:
    w("*STATIC")
    w(inc)
    lines = tire.slide_controls if slide and tire.slide_controls is not None else tire.controls
    for line in lines:
        w(line)


def _outputs(w, frequency: int) -> None:
    # CalculiX 2.20 uses one output frequency for the .frd and the .dat requests; the
    # last increment of each step is always written
    w(f"*NODE FILE, NSET=TIREN, FREQUENCY={frequency}")
    w("U")
    w(f"*CONTACT FILE, FREQUENCY={frequency}")
    w("CDIS, CSTR")
    w(f"*NODE PRINT, NSET=REFN, FREQUENCY={frequency}")
    w("U, RF")
    w(f"*NODE PRINT, NSET=ROTN, FREQUENCY={frequency}")
    w("U, RF")
    w(f"*NODE PRINT, NSET=BEAD, TOTALS=ONLY, FREQUENCY={frequency}")
    w("RF")


def write_base_deck(
    path,
    mesh: TireMesh,
    rim_travel: float,
    origin: tuple[float, float],
    tire: RigTire = SMALL,
    inflation_only: bool = False,
    vertical_inc: str | None = None,
) -> RigNodes:
    """Steps 1-2 (inflation, vertical rim travel) with the rigid road; writes a restart file.

    ``inflation_only``: step 1 alone (the pre-run that finds the inflated clearance).
    ``vertical_inc``: the ``*STATIC`` line of the vertical travel (default the tire's).
    """
    road = tire.road()
    nt, nr = mesh.nodes.shape[0], road.nodes.shape[0]
    title = "fepost tire sector, slide/spin rig" + ("" if tire is SMALL else f" ({tire.name} tire)")
    out = tire.model_lines(mesh, title, road, cut_refs=nt + nr + 3)
    w = out.append
    nodes = RigNodes(ref=nt + nr + 1, rot=nt + nr + 2, ref_xy=(float(origin[0]), float(origin[1])))
    w("*NODE, NSET=NALL")
    w(f"{nodes.ref}, {origin[0]:.9e}, {origin[1]:.9e}, 0.0")
    w(f"{nodes.rot}, {origin[0]:.9e}, {origin[1]:.9e}, 0.0")
    w("*NSET, NSET=REFN")
    w(str(nodes.ref))
    w("*NSET, NSET=ROTN")
    w(str(nodes.rot))
    w(f"*RIGID BODY, NSET=ROADN, REF NODE={nodes.ref}, ROT NODE={nodes.rot}")
    w("*BOUNDARY")
    w("REFN, 1, 3")
    w("ROTN, 1, 3")
    w("BEAD, 1, 3")
    if dk.cut_nodes(mesh):
        w("CUTREF, 1, 3")
    table = face_lookup(mesh.hexes)
    if tire.one_step:
        _one_step_base(out, mesh, rim_travel, tire, inflation_only)
        with open(path, "w") as fh:
            fh.write("\n".join(out) + "\n")
        return nodes
    w("*STEP, NLGEOM, INC=400")
    _static(w, tire, tire.inflation_inc)
    w("*DLOAD")
    out += cx.pressure_load(mesh.hexes, mesh.inner_quads, tire.pressure, table)
    _outputs(w, 1000)
    w("*END STEP")
    if inflation_only:
        with open(path, "w") as fh:
            fh.write("\n".join(out) + "\n")
        return nodes
    w("*STEP, NLGEOM, INC=400")
    _static(w, tire, vertical_inc or tire.vertical_inc)
    w("*BOUNDARY")
    _rim_z(w, mesh, rim_travel)
    _outputs(w, 1000)
    w("*RESTART, WRITE, FREQUENCY=1")
    w("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return nodes


def _one_step_base(out: list[str], mesh: TireMesh, rim_travel: float, tire: RigTire, inflation_only: bool):
    """The base as one step: inflation over [0, INFLATION_TIME], then the vertical travel over 1.

    With the aircraft tire, CalculiX 2.20 failed the first increment of every
    new step after the inflation (a residual of about 1e5 N at a node far from
    the road, whatever the increment), while the same path inside one step
    converges; the aircraft sweep runs in one step for the same reason.
    """
    w = out.append
    t0, t1 = INFLATION_TIME, INFLATION_TIME + 1.0
    w("*AMPLITUDE, NAME=APRESS")
    w(f"0.0, 0.0, {t0}, 1.0, {t1}, 1.0")
    w("*AMPLITUDE, NAME=ARIMZ")
    w(f"0.0, 0.0, {t0}, 0.0, {t1}, 1.0")
    w("*STEP, NLGEOM, INC=1000")
    first, _, smallest, largest = (v.strip() for v in tire.vertical_inc.split(","))
    _static(w, tire, f"{first}, {t0 if inflation_only else t1}, {smallest}, {largest}")
    w("*BOUNDARY, AMPLITUDE=ARIMZ")
    _rim_z(w, mesh, rim_travel)
    w("*DLOAD, AMPLITUDE=APRESS")
    out += cx.pressure_load(mesh.hexes, mesh.inner_quads, tire.pressure, face_lookup(mesh.hexes))
    _outputs(w, 1000)
    if not inflation_only:
        w("*RESTART, WRITE, FREQUENCY=1")
    w("*END STEP")


def _rim_z(w, mesh: TireMesh, rim_travel: float) -> None:
    """The rim's vertical travel on the bead nodes and, for a sector, the cut faces' reference nodes."""
    w(f"BEAD, 3, 3, {-rim_travel:.9e}")
    if dk.cut_nodes(mesh):
        w(f"CUTREF, 3, 3, {-rim_travel:.9e}")


def tire_motion(kin: Kinematics, origin: tuple[float, float], t: float) -> tuple[float, np.ndarray]:
    """Rigid motion of the rim at pseudo-time ``t``: (rotation angle about z, rad; 2x3 affine map).

    The road stays put; the tire turns by wz t about the vertical axis through
    the instantaneous centre P (for wz = 0: translates by (vx, vy) t). The map
    ``A`` sends a reference point (x, y, 1) to its moved (x, y).
    """
    pivot = kin.pivot(origin)
    if pivot is None:
        return 0.0, np.array([[1.0, 0.0, kin.vx * t], [0.0, 1.0, kin.vy * t]])
    th = kin.wz * t
    c, s = math.cos(th), math.sin(th)
    rot = np.array([[c, -s], [s, c]])
    p = np.asarray(pivot)
    return th, np.column_stack([rot, p - rot @ p])


@dataclass(frozen=True)
class RoadExit:
    """Where a moving patch first passes a limit near the road's edge (the road's half extent,
    less a number of road faces, along x and along y)."""

    t: float  # pseudo-time (share of the path) of the first sample past the limit
    reach: float  # the farthest a patch point gets over the whole run: |x|, |y| over the axis' limit


def road_exit(
    kin: Kinematics,
    origin: tuple[float, float],
    points: np.ndarray,
    road: cx.Road,
    faces: int = 0,
    samples: int = 1001,
) -> RoadExit | None:
    """The first pseudo-time at which one of ``points`` (the static patch's (x, y), m) passes the edge
    of ``road`` less ``faces`` road faces under the run's rigid motion, or None if none does.

    A patch that runs off the road loses its leading edge's contact while the slide goes on: the
    forces fall and CalculiX cuts the increment until it stops. The whole tire's 45 degree run with
    20 degrees of spin over 0.90 m (``d045_a20n``, road |x|, |y| <= 0.80 m, 50 mm faces): its
    farthest loaded node entered the last face at 69 % of the path and passed the road's edge at
    75 %; the rim's force in the tire's frame, steady to 0.0011 f N over 56-76 %, fell by 0.014 f N
    over 83-90 %, and the solve stalled at 90 % (increments cut to 2e-6). The motion is sampled at
    ``samples`` pseudo-times: the crossing is found to 1/(samples-1) of the path; an arc bulges out
    between samples by under 1 micrometre for the rig's runs.
    """
    xy = np.asarray(points, dtype=float).reshape(-1, 2)
    half = np.abs(road.nodes[:, :2]).max(axis=0)
    face = max(float(np.diff(np.unique(road.nodes[:, k])).max()) for k in (0, 1))
    limit = half - faces * face
    ts = np.linspace(0.0, 1.0, samples)
    maps = np.array([tire_motion(kin, origin, float(t))[1] for t in ts])  # (samples, 2, 3)
    moved = np.einsum("tij,nj->tni", maps[:, :, :2], xy) + maps[:, None, :, 2]  # (samples, n, 2)
    # the largest |x| and |y| at each sample, as a share of the axis' limit
    share = (np.abs(moved).max(axis=1) / limit).max(axis=1)
    if not (share > 1.0).any():
        return None
    return RoadExit(t=float(ts[np.argmax(share > 1.0)]), reach=float(share.max()))


def substeps(inc: float) -> int:
    """Number of slide steps K for the largest increment ``inc`` (pseudo-time)."""
    if not 0.0 < inc <= 1.0:
        raise ValueError(f"increment {inc} outside (0, 1]")
    return math.ceil(1.0 / inc - 1e-9)


def write_slide_deck(
    path,
    mesh: TireMesh,
    kin: Kinematics,
    rim_travel: float,
    origin: tuple[float, float],
    inc: float,
    tire: RigTire = SMALL,
) -> None:
    """The run's deck: restart from the base's step 2, then K slide steps of pseudo-time 1/K.

    Each step prescribes the rim (bead) nodes at the exact rigid motion of its
    end (``tire_motion``); within a step CalculiX ramps them linearly (the
    chord), off the arc by at most d (wz/K)^2 / 8 for a bead node at distance d
    from P (below 0.1 mm here, a strain of the rim below 2e-4).
    """
    k = substeps(inc)
    dt = 1.0 / k
    # the rim's nodes and the cut faces' reference nodes (numbered after the road's
    # reference and rotation nodes) follow the rim's rigid motion
    nt = mesh.nodes.shape[0]
    cut = dk.cut_nodes(mesh)
    first = nt + tire.road().nodes.shape[0] + 3
    bead = np.unique(mesh.bead_nodes)
    numbers = [int(n) + 1 for n in bead] + list(range(first, first + len(cut)))
    pos = np.vstack([mesh.nodes[bead, :2], mesh.nodes[cut, :2]])
    xy1 = np.column_stack([pos, np.ones(len(numbers))])
    if tire.one_step:
        _one_step_slide(path, kin, origin, k, numbers, xy1, rim_travel, tire, bool(cut))
        return
    out = ["*RESTART, READ, STEP=2"]
    w = out.append
    for i in range(1, k + 1):
        _, a = tire_motion(kin, origin, i * dt)
        u = xy1 @ a.T - xy1[:, :2]
        w("*STEP, NLGEOM, INC=400")
        _static(w, tire, f"{dt / 2 if i == 1 else dt:.6g}, {dt:.6g}, 1e-8, {dt:.6g}", slide=True)
        w("*BOUNDARY")
        for n, (ux, uy) in zip(numbers, u, strict=True):
            w(f"{n}, 1, 1, {ux:.12e}")
            w(f"{n}, 2, 2, {uy:.12e}")
        _rim_z(w, mesh, rim_travel)
        _outputs(w, 1)
        w("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")


def _one_step_slide(
    path, kin: Kinematics, origin, k: int, numbers, xy1, rim_travel: float, tire: RigTire, cuts: bool = True
):
    """The slide as one step: each rim node and cut-face reference node follows its own
    piecewise-linear amplitude through the exact rigid positions at t = i / k (the chords
    of ``write_slide_deck``'s steps), so the first-increment failure of a new step
    (``_one_step_base``) is met once per run, not once per sub-step."""
    times = [i / k for i in range(k + 1)]
    moves = [xy1 @ tire_motion(kin, origin, t)[1].T - xy1[:, :2] for t in times]
    out = ["*RESTART, READ, STEP=1"]
    w = out.append
    names = []
    for j, n in enumerate(numbers):
        for d in (0, 1):
            name = f"A{n}_{d + 1}"
            names.append((n, d + 1, name))
            w(f"*AMPLITUDE, NAME={name}")
            w(cx.data_lines((f"{t:.6g}, {u[j, d]:.12e}" for t, u in zip(times, moves, strict=True)), per=4))
    dt = 1.0 / k
    w("*STEP, NLGEOM, INC=1000")
    # the first increment starts small: at dt / 2 the aircraft tire's first iteration diverged
    # (the stick predictor of the whole patch against a rim move of several mm) and CalculiX
    # cut back five or six times to a few 1e-5 before it converged
    _static(w, tire, f"{FIRST_SLIDE_INC:.6g}, 1.0, 1e-8, {dt:.6g}", slide=True)
    for n, dof, name in names:
        w(f"*BOUNDARY, AMPLITUDE={name}")
        w(f"{n}, {dof}, {dof}, 1.0")
    w("*BOUNDARY")
    w(f"BEAD, 3, 3, {-rim_travel:.9e}")
    if cuts:
        w(f"CUTREF, 3, 3, {-rim_travel:.9e}")
    _outputs(w, 1)
    w("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
