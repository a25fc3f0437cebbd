"""Time the test suite as a newcomer waits for it: the README's ``make test``, whole.

    python benchmarks/bench_suite.py [--repeat N] [--workers auto|N] [--log FILE]

Runs ``make test TEST_WORKERS=...`` from the repository's root ``N`` times (the
virtual environment already made: the first ``make test`` builds it), and prints for
each run the wall time, the CPU time of the test processes (user + system, from
``getrusage`` of the reaped children: every worker and every command the tests run) and the pytest summary
line, then the median wall time against the target (5 min on the 2-core machine).
Afterwards pytest's cache holds each file's seconds of the last run
(``.pytest_cache/v/fepost/seconds-per-file``); ``--files K`` prints the K longest.
"""

from __future__ import annotations

import argparse
import json
import re
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TARGET_S = 300.0
SUMMARY = re.compile(r"^=*\s*(\d+ (passed|failed).*) in [\d.]+s")


def run_once(workers: str, log: Path | None = None) -> tuple[float, float, str, int]:
    """(wall s, CPU s of the whole process tree, pytest's summary, exit status) of one make test;
    its output is written to ``log`` when given."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(
        ["make", "test", f"TEST_WORKERS={workers}"],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)  # the reaped descendants' totals
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if log is not None:
        log.write_text(proc.stdout, encoding="utf-8")
    lines = proc.stdout.splitlines()
    summary = next((m.group(1) for line in lines if (m := SUMMARY.match(line))), "no summary")
    return wall, cpu, summary, proc.returncode


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=1, help="runs (default 1); the median is printed")
    p.add_argument("--workers", default="auto", help="TEST_WORKERS (default auto: one per core)")
    p.add_argument("--files", type=int, default=10, help="longest files of the last run to print")
    p.add_argument("--log", type=Path, help="write each run's output here (run k to LOG.k)")
    args = p.parse_args(argv)
    walls = []
    for k in range(args.repeat):
        log = None if args.log is None else args.log.with_name(f"{args.log.name}.{k + 1}")
        wall, cpu, summary, rc = run_once(args.workers, log)
        walls.append(wall)
        cores = cpu / wall
        print(f"run {k + 1}: wall {wall:.1f} s, CPU {cpu:.1f} s ({cores:.2f} cores), exit {rc}: {summary}")
    median = statistics.median(walls)
    verdict = "within" if median <= TARGET_S else "above"
    print(f"median wall {median:.1f} s over {len(walls)} run(s), {verdict} the {TARGET_S:.0f} s target")
    cache = REPO / ".pytest_cache" / "v" / "fepost" / "seconds-per-file"
    if cache.is_file() and args.files:
        seconds = json.loads(cache.read_text())
        total = sum(seconds.values())
        print(f"longest files of the last run (their tests' seconds summed; {total:.0f} s in all):")
        for name, s in sorted(seconds.items(), key=lambda kv: -kv[1])[: args.files]:
            print(f"  {s:6.1f} s  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
