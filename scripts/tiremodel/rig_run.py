"""Solve the slide/spin rig runs with CalculiX and collect what the export needs.

Shared by all runs of one mesh: the inflation pre-run (where the inflated
crown sits, hence the rim travel of the static case's 29 mm deflection) and
the base run (inflation and vertical load with the rigid road, which writes a
CalculiX restart file). Each run restarts from the base. A work folder is
reused when it holds a finished solution of the same decks (the programme can
be stopped and resumed).
"""

from __future__ import annotations

import hashlib
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import deck as dk
from . import rig_deck as rd
from .frd import read_dat_blocks, read_frd
from .geometry import TireMesh
from .solve import ModelError, run_ccx

SLIDE_START = 2.0  # total time at the start of the slide step (steps 1 and 2 last 1 each)


@dataclass(frozen=True)
class History:
    """The road's reactions per increment of the slide step, as printed by CalculiX."""

    time: np.ndarray  # (k,) step time in [0, 1] (pseudo-time of the slide)
    ref_u: np.ndarray  # (k, 3) m, displacement of the rigid road's reference node
    ref_rf: np.ndarray  # (k, 3) N, reaction at the reference node = force of the road on the tire
    rot_u: np.ndarray  # (k, 3) rad, rotation vector of the road
    rot_rf: np.ndarray  # (k, 3) N m, reaction moment at the rotation node, about the reference node
    # (all in the road's frame; the road is held, so ref_u and rot_u stay zero)
    bead_rf: np.ndarray  # (k, 3) N, total reaction on the rim nodes


@dataclass(frozen=True)
class Base:
    """The shared inflation + vertical-load solution the runs restart from."""

    nodes: rd.RigNodes
    restart: Path  # CalculiX restart file (.rout)
    static_load: np.ndarray  # (3,) N, road's force on the tire at the end of the vertical step
    static_cpress: np.ndarray  # (n_tire,) Pa, end of the vertical step
    static_u: np.ndarray  # (n_tire, 3) m
    runtime_s: float
    deck_sha256: str
    cpu_s: float | None = None  # the solver's CPU time (user + system), where it was measured
    static_rim_force: np.ndarray | None = None  # (3,) N, total reaction on the rim, end of the base


@dataclass(frozen=True)
class RunResult:
    name: str
    kin: rd.Kinematics
    nodes: rd.RigNodes
    history: History
    static_load: np.ndarray  # (3,) N, as Base
    static_cpress: np.ndarray
    static_u: np.ndarray
    contact: dict  # name -> (n_tire,) CalculiX CONTACT components at the end of the slide
    u: np.ndarray  # (n_tire, 3) m, end of the slide
    runtime_s: float  # the run's own solve (restart from the base)
    base_runtime_s: float
    deck_sha256: str
    dat_excerpt: str  # the .dat records of the last slide increment, verbatim
    cpu_s: float | None = None  # the run's CPU time (user + system), where it was measured
    base_cpu_s: float | None = None


def inflation_rim_travel(
    mesh: TireMesh, workdir: Path, exe: str, tire: rd.RigTire = rd.SMALL
) -> tuple[float, float, float]:
    """(rim travel, inflated clearance, wall time): the inflation pre-run, reused when present.

    The small tire's pre-run is its static case's; the other tires' is the rig's
    base deck cut after the inflation step.
    """
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / "inflate.inp"
    if tire is rd.SMALL:
        dk.write_deck(inp, mesh, dk.CASES["static"], 0.0, inflation_only=True)
    else:
        rd.write_base_deck(inp, mesh, 0.0, (0.0, 0.0), tire, inflation_only=True)
    t = _solve_once(exe, inp, "", tire.timeout)
    r0 = read_frd(inp.with_suffix(".frd"))
    _, u0 = r0.field(max(r0.last), "U")
    slave = np.unique(mesh.contact_quads)
    z = float((mesh.nodes[slave, 2] + u0[slave, 2]).min())
    if z <= 0.0:
        raise ModelError("inflated tire already touches the road")
    return z + tire.deflection, z, t


def _solve_once(exe: str, inp: Path, key: str, timeout: float = 1800.0) -> float:
    """Run ccx unless a finished solution of this deck (and ``key``) is there; return its wall time."""
    digest = hashlib.sha256(inp.read_bytes() + key.encode()).hexdigest()
    stamp = inp.with_suffix(".done")
    if stamp.exists() and stamp.read_text().split()[0] == digest and inp.with_suffix(".frd").exists():
        return float(stamp.read_text().split()[1])
    stamp.unlink(missing_ok=True)
    t = run_ccx(exe, inp, threads=1, timeout=timeout)
    cpu = inp.with_suffix(".cpu")
    stamp.write_text(f"{digest} {t:.1f}" + (f" {cpu.read_text().strip()}" if cpu.exists() else "") + "\n")
    return t


def cpu_of(inp: Path) -> float | None:
    """The CPU seconds of a finished solve of ``inp`` (its stamp's third field), if measured."""
    stamp = inp.with_suffix(".done")
    fields = stamp.read_text().split() if stamp.exists() else []
    return float(fields[2]) if len(fields) > 2 else None


def _nodal(mesh: TireMesh, frd: Path, step: int | None = None):
    """(CONTACT components, U) of the last increment of ``step`` (default: the last step)."""
    nt = mesh.nodes.shape[0]
    res = read_frd(frd)
    if res.node_ids[:nt].tolist() != list(range(1, nt + 1)):
        raise ModelError(f"unexpected node numbering in {frd.name}")
    step = max(res.last) if step is None else step
    comps, c = res.field(step, "CONTACT")
    return {k: c[:nt, i] for i, k in enumerate(comps)}, res.field(step, "U")[1][:nt]


def solve_base(
    mesh: TireMesh,
    rim_travel: float,
    workdir: Path,
    exe: str,
    tire: rd.RigTire = rd.SMALL,
    vertical_inc: str | None = None,
) -> Base:
    """Solve (or reuse) the base run: inflation and vertical load with the rigid road
    (``vertical_inc``: the ``*STATIC`` line of the vertical travel; default the tire's)."""
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / "base.inp"
    nodes = rd.write_base_deck(inp, mesh, rim_travel, (0.0, 0.0), tire, vertical_inc=vertical_inc)
    t = _solve_once(exe, inp, "", tire.timeout)
    contact, u = _nodal(mesh, inp.with_suffix(".frd"), 1 if tire.one_step else 2)
    recs = [r for r in read_dat_blocks(inp.with_suffix(".dat")) if r[0] == "forces" and r[1] == "REFN"]
    load = next(arr[-1, -3:] for _, _, t_, arr in recs if abs(t_ - tire.slide_start) < 1e-9)
    rim = [
        r[3][-1, -3:]
        for r in read_dat_blocks(inp.with_suffix(".dat"))
        if r[0] == "total force" and r[1] == "BEAD" and abs(r[2] - tire.slide_start) < 1e-9
    ]
    return Base(
        nodes=nodes,
        restart=inp.with_suffix(".rout"),
        static_load=load,
        static_cpress=np.clip(contact["CPRESS"], 0.0, None),
        static_u=u,
        runtime_s=t,
        deck_sha256=hashlib.sha256(inp.read_bytes()).hexdigest(),
        cpu_s=cpu_of(inp),
        static_rim_force=rim[-1] if rim else None,
    )


def check_on_road(
    mesh: TireMesh,
    base: Base,
    road,
    runs: dict[str, rd.Kinematics],
    path: float,
    log: Callable[[str], None] | None = None,
) -> None:
    """Refuse, before any is solved, the runs whose static patch (the base's loaded nodes, moved by
    the run's rigid motion) would leave the road (``rig_deck.road_exit``): one ModelError naming
    each such run and where along its ``path`` (m) the patch gets there. Runs whose patch only
    enters the road's last face are reported through ``log``."""
    loaded = base.static_cpress > 0.0
    xy = mesh.nodes[loaded, :2] + base.static_u[loaded, :2]
    bad = []
    for name, kin in runs.items():
        last = rd.road_exit(kin, base.nodes.ref_xy, xy, road, faces=1)
        if last is None:  # clear of the last face, so on the road (the usual case: one pass)
            continue
        off = rd.road_exit(kin, base.nodes.ref_xy, xy, road)
        if off is not None:
            bad.append(
                f"{name} from {off.t * path:.3f} m of its {path:.2f} m path ({off.reach:.2f} x as far out)"
            )
        elif log is not None:
            log(
                f"{name}: the patch enters the road's last face from {last.t * path:.3f} m "
                f"of its {path:.2f} m path"
            )
    if bad:
        raise ModelError(
            "the patch would run off the road (its leading edge loses contact, the solve stalls): "
            + "; ".join(bad)
            + ": give a shorter --path"
        )


def _history(dat: Path, start: float = SLIDE_START) -> History:
    blocks = read_dat_blocks(dat)
    rows: dict[tuple[str, str], dict[float, np.ndarray]] = {}
    for kind, name, t, arr in blocks:
        if t > start + 1e-9 or (kind, name) == ("total force", "BEAD"):
            rows.setdefault((kind, name), {})[t] = arr[-1, -3:]
    key_u, key_f = "displacements", "forces"
    times = sorted(t for t in rows.get((key_f, "REFN"), {}) if t > start + 1e-9)
    if not times:
        raise ModelError(f"no reactions of the slide step in {dat.name}")

    def stack(kind, name):
        d = rows[(kind, name)]
        return np.array([d[t] for t in times])

    return History(
        time=np.array(times) - start,
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
    base: Base,
    name: str,
    kin: rd.Kinematics,
    rim_travel: float,
    workdir: Path,
    exe: str,
    inc: float,
    tire: rd.RigTire = rd.SMALL,
) -> RunResult:
    """Write the run's deck, solve it from the base's restart file (or reuse it) and read it."""
    workdir.mkdir(parents=True, exist_ok=True)
    inp = workdir / f"{name}.inp"
    rd.write_slide_deck(inp, mesh, kin, rim_travel, base.nodes.ref_xy, inc, tire)
    shutil.copyfile(base.restart, inp.with_suffix(".rin"))
    runtime = _solve_once(exe, inp, base.deck_sha256, tire.timeout)
    contact, u = _nodal(mesh, inp.with_suffix(".frd"))
    return RunResult(
        name=name,
        kin=kin,
        nodes=base.nodes,
        history=_history(inp.with_suffix(".dat"), tire.slide_start),
        static_load=base.static_load,
        static_cpress=base.static_cpress,
        static_u=base.static_u,
        contact=contact,
        u=u,
        runtime_s=runtime,
        base_runtime_s=base.runtime_s,
        deck_sha256=hashlib.sha256(inp.read_bytes() + base.deck_sha256.encode()).hexdigest(),
        dat_excerpt=_excerpt(inp.with_suffix(".dat")),
        cpu_s=cpu_of(inp),
        base_cpu_s=base.cpu_s,
    )
