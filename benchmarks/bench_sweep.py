"""Speed of ``fepost sweep``: per-file overhead, scaling to 2 workers, an external cluster.

    .venv/bin/python benchmarks/bench_sweep.py [--files 32] [--rings 166] [--repeats 3]

Inputs: ``--files`` copies (hard links) of one Hertz map of ~200 000 nodes
(``--rings 166``), written as VTU into a temporary folder.

Measured, each ``--repeats`` times, interleaved (so a busy neighbour slows all
of them alike), medians printed:

1. **in-process**: ``fepost coefficients FILE --json PATH`` through
   ``fepost.cli.main`` for every file, one after the other, in this process
   (imports done beforehand);
2. **sweep, 1 worker** and **sweep, 2 workers**: :func:`fepost.sweep.run_sweep`
   of all files into a fresh folder (table and trends page) on an embedded
   ``LocalCluster`` that is already running and has imported fepost: the
   per-file cost. The one-off start and stop of the cluster is timed apart,
   and so is a whole ``fepost sweep --workers 2`` including both;
3. **external cluster**: ``dask scheduler`` and ``dask worker --nworkers 2
   --nthreads 1`` started by this script as separate processes, the sweep run
   with ``scheduler=ADDRESS``, the processes stopped at the end.

Targets: sweep on 1 worker / in-process < 1.2 (per-file overhead);
1-worker time / 2-worker time >= 1.7 (throughput on 2 local workers).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def make_inputs(folder: Path, files: int, rings: int) -> list[Path]:
    from fepost.synthetic import write_map

    first = write_map(folder / "case000.vtu", "hertz", radius=0.15, peak=1.2e6, n_rings=rings)
    paths = [first]
    for i in range(1, files):
        p = folder / f"case{i:03d}.vtu"
        os.link(first, p)
        paths.append(p)
    return paths


def in_process(paths: list[Path], scratch: Path) -> float:
    from fepost.cli import main

    t = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):
        for p in paths:
            assert main(["coefficients", str(p), "--json", str(scratch / "one.json")]) == 0
    return time.perf_counter() - t


def sweep(paths: list[Path], out: Path, **kw) -> float:
    from fepost.sweep import run_sweep

    shutil.rmtree(out, ignore_errors=True)
    t = time.perf_counter()
    res = run_sweep([str(p) for p in paths], out, progress=False, **kw)
    elapsed = time.perf_counter() - t
    assert res.ok and res.computed == len(paths), res.to_dict()
    return elapsed


def local_cluster(n: int):
    from distributed import Client, LocalCluster

    t = time.perf_counter()
    cluster = LocalCluster(
        n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
    )
    client = Client(cluster)
    client.run(__import__, "fepost.analysis")
    return cluster, client, time.perf_counter() - t


@contextlib.contextmanager
def external_cluster(folder: Path, workers: int):
    """``dask scheduler`` + ``dask worker`` processes on this machine; stopped on exit."""
    dask = str(Path(sys.executable).with_name("dask"))
    sched_file = folder / "scheduler.json"
    log = open(folder / "cluster.log", "w")  # noqa: SIM115  # closed below
    procs = [
        subprocess.Popen(
            [
                dask,
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--scheduler-file",
                str(sched_file),
            ],
            stdout=log,
            stderr=subprocess.STDOUT,
        )
    ]
    try:
        deadline = time.monotonic() + 60
        while not sched_file.is_file():
            if time.monotonic() > deadline or procs[0].poll() is not None:
                raise RuntimeError(f"dask scheduler did not start; see {folder / 'cluster.log'}")
            time.sleep(0.1)
        procs.append(
            subprocess.Popen(
                [
                    dask,
                    "worker",
                    "--scheduler-file",
                    str(sched_file),
                    "--nworkers",
                    str(workers),
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                ],
                stdout=log,
                stderr=subprocess.STDOUT,
            )
        )
        import json

        from distributed import Client

        address = json.loads(sched_file.read_text())["address"]
        with Client(address) as client:
            client.wait_for_workers(workers, timeout=120)
            client.run(__import__, "fepost.analysis")
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        log.close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--files", type=int, default=32)
    ap.add_argument("--rings", type=int, default=166, help="rings of the disc mesh (166: ~200 000 nodes)")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()

    with tempfile.TemporaryDirectory(prefix="bench_sweep.") as tmp:
        tmp = Path(tmp)
        inputs = tmp / "inputs"
        inputs.mkdir()
        paths = make_inputs(inputs, args.files, args.rings)
        from fepost.reader import read_contact

        nodes = read_contact(paths[0]).n_points
        load = os.getloadavg()[0]
        print(f"{len(paths)} files of {nodes} nodes; {os.cpu_count()} CPUs; load average {load:.1f}")
        in_process(paths[:1], tmp)  # imports and first-call set-up outside the timing

        c1, cl1, start1 = local_cluster(1)
        c2, cl2, start2 = local_cluster(2)
        times: dict[str, list[float]] = {"in-process": [], "sweep, 1 worker": [], "sweep, 2 workers": []}
        try:
            for r in range(args.repeats):
                times["in-process"].append(in_process(paths, tmp))
                times["sweep, 1 worker"].append(sweep(paths, tmp / f"s1-{r}", client=cl1))
                times["sweep, 2 workers"].append(sweep(paths, tmp / f"s2-{r}", client=cl2))
        finally:
            t = time.perf_counter()
            cl1.close()
            c1.close()
            stop1 = time.perf_counter() - t
            cl2.close()
            c2.close()
        whole = [sweep(paths, tmp / f"w-{r}", workers=2) for r in range(args.repeats)]
        with external_cluster(tmp, 2) as address:
            ext = [sweep(paths, tmp / f"x-{r}", scheduler=address) for r in range(args.repeats)]

        med = {k: statistics.median(v) for k, v in times.items()}
        n = len(paths)
        print(f"\nmedians of {args.repeats} runs (interleaved); the machine is shared, so compare ratios")
        print(f"{'':34s}{'total s':>10s}{'per file s':>12s}   runs")
        for k, v in times.items():
            print(f"{k:34s}{med[k]:10.2f}{med[k] / n:12.3f}   " + " ".join(f"{x:.2f}" for x in v))
        print(
            f"{'fepost sweep --workers 2 (whole)':34s}{statistics.median(whole):10.2f}"
            f"{statistics.median(whole) / n:12.3f}   " + " ".join(f"{x:.2f}" for x in whole)
        )
        print(
            f"{'external dask cluster, 2 workers':34s}{statistics.median(ext):10.2f}"
            f"{statistics.median(ext) / n:12.3f}   " + " ".join(f"{x:.2f}" for x in ext)
        )
        print(
            f"\nembedded cluster start (incl. worker imports): 1 worker {start1:.2f} s, "
            f"2 workers {start2:.2f} s; stop {stop1:.2f} s"
        )
        over = med["sweep, 1 worker"] / med["in-process"]
        speed = med["sweep, 1 worker"] / med["sweep, 2 workers"]
        ext_speed = med["sweep, 1 worker"] / statistics.median(ext)
        print(f"per-file overhead, sweep on 1 worker / in-process: {over:.3f}  (target < 1.2)")
        print(f"throughput, 2 local workers / 1 worker:            {speed:.3f}  (target >= 1.7)")
        print(f"throughput, external 2-worker cluster / 1 worker:  {ext_speed:.3f}")
        print(
            f"whole command incl. cluster start and stop / in-process: "
            f"{statistics.median(whole) / med['in-process']:.3f}"
        )


if __name__ == "__main__":
    main()
