"""Benchmark: a 1,000,000-node unstructured patch in VTU, from file to coefficients.

Target (issue 2): total time < 2x the time of reading the file alone, peak
memory < 3 GB. Each measurement runs in a fresh process so peak RSS is its own.

    .venv/bin/python benchmarks/bench_coefficients.py [--nodes 1000000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHILD = r"""
import json, resource, sys, time
mode, path = sys.argv[1], sys.argv[2]
t0 = time.perf_counter()
if mode == "read":
    import pyvista as pv
    t0 = time.perf_counter()
    mesh = pv.read(path)
    n = mesh.n_points
    extra = {}
else:
    import fepost
    t0 = time.perf_counter()
    a = fepost.analyse(path)
    n = a.static_field.n_points
    c = a.coefficients
    extra = {"N": c.N, "N_fe": a.static_patch.N_fe, "M0": c.M0, "a": c.a, "m": c.m}
dt = time.perf_counter() - t0
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print(json.dumps({"time": dt, "rss_mb": rss, "n": n, **extra}))
"""


def child(mode: str, path: Path) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", CHILD, mode, str(path)], capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--keep", type=Path, help="write the generated mesh here (reused if it exists)")
    args = ap.parse_args()

    from fepost import analytic
    from fepost.synthetic import write_map

    # rings needed for ~n nodes: n ≈ π·rings²·(4/π)... measured: 60 rings → ~24k nodes
    rings = int(60 * (args.nodes / 24_000) ** 0.5)
    with tempfile.TemporaryDirectory() as tmp:
        path = args.keep or Path(tmp) / "big.vtu"
        if not path.is_file():
            t = time.perf_counter()
            write_map(path, "hertz", radius=0.15, peak=1e6, n_rings=rings)
            print(f"wrote {path.name}: {path.stat().st_size / 1e6:.1f} MB in {time.perf_counter() - t:.1f} s")
        reads = [child("read", path) for _ in range(args.repeat)]
        fulls = [child("full", path) for _ in range(args.repeat)]
    tr = min(r["time"] for r in reads)
    tf = min(r["time"] for r in fulls)
    mr = statistics.median(r["time"] for r in reads)
    mf = statistics.median(r["time"] for r in fulls)
    f = fulls[0]
    N_ref = analytic.load("hertz", 0.15, 1e6)
    print(f"nodes: {f['n']:,}")
    print(f"read only (pyvista.read):  {tr:.2f} s   peak RSS {max(r['rss_mb'] for r in reads):.0f} MB")
    print(f"file -> coefficients:      {tf:.2f} s   peak RSS {max(r['rss_mb'] for r in fulls):.0f} MB")
    print(f"ratio: {tf / tr:.2f} of the best runs, {mf / mr:.2f} of the medians (target < 2)")
    print(f"N/N_exact - 1 = {f['N'] / N_ref - 1:+.2e}, N_fe/N_exact - 1 = {f['N_fe'] / N_ref - 1:+.2e}")


if __name__ == "__main__":
    main()
