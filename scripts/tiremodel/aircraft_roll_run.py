"""Solve one rolling deck with CalculiX (or reuse a finished solve) and read its results.

A run's work folder holds ``<run>.inp`` and CalculiX's files. A solve is
reused when the folder holds a finished run (``Job finished`` in its log, the
.frd and .dat present, a ``<run>.runtime`` stamp) of exactly the same deck.

Everything is read in the axle's frame (the solver's): the axle is the y axis
through (0, 0, axle_z) and stays put; the road plane is at the road block's
current height, which is subtracted so that the road is z = 0, as in the
static maps. Forces are the full tire's (twice the half model's; the lateral
resultant is zero by symmetry).
"""

from __future__ import annotations

import hashlib
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import aircraft_roll_deck as rdk
from .aircraft_geometry import AircraftMesh
from .frd import read_dat_blocks, read_frd
from .solve import ModelError, run_ccx

_PARSE_LOCK = threading.Lock()  # ccx2paraview keeps its node renumbering in module state


@dataclass(frozen=True)
class RollState:
    """The tire at one written time (full tire's forces, the axle's frame)."""

    name: str
    time: float
    displacement: np.ndarray  # (n_tire, 3), m: deformed position (axle frame, road z = 0) - reference
    cpress: np.ndarray  # (n_tire,), Pa, >= 0
    road_force: np.ndarray  # (3,), N, force of the road on the tire (full tire, y = 0)
    rotation: float  # rad, the rim's turn about +y
    axle_travel: float  # m, the axle's travel along +x relative to the road
    road_z: float  # m, the road block's rise (the rim travel relative to the road)
    axle_torque: float  # N m, torque of the axle on the rim about +y (full tire)


@dataclass(frozen=True)
class RollHistory:
    """Every written time (full tire): time, axle travel, turn, Fx, Fz, axle torque, road rise.

    CalculiX prints the .dat records at the deck's TIME POINTS only, like the .frd."""

    time: np.ndarray
    axle_travel: np.ndarray
    rotation: np.ndarray
    fx: np.ndarray
    fz: np.ndarray
    torque: np.ndarray
    road_z: np.ndarray  # m, the road block's rise


@dataclass(frozen=True)
class RollResult:
    name: str
    plan: rdk.RollPlan
    states: tuple[RollState, ...]  # inflation, static, roll001, ...
    history: RollHistory
    runtime_s: float
    solver: str
    deck_sha256: str
    deck_info: dict
    last_increment: str  # the .dat records of the last increment, verbatim

    def state(self, name: str) -> RollState:
        for s in self.states:
            if s.name == name:
                return s
        raise KeyError(name)


def deck_text(mesh: AircraftMesh, plan: rdk.RollPlan, tmp: Path) -> tuple[str, dict]:
    """The deck of ``plan`` as text (written through ``tmp``, which is removed) and its numbering."""
    info = rdk.write_roll_deck(tmp, mesh, plan)
    text = tmp.read_text()
    tmp.unlink()
    return text, info


def sha256_text(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def finished_runtime(workdir: Path, name: str, deck: str) -> float | None:
    """Run time of a completed solve of exactly ``deck`` in ``workdir``, else None."""
    try:
        same = (workdir / f"{name}.inp").read_text() == deck
        done = "Job finished" in (workdir / f"{name}.log").read_text(errors="replace")
        seconds = float((workdir / f"{name}.runtime").read_text())
    except (OSError, ValueError):
        return None
    if same and done and (workdir / f"{name}.frd").exists() and (workdir / f"{name}.dat").exists():
        return seconds
    return None


def solve(
    exe: str, solver: str, mesh: AircraftMesh, name: str, plan: rdk.RollPlan, workdir: Path
) -> RollResult:
    """Solve the run (unless a finished solve of the same deck is there) and read it."""
    workdir.mkdir(parents=True, exist_ok=True)
    deck, info = deck_text(mesh, plan, workdir / f"{name}.deck.tmp")
    seconds = finished_runtime(workdir, name, deck)
    if seconds is None:
        (workdir / f"{name}.runtime").unlink(missing_ok=True)
        (workdir / f"{name}.inp").write_text(deck)
        seconds = run_ccx(exe, workdir / f"{name}.inp", threads=1, timeout=4 * 3600.0)
        (workdir / f"{name}.runtime").write_text(f"{seconds:.1f}\n")
    with _PARSE_LOCK:
        return collect(mesh, workdir / f"{name}.inp", name, plan, info, seconds, solver, sha256_text(deck))


def _by_time(blocks, kind: str, nset: str) -> dict[float, np.ndarray]:
    return {round(b[2], 9): b[3] for b in blocks if b[0] == kind and b[1] == nset}


def read_history(dat: Path, plan: rdk.RollPlan) -> RollHistory:
    """The printed records of the .dat file (road force, road travel, rim turn, torque)."""
    blocks = read_dat_blocks(dat)
    force = _by_time(blocks, "total force", "ROADN")
    road_u = _by_time(blocks, "displacements", "ROADREF")
    rot_u = _by_time(blocks, "displacements", "ROTN")
    rot_f = _by_time(blocks, "forces", "ROTN")
    drv_f = _by_time(blocks, "forces", "DRVN")
    times = sorted(set(force) & set(road_u) & set(rot_u) & set(rot_f) & set(drv_f))
    if not times:
        raise ModelError(f"{dat.name}: no printed road force / rim turn records")
    turn = np.array([rot_u[t][0, 2] for t in times])
    # torque on the rim: the rotation node's reaction (imposed turn) plus the driver
    # node's (elastic drive: the spring's torque; the rim's own turn is then free)
    reaction = np.array([rot_f[t][0, 2] + drv_f[t][0, 2] for t in times])
    return RollHistory(
        time=np.array(times),
        axle_travel=-np.array([road_u[t][0, 1] for t in times]),
        rotation=turn,
        fx=2.0 * np.array([force[t][0][0] for t in times]),
        fz=2.0 * np.array([force[t][0][2] for t in times]),
        torque=2.0 * reaction,
        road_z=np.array([road_u[t][0, 3] for t in times]),
    )


def last_increment_text(dat: Path) -> str:
    """The .dat records of the last printed time, verbatim."""
    lines = dat.read_text(encoding="latin-1").splitlines()
    starts = [i for i, ln in enumerate(lines) if "total force (fx,fy,fz) for set ROADN" in ln]
    if not starts:
        raise ModelError(f"{dat.name}: no road force records")
    return "\n".join(lines[starts[-1] :]).rstrip() + "\n"


def read_results(inp: Path, nt: int):
    """The .frd results of every written increment of the run ``inp`` (its first ``nt`` nodes
    the tire's, numbered 1..nt, as the decks write them)."""
    res = read_frd(inp.with_suffix(".frd"), every=True)
    if res.node_ids[:nt].tolist() != list(range(1, nt + 1)):
        raise ModelError(f"{inp.stem}: unexpected node numbering in the .frd file")
    return res


def surface_fields(store: dict, nt: int, road_z: float) -> tuple[np.ndarray, np.ndarray]:
    """(displacement of the ``nt`` tire nodes in the frame that follows the road's height
    ``road_z``, their contact pressure CPRESS clipped at 0) from one .frd result block."""
    u = store["U"][1][:nt] - np.array([0.0, 0.0, road_z])
    cp = np.zeros(nt)
    if "CONTACT" in store:
        comps, c = store["CONTACT"]
        cp = np.clip(c[:nt, comps.index("CPRESS")], 0.0, None)
    return u, cp


def collect(
    mesh: AircraftMesh,
    inp: Path,
    name: str,
    plan: rdk.RollPlan,
    info: dict,
    runtime: float,
    solver: str,
    deck_sha256: str,
) -> RollResult:
    nt = mesh.nodes.shape[0]
    res = read_results(inp, nt)
    hist = read_history(inp.with_suffix(".dat"), plan)
    states = []
    for case, t in info["output_times"].items():
        store = next((blk for time_, blk in res.every if abs(time_ - t) < 1e-6), None)
        if store is None or "U" not in store:
            raise ModelError(f"{inp.stem}: no results at analysis time {t:g} ({case})")
        k = int(np.argmin(np.abs(hist.time - t)))
        if abs(hist.time[k] - t) > 1e-6:
            raise ModelError(f"{inp.stem}: no printed reactions at analysis time {t:g} ({case})")
        road = float(hist.road_z[k])
        u, cp = surface_fields(store, nt, road)
        states.append(
            RollState(
                name=case,
                time=float(t),
                displacement=u,
                cpress=cp,
                road_force=np.array([hist.fx[k], 0.0, hist.fz[k]]),
                rotation=float(hist.rotation[k]),
                axle_travel=float(hist.axle_travel[k]),
                road_z=road,
                axle_torque=float(hist.torque[k]),
            )
        )
    return RollResult(
        name=name,
        plan=plan,
        states=tuple(states),
        history=hist,
        runtime_s=float(runtime),
        solver=solver,
        deck_sha256=deck_sha256,
        deck_info=info,
        last_increment=last_increment_text(inp.with_suffix(".dat")),
    )
