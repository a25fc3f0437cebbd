"""Speed of the shimmy study (fepost.shimmy) on the aircraft tire at its rated load, rolled map.

Each measurement is a whole process (interpreter start, imports, reading the maps,
the work), timed from outside, median of ``--repeat`` runs; the CPU time of the
child (user + system) is given beside the wall time, since on a shared machine the
CPU time is the cost and the wall time what a user waits:

* ``map``: one friction model's stability map over 200 speeds (1 to 150 m/s): the
  contact, the steady state, the contact's Jacobian, the eigenvalues, the boundaries;
* ``motion``: 10 s of motion at 1.2 times that model's critical speed (the
  tabulation over the sphere of directions included for the map-based models);
* ``cli``: ``fepost shimmy`` with its defaults (3 models, intervals, maps over speed x
  trail, damping and stiffness, time histories, limit-cycle sweeps, figures).

Targets (issue 40): a 200-speed map in at most 10 s, 10 s of motion in at most 5 s.
With ``--baseline DIR`` (a copy of another version's ``fepost`` package, e.g. from
``git archive``), every measurement is also run on that version, alternating with
this one so that both see the same load, and the ratio this/baseline is printed.

Run: ``.venv/bin/python benchmarks/bench_shimmy.py [--repeat 3] [--no-cli] [--baseline DIR]``
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
STATIC = REPO / "meshes" / "aircraft" / "static_100.vtu"
ROLLING = REPO / "meshes" / "rig-aircraft" / "roll_free.vtu"
GEAR = REPO / "examples" / "gear_a320_main.json"
MODELS = ("closed_forms", "generalised", "exact")


def stage(kind: str, model: str) -> None:
    """The work of one measured process (run in the child)."""
    import fepost
    from fepost.shimmy import load_gear
    from fepost.shimmy.linear import Linearisation, stability_map
    from fepost.shimmy.study import contacts

    an = fepost.analyse(STATIC, ROLLING)
    gear = load_gear(GEAR)
    contact = contacts(an, [model])[model]
    lin = Linearisation.of(gear, contact)
    smap = stability_map(lin, np.linspace(1.0, 150.0, 200))
    vc = smap.critical_speed or 150.0
    if kind == "motion":
        from fepost.shimmy.simulate import simulate
        from fepost.shimmy.table import DirectionTable

        sim = contact if contact.scalar is not None else DirectionTable.build(contact).as_contact()
        h = simulate(gear, sim, 1.2 * vc, equilibrium=lin.state, name=model, duration=10.0)
        print(f"{h.verdict} {h.final_amplitude:.4g}")
    else:
        print(f"{vc:.4f}")


def _run(cmd: list[str], package: Path | None) -> tuple[float, float, str]:
    """(wall s, child CPU s, stdout) of one process; ``package``: the folder holding the
    ``fepost`` package to import (None: this checkout)."""
    env = dict(os.environ)
    if package is not None:
        env["PYTHONPATH"] = str(package)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=package or REPO)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if out.returncode != 0:
        return wall, cpu, f"FAILED (exit {out.returncode}): {out.stderr.strip().splitlines()[-1][:80]}"
    return wall, cpu, out.stdout.strip().splitlines()[-1] if out.stdout.strip() else ""


def _measure(name: str, cmd: list[str], repeat: int, baseline: Path | None) -> None:
    runs: dict[str, list] = {"this": [], "base": []}
    for _ in range(repeat):
        runs["this"].append(_run(cmd, None))
        if baseline is not None:
            runs["base"].append(_run(cmd, baseline))
    wall = float(np.median([r[0] for r in runs["this"]]))
    cpu = float(np.median([r[1] for r in runs["this"]]))
    text = f"{name:<28}{wall:8.2f} s wall {cpu:7.2f} s CPU   {runs['this'][-1][2]}"
    if baseline is not None:
        bw = float(np.median([r[0] for r in runs["base"]]))
        bc = float(np.median([r[1] for r in runs["base"]]))
        text += f"   | baseline {bw:6.2f} s wall {bc:6.2f} s CPU, ratio {wall / bw:.2f} (CPU {cpu / bc:.2f})"
        if runs["base"][-1][2].startswith("FAILED"):
            text += f" baseline {runs['base'][-1][2]}"
    print(text, flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-cli", action="store_true")
    ap.add_argument("--baseline", type=Path, help="folder holding another version's fepost package")
    ap.add_argument("--stage", choices=("map", "motion"), help=argparse.SUPPRESS)
    ap.add_argument("--model", choices=MODELS, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.stage:
        stage(args.stage, args.model)
        return
    me = [sys.executable, str(Path(__file__).resolve())]
    print(f"medians of {args.repeat} fresh processes; load average {os.getloadavg()[0]:.1f}")
    for kind in ("map", "motion"):
        for model in MODELS:
            label = f"{model}: {'map of 200 speeds' if kind == 'map' else '10 s of motion'}"
            _measure(label, [*me, "--stage", kind, "--model", model], args.repeat, args.baseline)
    if not args.no_cli:
        with tempfile.TemporaryDirectory() as tmp:
            cmd = [sys.executable, "-m", "fepost", "shimmy", str(STATIC), "--rolling", str(ROLLING),
                   "--gear", str(GEAR), "--out", str(Path(tmp) / "out"), "--force"]  # fmt: skip
            _measure("fepost shimmy (defaults)", cmd, args.repeat, args.baseline)
    print(f"load average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
