"""Solve one whole-tire rolling deck (``aircraft_roll360_deck``), read it, judge it, export it.

Read in the axle's frame (the solver's), road plane z = 0, forces of the whole
tire (twice the half model's). Per printed time (``Plan.print_every``): the
road's force on the tire (RF of the road block), the rim's reaction (RF of the
rigid rim's reference node), the axle torque (the rotation node's reaction
about +y: zero by construction when the rim turns freely), the rim's turn and
the axle's travel.

Checks a sidecar records:

- steadiness over the last fifth of the roll: Fx moving less than 0.005 f N, Fz less than
  0.005 N and the axle torque less than 0.005 f N R_l (R_l the loaded radius), as the issue asks
  (``steadiness``'s criteria and tolerance, with the axle torque added);
- equilibrium: road_force + rim_force - rim_pressure_load = 0, where rim_pressure_load is the
  cavity pressure's nodal load at the bead nodes that CalculiX's rim reaction includes
  (``rig_export.bead_pressure_load``); the residual is reported relative to N.

Files per run: ``<run>.vtu``, ``<run>.dat.txt`` (the printed records of the last
time, verbatim) and ``<run>.json`` (written last; the deck's sha256 marks a finished run).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import aircraft_deck as ad
from . import aircraft_roll360_deck as r3
from .aircraft_export import mirror_surface, model_description, patch_metrics
from .aircraft_roll_export import centre_of_pressure, write_map
from .aircraft_roll_run import (
    RollState,
    finished_runtime,
    last_increment_text,
    read_results,
    sha256_text,
    surface_fields,
)
from .frd import read_dat_blocks
from .rig_export import bead_pressure_load, write_text
from .solve import ModelError, run_ccx
from .steadiness import SHARE, TOL

#: the sidecar's layout: a sidecar of another version is written again from its finished solve
EXPORT_VERSION = 3
TIMEOUT = 12 * 3600.0  # s, wall time allowed to one CalculiX run (the fine mesh's roll is hours)


@dataclass(frozen=True)
class History:
    """Every printed time (whole tire): travel, turn, road force, rim force, axle torque, road rise."""

    time: np.ndarray
    axle_travel: np.ndarray
    rotation: np.ndarray
    road: np.ndarray  # (n, 3) N, the road's force on the tire (y: 0 by symmetry)
    rim: np.ndarray  # (n, 3) N, CalculiX's reaction of the rigid rim (includes the bead pressure)
    torque: np.ndarray  # N m, torque of the axle on the rim about +y
    road_z: np.ndarray


@dataclass(frozen=True)
class Result:
    name: str
    plan: r3.Plan
    states: tuple[RollState, ...]  # inflation, static, roll001, ...
    history: History
    runtime_s: float
    cpu_s: float | None
    deck_sha256: str
    deck_info: dict
    last_increment: str


def deck_text(mesh: r3.Roll360Mesh, plan: r3.Plan, tmp: Path) -> tuple[str, dict]:
    """The deck of ``plan`` as text (written through ``tmp``, which is removed) and its numbering."""
    tmp.parent.mkdir(parents=True, exist_ok=True)
    info = r3.write_deck(tmp, mesh, plan)
    text = tmp.read_text()
    tmp.unlink()
    return text, info


def solve(exe: str, mesh: r3.Roll360Mesh, name: str, plan: r3.Plan, workdir: Path) -> Result:
    """Solve the run on one thread, niced (unless a finished solve of the same deck is there)."""
    workdir.mkdir(parents=True, exist_ok=True)
    deck, info = deck_text(mesh, plan, workdir / f"{name}.deck.tmp")
    seconds = finished_runtime(workdir, name, deck)
    if seconds is None:
        (workdir / f"{name}.runtime").unlink(missing_ok=True)
        (workdir / f"{name}.inp").write_text(deck)
        seconds = run_ccx(exe, workdir / f"{name}.inp", threads=1, timeout=TIMEOUT, niceness=5)
        (workdir / f"{name}.runtime").write_text(f"{seconds:.1f}\n")
    try:
        cpu: float | None = float((workdir / f"{name}.cpu").read_text())
    except (OSError, ValueError):
        cpu = None
    return collect(mesh, workdir / f"{name}.inp", name, plan, info, seconds, cpu, sha256_text(deck))


def read_history(dat: Path) -> History:
    """The printed records of the .dat file (whole tire: the half model's forces times 2)."""
    blocks = read_dat_blocks(dat)

    def by_time(kind: str, nset: str) -> dict[float, np.ndarray]:
        return {round(b[2], 9): b[3] for b in blocks if b[0] == kind and b[1] == nset}

    road, road_u = by_time("total force", "ROADN"), by_time("displacements", "ROADREF")
    rot_u, rot_f, rim = by_time("displacements", "ROTN"), by_time("forces", "ROTN"), by_time("forces", "REFN")
    times = sorted(set(road) & set(road_u) & set(rot_u) & set(rot_f) & set(rim))
    if not times:
        raise ModelError(f"{dat.name}: no printed road force / rim records")
    return History(
        time=np.array(times),
        axle_travel=-np.array([road_u[t][0, 1] for t in times]),
        rotation=np.array([rot_u[t][0, 2] for t in times]),
        road=2.0 * np.array([[road[t][0][0], 0.0, road[t][0][2]] for t in times]),
        rim=2.0 * np.array([[rim[t][0, 1], 0.0, rim[t][0, 3]] for t in times]),
        torque=2.0 * np.array([rot_f[t][0, 2] for t in times]),
        road_z=np.array([road_u[t][0, 3] for t in times]),
    )


def collect(
    mesh: r3.Roll360Mesh,
    inp: Path,
    name: str,
    plan: r3.Plan,
    info: dict,
    runtime: float,
    cpu: float | None,
    sha: str,
) -> Result:
    """Read the .frd surface results at the output times and the .dat history."""
    nt = mesh.nodes.shape[0]
    res = read_results(inp, nt)
    hist = read_history(inp.with_suffix(".dat"))
    states = []
    for case, t in info["output_times"].items():
        store = next((blk for time_, blk in res.every if abs(time_ - t) < 1e-6), None)
        k = int(np.argmin(np.abs(hist.time - t)))
        if store is None or "U" not in store or abs(hist.time[k] - t) > 1e-6:
            raise ModelError(f"{inp.stem}: no results at analysis time {t:g} ({case})")
        u, cp = surface_fields(store, nt, float(hist.road_z[k]))
        states.append(
            RollState(
                name=case,
                time=float(t),
                displacement=u,
                cpress=cp,
                road_force=hist.road[k].copy(),
                rotation=float(hist.rotation[k]),
                axle_travel=float(hist.axle_travel[k]),
                road_z=float(hist.road_z[k]),
                axle_torque=float(hist.torque[k]),
            )
        )
    return Result(
        name,
        plan,
        tuple(states),
        hist,
        float(runtime),
        cpu,
        sha,
        info,
        last_increment_text(inp.with_suffix(".dat")),
    )


def rolling_part(h: History, share: float = SHARE) -> np.ndarray:
    """Mask of the printed times in the last ``share`` of the roll (travel > 0)."""
    rolled = h.axle_travel > 1e-12
    if rolled.sum() < 2:
        raise ValueError("fewer than two printed times along the roll")
    return rolled & (h.axle_travel >= (1.0 - share) * h.axle_travel[rolled].max() - 1e-12)


def steady_turn_rate(h: History, share: float = SHARE) -> float:
    """dtheta/dX (rad/m) over the last ``share`` of the roll: a least-squares line."""
    keep = rolling_part(h, share)
    if keep.sum() < 2:
        raise ValueError(f"fewer than two printed times in the last {share:g} of the roll")
    return float(np.polyfit(h.axle_travel[keep], h.rotation[keep], 1)[0])


def steadiness(h: History, loaded_radius: float) -> dict:
    """Peak-to-peak motions over the last fifth of the roll, in the issue's units, and the verdict."""
    keep = rolling_part(h)
    fx, fz, torque = h.road[keep, 0], h.road[keep, 2], h.torque[keep]
    n = float(fz[-1])
    m = {
        "Fx_over_fN": float(np.ptp(fx)) / (ad.FRICTION * n),
        "Fz_over_N": float(np.ptp(fz)) / n,
        "torque_over_fNR": float(np.ptp(torque)) / (ad.FRICTION * n * loaded_radius),
    }
    return {
        **m,
        "printed_times": int(keep.sum()),
        "travel_from_m": float(h.axle_travel[keep].min()),
        "tolerance": TOL,
        "steady": bool(max(m.values()) < TOL),
        "note": f"peak-to-peak over the printed times in the last {SHARE:g} of the roll: Fx in f N, "
        "Fz in N, the axle torque in f N R_l (R_l = axle height over the road); steady when all "
        f"are below {TOL:g}",
    }


def balance(mesh: r3.Roll360Mesh, h: History, state: RollState) -> dict:
    """Rim against road at ``state``: road + rim - bead pressure load, relative to N (whole tire)."""
    k = int(np.argmin(np.abs(h.time - state.time)))
    u = state.displacement + np.array([0.0, 0.0, state.road_z])
    bead = 2.0 * bead_pressure_load(mesh, u, ad.PRESSURE) * np.array([1.0, 0.0, 1.0])
    residual = h.road[k] + h.rim[k] - bead
    n = float(h.road[k, 2])
    return {
        "road_force": [float(v) for v in h.road[k]],
        "rim_force": [float(v) for v in h.rim[k]],
        "rim_pressure_load": [float(v) for v in bead],
        "residual_over_N": [float(v) / n for v in residual],
        "note": "whole tire, N: road_force = RF of the road block, rim_force = RF of the rigid rim's "
        "reference node (includes the cavity pressure applied at the bead nodes), rim_pressure_load = "
        "that pressure load; equilibrium: road_force + rim_force - rim_pressure_load = 0",
    }


def samples(mesh: r3.Roll360Mesh, result: Result) -> list[dict]:
    """The surface frames along the roll: forces, load integral and exact centre-of-pressure shift."""
    n0, x0 = centre_of_pressure(mesh, next(s for s in result.states if s.name == "static"))
    out = []
    for s in result.states:
        if s.name.startswith("roll"):
            n, x = centre_of_pressure(mesh, s)
            out.append(
                {
                    "axle_travel_m": s.axle_travel,
                    "rim_rotation_deg": math.degrees(s.rotation),
                    "Fx": float(s.road_force[0]),
                    "Fz": float(s.road_force[2]),
                    "axle_torque_Nm": s.axle_torque,
                    "cpress_integral_projected": n,
                    "centre_of_pressure_shift_m": x - x0,
                }
            )
    return out


def patch_strips(pts: np.ndarray, disp: np.ndarray, cp: np.ndarray) -> dict:
    """The loaded length of each lateral strip of the patch: for each node column (reference y)
    with loaded nodes, the x extent of its loaded nodes on the deformed surface, and the strip
    width (half-way to the next columns, the outer columns to the patch edge at their own y)."""
    loaded = cp > 0.0
    ys = np.round(pts[loaded, 1], 9)
    cols = np.unique(ys)
    x = (pts + disp)[loaded, 0]
    length = np.array([np.ptp(x[ys == y]) for y in cols])
    edges = np.concatenate([[cols[0]], 0.5 * (cols[1:] + cols[:-1]), [cols[-1]]])
    return {
        "y": cols.tolist(),
        "length": length.tolist(),
        "width": np.diff(edges).tolist(),
        "note": "m: per node column of the static patch, the loaded x extent (deformed) and the strip "
        "width it stands for (half-way to the neighbouring columns)",
    }


def write_static(mesh: r3.Roll360Mesh, result: Result, out: Path, name: str) -> dict:
    """The loaded, not yet rolled state (the end of the first step): the rolled maps' static partner."""
    state = next(s for s in result.states if s.name == "static")
    figures = write_map(mesh, state, out, name)
    side = {
        "case": name,
        "kind": "static map",
        "export_version": EXPORT_VERSION,
        "description": f"the whole tire (half model, mirrored) at the end of its vertical travel in run "
        f"'{result.name}', before rolling: the static partner of the roll_*.vtu maps",
        "reaction_z": float(state.road_force[2]),
        "reaction_z_source": "CalculiX total RF of the road block's nodes (half model, times 2)",
        "cpress_integral_projected": figures["cpress_integral_projected"],
        "patch": figures["patch"],
        "balance": balance(mesh, result.history, state),
        "friction": ad.FRICTION,
        "deck_sha256": result.deck_sha256,
        "mesh": {k: v for k, v in mesh.info.items() if isinstance(v, (int, float, str, bool, list))},
        "units": "SI (m, Pa, N, N m, rad)",
    }
    write_text(out / f"{name}.json", json.dumps(side, indent=2) + "\n")
    return side


def write_run(mesh: r3.Roll360Mesh, result: Result, out: Path, name: str, labels: dict) -> dict:
    """``<name>.vtu``, ``<name>.dat.txt``, then ``<name>.json``; ``labels``: what the run is
    (``description``, ``imposed``, ``slip_radius_m``, the radius the slip is measured against, and
    its ``slip_radius_source``; a free or free-referenced run also ``effective_rolling_radius_m``)."""
    state, h = result.states[-1], result.history
    static = next(s for s in result.states if s.name == "static")
    pts, quads, cp, disp = mirror_surface(mesh, static)
    figures = write_map(mesh, state, out, name)
    write_text(out / f"{name}.dat.txt", result.last_increment)
    rate = steady_turn_rate(h)
    radius = labels.get("slip_radius_m")
    loaded = float(mesh.params.axle_z - state.road_z)
    side = {
        "case": name,
        "kind": "rolling run",
        "export_version": EXPORT_VERSION,
        **labels,
        "rim_rotation_deg": math.degrees(state.rotation),
        "axle_travel_m": state.axle_travel,
        "turn_per_travel_rad_per_m": rate,
        "longitudinal_slip": None if radius is None else radius * rate - 1.0,
        "longitudinal_slip_definition": "kappa = R dtheta/dX - 1, dtheta/dX over the last fifth "
        "of the roll; R = slip_radius_m (see its source); < 0 braking, > 0 driving",
        "axle_torque_Nm": state.axle_torque,
        "axle_torque_tail_mean_Nm": float(h.torque[rolling_part(h)].mean()),
        "axle_torque_note": "torque of the axle on the rim about +y (whole tire): the rotation node's "
        "reaction; 0 by construction when the rim is free to turn",
        "friction": ad.FRICTION,
        "reaction": {
            "force": [float(v) for v in state.road_force],
            "sign": "force of the road on the tire, x rolling direction: Fx < 0 braking",
            "source": "CalculiX total RF of the road block's nodes (half model, times 2)",
        },
        "longitudinal_force_ratio": float(state.road_force[0] / state.road_force[2]),
        "tail_means": {
            k: float(v[rolling_part(h)].mean()) for k, v in (("Fx", h.road[:, 0]), ("Fz", h.road[:, 2]))
        },
        "steadiness": steadiness(h, loaded),
        "balance": balance(mesh, h, state),
        "samples": samples(mesh, result),
        "samples_note": "surface frames along the roll; centre shift = x of the CPRESS centre on the "
        "deformed faces projected on the road (projected_integral of CPRESS weighted by the deformed "
        "x: the exact integral of the product of the two bilinear fields) minus the static one's",
        "history": {
            "axle_travel_m": h.axle_travel.tolist(),
            "rim_rotation_rad": h.rotation.tolist(),
            "Fx": h.road[:, 0].tolist(),
            "Fz": h.road[:, 2].tolist(),
            "rim_Fx": h.rim[:, 0].tolist(),
            "rim_Fz": h.rim[:, 2].tolist(),
            "axle_torque_Nm": h.torque.tolist(),
        },
        "cpress_integral_projected": figures["cpress_integral_projected"],
        "patch": figures["patch"],
        "static_load": float(static.road_force[2]),
        "static_patch": patch_metrics(pts + disp, quads, cp),
        "static_patch_strips": patch_strips(pts, disp, cp),
        "loaded_radius_m": loaded,
        "runtime_s": round(result.runtime_s, 1),
        "cpu_s": result.cpu_s,
        "cpu_s_per_m": None if result.cpu_s is None else result.cpu_s / result.plan.travel_x,
        "solver_tolerances": {
            "roll": list(result.plan.tolerances),
            "inflation_and_load": list(result.plan.load_tolerances),
            "note": "CalculiX *CONTROLS, PARAMETERS=FIELD: R_n (force residual over the average "
            "nodal force), C_n (displacement correction over the increment)",
        },
        "deck_sha256": result.deck_sha256,
        "mesh": {k: v for k, v in mesh.info.items() if isinstance(v, (int, float, str, bool, list))},
        "model": {
            **model_description(mesh),
            "rim": "rigid body on the bead nodes, its reference node on the axle",
            "contact": "the whole rig tire's contact pair (aircraft_rig_deck.WHOLE's model lines): "
            f"node-to-surface penalty, {result.deck_info['contact_law']}, Coulomb friction {ad.FRICTION}",
            "elements": "two elements through the rubber; C3D8I, plain C3D8 in the rubber under the "
            f"patch's lateral edges (aircraft_rig_deck.incompatible_mask): {result.deck_info['elements']}",
        },
        "units": "SI (m, Pa, N, N m, rad)",
    }
    write_text(out / f"{name}.json", json.dumps(side, indent=2) + "\n")
    return side
