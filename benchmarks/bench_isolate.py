"""Benchmark: what reading a file in a forked child costs a long-lived process.

    python benchmarks/bench_isolate.py [--reads 50] [--rounds 5]

fepost reads every file in a forked child (`fepost.reader.isolate`). In a process that has
imported the scientific stack (a pytest-xdist worker, a sweep's Dask worker) the child's
first steps touch inherited memory, and every page it touches is copied (copy-on-write).
This times ``read_contact`` of a small Hertz map, ``--reads`` times per round, with the
isolation on and off (``FEPOST_READ_ISOLATION=off``) in alternating rounds of the same
process, and prints the medians of the wall time and of the CPU time (this process and its
reaped children) per read, side by side with their ratio.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import tempfile
import time
from pathlib import Path


def _cpu() -> float:
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--reads", type=int, default=50, help="reads per round (default 50)")
    p.add_argument("--rounds", type=int, default=5, help="rounds per setting (default 5)")
    args = p.parse_args(argv)

    import matplotlib

    matplotlib.use("Agg")
    import distributed  # noqa: F401  (what a sweep worker or a test worker holds)
    import matplotlib.pyplot  # noqa: F401
    import pyvista  # noqa: F401
    import scipy.optimize  # noqa: F401

    from fepost.reader import read_contact
    from fepost.synthetic import write_map

    path = write_map(Path(tempfile.mkdtemp()) / "hertz.vtu", "hertz", radius=0.1, peak=1e6, n_rings=8)
    times: dict[str, list[tuple[float, float]]] = {"on": [], "off": []}
    for _ in range(3):
        read_contact(path)  # warm: the child's imports are preloaded here after the first
    for _ in range(args.rounds):
        for mode in ("on", "off"):
            os.environ["FEPOST_READ_ISOLATION"] = mode
            time.sleep(0.3)  # children of the last round reaped
            c0, t0 = _cpu(), time.perf_counter()
            for _ in range(args.reads):
                read_contact(path)
            wall = time.perf_counter() - t0
            time.sleep(0.5)  # the last child's exit is reaped in the background
            times[mode].append((wall / args.reads, (_cpu() - c0) / args.reads))
    med = {m: [statistics.median(t[i] for t in times[m]) * 1e3 for i in (0, 1)] for m in times}
    print(f"isolated read of {path.name} ({args.rounds} rounds of {args.reads}; medians, ms per read)")
    print(f"{'':12}{'isolated':>10}{'in-process':>12}{'ratio':>8}")
    for i, what in enumerate(("wall", "CPU")):
        print(f"{what:12}{med['on'][i]:10.1f}{med['off'][i]:12.1f}{med['on'][i] / med['off'][i]:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
