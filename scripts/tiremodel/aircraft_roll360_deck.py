"""Steady rolling of the whole aircraft tire: its mesh and its CalculiX deck (issue 39).

The model. The whole rig tire's materials, elements (two through the rubber;
C3D8I, plain C3D8 in the rubber under the patch's lateral edges) and contact
(``aircraft_rig_deck.WHOLE``'s model lines, imported, not copied: whatever
element split and contact law the whole rig tire uses, rolling uses too),
revolved over the full 360 degrees with uniform circumferential layers all
round: a roll of X metres turns the rim by about X / R_e (1.6 m: 164 degrees),
so material from almost the whole circumference passes through the patch and
every layer but the top one is a contact slave. Straight rolling
is symmetric about the mid-plane y = 0, so the model is the half y >= 0 with
a symmetry plane (u_y = 0 there): half the cost of the full section. Forces
are reported for the whole tire (twice the half model's).

Frame: the axle's, as ``aircraft_roll_deck``. The axle (the y axis through
(0, 0, axle_z)) stays put; the rim is a rigid body on the bead nodes (reference
node REFN on the axle, rotation node ROTN whose second degree of freedom is the
rim's turn about +y). The road block (every node prescribed) rises by the rim
travel, then moves along -x by the axle travel X. One CalculiX step, NLGEOM,
driven by amplitudes: inflation over [0, 0.2], vertical travel over [0.2, 1.2],
rolling over [1.2, 1.2 + ROLL_TIME]. The rim's turn is either prescribed
(``rotation``: linear in the axle travel, imposed slip) or left free
(``rotation=None``: no torque on the rim, a free-rolling wheel).

Printed records (.dat) every ``print_every`` of the rolling time, for the
steadiness test over the last fifth of the roll; surface results (.frd) at the
static state and at ``frames`` times along the roll.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import aircraft_deck as ad
from . import aircraft_rig_deck as ard
from . import ccxdeck as cx
from .aircraft_geometry import AircraftMesh, AircraftParams, build_aircraft_mesh
from .aircraft_roll_mesh import turn_about_axle
from .meshing import face_lookup

LOAD_TIME = 1.0  # analysis time of the vertical road travel
ROLL_TIME = 2.0  # analysis time of the rolling stage
FIRST_INC = 0.02  # first increment (inflation)
#: CalculiX's field controls: the force residual R_n at its default 0.005 (the sector's rolling
#: runs: 0.02), which sets how well rim and road balance; the displacement correction C_n at 1.0
#: (default 0.01, the sector's 0.5): under 0.01 and 0.5 the tiny deck's roll stalled with the
#: residual at 1e-4 N and 0.5 N of an average nodal force of 460-520 N, the correction of an
#: incompatible-mode unknown 0.4-0.8 of the increment, the increment cut to 3e-6 of the roll
TOLERANCES = (0.005, 1.0)
#: the first step's (inflation and vertical travel, not measured): the whole rig tire's base
#: criteria (0.02, 0.5). Under TOLERANCES the fine mesh's loading iterated with the largest
#: residual flipping between 110 and 1660 N (contact flips at the patch edge, 240 contact
#: elements) at 96 % of the travel, and CalculiX then stopped inside the equation solver
#: (exit status 255, no message)
LOAD_TOLERANCES = (0.02, 0.5)
INCREMENTATION = "4, 8, 9, 16, 10, 4, 0, 10"  # the sweep's and the sector rig's
#: the roll's: an increment grows after two that converged in fewer than 7 iterations (IG; the
#: sweep's 4 kept the fine mesh's roll at 1.4 mm of travel an increment, each taking 5-6
#: iterations: 1400 increments for 1.6 m), and may take 30 iterations (the whole rig tire's
#: slides: 50) before it is cut back
ROLL_INCREMENTATION = "8, 16, 16, 30, 16, 7, 0, 20"
#: the supports of every step: symmetry plane, the road's lateral motion, the axle's position and
#: the rim's turns about x and z
HELD = ("SYMN, 2, 2", "ROADN, 2, 2", "REFN, 1, 3", "ROTN, 1, 1", "ROTN, 3, 3")
#: the share of the roll over which a pre-wind (``Plan.prewind``) is applied
PREWIND_SHARE = 0.01
TURN_DEG = 20.0  # the mesh is turned by about this (a whole number of layers) towards +x


@dataclass
class Roll360Mesh(AircraftMesh):
    """The half-section whole tire (an ``AircraftMesh``) with no sector cut faces."""

    cut_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


#: section counts (half section) and circumferential layer of each mesh kind: ``fine`` is the
#: whole rig tire's programme mesh (``whole-fine``: 6 + 3 + 4, two rubber elements, 1.5 degrees),
#: ``mid`` the whole rig tire's ``whole`` counts, ``tiny`` a test deck that solves in seconds
MESHES = {
    "fine": {"n_crown": 6, "n_shoulder": 3, "n_side": 4, "layer_deg": 1.5, "n_rubber": 2},
    "mid": {"n_crown": 5, "n_shoulder": 3, "n_side": 4, "layer_deg": 1.8, "n_rubber": 2},
    "tiny": {"n_crown": 2, "n_shoulder": 1, "n_side": 1, "layer_deg": 10.0, "n_rubber": 2},
}


def mesh_params(kind: str) -> AircraftParams:
    """The aircraft tire's dimensions with the counts of ``kind``: uniform layers all round."""
    if kind not in MESHES:
        raise ValueError(f"unknown roll360 mesh {kind!r} ({', '.join(MESHES)})")
    m = MESHES[kind]
    return AircraftParams(
        n_crown=m["n_crown"],
        n_shoulder=m["n_shoulder"],
        n_side=m["n_side"],
        n_rubber=m["n_rubber"],
        incompatible_all=True,
        first_deg=m["layer_deg"],
        growth=1.0,
        # the revolution needs a coarse part: one layer of the same size at the top (+-180 deg),
        # which never reaches the patch (no contact slave there)
        fine_deg=180.0 - m["layer_deg"],
        n_coarse=1,
    )


def build_mesh(kind: str) -> Roll360Mesh:
    """The half-section whole tire of ``kind`` (gmsh): uniform layers all round, turned by a whole
    number of layers (about ``TURN_DEG``) so that the one top layer, which is no contact slave, lies
    behind the bottom and the contact slaves reach ``max_roll_deg`` ahead of it."""
    p = mesh_params(kind)
    turn = round(TURN_DEG / p.first_deg) * p.first_deg
    half = turn_about_axle(build_aircraft_mesh(p), turn)
    mesh = Roll360Mesh(**{f.name: getattr(half, f.name) for f in AircraftMesh.__dataclass_fields__.values()})
    ang = np.degrees(np.arctan2(mesh.nodes[:, 0], p.axle_z - mesh.nodes[:, 2]))
    layers = np.unique(np.round(ang, 6)).size
    mesh.info.update(
        {
            "kind": kind,
            "nodes": int(mesh.nodes.shape[0]),
            "hexahedra": int(mesh.hexes.shape[0]),
            "layer_deg": p.first_deg,
            "circumferential_node_rings": int(layers),
            "whole_tire": True,
            "turned_deg": turn,
            # the material at phi (from the bottom, towards +x) is in the patch when the rim has
            # turned by phi - half patch: the slaves end at 180 - layer + turn
            "slave_arc_deg": [-180.0 + turn, 180.0 - p.first_deg + turn],
            "symmetry": "half model y >= 0, symmetry plane y = 0",
        }
    )
    return mesh


@dataclass(frozen=True)
class Plan:
    """One rolling run: vertical rim travel, then axle travel X and the rim's turn.

    ``rotation``: the imposed total turn (rad, about +y, linear in the travel); None: the rim
    is free to turn (no torque about the axle). ``print_every``: analysis time between printed
    records (also the largest increment); ``frames``: surface results along the roll.
    """

    travel_z: float
    travel_x: float
    rotation: float | None
    print_every: float = 0.05
    frames: int = 4
    tolerances: tuple[float, float] = TOLERANCES
    load_tolerances: tuple[float, float] = LOAD_TOLERANCES
    # the roll's *CONTROLS, PARAMETERS=TIME INCREMENTATION (I0, IR, IP, IC, IL, IG, IS, IA)
    roll_incrementation: str = ROLL_INCREMENTATION
    road_margin: float = 0.45  # m of road before and behind the patch
    road_face: float = 0.025  # m, road face size
    # the roll's first increment: the fine mesh cut 0.02 back four times to 3e-4
    first_roll_inc: float | None = 0.002
    #: rad, an imposed turn's extra turn over the roll's first ``PREWIND_SHARE`` (0: none): the
    #: carcass wound up by the steady torque before the tread renews, so the roll starts near its
    #: steady state instead of building it up over the relaxation length
    prewind: float = 0.0


def roll_times(plan: Plan) -> list[float]:
    """Analysis times of the printed records along the roll (the last at its end)."""
    t1 = ad.INFLATION_TIME + LOAD_TIME
    n = max(1, round(ROLL_TIME / plan.print_every))
    return [t1 + ROLL_TIME * i / n for i in range(1, n + 1)]


def output_times(plan: Plan) -> dict[str, float]:
    """Surface results: inflation, static (loaded), then ``frames`` times along the roll."""
    t1 = ad.INFLATION_TIME + LOAD_TIME
    times = {"inflation": ad.INFLATION_TIME, "static": t1}
    rolls = roll_times(plan)
    for i in range(1, plan.frames + 1):
        times[f"roll{i:03d}"] = rolls[round(i * len(rolls) / plan.frames) - 1]
    return times


def road_block(plan: Plan) -> cx.Road:
    """x in [-margin, X + margin], y in [0, 0.3]: under the patch for the whole roll."""
    length = plan.travel_x + 2 * plan.road_margin
    road = cx.build_road(half_x=length / 2, half_y=0.15, thick=0.02, size=plan.road_face)
    road.nodes[:, 0] += length / 2 - plan.road_margin
    road.nodes[:, 1] += 0.15
    return road


def write_deck(path, mesh: Roll360Mesh, plan: Plan) -> dict:
    """Write the deck; return its numbering (``refn``, ``rotn``, counts) and output times."""
    road = road_block(plan)
    nt, et, nr = mesh.nodes.shape[0], mesh.hexes.shape[0], road.nodes.shape[0]
    refn, rotn = nt + nr + 1, nt + nr + 2
    zc = mesh.params.axle_z
    title = "fepost aircraft tire (46x17R20 class), whole 360-degree tire rolling, half model y >= 0"
    out = list(ard.WHOLE.model_lines(mesh, title, road))
    out += ["*NODE", *(f"{n}, 0.0, 0.0, {zc:.9e}" for n in (refn, rotn))]
    out += cx.node_sets(
        {
            "SYMN": (int(n) + 1 for n in mesh.symmetry_nodes),
            "ROADREF": [nt + 1],
            "REFN": [refn],
            "ROTN": [rotn],
        }
    )
    out.append(f"*RIGID BODY, NSET=BEAD, REF NODE={refn}, ROT NODE={rotn}")
    times = output_times(plan)
    k = next(i for i, line in enumerate(out) if line.startswith("*SURFACE BEHAVIOR"))
    law = f"{out[k].split(',', 1)[1].strip()}: {out[k + 1]}"
    out += _step(mesh, plan, times)
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return {
        "tire_nodes": nt,
        "tire_elements": et,
        "road_nodes": nr,
        "road_elements": int(road.hexes.shape[0]),
        "refn": refn,
        "rotn": rotn,
        "output_times": times,
        "print_times": roll_times(plan),
        "contact_law": law,
        "elements": {
            "C3D8I": int(ard.incompatible_mask(mesh).sum()),
            ard.plain_element(mesh): int((~ard.incompatible_mask(mesh)).sum()),
        },
    }


def _step(mesh: Roll360Mesh, plan: Plan, times: dict[str, float]) -> list[str]:
    """The free rim: two steps, inflation and vertical travel with the rim's turn held, then the
    roll with the turn released. An imposed turn: one step, every motion driven by amplitudes
    (the turn 0 until the roll), under the roll's criteria throughout. On the fine mesh the
    second step's first iteration put 49.5 kN on one bead-side node whatever the increment (the
    rig's finding with this tire: CalculiX 2.20 fails the first increment of a new step after the
    inflation); the free rim's roll got past it at 8e-6 of the roll, the imposed turn did not."""
    if plan.rotation is not None:
        return _one_step(mesh, plan, times)
    if plan.prewind:
        raise ValueError("a pre-wind needs an imposed turn (the free rim has none)")
    t1 = ad.INFLATION_TIME + LOAD_TIME
    first_roll = plan.first_roll_inc or min(FIRST_INC, plan.print_every)
    return [
        *_amplitudes(plan, times),
        "*STEP, NLGEOM, INC=10000",
        "*STATIC",
        f"{FIRST_INC}, {t1:.6f}, 1e-9, {plan.print_every}",
        *_controls(plan.load_tolerances, INCREMENTATION),
        "*BOUNDARY",
        *HELD,
        "ROTN, 2, 2",
        # the road held along x too: left free, it drifted by 0.23 um under the fine mesh's
        # loading (the roll's restatement then sets it back to 0)
        "ROADN, 1, 1",
        "*BOUNDARY, AMPLITUDE=ALOAD",
        f"ROADN, 3, 3, {plan.travel_z:.9e}",
        "*DLOAD, AMPLITUDE=APRESS",
        *cx.pressure_load(mesh.hexes, mesh.inner_quads, ad.PRESSURE, face_lookup(mesh.hexes)),
        *_outputs(),
        "*END STEP",
        # the roll: every condition again (OP=NEW), the rim's turn released
        "*STEP, NLGEOM, INC=10000",
        "*STATIC",
        f"{first_roll}, {ROLL_TIME:.6f}, 1e-9, {plan.print_every}",
        *_controls(plan.tolerances, plan.roll_incrementation),
        "*BOUNDARY, OP=NEW",
        *HELD,
        f"ROADN, 3, 3, {plan.travel_z:.9e}",
        "*BOUNDARY, AMPLITUDE=AROLL",
        f"ROADN, 1, 1, {-plan.travel_x:.9e}",
        *_outputs(),
        "*END STEP",
    ]


def _amplitudes(plan: Plan, times: dict[str, float]) -> list[str]:
    t0 = ad.INFLATION_TIME
    t1 = t0 + LOAD_TIME
    t2 = t1 + ROLL_TIME
    printed = sorted({round(t, 9) for t in (t0, t1, *roll_times(plan))})
    return [
        "*AMPLITUDE, NAME=APRESS, TIME=TOTAL TIME",
        f"0.0, 0.0, {t0:.6f}, 1.0, {t2:.6f}, 1.0",
        "*AMPLITUDE, NAME=ALOAD, TIME=TOTAL TIME",
        f"0.0, 0.0, {t0:.6f}, 0.0, {t1:.6f}, 1.0, {t2:.6f}, 1.0",
        "*AMPLITUDE, NAME=AROLL, TIME=TOTAL TIME",
        f"0.0, 0.0, {t1:.6f}, 0.0, {t2:.6f}, 1.0",
        "*TIME POINTS, NAME=TOUT, TIME=TOTAL TIME",
        cx.data_lines(f"{t:.9f}" for t in sorted(times.values())),
        "*TIME POINTS, NAME=TDAT, TIME=TOTAL TIME",
        cx.data_lines(f"{t:.9f}" for t in printed),
    ]


def _one_step(mesh: Roll360Mesh, plan: Plan, times: dict[str, float]) -> list[str]:
    """Inflation, vertical travel and the roll with the turn imposed: one step (``_step``). The
    turn follows the roll's amplitude, or with a pre-wind its own (``ATURN``): the extra turn over
    the roll's first ``PREWIND_SHARE``, then the rolling turn on top, linear in the travel."""
    t1 = ad.INFLATION_TIME + LOAD_TIME
    t2 = t1 + ROLL_TIME
    total = plan.rotation + plan.prewind
    turn_amp: list[str] = []
    if plan.prewind:
        tw = t1 + PREWIND_SHARE * ROLL_TIME
        at_tw = (plan.prewind + PREWIND_SHARE * plan.rotation) / total
        turn_amp = [
            "*AMPLITUDE, NAME=ATURN, TIME=TOTAL TIME",
            f"0.0, 0.0, {t1:.6f}, 0.0, {tw:.6f}, {at_tw:.12e}, {t2:.6f}, 1.0",
        ]
    return [
        *_amplitudes(plan, times),
        *turn_amp,
        "*STEP, NLGEOM, INC=100000",
        "*STATIC",
        f"{FIRST_INC}, {t2:.6f}, 1e-9, {plan.print_every}",
        *_controls(plan.tolerances, plan.roll_incrementation),
        "*BOUNDARY",
        *HELD,
        "*BOUNDARY, AMPLITUDE=ALOAD",
        f"ROADN, 3, 3, {plan.travel_z:.9e}",
        "*BOUNDARY, AMPLITUDE=AROLL",
        f"ROADN, 1, 1, {-plan.travel_x:.9e}",
        f"*BOUNDARY, AMPLITUDE={'ATURN' if plan.prewind else 'AROLL'}",
        f"ROTN, 2, 2, {total:.9e}",
        "*DLOAD, AMPLITUDE=APRESS",
        *cx.pressure_load(mesh.hexes, mesh.inner_quads, ad.PRESSURE, face_lookup(mesh.hexes)),
        *_outputs(),
        "*END STEP",
    ]


def _controls(tolerances: tuple[float, float], incrementation: str) -> list[str]:
    return [
        "*CONTROLS, PARAMETERS=FIELD",
        f"{tolerances[0]}, {tolerances[1]}",
        "*CONTROLS, PARAMETERS=TIME INCREMENTATION",
        incrementation,
    ]


def _outputs() -> list[str]:
    return [
        "*NODE FILE, NSET=TIREN, TIME POINTS=TOUT",
        "U",
        "*CONTACT FILE, TIME POINTS=TOUT",
        "CDIS, CSTR",
        "*NODE PRINT, NSET=ROADN, TOTALS=ONLY, TIME POINTS=TDAT",
        "RF",
        "*NODE PRINT, NSET=ROADREF, TIME POINTS=TDAT",
        "U",
        "*NODE PRINT, NSET=ROTN, TIME POINTS=TDAT",
        "U, RF",
        "*NODE PRINT, NSET=REFN, TIME POINTS=TDAT",
        "RF",
    ]


def turn_for(travel: float, radius: float, slip: float = 0.0) -> float:
    """The rim's turn (rad) for the slip ``slip`` = R_e dtheta/dX - 1 over ``travel``."""
    if not radius > 0.0 or not math.isfinite(radius):
        raise ValueError(f"effective rolling radius {radius!r} must be a positive number")
    return (1.0 + slip) * travel / radius
