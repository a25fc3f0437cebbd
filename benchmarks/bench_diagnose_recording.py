"""Time and peak memory of ``fepost diagnose`` on long rig recordings, against a plain read of the file.

A synthetic recording (:mod:`fepost.diagnose.synthetic_recording`: the default
rig programme's test points with a hidden ``pressure_dependent_friction``, each
held ``--hold`` s at ``--rate`` Hz with ``--ramp`` s ramps between, AR(1)
noise) of each size in ``--rows`` is written once per format into ``--dir``.
Then, ``--repeat`` times each, in fresh processes:

* ``fepost diagnose --simulation SIM --measured FILE --out DIR --force`` (the
  whole process: start-up, reading in chunks, holds, the diagnosis, figures);
* a plain read of the same file into memory: ``pyarrow.parquet.read_table`` or
  ``pyarrow.csv.read_csv`` (the floor any reader of the whole file pays).

Wall time, CPU time (user + system) and peak resident memory (``os.wait4``'s
rusage of that child) are reported as medians; on a loaded machine the CPU
time is the steadier figure. The machine is shared: run under ``nice`` and read
the load average printed with the results.

Run: ``python benchmarks/bench_diagnose_recording.py [--rows 1e6 3e6] [--formats parquet csv]
[--repeat 3] [--dir /tmp/fepost-bench]``
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

PLAIN = {
    ".parquet": "import pyarrow.parquet as pq, sys; t = pq.read_table(sys.argv[1]); print(t.num_rows)",
    ".csv": "import pyarrow.csv as c, sys; t = c.read_csv(sys.argv[1]); print(t.num_rows)",
}


def _make(folder: Path, rows: int, suffix: str, args) -> tuple[Path, Path]:
    from fepost.diagnose.synthetic import rig_programme, synthesize
    from fepost.diagnose.synthetic_recording import synthetic_recording, write_recording
    from fepost.synthetic import write_map

    sim = folder / "sim.vtu"
    if not sim.exists():
        write_map(sim, "hertz", radius=0.1, peak=3.0e5)
    path = folder / f"rec_{rows}{suffix}"
    if path.exists():
        return sim, path
    per = int(round((args.hold + args.ramp) * args.rate))
    points = max(20, int(np.ceil(rows / per)))
    from fepost.analysis import analyse

    pmap = analyse(sim, friction=0.3).static_map
    kin = rig_programme(0.1, points, seed=1)
    syn = synthesize(pmap, "pressure_dependent_friction", {"c_p": 0.3}, noise=0.0, seed=1, kinematics=kin)
    rec = synthetic_recording(syn, rate=args.rate, hold=args.hold, ramp=args.ramp, sd=(60, 60, 3), seed=2)
    rec = {k: v[:rows] for k, v in rec.items()}
    write_recording(rec, path)
    return sim, path


def _run(cmd: list[str]) -> tuple[float, float, int, float]:
    """(wall seconds, peak RSS in MB, exit status, CPU seconds) of one child process."""
    t = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t
    err = proc.stderr.read().decode() if proc.stderr else ""
    code = os.waitstatus_to_exitcode(status)
    if code:
        print(f"    failed ({code}): {err.strip().splitlines()[-1] if err.strip() else ''}")
    return seconds, usage.ru_maxrss / 1024.0, code, usage.ru_utime + usage.ru_stime


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=float, nargs="+", default=[1e6, 3e6])
    parser.add_argument("--formats", nargs="+", default=["parquet", "csv"], choices=["parquet", "csv"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--hold", type=float, default=5.0)
    parser.add_argument("--ramp", type=float, default=1.0)
    parser.add_argument("--dir", default="/tmp/fepost-bench-recording")
    args = parser.parse_args(argv)
    folder = Path(args.dir)
    folder.mkdir(parents=True, exist_ok=True)
    print(f"load average {os.getloadavg()}; {os.cpu_count()} CPUs; {args.rate:g} Hz, holds {args.hold:g} s, "
          f"ramps {args.ramp:g} s")  # fmt: skip
    for rows in (int(r) for r in args.rows):
        for fmt in args.formats:
            suffix = "." + fmt
            sim, path = _make(folder, rows, suffix, args)
            size = path.stat().st_size / 2**20
            out = folder / f"out_{rows}_{fmt}"
            diag = [sys.executable, "-m", "fepost", "diagnose", "--simulation", str(sim),
                    "--measured", str(path), "--out", str(out), "--force"]  # fmt: skip
            plain = [sys.executable, "-c", PLAIN[suffix], str(path)]
            res = {"diagnose": [], "plain read": []}
            for _ in range(args.repeat):
                res["diagnose"].append(_run(diag))
                res["plain read"].append(_run(plain))
            print(f"{rows:>10} rows {fmt:<8} ({size:.0f} MB):")
            for name, runs in res.items():
                secs = np.median([r[0] for r in runs])
                mem = np.median([r[1] for r in runs])
                cpu = np.median([r[3] for r in runs])
                ok = all(r[2] == 0 for r in runs)
                note = f"{len(runs)} runs" + ("" if ok else ", FAILED")
                what = f"median {secs:7.1f} s wall, {cpu:7.1f} s CPU, peak RSS {mem:7.0f} MB"
                print(f"    {name:<11} {what} ({note})")
    print(f"load average after {os.getloadavg()}")


if __name__ == "__main__":
    main()
