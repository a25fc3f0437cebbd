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
import math
import os
from pathlib import Path

import numpy as np

from . import rig_deck as rd
from .export import quad_integral
from .geometry import TireMesh
from .rig_run import RunResult

ARRAYS = {
    "CPRESS": "contact pressure at the end of the slide (CalculiX CPRESS), Pa, >= 0",
    "shear": "shear traction of the road on the tire at the end of the slide, Pa, in the tire's "
    "frame: (tau_x, tau_y, 0) = -Rot(-wz t)(CSHEAR1, CSHEAR2) of CalculiX (which act on the road)",
    "slip": "accumulated tangential slip (CSLIP1, CSLIP2, 0) as CalculiX writes it, m (road's frame)",
    "displacement": "nodal displacement at the end of the slide without the rim's rigid motion, "
    "tire's frame, m; deformed = points + displacement (CalculiX U, moved back by the rim's motion)",
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


def write_text(path: Path, text: str) -> None:
    """``text`` into ``path`` atomically: a part file beside it, then a rename."""
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(text)
    os.replace(tmp, path)


def tire_frame(res: RunResult, t: float, origin=(0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """(rotation Rot(-wz t) from the road's frame to the tire's, moved position of the origin) at ``t``."""
    th, a = rd.tire_motion(res.kin, origin, float(t))
    c, s = math.cos(th), math.sin(th)
    return np.array([[c, s], [-s, c]]), a @ np.array([origin[0], origin[1], 1.0])


def resultants(res: RunResult, origin=(0.0, 0.0)) -> np.ndarray:
    """(k, 3): Fx, Fy of the road on the tire in the tire's frame (N) and Mz about the moved origin (N m)."""
    h = res.history
    out = np.zeros((h.time.size, 3))
    for i, t in enumerate(h.time):
        rot, c_t = tire_frame(res, t, origin)
        f = h.ref_rf[i, :2]
        ref = np.asarray(res.nodes.ref_xy) + h.ref_u[i, :2]
        d = ref - c_t
        out[i, :2] = rot @ f
        out[i, 2] = h.rot_rf[i, 2] + d[0] * f[1] - d[1] * f[0]
    return out


def tire_fields(mesh: TireMesh, res: RunResult, origin=(0.0, 0.0)):
    """Contact-surface fields at the end of the slide in the tire's frame.

    Returns (points, quads, displacement without the rim's rigid motion, shear
    traction of the road on the tire, CPRESS, slip as CalculiX writes it).
    """
    pts, quads, used = contact_surface(mesh)
    rot, _ = tire_frame(res, res.history.time[-1], origin)
    _, a = rd.tire_motion(res.kin, origin, float(res.history.time[-1]))
    y = pts + res.u[used]  # deformed, road's frame
    # back to the tire's frame: invert x -> R x + b
    back = (y[:, :2] - a[:, 2]) @ rot.T
    disp = np.column_stack([back - pts[:, :2], res.u[used, 2]])
    c = res.contact
    tau = np.column_stack([-c["CSHEAR1"][used], -c["CSHEAR2"][used]]) @ rot.T
    zero = np.zeros(used.size)
    return (
        pts,
        quads,
        disp,
        np.column_stack([tau, zero]),
        np.clip(c["CPRESS"][used], 0.0, None),
        np.column_stack([c["CSLIP1"][used], c["CSLIP2"][used], zero]),
    )


def shear_resultants(mesh: TireMesh, res: RunResult, origin=(0.0, 0.0)) -> dict:
    """Integrals of the shear traction and pressure over the deformed contact faces, tire's frame."""
    pts, quads, disp, tau, cp, _ = tire_fields(mesh, res, origin)
    x = pts + disp
    dx, dy = x[:, 0] - origin[0], x[:, 1] - origin[1]
    return {
        "Fx": quad_integral(x, quads, tau[:, 0]),
        "Fy": quad_integral(x, quads, tau[:, 1]),
        "Mz": quad_integral(x, quads, dx * tau[:, 1] - dy * tau[:, 0]),
        "N": quad_integral(x, quads, cp),
    }


def write_static(mesh: TireMesh, res: RunResult, out: Path, info: dict, tire: rd.RigTire = rd.SMALL) -> dict:
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
        "description": f"the rig's static map: inflation, then {tire.deflection * 1e3:.4g} mm deflection; "
        "the simulation "
        "that the slide/spin runs are compared with",
        "reaction_z": _num(res.static_load[2]),
        "reaction_z_source": "CalculiX reaction at the rigid road's reference node, end of the vertical step",
        "cpress_integral": _num(n),
        "centre_of_pressure": _vec(
            [quad_integral(x, quads, cp * x[:, 0]) / n, quad_integral(x, quads, cp * x[:, 1]) / n], 4
        ),
        "friction": tire.friction,
        **_static_extra(mesh, res, tire),
        "arrays": STATIC_ARRAYS,
        "points": "reference (undeformed) coordinates of the contact faces (crown and shoulder "
        "within the refined sector), m; road plane z = 0, x rolling direction, y axle",
        **info,
    }
    write_text(out / "static.json", json.dumps(side, indent=2) + "\n")
    return side


def _history_block(res: RunResult, origin, r_ref: float) -> dict:
    h = res.history
    kin = res.kin
    # reference sliding path of the run at each increment: |v| t and |wz| R_REF t in quadrature
    ref_path = np.hypot(kin.vx, kin.vy) ** 2 + (kin.wz * r_ref) ** 2
    r = resultants(res, origin)
    return {
        "time": _vec(h.time, 6),
        "path": _vec(np.sqrt(ref_path) * h.time, 6),
        "Fx": _vec(r[:, 0]),
        "Fy": _vec(r[:, 1]),
        "Fz": _vec(h.ref_rf[:, 2]),
        "Mz": _vec(r[:, 2]),
        "tire_rotation": _vec(kin.wz * h.time),
        "note": "per increment of the slide: time = pseudo-time t in [0, 1]; path = "
        "sqrt(|v|^2 + (wz R_ref)^2) t (m, R_ref = rig reference radius); Fx, Fy: road's force "
        "on the tire in the tire's frame (N); Mz about the (moved) static patch origin (N m); "
        "tire_rotation: the rim's rotation wz t (rad)",
    }


#: the sidecars' note on the rim's force
RIM_NOTE = (
    "N, road's frame: road_force = the rigid road's reference-node reaction (the road's force on the "
    "tire); rim_force = CalculiX's total RF of the rim (bead) nodes, which includes the cavity "
    "pressure applied at those nodes; rim_pressure_load = that pressure load (the consistent nodal "
    "load of the follower pressure on the deformed cavity faces at the bead nodes, 2 x 2 Gauss, "
    "exact for the bilinear faces). The tire's equilibrium: road_force + rim_force - "
    "rim_pressure_load = 0 (the cavity pressure's total is zero)"
)
_GAUSS = (-1.0 / math.sqrt(3.0), 1.0 / math.sqrt(3.0))


def bead_pressure_load(mesh: TireMesh, u: np.ndarray, pressure: float) -> np.ndarray:
    """(3,) N: the follower pressure's consistent nodal load at the bead nodes (force on the tire),
    on the cavity faces deformed by ``u``: -p sum_faces sum_gauss N_i (dx/dxi x dx/deta)."""
    x = mesh.nodes + u[: mesh.nodes.shape[0]]
    bead = np.zeros(mesh.nodes.shape[0], dtype=bool)
    bead[np.asarray(mesh.bead_nodes, dtype=np.int64)] = True
    quads = mesh.inner_quads[bead[mesh.inner_quads].any(axis=1)]
    total = np.zeros(3)
    xi = np.array([-1.0, 1.0, 1.0, -1.0])
    eta = np.array([-1.0, -1.0, 1.0, 1.0])
    for q in quads:
        xq = x[q]
        for a in _GAUSS:
            for b in _GAUSS:
                shape = 0.25 * (1 + xi * a) * (1 + eta * b)
                n = np.cross(0.25 * (xi * (1 + eta * b)) @ xq, 0.25 * (eta * (1 + xi * a)) @ xq)
                total += (shape * bead[q]).sum() * n
    # the faces are oriented out of the solid (into the cavity): the pressure pushes against n
    return -pressure * total


def _static_extra(mesh: TireMesh, base, tire: rd.RigTire) -> dict:
    """The whole tire's base (no cut faces: the rim carries the road's load alone): the rim's
    total reaction and, where measured, the solver's CPU time."""
    out: dict = {}
    rim = getattr(base, "static_rim_force", None)
    if rim is not None and getattr(mesh, "info", {}).get("whole_tire"):
        out["road_force"] = _vec(base.static_load)
        out["rim_force"] = _vec(rim)
        out["rim_pressure_load"] = _vec(bead_pressure_load(mesh, base.static_u, tire.pressure))
        out["rim_force_note"] = "end of the vertical step, " + RIM_NOTE
        if getattr(base, "cpu_s", None) is not None:
            out["base_cpu_s"] = round(base.cpu_s, 1)
    return out


def _cpu_block(res: RunResult) -> dict:
    """The solver's CPU times (user + system, s) where they were measured (none: nothing)."""
    if res.cpu_s is None:
        return {}
    return {
        "cpu_s": round(res.cpu_s, 1),
        "base_cpu_s": None if res.base_cpu_s is None else round(res.base_cpu_s, 1),
        "cpu_s_note": "CPU time (user + system) of this run's CalculiX solve and of the shared "
        "base's, measured by os.wait4 on the solver process; one thread",
    }


def write_run(
    mesh: TireMesh, res: RunResult, out: Path, info: dict, origin=(0.0, 0.0), tire: rd.RigTire = rd.SMALL
) -> dict:
    """Write ``<run>.vtu``, ``<run>.dat.txt`` and ``<run>.json`` into ``out``; return the sidecar."""
    pts, quads, disp, tau, cp, slip = tire_fields(mesh, res, origin)
    arrays = {"CPRESS": cp, "shear": tau, "slip": slip, "displacement": disp}
    out.mkdir(parents=True, exist_ok=True)
    _write_vtu(out / f"{res.name}.vtu", pts, quads, arrays)
    write_text(out / f"{res.name}.dat.txt", res.dat_excerpt)
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
        "the road and spin wz of the tire relative to the road about +z (THEORY section 3), in the "
        "tire's frame; the road is held, the rim moves rigidly (turned by wz t about the "
        "instantaneous centre, or translated by (vx, vy) t)",
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
            **(
                {
                    "rim_pressure_load": _vec(bead_pressure_load(mesh, res.u, tire.pressure)),
                    "rim_force_note": "end of the slide, " + RIM_NOTE,
                }
                if getattr(mesh, "info", {}).get("whole_tire")
                else {}
            ),
            "time": _num(h.time[-1] + tire.slide_start, 7),
            "source": f"CalculiX .dat, last increment of the slide step ({res.name}.dat.txt): RF of "
            "the rigid road's reference node (force) and rotation node (moment)",
            "sign": "RF at the road's nodes = force (moment) of the road on the tire, in the road's "
            "frame; the moment is about the reference node's current position (ref_position + "
            "ref_displacement)",
        },
        "tire_motion": {
            "rotation_z": _num(k.wz * h.time[-1], 12),
            "origin_position": _vec(tire_frame(res, h.time[-1], origin)[1], 10),
            "note": "the tire's frame at the end of the slide: turned by rotation_z (rad) about +z "
            "against the road's frame; the static patch origin has moved to origin_position (m, "
            "road's frame). Forces in the tire's frame = Rot(-rotation_z) force; torque about the "
            "moved origin",
        },
        "static_load": _vec(res.static_load),
        "shear_integral": {key: _num(v) for key, v in shear.items()},
        "shear_integral_note": "exact integrals of the exported bilinear shear traction (and CPRESS) "
        "over the deformed contact faces, tire's frame: Fx, Fy (N), Mz about the origin (N m), N (N)",
        "history": _history_block(res, origin, tire.r_ref),
        "friction": tire.friction,
        "units": "SI (m, N, Pa)",
        "arrays": ARRAYS,
        "deck_sha256": res.deck_sha256,
        "runtime_s": round(res.runtime_s, 1),
        "base_runtime_s": round(res.base_runtime_s, 1),
        "runtime_s_note": "wall time of this run's CalculiX solve (the slide, restarted from the "
        "shared base run of inflation and vertical load, whose wall time is base_runtime_s); one "
        "thread, nice 10, on a shared 2-core machine",
        **_cpu_block(res),
        **info,
    }
    write_text(out / f"{res.name}.json", json.dumps(side, indent=2) + "\n")
    return side
