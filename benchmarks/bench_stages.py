"""Benchmark: CPU time of the stages after the read (patch, resampling, model summary) of one map.

On a shared machine the wall time of a stage follows the neighbours' load (here 3-4x the CPU
time at a load of 12 on 2 cores); its CPU time (``time.process_time``: every thread of the
process) moves much less. Each round runs one fresh process per checkout, the order
alternating; a process reads the map once (not timed), then runs the stages ``--reps`` times
and reports the smallest CPU and wall time of each. The medians over the rounds are printed
side by side, with their ratio (this checkout / ``--baseline``).

    .venv/bin/python benchmarks/bench_stages.py /tmp/fepost-bench/surface.vtu \\
        [--baseline OTHER_CHECKOUT] [--rounds 3] [--reps 4]

(``/tmp/fepost-bench/surface.vtu`` is the 1.08 M-node map of ``bench_read.py``.)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

STAGES = r"""
import json, sys, time
from pathlib import Path
from threadpoolctl import threadpool_limits
from fepost.analysis import Analysis, _warm_up
from fepost.cli import coefficients as cli
from fepost.coefficients import coefficients_from_moments
from fepost.moments import moments
from fepost.patch import build_patch
from fepost.polar import PolarGrid
from fepost.reader.contact import read_here
from fepost.resample import resample

import fepost.analysis

# what the checkout's pipeline runs after the default grid (None before fepost.refine)
refined_map = getattr(fepost.analysis, "refined_map", None)

_warm_up()
field = read_here(Path(sys.argv[1]))
best = {}
for _ in range(int(sys.argv[2])):
    laps = {}
    t = (time.perf_counter(), time.process_time())

    def lap(name):
        global t
        now = (time.perf_counter(), time.process_time())
        laps[name] = (now[0] - t[0], now[1] - t[1])
        t = now

    with threadpool_limits(limits=1, user_api="blas"):  # as fepost.analysis runs them
        patch = build_patch(field)
        lap("patch")
        pmap = resample(patch, PolarGrid.make(), radius=patch.r_max)
        lap("resample")
        mom = moments(pmap)
        lap("moments")
        if refined_map is not None:  # what fepost.analysis does on the default grid
            pmap, mom = refined_map(patch, pmap, mom)
            lap("refine check (fepost.refine)")
        coef = coefficients_from_moments(mom, None, friction=0.3)
    cli.format_analysis(Analysis(field, patch, pmap, mom, coef))
    lap("model summary, stated accuracy, table")
    laps["total"] = tuple(sum(v[i] for v in laps.values()) for i in (0, 1))
    for k, (wall, cpu) in laps.items():
        old = best.get(k, (float("inf"), float("inf")))
        best[k] = (min(old[0], wall), min(old[1], cpu))
print(json.dumps(best))
"""


def _one(path: Path, checkout: Path, reps: int) -> dict[str, tuple[float, float]]:
    env = dict(os.environ, PYTHONPATH=str(checkout))
    # from a neutral folder: the working directory must not decide which fepost is imported
    out = subprocess.run(
        [sys.executable, "-c", STAGES, str(path), str(reps)],
        env=env,
        cwd=path.parent,
        capture_output=True,
        text=True,
        check=True,
    )
    return {k: tuple(v) for k, v in json.loads(out.stdout.strip().splitlines()[-1]).items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("map", type=Path, help="the contact map (e.g. bench_read.py's surface.vtu)")
    ap.add_argument("--baseline", type=Path, help="another checkout, timed in the same rounds")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--reps", type=int, default=4, help="runs of the stages per process (smallest kept)")
    args = ap.parse_args()
    here = Path(__file__).resolve().parents[1]
    sides = [("this", here)] + ([("base", args.baseline.resolve())] if args.baseline else [])
    runs: dict[str, list[dict[str, tuple[float, float]]]] = {name: [] for name, _ in sides}
    for k in range(args.rounds):
        for name, checkout in sides[k % len(sides) :] + sides[: k % len(sides)]:
            runs[name].append(_one(args.map.resolve(), checkout, args.reps))
    print(f"{args.map.name}: medians over {args.rounds} rounds of the smallest of {args.reps} runs (s)")
    head = f"  {'stage':<40} {'CPU':>7} {'wall':>7}"
    if args.baseline:
        head += f" {'base CPU':>9} {'base wall':>9} {'CPU ratio':>9}"
    print(head)
    stages = list(runs["this"][0]) + [s for s in runs.get("base", [{}])[0] if s not in runs["this"][0]]
    for stage in stages:
        cpu = statistics.median(r.get(stage, (0.0, 0.0))[1] for r in runs["this"])
        wall = statistics.median(r.get(stage, (0.0, 0.0))[0] for r in runs["this"])
        row = f"  {stage:<40} {cpu:7.3f} {wall:7.3f}"
        if args.baseline:
            bcpu = statistics.median(r.get(stage, (0.0, 0.0))[1] for r in runs["base"])
            bwall = statistics.median(r.get(stage, (0.0, 0.0))[0] for r in runs["base"])
            row += f" {bcpu:9.3f} {bwall:9.3f} {cpu / bcpu if bcpu else float('nan'):9.2f}"
        print(row)
    print(f"load average at the end: {', '.join(f'{v:.1f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
