"""Export a solved case: outer tire surface as VTU + Exodus II, plus a JSON sidecar."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from fepost.synthetic import write_exodus

from . import deck as dk
from .solve import CaseResult

ARRAYS = {
    "CPRESS": "contact pressure from CalculiX (CSTR/CPRESS at the slave nodes), Pa, >= 0; "
    "0 where the node is not in contact",
    "displacement": "nodal displacement of the final state (CalculiX U), m, 3-vector; "
    "the points are the reference (undeformed) positions, deformed = points + displacement",
}


def surface_arrays(res: CaseResult):
    """Compact the tire's outer surface: (reference points, quads, CPRESS, displacement)."""
    m = res.mesh
    quads = m.outer_quads
    used = np.unique(quads)
    remap = -np.ones(m.nodes.shape[0], dtype=np.int64)
    remap[used] = np.arange(used.size)
    return m.nodes[used], remap[quads], res.cpress[used], res.displacement[used]


def quad_integral(points: np.ndarray, quads: np.ndarray, values: np.ndarray) -> float:
    """Exact integral of the bilinear nodal field over bilinear quads (2x2 Gauss)."""
    g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    total = 0.0
    x = points[quads]  # (f, 4, 3)
    v = values[quads]
    for a in g:
        for b in g:
            nshape = 0.25 * np.array(
                [(1 - a) * (1 - b), (1 + a) * (1 - b), (1 + a) * (1 + b), (1 - a) * (1 + b)]
            )
            da = 0.25 * np.array([-(1 - b), (1 - b), (1 + b), -(1 + b)])
            db = 0.25 * np.array([-(1 - a), -(1 + a), (1 + a), (1 - a)])
            ta = np.einsum("k,fkj->fj", da, x)
            tb = np.einsum("k,fkj->fj", db, x)
            jac = np.linalg.norm(np.cross(ta, tb), axis=1)
            total += float(np.sum(jac * (v @ nshape)))
    return total


def write_surface(out_dir: Path, name: str, pts, quads, cp, disp) -> None:
    """Write <name>.vtu and <name>.e (reference coordinates + nodal arrays)."""
    import meshio

    out_dir.mkdir(parents=True, exist_ok=True)
    cells = [("quad", quads.astype(np.int64))]
    mesh = meshio.Mesh(pts, cells, point_data={"CPRESS": cp, "displacement": disp})
    meshio.write(out_dir / f"{name}.vtu", mesh, binary=True, compression="zlib")
    # Exodus II through fepost's writer (pyexodus): the displacement vector is stored as
    # displacementX/Y/Z, which VTK's Exodus reader joins back into one 3-vector
    write_exodus(
        out_dir / f"{name}.e",
        pts,
        quads,
        [{"CPRESS": cp, "displacement": disp}],
        title=f"fepost tire sample {name}",
    )


def write_case(res: CaseResult, out_dir: Path) -> dict:
    name = res.case.name
    pts, quads, cp, disp = surface_arrays(res)
    write_surface(out_dir, name, pts, quads, cp, disp)
    n_int = quad_integral(pts + disp, quads, cp)
    loaded = cp > 0
    p = res.mesh.params
    side = {
        "case": name,
        "description": res.case.description,
        "reaction_z": float(res.road_force[2]),
        "reaction_z_source": "CalculiX total reaction force (RF) on the fixed road nodes, final increment",
        "reaction_force_road": [float(v) for v in res.road_force],
        "reaction_force_rim": [float(v) for v in res.bead_force],
        "cpress_integral": n_int,
        "cpress_integral_note": "exact integral of the bilinear CPRESS field over the deformed faces",
        "inflation_pressure": dk.PRESSURE,
        "deflection": res.case.deflection,
        "deflection_definition": "vertical rim travel after the inflated crown first touches the road",
        "rim_travel_z": res.rim_travel,
        "inflated_clearance": res.inflated_clearance,
        "friction": dk.FRICTION,
        "arrays": ARRAYS,
        "points": "reference (undeformed) coordinates, m, as solvers write them; add "
        "'displacement' for the deformed surface. Road plane z = 0, road normal +z, "
        "x = rolling direction, y = axle direction; axle at x = 0 before the rolling step",
        "cells": "quadrilateral faces of the tire's outer surface (the whole modelled sector)",
        "solver": res.solver,
        "runtime_s": round(res.runtime_s, 1),
        "runtime_s_note": "wall time of the CalculiX runs (inflation pre-run + load case)",
        "mesh": {
            "tire_nodes": int(res.mesh.nodes.shape[0]),
            "tire_elements": int(res.mesh.hexes.shape[0]),
            "element_type": "C3D8I",
            "surface_points": int(pts.shape[0]),
            "surface_faces": int(quads.shape[0]),
            "loaded_points": int(loaded.sum()),
            "road_elements": res.deck_info.get("road_elements"),
        },
        "model": {
            "outer_diameter": 2 * p.outer_radius,
            "section_width": p.section_width(),
            "bead_diameter": 2 * p.bead_radius(),
            "wall_thickness": p.wall,
            "sector_half_angle_deg": p.sector_deg,
            "refined_half_angle_deg": p.fine_deg,
            "youngs_modulus": dk.E_RUBBER,
            "poisson_ratio": dk.NU_RUBBER,
            "contact": f"CalculiX {dk.CONTACT_TYPE.lower()} penalty contact (slave: tire tread and "
            "shoulder nodes, master: road top face), linear pressure-overclosure "
            f"{dk.CONTACT_SLOPE:.3g} Pa/m, Coulomb friction {dk.FRICTION} "
            f"(stick slope {dk.STICK_SLOPE:.3g} Pa/m)",
            "nlgeom": True,
        },
        "units": "SI (m, Pa, N)",
    }
    if res.case.roll_dx:
        side["rolling_standin"] = {
            "imposed_rim_displacement": [res.case.roll_dx, 0.0, 0.0],
            "direction": "+x",
            "note": "quasi-static stand-in for rolling: after the static step the rim is "
            "translated along +x with friction active; no wheel rotation, inertia or "
            "rubber hysteresis is modelled. The road's friction force on the tire is along -x "
            "and the centre of pressure moves towards +x (as for a rolling tire's forward "
            "pressure shift).",
            "friction_force_on_road_x": float(res.road_force[0]),
        }
    with open(out_dir / f"{name}.json", "w") as fh:
        json.dump(side, fh, indent=2)
        fh.write("\n")
    return side
