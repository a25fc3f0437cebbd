"""Export a solved rig run: contact surface (VTU), sidecar (JSON), the solver's printed totals.

Everything written here is a deterministic function of the solver's files:
numbers are rounded to fixed digits in the JSON, the VTU is written by meshio
with zlib (no time stamps), so exporting the same work folder twice gives
byte-identical files (a fresh solve reproduces them as long as CalculiX does;
only ``runtime_s`` changes then).

Frames and signs (checked in the first runs and by ``fepost rig``'s tests):
- CalculiX's reaction at the rigid road's reference node is the force the
  support exerts on the road, which balances the tire's push, so it equals the
  force of the road on the tire; the rotation node's reaction is the moment of
  the road on the tire about the reference node's current position.
- CSHEAR1, CSHEAR2 of node-to-surface contact are the shear stresses along the
  global x and y (the road is the plane z = 0) exerted on the road, i.e. the
  negative of the road's traction on the tire; the export stores the traction
  on the tire, ``shear`` = -(CSHEAR1, CSHEAR2, 0).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from . import deck as dk
from . import rig_deck as rd
from .export import quad_integral
from .geometry import TireMesh
from .rig_run import RunResult

ARRAYS = {
    "CPRESS": "contact pressure at the end of the slide (CalculiX CPRESS), Pa, >= 0",
    "shear": "shear traction of the road on the tire at the end of the slide, Pa, "
    "(tau_x, tau_y, 0) = -(CSHEAR1, CSHEAR2, 0) of CalculiX (which are on the road)",
    "slip": "accumulated tangential slip (CSLIP1, CSLIP2, 0) as CalculiX writes it, m",
    "displacement": "nodal displacement at the end of the slide (CalculiX U), m; "
    "deformed = points + displacement",
}
STATIC_ARRAYS = {
    "CPRESS": "contact pressure after the vertical load, before the slide (CalculiX CPRESS), Pa",
    "displacement": "nodal displacement after the vertical load (CalculiX U), m",
}


def _num(x: float, digits: int = 7) -> float:
    """A float rounded to ``digits`` significant digits (stable JSON text)."""
    x = float(x)
    return 0.0 if x == 0.0 else float(f"{x:.{digits}g}")


def _vec(a, digits: int = 7) -> list[float]:
    return [_num(v, digits) for v in np.asarray(a, dtype=float).ravel()]


def contact_surface(mesh: TireMesh):
    """(reference points, quads, used node indices) of the contact faces, compacted."""
    quads = mesh.contact_quads
    used = np.unique(quads)
    remap = -np.ones(mesh.nodes.shape[0], dtype=np.int64)
    remap[used] = np.arange(used.size)
    return mesh.nodes[used], remap[quads], used


def _write_vtu(path: Path, pts, quads, arrays: dict) -> None:
    import meshio

    tmp = path.with_name(path.name + ".part.vtu")
    mesh = meshio.Mesh(pts, [("quad", quads.astype(np.int64))], point_data=arrays)
    meshio.write(tmp, mesh, binary=True, compression="zlib")
    os.replace(tmp, path)


def _write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(text)
    os.replace(tmp, path)


def moment_about_origin(res: RunResult, origin=(0.0, 0.0)) -> np.ndarray:
    """Mz of the road on the tire about ``origin`` per increment (N m), from the printed reactions."""
    h = res.history
    ref = np.asarray(res.nodes.ref_xy) + h.ref_u[:, :2]
    d = ref - np.asarray(origin)
    return h.rot_rf[:, 2] + d[:, 0] * h.ref_rf[:, 1] - d[:, 1] * h.ref_rf[:, 0]


def shear_resultants(mesh: TireMesh, res: RunResult, origin=(0.0, 0.0)) -> dict:
    """Integrals of the exported shear traction and pressure over the deformed contact faces."""
    pts, quads, used = contact_surface(mesh)
    x = pts + res.u[used]
    tx = -res.contact["CSHEAR1"][used]
    ty = -res.contact["CSHEAR2"][used]
    cp = np.clip(res.contact["CPRESS"][used], 0.0, None)
    dx, dy = x[:, 0] - origin[0], x[:, 1] - origin[1]
    return {
        "Fx": quad_integral(x, quads, tx),
        "Fy": quad_integral(x, quads, ty),
        "Mz": quad_integral(x, quads, dx * ty - dy * tx),
        "N": quad_integral(x, quads, cp),
    }


def write_static(mesh: TireMesh, res: RunResult, out: Path, info: dict) -> dict:
    """The static map of the rig's mesh (end of the vertical step) as ``static.vtu`` + sidecar."""
    pts, quads, used = contact_surface(mesh)
    cp = res.static_cpress[used]
    u = res.static_u[used]
    out.mkdir(parents=True, exist_ok=True)
    _write_vtu(out / "static.vtu", pts, quads, {"CPRESS": cp, "displacement": u})
    x = pts + u
    n = quad_integral(x, quads, cp)
    side = {
        "case": "static",
        "description": "the rig's static map: inflation, then 29 mm deflection; the simulation "
        "that the slide/spin runs are compared with",
        "reaction_z": _num(res.static_load[2]),
        "reaction_z_source": "CalculiX reaction at the rigid road's reference node, end of the vertical step",
        "cpress_integral": _num(n),
        "centre_of_pressure": _vec(
            [quad_integral(x, quads, cp * x[:, 0]) / n, quad_integral(x, quads, cp * x[:, 1]) / n], 4
        ),
        "friction": dk.FRICTION,
        "arrays": STATIC_ARRAYS,
        "points": "reference (undeformed) coordinates of the contact faces (crown and shoulder "
        "within the refined sector), m; road plane z = 0, x rolling direction, y axle",
        **info,
    }
    _write_text(out / "static.json", json.dumps(side, indent=2) + "\n")
    return side


def _history_block(res: RunResult, origin) -> dict:
    h = res.history
    path = np.hypot(h.ref_u[:, 0], h.ref_u[:, 1])  # the reference node's travel (pure sliding)
    kin = res.kin
    # reference sliding path of the run at each increment: |v| t and |wz| R_REF t in quadrature
    ref_path = np.hypot(kin.vx, kin.vy) ** 2 + (kin.wz * rd.R_REF) ** 2
    return {
        "time": _vec(h.time, 6),
        "path": _vec(np.sqrt(ref_path) * h.time, 6),
        "Fx": _vec(h.ref_rf[:, 0]),
        "Fy": _vec(h.ref_rf[:, 1]),
        "Fz": _vec(h.ref_rf[:, 2]),
        "Mz": _vec(moment_about_origin(res, origin)),
        "road_rotation": _vec(h.rot_u[:, 2]),
        "ref_travel": _vec(path, 6),
        "note": "per increment of the slide step: time = pseudo-time t in [0, 1]; path = "
        "sqrt(|v|^2 + (wz R_ref)^2) t (m, R_ref = rig reference radius); F: road's force on "
        "the tire (N); Mz: about the static patch origin (N m); road_rotation: rad",
    }


def write_run(mesh: TireMesh, res: RunResult, out: Path, info: dict, origin=(0.0, 0.0)) -> dict:
    """Write ``<run>.vtu``, ``<run>.dat.txt`` and ``<run>.json`` into ``out``; return the sidecar."""
    pts, quads, used = contact_surface(mesh)
    c = res.contact
    zero = np.zeros(used.size)
    arrays = {
        "CPRESS": np.clip(c["CPRESS"][used], 0.0, None),
        "shear": np.column_stack([-c["CSHEAR1"][used], -c["CSHEAR2"][used], zero]),
        "slip": np.column_stack([c["CSLIP1"][used], c["CSLIP2"][used], zero]),
        "displacement": res.u[used],
    }
    out.mkdir(parents=True, exist_ok=True)
    _write_vtu(out / f"{res.name}.vtu", pts, quads, arrays)
    _write_text(out / f"{res.name}.dat.txt", res.dat_excerpt)
    h = res.history
    f = h.ref_rf[-1]
    shear = shear_resultants(mesh, res, origin)
    k = res.kin
    side = {
        "case": res.name,
        "kind": "slide/spin rig run",
        "kinematics": {"vx": _num(k.vx, 12), "vy": _num(k.vy, 12), "wz": _num(k.wz, 12)},
        "kinematics_units": "m and rad per unit pseudo-time (quasi-static: only the direction "
        "of (vx, vy) and the ratio wz R / |v| matter)",
        "kinematics_definition": "sliding velocity (vx, vy) of the static patch origin relative to "
        "the road and spin wz of the tire relative to the road about +z (THEORY section 3); "
        "the rim is held, the road moves rigidly with the opposite velocity field",
        "origin": [_num(origin[0]), _num(origin[1]), 0.0],
        "origin_definition": "static patch origin (centre of pressure of the static map), m",
        "reaction": {
            "ref_node": res.nodes.ref,
            "rot_node": res.nodes.rot,
            "ref_position": [_num(res.nodes.ref_xy[0], 10), _num(res.nodes.ref_xy[1], 10), 0.0],
            "ref_displacement": _vec(h.ref_u[-1], 10),
            "force": _vec(f),
            "moment": _vec(h.rot_rf[-1]),
            "rim_force": _vec(h.bead_rf[-1]),
            "time": _num(h.time[-1] + 2.0, 7),
            "source": f"CalculiX .dat, last increment of the slide step ({res.name}.dat.txt): RF of "
            "the rigid road's reference node (force) and rotation node (moment)",
            "sign": "RF at the road's nodes = force (moment) of the road on the tire; the moment is "
            "about the reference node's current position (ref_position + ref_displacement)",
        },
        "static_load": _vec(res.static_load),
        "shear_integral": {key: _num(v) for key, v in shear.items()},
        "shear_integral_note": "exact integrals of the exported bilinear shear traction (and CPRESS) "
        "over the deformed contact faces: Fx, Fy (N), Mz about the origin (N m), N (N)",
        "history": _history_block(res, origin),
        "friction": dk.FRICTION,
        "units": "SI (m, N, Pa)",
        "arrays": ARRAYS,
        "deck_sha256": res.deck_sha256,
        "runtime_s": round(res.runtime_s, 1),
        "runtime_s_note": "wall time of this run's CalculiX solve (inflation, load, slide; one "
        "thread, nice 10, on a shared 2-core machine); the inflation pre-run is shared",
        **info,
    }
    _write_text(out / f"{res.name}.json", json.dumps(side, indent=2) + "\n")
    return side
