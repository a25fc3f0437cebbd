"""Time ``fepost report`` on the sample meshes (target: under 60 s in all).

    python benchmarks/bench_report.py [STATIC ROLLING] [--out DIR]

Prints the time of each step and the total. Without inputs it uses
``meshes/static.vtu`` and ``meshes/rolling.vtu``; when those are missing it
falls back to analytic tire-like maps (say so in the output).
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
    args = p.parse_args(argv)

    import pyvista

    pyvista.OFF_SCREEN = True
    from fepost.report import build_report
    from fepost.synthetic import write_map

    with tempfile.TemporaryDirectory(prefix="fepost-bench-") as tmp:
        if args.inputs:
            static, rolling = (args.inputs + [None])[:2]
            label = " ".join(args.inputs)
        elif (REPO / "meshes" / "static.vtu").is_file() and (REPO / "meshes" / "rolling.vtu").is_file():
            static, rolling = REPO / "meshes" / "static.vtu", REPO / "meshes" / "rolling.vtu"
            label = "sample meshes meshes/static.vtu meshes/rolling.vtu"
        else:
            static = write_map(Path(tmp) / "static.vtu", "tire", radius=0.15, peak=6e5)
            rolling = write_map(Path(tmp) / "rolling.vtu", "tire", radius=0.15, peak=6e5, k_x=0.13)
            label = "analytic stand-ins (meshes/ has no samples yet)"
        out = args.out or Path(tmp) / "report"
        print(f"fepost report on {label}")
        t0 = time.perf_counter()
        result = build_report(static, rolling, out, force=True)
        total = time.perf_counter() - t0
    width = max(len(s) for s, _ in result.timings)
    for step, seconds in result.timings:
        print(f"  {step:<{width}}  {seconds:6.2f} s")
    verdict = "OK" if total < TARGET_S else "OVER TARGET"
    print(f"  {'total (wall)':<{width}}  {total:6.2f} s   target < {TARGET_S:.0f} s: {verdict}")
    return 0 if total < TARGET_S else 1


if __name__ == "__main__":
    sys.exit(main())
