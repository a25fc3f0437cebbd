"""Export the rolling runs: the deformed contact surface in the axle-following frame + sidecar.

Points are the reference (undeformed, unrolled) coordinates of the outer
surface (half model mirrored about y = 0), ``displacement`` takes them to the
deformed surface at the end of the roll in the frame that follows the axle:
x relative to the axle's current x (the axle is at x = 0), road plane z = 0.
So the rolled patch sits where the static map's patch sits, and fepost reads
the map as the rolling partner of ``roll_static.vtu`` (the same run at the end
of its vertical travel, before the roll). The tread material has turned by the
rim's rotation: a reference point's displacement is large (up to
2 sin(theta/2) times its distance from the axle), not a small strain.

Files per run: ``roll_<run>.vtu``, ``roll_<run>.dat.txt`` (CalculiX's printed
records of the last increment) and ``roll_<run>.json`` (written last: its
presence with the deck's sha256 marks a finished run).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np

from . import aircraft_deck as ad
from . import aircraft_roll_deck as rdk
from .aircraft_export import mirror_surface, model_description, patch_metrics
from .aircraft_geometry import AircraftMesh
from .aircraft_roll_run import RollResult, RollState
from .export import quad_integral
from .rig_export import write_text

ARRAYS = {
    "CPRESS": "contact pressure from CalculiX (CSTR/CPRESS at the slave nodes), Pa, >= 0",
    "displacement": "m, 3-vector: reference point + displacement = the deformed point at the end of "
    "the roll in the axle-following frame (x relative to the axle's current x, road plane z = 0)",
}
POINTS = (
    "reference (undeformed) coordinates, m, of the full outer surface (half model mirrored about "
    "y = 0); add 'displacement' for the deformed surface. Axle-following frame: x = rolling "
    "direction relative to the axle (axle at x = 0), y = axle direction, road plane z = 0, normal +z"
)
SLIP_DEFINITION = (
    "kappa = R_e * dtheta/dX - 1: dtheta/dX is the rim's turn per axle travel over the second "
    "half of the roll (constant in the imposed-slip runs), R_e the free-rolling run's effective "
    "rolling radius dX/dtheta over the same part (that run's rim is driven through a soft spring, "
    "not torque-free: see its axle_torque_Nm); kappa < 0 braking (-1 = locked wheel), > 0 "
    "driving, 0 = free rolling"
)


def _imposed(plan: rdk.RollPlan) -> str:
    if plan.drive_stiffness is None:
        return "rim turn prescribed (imposed slip)"
    return (
        "free rolling by an elastic drive: a driver turned by "
        f"{math.degrees(plan.rotation):.3f} deg drives the rim through a torsion spring of "
        f"{2 * plan.drive_stiffness:g} N m/rad (full tire), soft against the tire's slip stiffness"
    )


def _write_vtu(path: Path, pts, quads, cp, disp) -> None:
    import meshio

    mesh = meshio.Mesh(
        pts, [("quad", quads.astype(np.int64))], point_data={"CPRESS": cp, "displacement": disp}
    )
    part = path.with_name(path.name + ".part.vtu")
    meshio.write(part, mesh, binary=True, compression="zlib")
    os.replace(part, path)


def projected_integral(
    points: np.ndarray, quads: np.ndarray, values: np.ndarray, weight: np.ndarray | None = None
) -> float:
    """Integral of the bilinear nodal field over the faces projected on the road plane (2x2 Gauss).

    The vertical force of a pressure p acting normal to a deformed face is the
    integral of p over the face's projection on the road; this is the load that
    the road's reaction measures (and the one fepost's N_fe integrates).
    ``weight``: a second nodal field w (e.g. the deformed x); the integral is then of the
    product of the two bilinear fields, p(xi) w(xi), not of the bilinear interpolation of the
    nodal products p w. The integrand (bilinear x bilinear x the projected Jacobian, linear in
    each of xi, eta) is of degree 3 in each: 2x2 Gauss integrates it exactly.
    """
    g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    x, v, total = points[quads], values[quads], 0.0
    w = None if weight is None else weight[quads]
    for a in g:
        for b in g:
            shape = 0.25 * np.array(
                [(1 - a) * (1 - b), (1 + a) * (1 - b), (1 + a) * (1 + b), (1 - a) * (1 + b)]
            )
            ta = np.einsum("k,fkj->fj", 0.25 * np.array([-(1 - b), 1 - b, 1 + b, -(1 + b)]), x)
            tb = np.einsum("k,fkj->fj", 0.25 * np.array([-(1 - a), -(1 + a), 1 + a, 1 - a]), x)
            jac = np.abs(ta[:, 0] * tb[:, 1] - ta[:, 1] * tb[:, 0])
            field = v @ shape if w is None else (v @ shape) * (w @ shape)
            total += float(np.sum(jac * field))
    return total


def centre_of_pressure(mesh: AircraftMesh, state: RollState) -> tuple[float, float]:
    """(N, x): the vertical load of the CPRESS field and its centre's x (m, axle frame)."""
    pts, quads, cp, disp = mirror_surface(mesh, state)
    deformed = pts + disp
    n = projected_integral(deformed, quads, cp)
    return n, projected_integral(deformed, quads, cp, deformed[:, 0]) / n


def steady_turn_rate(result: RollResult) -> float:
    """dtheta/dX (rad/m) over the second half of the roll: a least-squares line."""
    h = result.history
    t1 = ad.INFLATION_TIME + rdk.LOAD_TIME
    keep = h.time >= t1 + 0.5 * rdk.ROLL_TIME - 1e-9
    if keep.sum() < 2:
        raise ValueError(f"{result.name}: fewer than 2 increments in the second half of the roll")
    return float(np.polyfit(h.axle_travel[keep], h.rotation[keep], 1)[0])


def patch_nodes(mesh: AircraftMesh, state: RollState) -> dict:
    """Loaded nodes of the full surface and along the centre line y = 0."""
    pts, _, cp, _ = mirror_surface(mesh, state)
    loaded = cp > 0
    return {
        "loaded": int(loaded.sum()),
        "along_centre_line": int((loaded & (np.abs(pts[:, 1]) < 1e-9)).sum()),
    }


def write_map(mesh: AircraftMesh, state: RollState, out: Path, name: str) -> dict:
    """The surface file of one state; returns its figures (CPRESS integral, patch)."""
    pts, quads, cp, disp = mirror_surface(mesh, state)
    out.mkdir(parents=True, exist_ok=True)
    _write_vtu(out / f"{name}.vtu", pts, quads, cp, disp)
    deformed = pts + disp
    return {
        "cpress_integral": quad_integral(deformed, quads, cp),
        "cpress_integral_projected": projected_integral(deformed, quads, cp),
        "patch": patch_metrics(deformed, quads, cp),
        "surface_points": int(pts.shape[0]),
        "surface_faces": int(quads.shape[0]),
    }


def common_keys(mesh: AircraftMesh, result: RollResult, state: RollState, figures: dict) -> dict:
    p = mesh.params
    return {
        "reaction_z": float(state.road_force[2]),
        "reaction_z_source": "CalculiX total reaction (RF) on the road block's nodes, times 2 (half model)",
        "load": float(state.road_force[2]),
        "rated_load": ad.RATED_LOAD,
        "load_fraction": float(state.road_force[2]) / ad.RATED_LOAD,
        "cpress_integral": figures["cpress_integral"],
        "cpress_integral_projected": figures["cpress_integral_projected"],
        "cpress_integral_note": "exact integral of the bilinear CPRESS field over the deformed faces "
        "(cpress_integral_projected: over their projection on the road, the vertical load)",
        "inflation_pressure": ad.PRESSURE,
        "rim_travel_z": float(state.road_z),
        "friction": ad.FRICTION,
        "patch": {**figures["patch"], "nodes": patch_nodes(mesh, state)},
        "arrays": ARRAYS,
        "points": POINTS,
        "cells": "quadrilateral faces of the tire's whole outer surface",
        "solver": result.solver,
        "runtime_s": round(result.runtime_s, 1),
        "runtime_s_note": "wall time of the CalculiX run (inflation, vertical travel, roll), one "
        "thread, on a shared 2-core machine",
        "deck_sha256": result.deck_sha256,
        "mesh": {
            "model_nodes": int(mesh.nodes.shape[0]),
            "model_elements": int(mesh.hexes.shape[0]),
            "symmetry": "half model y >= 0, symmetry plane y = 0; exported mirrored",
            "circumferential_layer_deg": p.first_deg,
            "fine_arc_deg": mesh.info.get("fine_arc_deg"),
            "fine_arc_note": "uniform layers (and contact slave nodes) over this arc of the "
            "reference tire, from the bottom towards +x: all material that passes through the "
            "patch during the roll",
            "section_elements_half": [p.n_crown, p.n_shoulder, p.n_side],
            "surface_points": figures["surface_points"],
            "surface_faces": figures["surface_faces"],
            "road_elements": result.deck_info["road_elements"],
        },
        "model": {
            **model_description(mesh),
            "rim": "rigid body on the bead nodes (*RIGID BODY, reference node on the axle); its "
            "turn about the axle is prescribed (imposed slip) or driven through a soft torsion spring "
            "(the free-rolling run)",
        },
        "units": "SI (m, Pa, N, N m, rad)",
    }


def write_static(mesh: AircraftMesh, result: RollResult, out: Path, name: str) -> dict:
    """The loaded, not yet rolled state of a run: the static partner of the rolled maps."""
    state = result.state("static")
    figures = write_map(mesh, state, out, name)
    side = {
        "case": name,
        "kind": "static map",
        "description": "the rolling runs' tire at the end of its vertical travel, before rolling "
        f"(run '{result.name}' at analysis time {state.time:g}): the static partner of roll_*.vtu",
        **common_keys(mesh, result, state, figures),
    }
    write_text(out / f"{name}.json", json.dumps(side, indent=2) + "\n")
    return side


def write_rolling(
    mesh: AircraftMesh, result: RollResult, out: Path, name: str, effective_radius: float, description: str
) -> dict:
    """``<name>.vtu``, ``<name>.dat.txt``, then ``<name>.json`` of the end of the roll."""
    state = result.states[-1]
    static = result.state("static")
    figures = write_map(mesh, state, out, name)
    write_text(out / f"{name}.dat.txt", result.last_increment)
    rate = steady_turn_rate(result)
    n0, x0 = centre_of_pressure(mesh, static)
    samples = []
    for s in result.states:
        if not s.name.startswith("roll"):
            continue
        n, x = centre_of_pressure(mesh, s)
        samples.append(
            {
                "axle_travel_m": s.axle_travel,
                "rim_rotation_deg": math.degrees(s.rotation),
                "Fx": float(s.road_force[0]),
                "Fz": float(s.road_force[2]),
                "axle_torque_Nm": s.axle_torque,
                "cpress_integral": n,
                "centre_of_pressure_shift_m": x - x0,
            }
        )
    h = result.history
    side = {
        "case": name,
        "kind": "rolling run",
        "description": description,
        "rim_rotation_deg": math.degrees(state.rotation),
        "axle_travel_m": state.axle_travel,
        "longitudinal_slip": effective_radius * rate - 1.0,
        "longitudinal_slip_definition": SLIP_DEFINITION,
        "effective_rolling_radius_m": effective_radius,
        "turn_per_travel_rad_per_m": rate,
        "imposed": _imposed(result.plan),
        "axle_torque_Nm": state.axle_torque,
        "axle_torque_note": "torque on the rim about +y (the rolling turn's sense) at the end of "
        "the roll, full tire: the reaction moment of the imposed turn (rotation node), or in the "
        "elastic drive the torsion spring's torque (driver node's reaction)",
        "friction": ad.FRICTION,
        "reaction": {
            "force": [float(v) for v in state.road_force],
            "frame": "the tire's: x rolling direction, y axle, z road normal (the road does not turn)",
            "sign": "force of the road on the tire: Fx < 0 braking, > 0 driving",
            "source": f"CalculiX total RF on the road block's nodes at analysis time {state.time:g} "
            f"(times 2, half model); {name}.dat.txt holds the printed records",
        },
        "longitudinal_force_ratio": float(state.road_force[0] / state.road_force[2]),
        "static_centre_of_pressure_x_m": x0,
        "static_cpress_integral": n0,
        "samples": samples,
        "samples_note": "the written times along the roll: centre-of-pressure shift = x of the "
        "CPRESS centre on the deformed faces projected on the road, minus the static one's (an "
        "exact face integral of its own, beside fepost's x_c from its polar resampling); steady "
        "when it stops changing",
        "history": {
            "axle_travel_m": h.axle_travel.tolist(),
            "rim_rotation_rad": h.rotation.tolist(),
            "Fx": h.fx.tolist(),
            "Fz": h.fz.tolist(),
            "axle_torque_Nm": h.torque.tolist(),
        },
        "history_note": "every written time (CalculiX prints the .dat at the deck's TIME POINTS only): "
        "inflation, end of the vertical travel, then the samples along the roll; full tire",
        **common_keys(mesh, result, state, figures),
    }
    write_text(out / f"{name}.json", json.dumps(side, indent=2) + "\n")
    return side
