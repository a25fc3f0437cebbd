"""Time ``fepost report`` on the sample meshes (target: under 60 s in all).

    python benchmarks/bench_report.py [STATIC ROLLING] [--out DIR] [--repeat N]

Prints the time of each step and the total (with ``--repeat``, of each run and
the median). Without inputs it uses the report's own default inputs, the
aircraft tire of ``meshes/aircraft/`` (:mod:`fepost.report.samples`, as
``make demo``), with the report's default sections (the sample load sweep);
when those are missing it falls back to analytic tire-like maps (say so in the
output).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TARGET_S = 60.0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("inputs", nargs="*", help="STATIC ROLLING (default: the sample meshes)")
    p.add_argument("--out", type=Path, help="report folder (default: a temporary one, removed)")
    p.add_argument("--repeat", type=int, default=1, help="runs (default 1); the median is printed")
    args = p.parse_args(argv)

    import pyvista

    pyvista.OFF_SCREEN = True
    from fepost.errors import ArgumentError
    from fepost.report import build_report
    from fepost.report.samples import SAMPLE_ROLLING, SAMPLE_STATIC, sample_inputs
    from fepost.synthetic import write_map

    totals = []
    with tempfile.TemporaryDirectory(prefix="fepost-bench-") as tmp:
        if args.inputs:
            static, rolling = (args.inputs + [None])[:2]
            label = " ".join(args.inputs)
        else:
            try:
                static, rolling = sample_inputs()
                label = f"sample meshes meshes/{SAMPLE_STATIC} meshes/{SAMPLE_ROLLING}"
            except ArgumentError:
                static = write_map(Path(tmp) / "static.vtu", "tire", radius=0.15, peak=6e5)
                rolling = write_map(Path(tmp) / "rolling.vtu", "tire", radius=0.15, peak=6e5, k_x=0.13)
                label = "analytic stand-ins (meshes/ has no samples)"
        out = args.out or Path(tmp) / "report"
        print(f"fepost report on {label}")
        for _ in range(max(1, args.repeat)):
            t0 = time.perf_counter()
            result = build_report(static, rolling, out, force=True)
            totals.append(time.perf_counter() - t0)
            width = max(len(s) for s, _ in result.timings)
            for step, seconds in result.timings:
                print(f"  {step:<{width}}  {seconds:6.2f} s")
            print(f"  {'total (wall)':<{width}}  {totals[-1]:6.2f} s")
    total = sorted(totals)[len(totals) // 2]
    verdict = "OK" if total < TARGET_S else "OVER TARGET"
    runs = ", ".join(f"{t:.1f}" for t in totals)
    print(f"median of {len(totals)} ({runs} s): {total:.2f} s   target < {TARGET_S:.0f} s: {verdict}")
    return 0 if total < TARGET_S else 1


if __name__ == "__main__":
    sys.exit(main())
