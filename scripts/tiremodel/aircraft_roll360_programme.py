"""The whole tire's rolling programme: free rolling with the rim free to turn, then imposed slips.

Runs (half model of the whole 360-degree tire, ``aircraft_roll360_deck``; rim travel 120.7 mm:
the mesh's 18.4 mm inflated clearance + the static sweep's rated-load deflection of 102.3 mm):

- ``roll_free``: the rim free to turn about the axle (no torque on it, no driver): free rolling
  as it is; its steady turn per travel over the last fifth of the roll gives R_e;
- ``roll_brake<k>`` / ``roll_drive<k>``: imposed slip kappa = -k/1000 / +k/1000 against that
  R_e, the rim turned by (1 + kappa) X / R_e; the small slips first (the slip curve's initial
  slope and a second, torque-zero estimate of free rolling), then the large ones.

Why the free rim and not a driver: the sector's free run was driven through a torsion spring
whose driver turned 2.4 % fast (1.87 kN m on the rim). With the turn held during inflation and
loading and released for the roll (a second step), the free rim's roll converged on the tiny
deck at the rotation node's residual torque of a few N m.

The runs are Dask tasks (``fepost.sweep.engine.Cluster``, one worker), each solved in
``work/<run>/`` on one thread (``nice -n 5``). Resume rule: a run whose ``<run>.json`` holds the
sha256 of the deck it would now write and the current export version (its .vtu and .dat.txt
beside it) is skipped; any other state is redone, reusing a finished CalculiX solve of the same
deck in the work folder (an older export is thus written again without a new solve).

``python -m scripts.tiremodel.aircraft_roll360_programme --work DIR [--out DIR] [--mesh fine|mid|tiny]
[--travel M] [--only RUN ...] [--scheduler ADDRESS]`` runs it; ``--table`` prints the finished
runs (slip, Fx/N, torque, steadiness, balance) and the brush estimate of the initial slope.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import aircraft_deck as ad
from . import aircraft_roll360_deck as r3
from .aircraft_roll_programme import run_phases, runs_to_do

#: braking (< 0) and driving slips, in run order: small ones first
SLIPS = (-0.01, 0.01, -0.03, 0.03, -0.10, 0.10)
FREE = "roll_free"
STATIC = "roll_static"
TREAD_DEPTH = 0.020  # m, the crown rubber (aircraft_geometry: rubber_thickness on the crown)
OUT = Path(__file__).resolve().parents[2] / "meshes" / "rig-tire360" / "roll"


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

    def plan(self, rotation: float | None) -> r3.Plan:
        return r3.Plan(self.rim_travel, self.travel, rotation, self.print_every, self.frames, self.tolerances)


@dataclass(frozen=True)
class RunSpec:
    name: str
    slip: float | None  # None: the free rim

    def plan(self, radius: float | None, setup: Setup) -> r3.Plan:
        if self.slip is None:
            return setup.plan(None)
        if radius is None:
            raise ValueError(f"{self.name}: needs the free-rolling run's effective radius")
        return setup.plan(r3.turn_for(setup.travel, radius, self.slip))

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
            }
        kind = "braking" if self.slip < 0 else "driving"
        return {
            "description": head + f"; {kind} at the imposed longitudinal slip {self.slip:+g}",
            "imposed": f"rim turn (1 {self.slip:+g}) X / R_e, linear in the axle travel X",
            "imposed_slip": self.slip,
            "effective_rolling_radius_m": radius,
            "effective_rolling_radius_source": f"{FREE}.json (the free rim's dX/dtheta)",
        }


def run_name(slip: float | None) -> str:
    if slip is None:
        return FREE
    return f"roll_{'brake' if slip < 0 else 'drive'}{round(abs(slip) * 1000):03d}"


def programme(slips: tuple[float, ...] = SLIPS) -> list[RunSpec]:
    return [RunSpec(FREE, None), *(RunSpec(run_name(s), s) for s in slips)]


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
        radius=effective_radius(out),
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
    )


def brush_slope(side: dict) -> float:
    """C_kappa / N of the brush model from the run's static patch, strip by strip: a lateral strip
    of width dy and length 2 a carries bristles of stiffness G_t / h per unit area (tread rubber
    shear modulus G_t, tread depth h = 20 mm), and under a small slip kappa its force is
    (G_t / h) 2 a^2 kappa dy; summed over the strips, over N."""
    strips = side["static_patch_strips"]
    g = ad.RUBBER["TREAD"]["shear_modulus"]
    a = np.asarray(strips["length"]) / 2.0
    return float(g / TREAD_DEPTH * np.sum(2.0 * a**2 * np.asarray(strips["width"])) / side["static_load"])


def fepost_kx(out: Path, name: str) -> float:
    """k_x that ``fepost coefficients`` gives the run's map against ``roll_static``."""
    import tempfile

    from fepost.cli import main as fepost

    with tempfile.TemporaryDirectory(prefix="roll360-kx-") as tmp:
        js = Path(tmp) / "coef.json"
        static, rolled = out / f"{STATIC}.vtu", out / f"{name}.vtu"
        if fepost(["coefficients", str(static), "--rolling", str(rolled), "--json", str(js)]) != 0:
            raise RuntimeError(f"fepost coefficients failed on {rolled}")
        coef = json.loads(js.read_text())
    return float(coef.get("coefficients", coef)["k_x"])


def table(out: Path, kx: bool = True) -> list[str]:
    """One line per finished run: slip, Fx/N, axle torque, steadiness, balance, fepost's k_x; the
    slip curve's initial slope from the two smallest slips against the brush estimate."""
    lines = [
        f"{'run':<15} {'kappa':>7} {'Fx/N':>7} {'T kN m':>7} {'dFx/fN':>7} {'dFz/N':>7} {'dT/fNR':>7} "
        f"{'bal x/N':>8} {'bal z/N':>8} {'k_x':>7} {'CPU s/m':>7}"
    ]
    slope, points = None, []
    for p in sorted(out.glob("roll_*.json")):
        side = json.loads(p.read_text())
        if side.get("kind") != "rolling run":
            continue
        st, bal = side["steadiness"], side["balance"]["residual_over_N"]
        kappa = side["longitudinal_slip"]
        ratio = side["tail_means"]["Fx"] / side["tail_means"]["Fz"]
        k = fepost_kx(out, side["case"]) if kx else math.nan
        cpu = side["cpu_s_per_m"] or math.nan
        lines.append(
            f"{side['case']:<15} {kappa if kappa is not None else math.nan:7.4f} {ratio:7.4f} "
            f"{side['axle_torque_tail_mean_Nm'] / 1e3:7.3f} {st['Fx_over_fN']:7.4f} {st['Fz_over_N']:7.4f} "
            f"{st['torque_over_fNR']:7.4f} {bal[0]:8.1e} {bal[2]:8.1e} {k:7.4f} {cpu:7.0f}"
        )
        slope = brush_slope(side)
        if kappa is not None:
            points.append((abs(kappa), kappa, ratio))
    if slope is not None:
        lines.append(f"brush estimate of the initial slope C_kappa/N (strip by strip): {slope:.2f}")
    near = sorted(points)[:3]
    if len(near) >= 2 and np.ptp([q[1] for q in near]) > 0:
        fit = np.polyfit([q[1] for q in near], [q[2] for q in near], 1)
        lines.append(
            f"slip curve: C_kappa/N = {fit[0]:.2f} (a least-squares line, the {len(near)} smallest slips)"
        )
    return lines


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
    ap.add_argument("--scheduler")
    ap.add_argument("--table", action="store_true", help="print the finished runs' table and stop")
    ap.add_argument("--no-kx", action="store_true", help="the table without fepost's k_x")
    ap.add_argument(
        "--progress", action="store_true", help="print the runs' records so far (--work) and stop"
    )
    a = ap.parse_args(argv)
    if a.table:
        print("\n".join(table(a.out, kx=not a.no_kx)))
        return 0
    if a.work is None:
        print(f"{ap.prog}: --work DIR is needed to run the programme", file=sys.stderr)
        return 2
    if a.progress:
        print("\n".join(progress(a.work)))
        return 0
    specs = programme()
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
    setup = Setup(mesh_kind=a.mesh, travel=a.travel)
    done = run_programme(a.out, a.work, specs, setup, a.scheduler)
    _log(f"done now: {', '.join(done) or 'nothing'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
