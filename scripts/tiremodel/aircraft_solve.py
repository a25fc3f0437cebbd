"""Run the aircraft-tire decks with CalculiX and collect the results step by step.

One CalculiX run holds several load steps (inflation, then one step per rim
travel); every converged increment prints the road reaction and the rim
travel, so each run also yields the load-deflection curve at increment
resolution (used to plan the rim travels that hit the target loads).
Runs are started ``nice``-d with one thread each, at most ``jobs`` at a time.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import aircraft_deck as ad
from .aircraft_geometry import AircraftMesh
from .frd import read_dat_blocks, read_frd
from .solve import ModelError, ccx_version, find_ccx, run_ccx


@dataclass(frozen=True)
class StepState:
    """The final increment of one analysis step (half model, y >= 0)."""

    name: str
    displacement: np.ndarray  # (n_tire, 3), m
    cpress: np.ndarray  # (n_tire,), Pa, >= 0
    road_force: np.ndarray  # (3,), N, total reaction on the road nodes (half model)
    rim_displacement: np.ndarray  # (3,), m, rim reference node


@dataclass(frozen=True)
class RunResult:
    name: str
    steps: tuple[StepState, ...]  # inflation first
    curve_travel: np.ndarray  # downward rim travel at every converged increment, m
    curve_force: np.ndarray  # road reaction z (half model) at every converged increment, N
    curve_travel_x: np.ndarray  # rim travel along x at every converged increment, m
    runtime_s: float
    solver: str
    deck: ad.DeckInfo

    def step(self, name: str) -> StepState:
        for s in self.steps:
            if s.name == name:
                return s
        raise KeyError(name)


_PARSE_LOCK = threading.Lock()


def _finished(workdir: Path, name: str, deck: str) -> float | None:
    """Run time of an earlier, completed run of exactly this deck in ``workdir``, else None."""
    inp, stamp = workdir / f"{name}.inp", workdir / f"{name}.runtime"
    try:
        same = inp.read_text() == deck
        done = "Job finished" in (workdir / f"{name}.log").read_text(errors="replace")
        seconds = float(stamp.read_text())
    except (OSError, ValueError):
        return None
    if same and done and (workdir / f"{name}.frd").exists() and (workdir / f"{name}.dat").exists():
        return seconds
    return None


def _solve(exe: str, workdir: Path, name: str, timeout: float) -> float:
    seconds = run_ccx(exe, workdir / f"{name}.inp", threads=1, timeout=timeout, niceness=10)
    (workdir / f"{name}.runtime").write_text(f"{seconds:.1f}\n")
    return seconds


def run_decks(
    mesh: AircraftMesh,
    plans: dict[str, list[ad.Stage]],
    workdir: Path,
    jobs: int = 2,
    timeout: float = 3 * 3600.0,
    tolerances: dict[str, tuple[float, float | None]] | None = None,
) -> dict[str, RunResult]:
    """Write and solve one deck per plan (``jobs`` at a time); parse every output.

    A run whose deck is identical to a completed earlier run in ``workdir`` is
    not solved again (a build interrupted half-way resumes where it stopped).
    ``tolerances`` gives relaxed (residual, correction) tolerances per plan
    (see ``aircraft_deck.write_aircraft_deck``).
    """
    exe = find_ccx()
    workdir.mkdir(parents=True, exist_ok=True)
    infos, times, todo = {}, {}, []
    for name, steps in plans.items():
        deck_path = workdir / f"{name}.deck.tmp"
        tol = (tolerances or {}).get(name, (None, None))
        infos[name] = ad.write_aircraft_deck(deck_path, mesh, steps, *tol)
        deck = deck_path.read_text()
        deck_path.unlink()
        done = _finished(workdir, name, deck)
        if done is None:
            (workdir / f"{name}.inp").write_text(deck)
            todo.append(name)
        else:
            times[name] = done
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = {name: pool.submit(_solve, exe, workdir, name, timeout) for name in todo}
        times.update({name: f.result() for name, f in futures.items()})
    solver = ccx_version(exe)
    with _PARSE_LOCK:  # ccx2paraview keeps the node renumbering in module state
        return {
            name: _collect(mesh, workdir / f"{name}.inp", name, infos[name], times[name], solver)
            for name in plans
        }


def _at_time(records, t: float, what: str, job: str) -> np.ndarray:
    for time_, value in records:
        if abs(time_ - t) < 1e-6:
            return value
    raise ModelError(f"{job}: no {what} printed at analysis time {t:g}")


def _collect(mesh: AircraftMesh, inp: Path, name: str, info: ad.DeckInfo, runtime: float, solver: str):
    nt = mesh.nodes.shape[0]
    res = read_frd(inp.with_suffix(".frd"), every=True)
    if res.node_ids[:nt].tolist() != list(range(1, nt + 1)):
        raise ModelError("unexpected node numbering in the .frd file")
    blocks = read_dat_blocks(inp.with_suffix(".dat"))
    road = [(b[2], b[3][0]) for b in blocks if b[0] == "total force" and b[1] == "ROADN"]
    # rim displacement relative to the road = -(road block displacement)
    rim = [(b[2], -b[3][0, 1:4]) for b in blocks if b[0] == "displacements" and b[1] == "ROADREF"]
    if not road or len(road) != len(rim):
        raise ModelError(f"{inp.stem}: road force and road displacement records do not match")
    states = []
    for case, t in info.output_times.items():
        store = next((blk for time_, blk in res.every if abs(time_ - t) < 1e-6), None)
        if store is None or "U" not in store:
            raise ModelError(f"{inp.stem}: no results at analysis time {t:g} ({case})")
        u = store["U"][1][:nt]
        rim_u = np.asarray(_at_time(rim, t, "road displacement", inp.stem), dtype=float)
        if case == "inflation" or "CONTACT" not in store:
            cp = np.zeros(nt)
        else:
            comps, c = store["CONTACT"]
            cp = np.clip(c[:nt, comps.index("CPRESS")], 0.0, None)
        states.append(
            StepState(
                name=case,
                # in the road's frame the road is at rest and the rim moves by rim_u
                displacement=u + rim_u[None, :],
                cpress=cp,
                road_force=np.asarray(_at_time(road, t, "road force", inp.stem), dtype=float),
                rim_displacement=rim_u,
            )
        )
    rim_arr = np.array([v for _, v in rim])
    return RunResult(
        name=name,
        steps=tuple(states),
        curve_travel=-rim_arr[:, 2],
        curve_force=np.array([f[2] for _, f in road]),
        curve_travel_x=rim_arr[:, 0],
        runtime_s=runtime,
        solver=solver,
        deck=info,
    )


def inflated_clearance(mesh: AircraftMesh, inflated: StepState) -> float:
    """Gap between the inflated tread and the road (m): rim travel at first contact."""
    slave = np.unique(mesh.contact_quads)
    z = mesh.nodes[slave, 2] + inflated.displacement[slave, 2]
    return float(z.min())


def travel_for_loads(travel: np.ndarray, force: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Rim travels at which the (monotonic part of the) load curve reaches ``targets``.

    Linear interpolation between converged increments of a previous run; a
    target beyond the curve is extrapolated with the last secant.
    """
    t = np.asarray(travel, dtype=float)
    f = np.asarray(force, dtype=float)
    keep = f > 0
    t, f = t[keep], f[keep]
    order = np.argsort(t)
    t, f = t[order], f[order]
    f_mono = np.maximum.accumulate(f)
    out = []
    for target in np.atleast_1d(targets):
        if target <= f_mono[-1]:
            out.append(float(np.interp(target, f_mono, t)))
        else:
            slope = (f_mono[-1] - f_mono[-2]) / (t[-1] - t[-2])
            out.append(float(t[-1] + (target - f_mono[-1]) / slope))
    return np.array(out)
