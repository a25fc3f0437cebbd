"""CalculiX deck of the aircraft tire rolling quasi-statically on a rigid flat road.

Frame: the axle's. The axle (the y axis through (0, 0, axle_z)) stays put; the
rim is one rigid body (``*RIGID BODY`` on the bead nodes) with its reference
node on the axle and a rotation node whose second degree of freedom is the
rim's turn about +y. The road block (every node prescribed) first moves up by
the rim travel (the vertical load, as in the static sweep) and then along -x
by the axle travel X: relative to the road the axle moves +x by X while the rim
turns by theta. A positive turn about +y rolls the tire forward (+x).

One CalculiX step, NLGEOM, driven by amplitudes (as ``aircraft_deck``):
inflation over [0, 0.2], vertical road travel over [0.2, 1.2], rolling over
[1.2, 1.2 + ROLL_TIME]. Two ways to turn the rim:

- imposed slip: the rotation node's turn is prescribed, theta linear in time
  from 0 to ``rotation`` while the road travels (the robust way);
- elastic drive (the free-rolling run): a driver node's turn is prescribed
  (``rotation``, from an estimate of the effective rolling radius) and drives
  the rim through a torsion spring (``SPRING2`` between the driver and the
  rotation node, ``drive_stiffness`` N m/rad on the half model) that is soft
  against the tire's own resistance to slip, so the rim turns nearly as a
  free-rolling rim would; the spring's torque is the driver node's reaction
  and is reported. A first attempt with the rim left free (a 100 N m/rad
  spring to ground only) cut its increment to 2e-4 of the roll at the start of
  the roll (the rotation node's turn swinging between iterations) and was
  stopped there; the later runs cut back at the roll's start too and recovered.

Materials, contact and the relaxed convergence criteria are the static sweep's
(``aircraft_deck``). Node numbers: tire 1..n, road block, then the rim's
reference node (REFN), rotation node (ROTN) and the driver node (DRVN).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import aircraft_deck as ad
from . import ccxdeck as cx
from .aircraft_geometry import AircraftMesh
from .meshing import face_lookup

ROLL_TIME = 2.0  # analysis time of the rolling stage
LOAD_TIME = 1.0  # analysis time of the vertical road travel
MAX_INC = 0.05  # largest increment (analysis time)
FIRST_INC = 0.02  # the first (inflation) increment: 0.05 diverged and was cut back twice
DENSITY_RUBBER = 1150.0  # kg/m^3, tire materials (only written for the damped *DYNAMIC variant)
TOLERANCES = (0.02, 0.5)  # CalculiX R_n, C_n: as the static sweep's fine runs


@dataclass(frozen=True)
class RollPlan:
    """One rolling run: vertical rim travel, then axle travel and rim turn.

    ``rotation`` is the imposed total turn (rad, about +y) of the rim, or with
    ``drive_stiffness`` (N m/rad, half model) that of the driver node coupled to
    the rim by a torsion spring. ``samples``: result times evenly spread over the
    roll (the last at its end).
    """

    travel_z: float  # m, road travel up = rim travel down relative to the road
    travel_x: float  # m, axle travel along +x relative to the road
    rotation: float
    samples: int = 10
    road_length: float = 1.6  # m, along x; the block starts 0.4 m behind the axle
    road_half_width: float = 0.3  # m, along y (half model: y in [0, 0.3])
    drive_stiffness: float | None = None
    damping_beta: float | None = None  # s: Rayleigh stiffness damping of the tread (*DYNAMIC step)
    max_inc: float = MAX_INC  # largest increment (analysis time); larger only for quick test decks


def output_times(plan: RollPlan) -> dict[str, float]:
    """Analysis times of the written results: inflation, static (loaded), roll samples."""
    t1 = ad.INFLATION_TIME + LOAD_TIME
    times = {"inflation": ad.INFLATION_TIME, "static": t1}
    for i in range(1, plan.samples + 1):
        times[f"roll{i:03d}"] = t1 + ROLL_TIME * i / plan.samples
    return times


def road_block(plan: RollPlan) -> cx.Road:
    """The road: x in [-0.4, road_length - 0.4], y in [0, road_half_width], top face z = 0."""
    half_x = plan.road_length / 2
    road = cx.build_road(half_x=half_x, half_y=plan.road_half_width / 2, thick=0.02, size=0.025)
    road.nodes[:, 0] += half_x - 0.4
    road.nodes[:, 1] += plan.road_half_width / 2
    return road


def write_roll_deck(path, mesh: AircraftMesh, plan: RollPlan) -> dict:
    """Write the deck; return its numbering (``refn``, ``rotn``, node and element counts) and times."""
    road = road_block(plan)
    nt, et = mesh.nodes.shape[0], mesh.hexes.shape[0]
    nr = road.nodes.shape[0]
    refn, rotn, drvn = nt + nr + 1, nt + nr + 2, nt + nr + 3
    zc = mesh.params.axle_z
    out: list[str] = ["*HEADING", "fepost aircraft tire (46x17R20 class) rolling, half model y >= 0"]
    out += cx.node_block(mesh.nodes, road)
    out += [f"{n}, 0.0, 0.0, {zc:.9e}" for n in (refn, rotn, drvn)]
    out += _elements(mesh, road)
    table = face_lookup(mesh.hexes)
    out += cx.node_sets(
        {
            "BEAD": (int(n) + 1 for n in mesh.bead_nodes),
            "SYMN": (int(n) + 1 for n in mesh.symmetry_nodes),
            **cx.tire_road_sets(nt, road),
            "ROADREF": [nt + 1],
            "REFN": [refn],
            "ROTN": [rotn],
            "DRVN": [drvn],
        }
    )
    out += cx.contact_surfaces(mesh.hexes, mesh.contact_quads, road, table)
    out += _materials(mesh, plan.damping_beta)
    out.append(f"*RIGID BODY, NSET=BEAD, REF NODE={refn}, ROT NODE={rotn}")
    if plan.drive_stiffness is not None:
        out += [
            "*ELEMENT, TYPE=SPRING2, ELSET=ESPRING",
            f"{et + road.hexes.shape[0] + 1}, {drvn}, {rotn}",
            "*SPRING, ELSET=ESPRING",
            "2, 2",
            f"{plan.drive_stiffness:.6e}",
        ]
    out += cx.contact_pair(ad.CONTACT_SLOPE, ad.CONTACT_TENSION, ad.FRICTION, ad.STICK_SLOPE)
    times = output_times(plan)
    out += _amplitudes_and_step(mesh, plan, times, table)
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return {
        "tire_nodes": nt,
        "tire_elements": et,
        "road_nodes": nr,
        "road_elements": int(road.hexes.shape[0]),
        "refn": refn,
        "rotn": rotn,
        "drvn": drvn,
        "output_times": times,
    }


def _elements(mesh: AircraftMesh, road: cx.Road) -> list[str]:
    # as the static sweep: incompatible modes in the fine region except the shoulder rubber
    incompatible = mesh.fine & ~((mesh.region == 1) & (mesh.layer == 0))
    out: list[str] = []
    for etype, sel in (("C3D8I", incompatible), ("C3D8", ~incompatible)):
        if sel.any():
            out += cx.element_block(etype, "TIRE", np.flatnonzero(sel) + 1, mesh.hexes[sel])
    out += cx.road_elements(road, mesh.nodes.shape[0], mesh.hexes.shape[0])
    rubber = mesh.layer == 0
    tread = rubber & (mesh.region == 0)
    for name, sel in (("ETREAD", tread), ("ESIDEWALL", rubber & ~tread)):
        out += [f"*ELSET, ELSET={name}", cx.data_lines(int(e) + 1 for e in np.flatnonzero(sel))]
    return out


def _materials(mesh: AircraftMesh, beta: float | None = None) -> list[str]:
    """Materials and sections; with ``beta`` also densities (a *DYNAMIC step needs them)
    and Rayleigh stiffness damping (``*DAMPING, BETA``) on the tread rubber."""
    dens = [] if beta is None else ["*DENSITY", f"{DENSITY_RUBBER:g}"]
    out: list[str] = []
    for name, r in ad.RUBBER.items():
        out += [f"*MATERIAL, NAME={name}", "*HYPERELASTIC, NEO HOOKE"]
        out.append(f"{r['shear_modulus'] / 2:.6e}, {2.0 / r['bulk_modulus']:.6e}")
        out += dens
        if beta is not None and name == "TREAD":
            out += [f"*DAMPING, ALPHA=0.0, BETA={beta:.6e}"]
    for name, c in ad.CARCASS.items():
        out += [f"*MATERIAL, NAME={name}", "*ELASTIC, TYPE=ENGINEERING CONSTANTS"]
        out += [", ".join(f"{v:.6e}" for v in c[:8]), f"{c[8]:.6e}"]
        out += dens
    out += [*cx.ROAD_MATERIAL, *([] if beta is None else ["*DENSITY", "7850."])]
    out += ["*SOLID SECTION, ELSET=ETREAD, MATERIAL=TREAD"]
    out += ["*SOLID SECTION, ELSET=ESIDEWALL, MATERIAL=SIDEWALL", cx.ROAD_SECTION]
    for e in np.flatnonzero(mesh.layer == 1):
        a, b = mesh.meridian[e], mesh.circumferential[e]
        mat = "BELTED" if mesh.region[e] == 0 else "CARCASS"
        out += [f"*ORIENTATION, NAME=OR{e + 1}", ", ".join(f"{v:.8f}" for v in (*a, *b))]
        out += [f"*ELSET, ELSET=EC{e + 1}", str(e + 1)]
        out.append(f"*SOLID SECTION, ELSET=EC{e + 1}, MATERIAL={mat}, ORIENTATION=OR{e + 1}")
    return out


def _amplitudes_and_step(mesh: AircraftMesh, plan: RollPlan, times: dict[str, float], table) -> list[str]:
    t0 = ad.INFLATION_TIME
    t1 = t0 + LOAD_TIME
    t2 = t1 + ROLL_TIME
    out = [
        "*AMPLITUDE, NAME=APRESS",
        f"0.0, 0.0, {t0:.6f}, 1.0, {t2:.6f}, 1.0",
        "*AMPLITUDE, NAME=ALOAD",
        f"0.0, 0.0, {t0:.6f}, 0.0, {t1:.6f}, 1.0, {t2:.6f}, 1.0",
        "*AMPLITUDE, NAME=AROLL",
        f"0.0, 0.0, {t1:.6f}, 0.0, {t2:.6f}, 1.0",
        "*TIME POINTS, NAME=TOUT",
        cx.data_lines(f"{t:.9f}" for t in sorted(times.values())),
        "*BOUNDARY",
        "SYMN, 2, 2",
        "ROADN, 2, 2",
        "REFN, 1, 3",
        "ROTN, 1, 1",
        "ROTN, 3, 3",
        "DRVN, 1, 1",
        "DRVN, 3, 3",
        "*STEP, NLGEOM, INC=5000",
        "*STATIC" if plan.damping_beta is None else "*DYNAMIC",
        f"{min(FIRST_INC, plan.max_inc)}, {t2:.6f}, 1e-8, {plan.max_inc}",
        "*CONTROLS, PARAMETERS=FIELD",
        f"{TOLERANCES[0]}, {TOLERANCES[1]}",
        "*CONTROLS, PARAMETERS=TIME INCREMENTATION",
        "4, 8, 9, 16, 10, 4, 0, 10",
        "*BOUNDARY, AMPLITUDE=ALOAD",
        f"ROADN, 3, 3, {plan.travel_z:.9e}",
        "*BOUNDARY, AMPLITUDE=AROLL",
        f"ROADN, 1, 1, {-plan.travel_x:.9e}",
    ]
    turned = "ROTN" if plan.drive_stiffness is None else "DRVN"
    out += ["*BOUNDARY, AMPLITUDE=AROLL", f"{turned}, 2, 2, {plan.rotation:.9e}"]
    if plan.drive_stiffness is None:
        out += ["*BOUNDARY", "DRVN, 2, 2"]
    out.append("*DLOAD, AMPLITUDE=APRESS")
    out += cx.pressure_load(mesh.hexes, mesh.inner_quads, ad.PRESSURE, table)
    out += [
        "*NODE FILE, NSET=TIREN, TIME POINTS=TOUT",
        "U",
        "*CONTACT FILE, TIME POINTS=TOUT",
        "CDIS, CSTR",
        "*NODE PRINT, NSET=ROADN, TOTALS=ONLY",
        "RF",
        "*NODE PRINT, NSET=ROADREF",
        "U",
        "*NODE PRINT, NSET=ROTN",
        "U, RF",
        "*NODE PRINT, NSET=REFN",
        "RF",
        "*NODE PRINT, NSET=DRVN",
        "U, RF",
        "*END STEP",
    ]
    return out
