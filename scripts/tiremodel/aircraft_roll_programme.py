"""The rolling programme of the aircraft tire: free rolling, then braking and driving slips.

Runs (all at the rated-load rim travel, axle travel 0.75 m = 1.6 patch lengths):

- ``roll_free``: free rolling, the rim driven through a soft torsion spring (not torque-free:
  the spring's torque is in the sidecar); its steady turn per travel gives the effective
  rolling radius R_e;
- ``roll_brake<k>`` / ``roll_drive<k>``: imposed slip kappa = -k/100 / +k/100,
  the rim turned by theta = (1 + kappa) X / R_e while the axle travels X.

Order: free rolling first (every other deck needs its R_e), then the largest
braking and driving slips, then the intermediate ones. The runs are Dask
tasks (``fepost.sweep.engine.Cluster``: an embedded local cluster of one
worker by default, or ``--scheduler ADDRESS``); each task solves its run in
``work/<run>/`` and writes its files into ``out`` at once; the client logs the
progress. Resume rule: a run whose ``<run>.json`` is there with the sha256 of
the deck it would now write (and its .vtu and .dat.txt beside it) is skipped;
any other state (no sidecar, another deck, a missing file) is redone, reusing
a finished CalculiX solve of the same deck in the work folder.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from . import aircraft_roll_deck as rdk
from .aircraft_geometry import AircraftMesh
from .aircraft_roll_mesh import RollMeshSpec, build_roll_mesh

# run order after free rolling: the largest levels, then the small ones that bracket Fx = 0
SLIPS = (-0.20, 0.20, -0.01, 0.01, -0.04, 0.04)
STATIC_NAME = "roll_static"


@dataclass(frozen=True)
class Setup:
    """What every run of a programme shares: travels, samples, road and mesh."""

    rim_travel: float = 0.1209  # m: the aircraft set's rated-load rim travel (aircraft/rolling_100.json)
    travel: float = 0.75  # m, axle travel: 1.6 x the 0.47 m patch length at the rated load
    samples: int = 10
    road_length: float = 1.6
    mesh: RollMeshSpec = field(default_factory=RollMeshSpec)

    radius_guess: float = 0.556  # m, estimate of R_e for the free run's driver
    drive_stiffness: float = 3.0e4  # N m/rad, half model: the free run's torsion spring

    slip_max_inc: float = 0.1  # the slip runs' largest increment (38 mm of travel; free run 0.05)

    def plan(self, rotation: float | None) -> rdk.RollPlan:
        """Imposed turn ``rotation``; None: the free run's elastic drive."""
        if rotation is None:
            turn, k = self.travel / self.radius_guess, self.drive_stiffness
            return rdk.RollPlan(self.rim_travel, self.travel, turn, self.samples, self.road_length, 0.3, k)
        return rdk.RollPlan(
            self.rim_travel, self.travel, rotation, self.samples, self.road_length, max_inc=self.slip_max_inc
        )


AIRCRAFT = Setup()


@dataclass(frozen=True)
class RunSpec:
    name: str
    slip: float | None  # None: free rolling

    def plan(self, effective_radius: float | None, setup: Setup) -> rdk.RollPlan:
        if self.slip is None:
            return setup.plan(None)
        if effective_radius is None:
            raise ValueError(f"{self.name}: needs the free-rolling run's effective radius")
        return setup.plan((1.0 + self.slip) * setup.travel / effective_radius)

    def description(self, setup: Setup) -> str:
        head = (
            "quasi-static rolling of the aircraft tire: inflation, vertical rim travel "
            f"{1e3 * setup.rim_travel:.1f} mm, then {setup.travel:g} m of axle travel with the rim "
            "turning about the axle"
        )
        if self.slip is None:
            return head + (
                "; free rolling approximated by an elastic drive (a soft torsion spring turned at a "
                "guessed rate): not torque-free, the spring's torque is axle_torque_Nm"
            )
        kind = "braking" if self.slip < 0 else "driving"
        return head + f"; {kind}, imposed longitudinal slip {self.slip:+g} (rim turn prescribed)"


def run_name(slip: float | None) -> str:
    if slip is None:
        return "roll_free"
    return f"roll_{'brake' if slip < 0 else 'drive'}{round(abs(slip) * 100):02d}"


def programme(slips: tuple[float, ...] = SLIPS) -> list[RunSpec]:
    return [RunSpec(run_name(None), None), *(RunSpec(run_name(s), s) for s in slips)]


def finished(out: Path, name: str, deck_sha256: str) -> bool:
    """A run is finished when its sidecar holds this deck's sha256 and its other files exist."""
    try:
        side = json.loads((out / f"{name}.json").read_text())
    except (OSError, ValueError):
        return False
    files = all((out / f"{name}{ext}").is_file() for ext in (".vtu", ".dat.txt"))
    return files and side.get("deck_sha256") == deck_sha256


def effective_radius(out: Path) -> float | None:
    """R_e of the finished free-rolling run (its sidecar), None before it exists."""
    try:
        side = json.loads((out / f"{run_name(None)}.json").read_text())
    except (OSError, ValueError):
        return None
    return float(side["effective_rolling_radius_m"])


def _log(msg: str) -> None:
    print(f"{time.strftime('%H:%M:%S')} roll: {msg}", file=sys.stderr, flush=True)


@dataclass(frozen=True)
class Task:
    """Everything a worker needs for one run (picklable)."""

    spec: RunSpec
    plan: rdk.RollPlan
    setup: Setup
    mesh: AircraftMesh  # meshed by the client: gmsh needs the main thread
    out: Path
    work: Path
    effective_radius: float | None  # None for the free run: it measures its own


def solve_and_export(task: Task) -> dict:
    """Solve (or reuse) one run and write its files; returns the summary the client logs."""
    from .aircraft_roll_export import steady_turn_rate, write_rolling, write_static
    from .aircraft_roll_run import solve
    from .solve import ccx_version, find_ccx

    exe = find_ccx()
    mesh = task.mesh
    name = task.spec.name
    result = solve(exe, ccx_version(exe), mesh, name, task.plan, task.work / name)
    task.out.mkdir(parents=True, exist_ok=True)
    radius = task.effective_radius
    if task.spec.slip is None:
        radius = 1.0 / steady_turn_rate(result)
        write_static(mesh, result, task.out, STATIC_NAME)
    side = write_rolling(mesh, result, task.out, name, radius, task.spec.description(task.setup))
    return {k: side[k] for k in ("case", "longitudinal_slip", "axle_torque_Nm", "runtime_s")} | {
        "Fx": side["reaction"]["force"][0],
        "Fz": side["reaction"]["force"][2],
    }


def _tasks(specs, out, work, setup: Setup, deck_sha) -> tuple[list[Task], list[str]]:
    """(runs to do, runs skipped) for the runs whose deck can be written now."""
    from .aircraft_roll_run import deck_text

    mesh = build_roll_mesh(setup.mesh)
    return runs_to_do(
        specs,
        (out, work, setup, mesh),
        deck_sha,
        deck_text=deck_text,
        task_cls=Task,
        radius=effective_radius(out),
        finished_fn=finished,
    )


def runs_to_do(specs, where, deck_sha, *, deck_text, task_cls, radius, finished_fn) -> tuple[list, list[str]]:
    """(tasks to run, names of the runs finished earlier with the same deck).

    ``where`` = (out, work, setup, mesh). A slip waits for the free run's effective ``radius``
    (None: not known yet); a run whose deck hash (``deck_sha(spec, plan)``, or of the deck
    ``deck_text`` writes) its finished sidecar holds (``finished_fn(out, name, sha)``) is
    skipped; the others become ``task_cls(spec, plan, setup, mesh, out, work, radius)``.
    Shared with `aircraft_roll360_programme`."""
    from .aircraft_roll_run import sha256_text

    out, work, setup, mesh = where
    todo, skipped = [], []
    for spec in specs:
        if spec.slip is not None and radius is None:
            continue
        plan = spec.plan(radius, setup)
        tmp = work / f".{spec.name}.tmp"
        sha = deck_sha(spec, plan) if deck_sha else sha256_text(deck_text(mesh, plan, tmp)[0])
        if finished_fn(out, spec.name, sha):
            skipped.append(spec.name)
        else:
            todo.append(task_cls(spec, plan, setup, mesh, out, work, None if spec.slip is None else radius))
    return todo, skipped


def run_programme(
    out: Path,
    work: Path,
    specs: list[RunSpec] | None = None,
    setup: Setup = AIRCRAFT,
    scheduler: str | None = None,
    task_fn: Callable[[Task], dict] = solve_and_export,
    deck_sha: Callable[[RunSpec, rdk.RollPlan], str] | None = None,
    processes: bool = True,
) -> list[str]:
    """Run the programme (free rolling first); return the names of the runs done now.

    ``task_fn`` and ``deck_sha`` replace the solve and the deck's hash (tests: a
    fake solver, no CalculiX).
    """
    specs = programme() if specs is None else specs
    work.mkdir(parents=True, exist_ok=True)
    return run_phases(
        specs,
        lambda chosen: _tasks(chosen, out, work, setup, deck_sha),
        task_fn,
        "roll",
        scheduler=scheduler,
        processes=processes,
    )


def run_phases(
    specs,
    make_tasks,
    task_fn,
    prefix: str,
    *,
    scheduler: str | None,
    processes: bool,
    log=None,
    workers: int = 1,
) -> list[str]:
    """The free run(s) of ``specs`` first, then the slips (they need its effective radius), as
    Dask tasks on one embedded worker or on ``scheduler``; the names of the runs done now.

    ``make_tasks(chosen specs)`` gives (tasks to run, names finished earlier); each task's
    ``spec.name`` keys it (``prefix-name``). A failed free run stops the programme (the slips'
    decks need its radius); a failed slip is logged and the others go on. Shared by this
    programme and the whole tire's (`aircraft_roll360_programme`); ``workers``: embedded workers
    (one thread each)."""
    from fepost.sweep.engine import Cluster

    log = log or _log
    done_now: list[str] = []
    with Cluster(workers=None if scheduler else workers, scheduler=scheduler, processes=processes) as cluster:
        for phase in ("free", "slip"):
            chosen = [s for s in specs if (s.slip is None) == (phase == "free")]
            todo, skipped = make_tasks(chosen)
            for name in skipped:
                log(f"{name}: finished earlier with the same deck, skipped")
            if not todo:
                continue
            futures = [
                cluster.client.submit(task_fn, t, key=f"{prefix}-{t.spec.name}", pure=False, priority=-i)
                for i, t in enumerate(todo)
            ]
            log(f"{phase}: {len(todo)} run(s) submitted: {', '.join(t.spec.name for t in todo)}")
            failed = []
            for k, (fut, res) in enumerate(cluster.as_completed(futures), start=1):
                name = fut.key.removeprefix(f"{prefix}-")
                if isinstance(res, BaseException):
                    failed.append(name)
                    log(
                        f"[{k}/{len(todo)}] {name}: FAILED: {str(res).splitlines()[0] if str(res) else res!r}"
                    )
                    continue
                done_now.append(name)
                log(f"[{k}/{len(todo)}] {name}: saved ({json.dumps(res)})")
            if phase == "free" and failed:
                raise RuntimeError("the free-rolling run failed: the slip runs need its effective radius")
    return done_now
