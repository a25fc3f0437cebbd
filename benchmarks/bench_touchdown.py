"""Speed of one touchdown simulation (fepost.shimmy.touchdown) on the aircraft tire at its rated load.

The gear of ``examples/gear_a320_main_touchdown.json`` touches down at 70 m/s (sink
rate 1.5 m/s, initial strut torsion 0.5 degrees) and its motion is integrated for
2 s: the wheels' spin-up under the exact Coulomb friction of every tread element of
the brush tire over the FE map (`fepost.shimmy.brush`), then the gear's oscillation
on the gripping tire. Each measurement is a whole process (interpreter start,
imports, reading the map, building the tire, the run), timed from outside, median of
``--repeat`` runs, for the command's element grid (`fepost.shimmy.touchdown.GRID`)
and for the finer 16 x 6; the child's CPU time (user + system) beside the wall time,
since on a shared machine the CPU time is the cost and the wall time what a user waits.

Target (issue 40): a touchdown simulation with the exact integrals in at most 30 s.

Run: ``.venv/bin/python benchmarks/bench_touchdown.py [--repeat 3]``
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
STATIC = REPO / "meshes" / "rig-aircraft" / "roll_static.vtu"
GEAR = REPO / "examples" / "gear_a320_main_touchdown.json"
TARGET_S = 30.0

CHILD = """
import math, sys, time
from fepost.analysis import analyse
from fepost.friction.quadrature import PressureQuadrature
from fepost.shimmy.gear import load_gear
from fepost.shimmy.touchdown import simulate_touchdown, touchdown_tire
nx, ny = int(sys.argv[1]), int(sys.argv[2])
an = analyse(sys.argv[3])
gear = load_gear(sys.argv[4])
tire = touchdown_tire(gear, PressureQuadrature.from_polar(an.static_map), an.coefficients.f, nx=nx, ny=ny)
t0 = time.process_time()
run = simulate_touchdown(gear, tire, 70.0, sink_rate=1.5, yaw=math.radians(0.5), duration=2.0)
print(f"{tire.n} {run.spin_up_time} {run.verdict} {run.energy_residual:.2e} {time.process_time() - t0:.2f}")
"""


def measure(nx: int, ny: int) -> tuple[float, float, str]:
    """(wall s, child CPU s, the child's line) of one run in a fresh process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(nx), str(ny), str(STATIC), str(GEAR)],
        capture_output=True,
        text=True,
        check=True,
        cwd=REPO,
        env=env,
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, out.stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    from fepost.shimmy.touchdown import GRID

    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    for grid in (GRID, (16, 6)):
        runs = [measure(*grid) for _ in range(args.repeat)]
        wall = float(np.median([r[0] for r in runs]))
        cpu = float(np.median([r[1] for r in runs]))
        elements, spin_up, verdict, residual, integration = runs[-1][2].split()
        print(
            f"grid {grid[0]} x {grid[1]} ({elements} elements per wheel): {wall:.1f} s wall, {cpu:.1f} s CPU "
            f"(integration alone {integration} s CPU), spin-up {spin_up} s, {verdict}, energy residual "
            f"{residual}; target {TARGET_S:g} s: {'met' if wall <= TARGET_S else 'missed'}"
        )


if __name__ == "__main__":
    main()
