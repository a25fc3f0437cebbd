"""Run CalculiX on the tire decks and collect the results of one load case."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import deck as dk
from .frd import read_dat_totals, read_frd
from .geometry import TireMesh


class ModelError(RuntimeError):
    """A problem the CLI reports in one line (missing solver, no convergence...)."""


def find_ccx() -> str:
    exe = shutil.which("ccx")
    if exe is None:
        raise ModelError("CalculiX solver 'ccx' not found on PATH (Debian: apt-get install calculix-ccx)")
    return exe


def ccx_version(exe: str) -> str:
    try:
        out = subprocess.run([exe, "-v"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return "CalculiX (version unknown)"
    for line in out.splitlines():
        m = re.search(r"Version\s+(\S+)", line)
        if m:
            return f"CalculiX {m.group(1)}"
    return "CalculiX (version unknown)"


def run_ccx(exe: str, inp: Path, threads: int = 2, timeout: float = 1800.0, niceness: int = 0) -> float:
    """Run ``ccx -i <job>`` in the deck's folder; return the wall time (s).

    The solver's CPU time (user + system, s) is written beside the deck as ``<job>.cpu``.

    ``threads``: OpenMP and equation-solver threads; ``niceness`` > 0 starts
    ccx through ``nice -n``. The solver's output goes to ``<job>.log``; raises
    ModelError on a timeout, a non-zero exit, an ``*ERROR`` line or a run that
    did not finish.
    """
    job = inp.with_suffix("")
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
    cmd = [exe, "-i", job.name]
    if niceness > 0:
        cmd = ["nice", "-n", str(niceness), *cmd]
    t0 = time.perf_counter()
    log = inp.with_suffix(".log")
    with open(log, "w") as fh:
        proc = subprocess.Popen(cmd, cwd=inp.parent, stdout=fh, stderr=subprocess.STDOUT, env=env)
        returncode, cpu = _wait_cpu(proc, timeout)
    if returncode is None:
        raise ModelError(f"ccx run {job.name} exceeded {timeout:.0f} s")
    dt = time.perf_counter() - t0
    inp.with_suffix(".cpu").write_text(f"{cpu:.1f}\n")
    text = log.read_text(errors="replace")
    if "*ERROR" in text or returncode != 0 or "Job finished" not in text:
        msg = next((ln.strip() for ln in text.splitlines() if "*ERROR" in ln), "")
        raise ModelError(
            f"ccx run {job.name} did not converge or failed (exit {returncode}) {msg}; see {log}".replace(
                "  ", " "
            )
        )
    return dt


def _wait_cpu(proc: subprocess.Popen, timeout: float) -> tuple[int | None, float]:
    """(exit status, user + system CPU seconds) of ``proc``; (None, CPU) after killing it on a
    timeout. The CPU time is the solver's own (``os.wait4``; ``nice`` execs ccx in place)."""
    t0 = time.perf_counter()
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            proc.returncode = os.waitstatus_to_exitcode(status)
            return proc.returncode, usage.ru_utime + usage.ru_stime
        if time.perf_counter() - t0 > timeout:
            proc.kill()
            _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = os.waitstatus_to_exitcode(status)
            return None, usage.ru_utime + usage.ru_stime
        time.sleep(0.2)


@dataclass
class CaseResult:
    case: dk.LoadCase
    mesh: TireMesh
    displacement: np.ndarray  # (n_tire, 3) final step
    cpress: np.ndarray  # (n_tire,) Pa, >= 0
    copen: np.ndarray  # (n_tire,)
    road_force: np.ndarray  # total reaction force on the road nodes, final time (N)
    bead_force: np.ndarray  # total reaction force on the rim (bead) nodes, final time (N)
    rim_travel: float
    inflated_clearance: float
    runtime_s: float
    solver: str
    deck_info: dict = field(default_factory=dict)
    step_forces: list = field(default_factory=list)


def _final_totals(dat: Path, name: str) -> np.ndarray:
    rec = [r for r in read_dat_totals(dat) if r[0] == name]
    if not rec:
        raise ModelError(f"no total force records for set {name} in {dat.name}")
    return rec[-1][2]


def solve_case(
    mesh: TireMesh,
    case: dk.LoadCase,
    workdir: Path,
    threads: int = 2,
    increments: str = dk.FINE_INC,
) -> CaseResult:
    """Inflate (a pre-run that finds the inflated clearance), then solve ``case``: the rim
    moved ``case.deflection`` beyond first contact, ``increments`` the ``*STATIC`` line of its load steps."""
    exe = find_ccx()
    workdir.mkdir(parents=True, exist_ok=True)
    nt = mesh.nodes.shape[0]
    t_total = 0.0
    # 1) inflation only: where does the inflated crown sit?
    inp0 = workdir / f"{case.name}_inflate.inp"
    dk.write_deck(inp0, mesh, case, 0.0, inflation_only=True)
    t_total += run_ccx(exe, inp0, threads)
    r0 = read_frd(inp0.with_suffix(".frd"))
    _, u0 = r0.field(max(r0.last), "U")
    slave = np.unique(mesh.contact_quads)
    z_infl = (mesh.nodes[slave, 2] + u0[slave, 2]).min()
    if z_infl <= 0.0:
        raise ModelError("inflated tire already touches the road; increase the initial clearance")
    if np.abs(_final_totals(inp0.with_suffix(".dat"), "ROADN")).max() > 1e-6:
        raise ModelError("contact force during inflation")
    rim_travel = float(z_infl + case.deflection)
    # 2) the load case
    inp = workdir / f"{case.name}.inp"
    info = dk.write_deck(inp, mesh, case, rim_travel, increments=increments)
    t_total += run_ccx(exe, inp, threads)
    res = read_frd(inp.with_suffix(".frd"))
    last = max(res.last)
    _, u = res.field(last, "U")
    comps, c = res.field(last, "CONTACT")
    if res.node_ids[:nt].tolist() != list(range(1, nt + 1)):
        raise ModelError("unexpected node numbering in the .frd file")
    u = u[:nt]
    cp = c[:nt, comps.index("CPRESS")]
    co = c[:nt, comps.index("COPEN")]
    dat = inp.with_suffix(".dat")
    road_f = _final_totals(dat, "ROADN")
    bead_f = _final_totals(dat, "BEAD")
    return CaseResult(
        case=case,
        mesh=mesh,
        displacement=u,
        cpress=np.clip(cp, 0.0, None),
        copen=co,
        road_force=road_f,
        bead_force=bead_f,
        rim_travel=rim_travel,
        inflated_clearance=float(z_infl),
        runtime_s=t_total,
        solver=ccx_version(exe),
        deck_info=info,
    )
