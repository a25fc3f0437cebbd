"""The whole tire's rolling programme: imposed slips about a reference radius, or about a free rim's.

Runs (half model of the whole 360-degree tire, ``aircraft_roll360_deck``; rim travel 120.7 mm:
the mesh's 18.4 mm inflated clearance + the static sweep's rated-load deflection of 102.3 mm).
Two ways to find free rolling:

- **driven** (``--reference-radius R``, the fine mesh's way): every run turns the rim by
  (1 + kappa_ref) X / R, kappa_ref from ``--slips`` (named ``roll_ref`` for 0,
  ``roll_brake<k>`` / ``roll_drive<k>`` for -k/1000 / +k/1000). Free rolling is where the axle
  torque is zero: ``free_rolling`` interpolates the steady torques against the turn per travel,
  which gives R_e, and re-expresses each run's slip against it (``--table``);
- **free rim** (no reference radius): ``roll_free`` leaves the rim free to turn about the axle
  (no torque, no driver); its steady turn per travel over the last fifth of the roll gives R_e,
  and the slips are imposed against that R_e.

Why both: the sector's free run was driven through a torsion spring whose driver turned 2.4 %
fast (1.87 kN m on the rim). The free rim (turn held during inflation and loading, released
for the roll) converges on the tiny deck at a residual torque of a few N m; on the fine mesh it
did not: at 2.5 % of the roll the residual flipped between two contact nodes (5-10 N against the
criterion's 0.85 N: 0.005 of an average nodal force of 170 N) while the increment fell to 4e-5
of the roll. With the turn imposed the rim's rotation is no unknown held by friction alone.

The runs are Dask tasks (``fepost.sweep.engine.Cluster``, one worker each), each solved in
``work/<run>/`` on one thread (``nice -n 5``). Resume rule: a run whose ``<run>.json`` holds the
sha256 of the deck it would now write and the current export version (its .vtu and .dat.txt
beside it) is skipped; any other state is redone, reusing a finished CalculiX solve of the same
deck in the work folder (an older export is thus written again without a new solve).

``python -m scripts.tiremodel.aircraft_roll360_programme --work DIR [--out DIR] [--mesh fine|mid|tiny]
[--travel M] [--reference-radius R --slips K ...] [--workers W] [--only RUN ...] [--scheduler ADDRESS]``
runs it; ``--table`` prints the finished runs (slip, Fx/N, torque, steadiness, balance), free
rolling found from them and the brush estimate of the initial slope.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from . import aircraft_roll360_deck as r3
from . import aircraft_roll360_results as results
from .aircraft_roll_programme import run_phases, runs_to_do

#: braking (< 0) and driving slips, in run order: small ones first
SLIPS = (-0.01, 0.01, -0.03, 0.03, -0.10, 0.10)
#: the driven programme's slips against its reference radius: wide enough to straddle free rolling
#: when the reference is off by up to 2 %, small enough for the slip curve's initial part (the
#: brush estimate's theta = C kappa / 3 f N is 0.24 at 0.02)
DRIVEN_SLIPS = (-0.02, 0.02, 0.0)
#: m: the fine mesh's reference radius, an estimate of R_e before any run: the sector rig's
#: measured effective rolling radius at the same deflection (meshes/rig-aircraft/roll)
REFERENCE_RADIUS = 0.5694
FREE = "roll_free"
STATIC = results.STATIC
OUT = Path(__file__).resolve().parents[2] / "meshes" / "rig-tire360" / "roll"
RIG = OUT.parent


@dataclass(frozen=True)
class Setup:
    """What every run of a programme shares."""

    mesh_kind: str = "fine"
    # m: this mesh's inflated clearance (18.41 mm at the end of the inflation of roll_free) plus the
    # static sweep's rated-load deflection 102.3 mm. (At 124.1 mm, the whole rig tire's travel for
    # its own 21.77 mm clearance, the deflection was 105.7 mm and the load 208.4 kN.)
    rim_travel: float = 0.12071
    travel: float = 1.6  # m of axle travel
    print_every: float = 0.05  # analysis time (the roll takes 2): 40 mm of travel at 1.6 m
    frames: int = 4
    tolerances: tuple[float, float] = r3.TOLERANCES
    #: m: None: the free rim finds R_e (``roll_free``); a number: every run is driven against it
    reference_radius: float | None = None

    def plan(self, rotation: float | None, prewind: float = 0.0) -> r3.Plan:
        return r3.Plan(
            self.rim_travel,
            self.travel,
            rotation,
            self.print_every,
            self.frames,
            self.tolerances,
            prewind=prewind,
        )


@dataclass(frozen=True)
class RunSpec:
    name: str
    slip: float | None  # None: the free rim
    #: rad, the rim's extra turn at the roll's start (``aircraft_roll360_deck.Plan.prewind``)
    prewind: float = 0.0

    def plan(self, radius: float | None, setup: Setup) -> r3.Plan:
        if self.slip is None:
            return setup.plan(None)
        if radius is None:
            raise ValueError(f"{self.name}: needs the free-rolling run's effective radius")
        return setup.plan(r3.turn_for(setup.travel, radius, self.slip), self.prewind)

    def labels(self, setup: Setup, radius: float | None) -> dict:
        head = (
            f"quasi-static rolling of the whole aircraft tire (half model, symmetry plane y = 0, "
            f"mesh '{setup.mesh_kind}'): inflation, {1e3 * setup.rim_travel:.1f} mm rim travel, then "
            f"{setup.travel:g} m of axle travel"
        )
        if self.slip is None:
            return {
                "description": head + "; free rolling: the rim free to turn (no torque on it)",
                "imposed": "axle travel only; the rim's turn is free (held during inflation and load)",
                "effective_rolling_radius_m": radius,
                "effective_rolling_radius_source": "this run: dX/dtheta over the last fifth of its roll",
                "slip_radius_m": radius,
                "slip_radius_source": "this run's effective rolling radius (its slip is 0 by definition)",
            }
        if setup.reference_radius is not None:
            kind = (
                "driven at the reference radius"
                if self.slip == 0
                else ("braking" if self.slip < 0 else "driving")
            )
            wind = (
                f", wound by {self.prewind:+.5g} rad over the roll's first {100 * r3.PREWIND_SHARE:g} % "
                "(the carcass set near its steady wind-up)"
                if self.prewind
                else ""
            )
            return {
                "description": head + f"; {kind}: the rim turned at the slip {self.slip:+g} against "
                f"the reference radius {setup.reference_radius:g} m (an estimate, not R_e){wind}",
                "imposed": f"rim turn (1 {self.slip:+g}) X / R_ref, linear in the axle travel X"
                + (f", plus {self.prewind:+.5g} rad at the start" if self.prewind else ""),
                "prewind_rad": self.prewind,
                "imposed_slip": self.slip,
                "slip_radius_m": radius,
                "slip_radius_source": "the programme's reference radius R_ref (an estimate of R_e): "
                "free rolling is where the axle torque vanishes (free_rolling), which gives R_e and "
                "each run's slip against it",
            }
        kind = "braking" if self.slip < 0 else "driving"
        return {
            "description": head + f"; {kind} at the imposed longitudinal slip {self.slip:+g}",
            "imposed": f"rim turn (1 {self.slip:+g}) X / R_e, linear in the axle travel X",
            "imposed_slip": self.slip,
            "effective_rolling_radius_m": radius,
            "effective_rolling_radius_source": f"{FREE}.json (the free rim's dX/dtheta)",
            "slip_radius_m": radius,
            "slip_radius_source": f"{FREE}.json (the free rim's effective rolling radius)",
        }


def run_name(slip: float | None, prewind: float = 0.0) -> str:
    """``roll_free``, ``roll_ref``, ``roll_brake<k>`` / ``roll_drive<k>`` (k = 1000 |slip|); a
    pre-wound run ends in ``w``."""
    if slip is None:
        return FREE
    if slip == 0:
        name = "roll_ref"
    else:
        name = f"roll_{'brake' if slip < 0 else 'drive'}{round(abs(slip) * 1000):03d}"
    return name + ("w" if prewind else "")


def programme(slips: tuple[float, ...] = SLIPS, free: bool = True, prewind: float = 0.0) -> list[RunSpec]:
    """The runs in solving order: the free rim first (``free``), then the imposed slips (each wound
    by ``prewind`` at its start when given)."""
    return [
        *([RunSpec(FREE, None)] if free else []),
        *(RunSpec(run_name(s, prewind), s, prewind) for s in slips),
    ]


def finished(out: Path, name: str, deck_sha256: str) -> bool:
    """A run is finished when its sidecar holds this deck's sha256 and the current export version
    and its .vtu and .dat.txt exist (an older export is redone from its finished solve)."""
    from .aircraft_roll360_run import EXPORT_VERSION

    try:
        side = json.loads((out / f"{name}.json").read_text())
    except (OSError, ValueError):
        return False
    files = all((out / f"{name}{ext}").is_file() for ext in (".vtu", ".dat.txt"))
    current = side.get("export_version") == EXPORT_VERSION
    return files and current and side.get("deck_sha256") == deck_sha256


def effective_radius(out: Path) -> float | None:
    """R_e of the finished free run (its sidecar), None before it exists."""
    try:
        return float(json.loads((out / f"{FREE}.json").read_text())["effective_rolling_radius_m"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _log(msg: str) -> None:
    print(f"{time.strftime('%H:%M:%S')} roll360: {msg}", file=sys.stderr, flush=True)


@dataclass(frozen=True)
class Task:
    """Everything a worker needs for one run (picklable; the mesh from the client: gmsh)."""

    spec: RunSpec
    plan: r3.Plan
    setup: Setup
    mesh: r3.Roll360Mesh
    out: Path
    work: Path
    radius: float | None


def solve_and_export(task: Task) -> dict:
    """Solve (or reuse) one run and write its files; the summary the client logs."""
    from .aircraft_roll360_run import solve, steady_turn_rate, write_run, write_static
    from .solve import find_ccx

    result = solve(find_ccx(), task.mesh, task.spec.name, task.plan, task.work / task.spec.name)
    task.out.mkdir(parents=True, exist_ok=True)
    radius = task.radius
    if task.spec.slip is None:
        radius = 1.0 / steady_turn_rate(result.history)
    driven = task.setup.reference_radius is not None
    if task.spec.slip is None or (driven and not (task.out / f"{STATIC}.json").is_file()):
        # the static partner of the maps: the free run's, or (driven: every run's first step is the
        # same deck, so the same map) the first finished run's, kept as it is by the runs after it
        write_static(task.mesh, result, task.out, STATIC)
    side = write_run(task.mesh, result, task.out, task.spec.name, task.spec.labels(task.setup, radius))
    return {
        "slip": side["longitudinal_slip"],
        "Fx/N": side["longitudinal_force_ratio"],
        "torque_Nm": side["axle_torque_tail_mean_Nm"],
        "steady": side["steadiness"]["steady"],
        "cpu_s": side["cpu_s"],
    }


def _tasks(specs, out: Path, work: Path, setup: Setup, mesh, deck_sha) -> tuple[list[Task], list[str]]:
    from .aircraft_roll360_run import deck_text

    return runs_to_do(
        specs,
        (out, work, setup, mesh),
        deck_sha,
        deck_text=deck_text,
        task_cls=Task,
        radius=effective_radius(out) if setup.reference_radius is None else setup.reference_radius,
        finished_fn=finished,
    )


def run_programme(
    out: Path,
    work: Path,
    specs: list[RunSpec] | None = None,
    setup: Setup = Setup(),
    scheduler: str | None = None,
    task_fn: Callable[[Task], dict] = solve_and_export,
    deck_sha: Callable[[RunSpec, r3.Plan], str] | None = None,
    processes: bool = True,
    mesh=None,
    workers: int = 1,
) -> list[str]:
    """Run the programme (the free run first: the slips need its R_e); the runs done now.

    ``task_fn``, ``deck_sha`` and ``mesh`` replace the solve, the deck's hash and the mesh (tests).
    """
    specs = programme() if specs is None else specs
    mesh = r3.build_mesh(setup.mesh_kind) if mesh is None else mesh
    work.mkdir(parents=True, exist_ok=True)
    return run_phases(
        specs,
        lambda chosen: _tasks(chosen, out, work, setup, mesh, deck_sha),
        task_fn,
        "roll360",
        scheduler=scheduler,
        processes=processes,
        log=_log,
        workers=workers,
    )


def progress(work: Path) -> list[str]:
    """The printed records so far of every run in the work folder (a run still solving included)."""
    from .aircraft_roll360_run import read_history
    from .solve import ModelError

    lines = []
    for dat in sorted(work.glob("*/*.dat")):
        try:
            h = read_history(dat)
        except (ModelError, OSError, ValueError) as exc:
            lines.append(f"{dat.stem}: {exc}")
            continue
        lines.append(f"{dat.stem}: travel m, turn rad, Fx N, Fz N, axle torque N m (whole tire)")
        lines += [
            f"  {x:7.4f} {th:8.5f} {f[0]:10.1f} {f[2]:10.1f} {t:9.2f}"
            for x, th, f, t in zip(h.axle_travel, h.rotation, h.road, h.torque, strict=True)
        ]
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m scripts.tiremodel.aircraft_roll360_programme")
    ap.add_argument("--work", type=Path, help="work folder (CalculiX runs)")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--mesh", default="fine", choices=sorted(r3.MESHES))
    ap.add_argument("--travel", type=float, default=Setup.travel)
    ap.add_argument("--only", nargs="+", metavar="RUN")
    ap.add_argument(
        "--reference-radius",
        type=float,
        metavar="R",
        help=f"drive every run against this radius, m (the fine mesh: {REFERENCE_RADIUS}); "
        "default: the free rim first",
    )
    ap.add_argument("--slips", type=float, nargs="+", metavar="K", help="imposed slips, in run order")
    ap.add_argument(
        "--prewind",
        type=float,
        default=0.0,
        metavar="RAD",
        help="the rim's extra turn at the roll's start, for driven runs (the steady wind-up: "
        "F_inf / (K_x R_l)); the runs are named ...w",
    )
    ap.add_argument("--workers", type=int, default=1, help="embedded Dask workers (one CalculiX thread each)")
    ap.add_argument(
        "--tolerances",
        type=float,
        nargs=2,
        metavar=("R_N", "C_N"),
        default=r3.TOLERANCES,
        help="the roll's CalculiX field controls: force residual and displacement correction "
        f"(default {r3.TOLERANCES[0]} {r3.TOLERANCES[1]})",
    )
    ap.add_argument("--scheduler")
    ap.add_argument("--table", action="store_true", help="print the finished runs' table and stop")
    ap.add_argument("--no-kx", action="store_true", help="the table without fepost's k_x")
    ap.add_argument(
        "--rig",
        type=Path,
        default=RIG,
        help="the rig's folder whose longitudinal slide gives the standstill stiffness K_x (--table)",
    )
    ap.add_argument(
        "--progress", action="store_true", help="print the runs' records so far (--work) and stop"
    )
    a = ap.parse_args(argv)
    if a.table:
        print("\n".join(results.table(a.out, kx=not a.no_kx, rig=a.rig)))
        return 0
    if a.work is None:
        print(f"{ap.prog}: --work DIR is needed to run the programme", file=sys.stderr)
        return 2
    if a.progress:
        print("\n".join(progress(a.work)))
        return 0
    if a.reference_radius is not None and not 0.3 < a.reference_radius < 0.7:
        print(
            f"{ap.prog}: --reference-radius {a.reference_radius} m is no radius of this tire", file=sys.stderr
        )
        return 2
    if a.workers < 1:
        print(f"{ap.prog}: --workers {a.workers}: at least one", file=sys.stderr)
        return 2
    driven = a.reference_radius is not None
    slips = tuple(a.slips) if a.slips else (DRIVEN_SLIPS if driven else SLIPS)
    if any(not -0.5 < k < 0.5 for k in slips) or (not driven and 0.0 in slips):
        print(
            f"{ap.prog}: --slips {slips}: each in (-0.5, 0.5), and 0 only with --reference-radius",
            file=sys.stderr,
        )
        return 2
    if a.prewind and (not driven or not abs(a.prewind) < 0.5):
        print(
            f"{ap.prog}: --prewind {a.prewind}: only with --reference-radius, and under 0.5 rad",
            file=sys.stderr,
        )
        return 2
    specs = programme(slips, free=not driven, prewind=a.prewind)
    if a.only:
        unknown = sorted(set(a.only) - {s.name for s in specs})
        if unknown:
            print(f"{ap.prog}: unknown run(s) {', '.join(unknown)}", file=sys.stderr)
            return 2
        specs = [s for s in specs if s.name in a.only]
    if not 0.01 <= a.travel <= 1.7:
        print(
            f"{ap.prog}: --travel {a.travel} outside [0.01, 1.7] m (the contact slaves' arc)", file=sys.stderr
        )
        return 2
    if not (0.0 < a.tolerances[0] <= 0.1 and 0.0 < a.tolerances[1] <= 1.0):
        print(f"{ap.prog}: --tolerances {a.tolerances}: R_n in (0, 0.1], C_n in (0, 1]", file=sys.stderr)
        return 2
    setup = Setup(
        mesh_kind=a.mesh,
        travel=a.travel,
        reference_radius=a.reference_radius,
        tolerances=tuple(a.tolerances),
    )
    done = run_programme(a.out, a.work, specs, setup, a.scheduler, workers=a.workers)
    _log(f"done now: {', '.join(done) or 'nothing'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
