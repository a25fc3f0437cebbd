"""Export the aircraft-tire cases: full outer surface (mirrored half model) + sidecar.

The solver works on the half y >= 0 (symmetry plane y = 0). The export mirrors
the outer surface to the full tire: points with y > 0 get a mirror image
(x, -y, z) carrying the mirrored displacement (u_x, -u_y, u_z) and the same
contact pressure; faces are mirrored with reversed node order so normals stay
outward. Forces of the full tire are twice the half model's (z, x); the
lateral resultant is zero by symmetry.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import aircraft_deck as ad
from .aircraft_geometry import AircraftMesh
from .aircraft_solve import RunResult, StepState
from .export import quad_integral, write_surface

ARRAYS = {
    "CPRESS": "contact pressure from CalculiX (CSTR/CPRESS at the slave nodes), Pa, >= 0; "
    "0 where the node is not in contact",
    "displacement": "nodal displacement of the final state (CalculiX U), m, 3-vector; "
    "the points are the reference (undeformed) positions, deformed = points + displacement",
}


def mirror_surface(mesh: AircraftMesh, state: StepState):
    """(reference points, quads, CPRESS, displacement) of the full outer surface."""
    quads = mesh.outer_quads
    used = np.unique(quads)
    pts = mesh.nodes[used]
    u = state.displacement[used]
    cp = state.cpress[used]
    n = used.size
    remap = -np.ones(mesh.nodes.shape[0], dtype=np.int64)
    remap[used] = np.arange(n)
    half = remap[quads]
    on_plane = np.abs(pts[:, 1]) < 1e-9
    mirror_index = np.arange(n)
    off = np.flatnonzero(~on_plane)
    mirror_index[off] = n + np.arange(off.size)
    flip = np.array([1.0, -1.0, 1.0])
    all_pts = np.vstack([pts, pts[off] * flip])
    all_u = np.vstack([u, u[off] * flip])
    all_cp = np.concatenate([cp, cp[off]])
    mirrored = mirror_index[half][:, ::-1]
    return all_pts, np.vstack([half, mirrored]), all_cp, all_u


def patch_metrics(points: np.ndarray, quads: np.ndarray, cp: np.ndarray) -> dict:
    """Patch size from the deformed surface: extents, area, mean and peak pressure.

    Length/width are the extents along x/y of the loaded nodes (CPRESS > 0);
    the area counts each face in proportion to its loaded corner nodes
    (projected on the road plane); mean pressure = integral of CPRESS / area.
    """
    loaded = cp > 0
    if not loaded.any():
        return {}
    x = points[quads]
    d1, d2 = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
    area_z = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    frac = loaded[quads].mean(axis=1)
    area = float(np.sum(area_z * frac))
    lp = points[loaded]
    length = float(lp[:, 0].max() - lp[:, 0].min())
    width = float(lp[:, 1].max() - lp[:, 1].min())
    centre_line = loaded & (np.abs(points[:, 1]) < 1e-6)
    force = quad_integral(points, quads, cp)
    return {
        "length": length,
        "width": width,
        "aspect": length / width,
        "area": area,
        "mean_pressure": force / area,
        "peak_pressure": float(cp.max()),
        "loaded_nodes": int(loaded.sum()),
        "loaded_nodes_along_length": int(centre_line.sum()),
        "definition": "length/width: extents along x/y of the loaded nodes of the deformed "
        "surface; area: projected area of the faces weighted by their share of loaded corner "
        "nodes; mean_pressure: CPRESS integral / area",
    }


def write_aircraft_case(
    mesh: AircraftMesh,
    run: RunResult,
    step_name: str,
    case: str,
    out_dir: Path,
    description: str,
    clearance: float,
    target_fraction: float,
) -> dict:
    """Write <case>.vtu, <case>.e and <case>.json for one step of one run."""
    state = run.step(step_name)
    pts, quads, cp, disp = mirror_surface(mesh, state)
    write_surface(out_dir, case, pts, quads, cp, disp)
    deformed = pts + disp
    n_int = quad_integral(deformed, quads, cp)
    road = 2.0 * state.road_force
    road[1] = 0.0
    travel_z = float(-state.rim_displacement[2])
    p = mesh.params
    side = {
        "case": case,
        "description": description,
        "reaction_z": float(road[2]),
        "reaction_z_source": "CalculiX total reaction force (RF) on the fixed road nodes, final "
        "increment of the step, times 2 (half model)",
        "reaction_force_road": [float(v) for v in road],
        "cpress_integral": n_int,
        "cpress_integral_note": "exact integral of the bilinear CPRESS field over the deformed faces "
        "of the mirrored full surface",
        "load": float(road[2]),
        "load_note": "vertical tire load = reaction_z (N); the case aimed at load_target",
        "load_target": target_fraction * ad.RATED_LOAD,
        "rated_load": ad.RATED_LOAD,
        "load_fraction": float(road[2]) / ad.RATED_LOAD,
        "inflation_pressure": ad.PRESSURE,
        "deflection": travel_z - clearance,
        "deflection_definition": "vertical rim travel after the inflated tread first touches the road",
        "deflection_fraction_of_section_height": (travel_z - clearance) / (p.outer_radius - p.bead()[1]),
        "rim_travel_z": travel_z,
        "inflated_clearance": clearance,
        "friction": ad.FRICTION,
        "patch": patch_metrics(deformed, quads, cp),
        "arrays": ARRAYS,
        "points": "reference (undeformed) coordinates, m, as solvers write them; add "
        "'displacement' for the deformed surface. Road plane z = 0, road normal +z, "
        "x = rolling direction, y = axle direction; axle at x = 0 before the rolling step",
        "cells": "quadrilateral faces of the tire's whole outer surface (half model mirrored about y = 0)",
        "solver": run.solver,
        "runtime_s": round(run.runtime_s, 1),
        "runtime_s_note": f"wall time of the CalculiX run '{run.name}' that produced this case "
        f"(steps: {', '.join(run.deck.step_names)}), one thread, nice 10, on a shared 2-core machine",
        "mesh": {
            "model_nodes": int(mesh.nodes.shape[0]),
            "model_elements": int(mesh.hexes.shape[0]),
            "element_type": "C3D8I",
            "symmetry": "half model y >= 0, symmetry plane y = 0 (u_y = 0); exported mirrored",
            "surface_points": int(pts.shape[0]),
            "surface_faces": int(quads.shape[0]),
            "first_circumferential_layer_deg": p.first_deg,
            "road_elements": run.deck.road_elements,
        },
        "model": model_description(mesh),
        "units": "SI (m, Pa, N)",
    }
    if abs(float(state.rim_displacement[0])) > 0:
        side["rolling_standin"] = {
            "imposed_rim_displacement": [float(state.rim_displacement[0]), 0.0, 0.0],
            "direction": "+x",
            "note": "quasi-static stand-in for rolling: after the vertical step the rim is "
            "translated along +x with friction active; no wheel rotation, inertia or rubber "
            "hysteresis is modelled. The road's friction force on the tire is along -x.",
            "friction_force_on_road_x": float(road[0]),
        }
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / f"{case}.json", "w") as fh:
        json.dump(side, fh, indent=2)
        fh.write("\n")
    return side


def model_description(mesh: AircraftMesh) -> dict:
    p = mesh.params
    return {
        "tire": "radial aircraft main-gear tire of the 46x17R20 size class (generic, not a product)",
        "outer_diameter": 2 * p.outer_radius,
        "section_width": p.section_width(),
        "section_height": p.outer_radius - p.bead()[1],
        "bead_diameter": 2 * p.bead()[1],
        "wall_thickness_crown": p.total_thickness[0][0],
        "wall_thickness_sidewall": p.total_thickness[2][0],
        "tread_thickness": p.rubber_thickness[0][0],
        "rubber": {k: {"model": "Neo-Hooke", **v} for k, v in ad.RUBBER.items()},
        "carcass": {
            k: dict(
                zip(
                    (
                        "E1_meridional",
                        "E2_circumferential",
                        "E3_normal",
                        "nu12",
                        "nu13",
                        "nu23",
                        "G12",
                        "G13",
                        "G23",
                    ),
                    v,
                    strict=True,
                )
            )
            for k, v in ad.CARCASS.items()
        },
        "carcass_note": "BELTED under the crown (radial carcass + belts), CARCASS in shoulder and "
        "sidewall; *ELASTIC, TYPE=ENGINEERING CONSTANTS in per-element *ORIENTATION frames",
        "rim": "rigid body on the bead nodes (*RIGID BODY), rotation held",
        "contact": "CalculiX node-to-surface penalty contact (slave: tread and shoulder nodes "
        f"{_slave_arc(mesh)}, master: road top face), linear "
        f"pressure-overclosure {ad.CONTACT_SLOPE:.3g} Pa/m, Coulomb friction {ad.FRICTION} "
        f"(stick slope {ad.STICK_SLOPE:.3g} Pa/m)",
        "nlgeom": True,
    }


def _slave_arc(mesh) -> str:
    """Where the contact slave nodes are: the fine arc, symmetric about the bottom or not (the
    rolling mesh's arc is turned towards +x: ``info["fine_arc_deg"]``)."""
    arc = getattr(mesh, "info", {}).get("fine_arc_deg")
    if arc is not None:
        return f"from {arc[0]:g} to {arc[1]:g} deg from the bottom (towards +x)"
    return f"within +-{mesh.params.fine_deg:g} deg of the bottom"
