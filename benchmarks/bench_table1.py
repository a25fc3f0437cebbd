"""End-to-end timing of ``fepost table1`` (target: under 10 s).

Runs the command as a user would (a fresh ``python -m fepost table1`` process, so
imports count), on the sample meshes in ``meshes/`` when present, else on an
analytic Hertzian disc pair written to a temporary folder; then times the stages
in-process and prints the grid sizes.

    .venv/bin/python benchmarks/bench_table1.py [--static S --rolling R] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LIMIT_S = 10.0
MESHES = Path(__file__).resolve().parents[1] / "meshes"


def analytic_pair(folder: Path) -> tuple[Path, Path]:
    import pyvista

    from fepost import analytic

    paths = []
    for name, k in (("static", 0.0), ("rolling", 0.13)):
        disc = pyvista.Disc(center=(0, 0, 0), inner=0.0, outer=0.1, r_res=40, c_res=160).triangulate()
        x, y = disc.points[:, 0], disc.points[:, 1]
        disc.point_data["CPRESS"] = analytic.pressure_function("hertz", 0.1, 2.0e5, k_x=k)(x, y)
        p = folder / f"{name}.vtu"
        disc.cast_to_unstructured_grid().save(p)
        paths.append(p)
    return paths[0], paths[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--static")
    ap.add_argument("--rolling")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        if args.static:
            static, rolling = Path(args.static), Path(args.rolling) if args.rolling else None
            label = "given meshes"
        elif (MESHES / "static.vtu").is_file() and (MESHES / "rolling.vtu").is_file():
            static, rolling, label = (
                MESHES / "static.vtu",
                MESHES / "rolling.vtu",
                "sample meshes (meshes/)",
            )
        else:
            static, rolling = analytic_pair(Path(tmp))
            label = "analytic Hertz disc pair (meshes/ not found)"
        cmd = [
            sys.executable,
            "-m",
            "fepost",
            "table1",
            "--static",
            str(static),
            "--json",
            str(Path(tmp) / "t1.json"),
        ]
        if rolling is not None:
            cmd += ["--rolling", str(rolling)]
        times, cpu = [], []
        for _ in range(args.repeat):
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            run = subprocess.run(cmd, capture_output=True, text=True)
            times.append(time.perf_counter() - t0)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
            if run.returncode != 0:
                print(f"fepost table1 failed (exit {run.returncode}): {run.stderr.strip()}")
                return 1

        # Stage timings in-process.
        from fepost.analysis import analyse
        from fepost.table1 import table1

        t0 = time.perf_counter()
        a = analyse(static, rolling)
        t1 = time.perf_counter()
        t = table1(a, bias=False, generalised=False)
        t2 = time.perf_counter()
        table1(a, bias=True, profile=False, generalised=False)
        t3 = time.perf_counter()
        table1(a, bias=False, profile=False, generalised=True)
        t4 = time.perf_counter()
        gen = t4 - t3 - (t2 - t1) * 0.5  # rough: subtract the paper fit without profile bounds

        print(f"inputs: {label}")
        print(f"  static  {static}: {a.static_field.n_points} points, {a.static_field.n_faces} faces")
        if a.rolling_field is not None:
            print(f"  rolling {rolling}: {a.rolling_field.n_points} points, {a.rolling_field.n_faces} faces")
        nr, nphi = a.grid.shape
        print(
            f"polar grid: {a.grid.rule}, {nr} x {nphi} = {nr * nphi} nodes (exact friction integrals on it)"
        )
        print(f"test curves: {t.curves.psi.size} + 2 x {t.curves.upsilon.size} = {t.curves.n_points} points")
        print(
            f"fepost table1 end to end (fresh process, {args.repeat} runs): "
            f"median {statistics.median(times):.2f} s, max {max(times):.2f} s "
            f"(limit {LIMIT_S:.0f} s); "
            f"CPU time median {statistics.median(cpu):.2f} s"
        )
        print(
            f"  machine load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs "
            "(wall time grows with it)"
        )
        print(
            f"  in-process: analyse {t1 - t0:.2f} s; "
            f"curves + fit + profile bounds {t2 - t1:.2f} s; "
            f"exact-data bias study + fit without profile {t3 - t2:.2f} s; "
            f"generalised rows (two model builds, exact curves, fit) about {gen:.2f} s"
        )
        ok = max(times) < LIMIT_S
        print("OK" if ok else "TOO SLOW")
        return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
