"""Solve one slide/spin rig run with CalculiX and collect what the export needs.

The inflation pre-run (where does the inflated crown sit, hence the rim travel
of the 29 mm deflection of the static case) is shared by all runs of one mesh.
A run's work folder is reused when it holds a finished solution of the same
deck (the programme can be stopped and resumed).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import deck as dk
from . import rig_deck as rd
from .frd import read_dat_blocks, read_frd
from .geometry import TireMesh
from .solve import ModelError, run_ccx

DEFLECTION = 0.029  # m, as the static sample case
SLIDE_START = 2.0  # total time at the start of the slide step (steps 1 and 2 last 1 each)


@dataclass(frozen=True)
class History:
    """The road's reactions per increment of the slide step, as printed by CalculiX."""

    time: np.ndarray  # (k,) step time in [0, 1] (pseudo-time of the slide)
    ref_u: np.ndarray  # (k, 3) m, displacement of the rigid road's reference node
    ref_rf: np.ndarray  # (k, 3) N, reaction at the reference node = force of the road on the tire
    rot_u: np.ndarray  # (k, 3) rad, rotation vector of the road
    rot_rf: np.ndarray  # (k, 3) N m, reaction moment at the rotation node, about the reference node
    bead_rf: np.ndarray  # (k, 3) N, total reaction on the rim nodes


@dataclass(frozen=True)
class RunResult:
    name: str
    kin: rd.Kinematics
    nodes: rd.RigNodes
    history: History
    static_load: np.ndarray  # (3,) N, road's force on the tire at the end of the vertical step
    static_cpress: np.ndarray  # (n_tire,) Pa, end of the vertical step
    static_u: np.ndarray  # (n_tire, 3) m
    contact: dict  # name -> (n_tire,) CalculiX CONTACT components at the end of the slide
    u: np.ndarray  # (n_tire, 3) m, end of the slide
    runtime_s: float
    deck_sha256: str
    dat_excerpt: str  # the .dat records of the last slide increment, verbatim


def inflation_rim_travel(mesh: TireMesh, workdir: Path, exe: str) -> tuple[float, float, float]:
    """(rim travel, inflated clearance, wall time): the static case's pre-run, reused when present."""
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / "inflate.inp"
    dk.write_deck(inp, mesh, dk.CASES["static"], 0.0, inflation_only=True)
    t = _solve_once(exe, inp)
    r0 = read_frd(inp.with_suffix(".frd"))
    _, u0 = r0.field(max(r0.last), "U")
    slave = np.unique(mesh.contact_quads)
    z = float((mesh.nodes[slave, 2] + u0[slave, 2]).min())
    if z <= 0.0:
        raise ModelError("inflated tire already touches the road")
    return z + DEFLECTION, z, t


def _solve_once(exe: str, inp: Path) -> float:
    """Run ccx unless a finished solution of this very deck is there; return its wall time."""
    digest = hashlib.sha256(inp.read_bytes()).hexdigest()
    stamp = inp.with_suffix(".done")
    if stamp.exists() and stamp.read_text().split()[0] == digest and inp.with_suffix(".frd").exists():
        return float(stamp.read_text().split()[1])
    stamp.unlink(missing_ok=True)
    t = run_ccx(exe, inp, threads=1)
    stamp.write_text(f"{digest} {t:.1f}\n")
    return t


def _history(dat: Path) -> History:
    blocks = read_dat_blocks(dat)
    rows: dict[tuple[str, str], dict[float, np.ndarray]] = {}
    for kind, name, t, arr in blocks:
        if t > SLIDE_START + 1e-9 or (kind, name) == ("total force", "BEAD"):
            rows.setdefault((kind, name), {})[t] = arr[-1, -3:]
    key_u, key_f = "displacements", "forces"
    times = sorted(t for t in rows.get((key_f, "REFN"), {}) if t > SLIDE_START + 1e-9)
    if not times:
        raise ModelError(f"no reactions of the slide step in {dat.name}")

    def stack(kind, name):
        d = rows[(kind, name)]
        return np.array([d[t] for t in times])

    return History(
        time=np.array(times) - SLIDE_START,
        ref_u=stack(key_u, "REFN"),
        ref_rf=stack(key_f, "REFN"),
        rot_u=stack(key_u, "ROTN"),
        rot_rf=stack(key_f, "ROTN"),
        bead_rf=stack("total force", "BEAD"),
    )


def _excerpt(dat: Path) -> str:
    """The last increment's records of the .dat file (REFN, ROTN, BEAD), verbatim."""
    lines = dat.read_text(encoding="latin-1").splitlines()
    starts = [i for i, ln in enumerate(lines) if "for set REFN" in ln and "displacements" in ln]
    return "\n".join(lines[starts[-1] :]).rstrip() + "\n"


def solve_run(
    mesh: TireMesh,
    name: str,
    kin: rd.Kinematics,
    rim_travel: float,
    workdir: Path,
    exe: str,
    inc: float,
) -> RunResult:
    """Write the deck, solve it (or reuse a finished solution) and read the results."""
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / f"{name}.inp"
    nodes = rd.write_rig_deck(inp, mesh, kin, rim_travel, (0.0, 0.0), inc)
    runtime = _solve_once(exe, inp)
    nt = mesh.nodes.shape[0]
    res = read_frd(inp.with_suffix(".frd"))
    if res.node_ids[:nt].tolist() != list(range(1, nt + 1)):
        raise ModelError("unexpected node numbering in the .frd file")
    if 3 not in res.last or 2 not in res.last:
        raise ModelError(f"{name}: the slide step did not finish")
    comps2, c2 = res.field(2, "CONTACT")
    comps, c = res.field(3, "CONTACT")
    hist = _history(inp.with_suffix(".dat"))
    static = [r for r in read_dat_blocks(inp.with_suffix(".dat")) if r[0] == "forces" and r[1] == "REFN"]
    static_load = next(arr[-1, -3:] for k, n, t, arr in static if abs(t - SLIDE_START) < 1e-9)
    return RunResult(
        name=name,
        kin=kin,
        nodes=nodes,
        history=hist,
        static_load=static_load,
        static_cpress=np.clip(c2[:nt, comps2.index("CPRESS")], 0.0, None),
        static_u=res.field(2, "U")[1][:nt],
        contact={k: c[:nt, i] for i, k in enumerate(comps)},
        u=res.field(3, "U")[1][:nt],
        runtime_s=runtime,
        deck_sha256=hashlib.sha256(inp.read_bytes()).hexdigest(),
        dat_excerpt=_excerpt(inp.with_suffix(".dat")),
    )
