"""Speed of ``fepost sweep``: per-file overhead, scaling to 2 workers, an external cluster.

    .venv/bin/python benchmarks/bench_sweep.py [--files 32] [--rings 166] [--repeats 3]

Inputs: ``--files`` copies (hard links) of one Hertz map of ~200 000 nodes
(``--rings 166``), written as VTU into a temporary folder.

Measured ``--repeats`` times, interleaved (a busy neighbour slows all of them
alike), medians printed, wall time and CPU time (user + system of every
process doing the work: this one, and the worker processes):

1. **in-process**: ``fepost coefficients FILE --json PATH`` through
   ``fepost.cli.main`` for every file, one after the other, in this process
   (imports and a first call done beforehand);
2. **sweep, 1 worker** and **sweep, 2 workers**:
   :func:`fepost.sweep.run_sweep` of all files into a fresh folder (table and
   trends page) on an embedded ``LocalCluster`` that is already running and
   warm: the per-file cost. Starting and stopping a cluster is timed apart,
   and a whole ``run_sweep(..., workers=2)`` including both is timed too;
3. **external cluster**: ``dask scheduler`` and ``dask worker --nworkers 2
   --nthreads 1`` started by this script as separate processes (on this
   machine), the sweep run with ``scheduler=ADDRESS``, the processes stopped
   at the end.

Targets: sweep on 1 worker / in-process < 1.2 (per-file overhead);
1-worker time / 2-worker time >= 1.7 (throughput on 2 local workers). On a
machine shared with other work, wall times swing with the neighbours' load
while CPU times do not: the CPU ratio is the overhead the sweep adds; the wall
ratios need a quiet machine.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import logging
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil  # a dependency of dask.distributed


def cpu_seconds(pids) -> float:
    """User + system CPU seconds of the processes ``pids`` and their live descendants."""
    total = 0.0
    seen = set()
    for pid in pids:
        try:
            root = psutil.Process(pid)
            procs = [root, *root.children(recursive=True)]
        except psutil.NoSuchProcess:
            continue
        for p in procs:
            if p.pid in seen:
                continue
            seen.add(p.pid)
            with contextlib.suppress(psutil.NoSuchProcess):
                t = p.cpu_times()
                total += t.user + t.system
    return total


class Timer:
    """Wall and CPU seconds of a block; CPU of ``pids`` (default: this process alone)."""

    def __init__(self, pids=None, own_only: bool = False):
        self.pids = pids
        self.own_only = own_only

    def _cpu(self) -> float:
        if self.own_only:
            t = psutil.Process().cpu_times()
            return t.user + t.system
        return cpu_seconds(self.pids)

    def __enter__(self):
        self.cpu0, self.t0 = self._cpu(), time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self.t0
        self.cpu = self._cpu() - self.cpu0


def make_inputs(folder: Path, files: int, rings: int) -> list[Path]:
    from fepost.synthetic import write_map

    first = write_map(folder / "case000.vtu", "hertz", radius=0.15, peak=1.2e6, n_rings=rings)
    paths = [first]
    for i in range(1, files):
        p = folder / f"case{i:03d}.vtu"
        os.link(first, p)
        paths.append(p)
    return paths


def in_process(paths: list[Path], scratch: Path) -> Timer:
    from fepost.cli import main

    with Timer(own_only=True) as t, contextlib.redirect_stdout(io.StringIO()):
        for p in paths:
            assert main(["coefficients", str(p), "--json", str(scratch / "one.json")]) == 0
    return t


def sweep(paths: list[Path], out: Path, pids=None, **kw) -> Timer:
    from fepost.report.sweeppage import write_trends
    from fepost.sweep import run_sweep

    shutil.rmtree(out, ignore_errors=True)
    with Timer(pids or [os.getpid()]) as t:
        res = run_sweep([str(p) for p in paths], out, progress=False, trends=write_trends, **kw)
    assert res.ok and res.computed == len(paths), res.to_dict()
    return t


def whole_command(paths: list[Path], out: Path, workers: int) -> Timer:
    """``run_sweep(workers=N)``: cluster start, sweep, stop. CPU: this process and its waited children."""
    from fepost.report.sweeppage import write_trends
    from fepost.sweep import run_sweep

    shutil.rmtree(out, ignore_errors=True)
    t0, w0 = os.times(), time.perf_counter()
    res = run_sweep([str(p) for p in paths], out, progress=False, workers=workers, trends=write_trends)
    t1 = os.times()
    assert res.ok and res.computed == len(paths), res.to_dict()
    t = Timer()
    t.wall = time.perf_counter() - w0
    t.cpu = sum(t1[:4]) - sum(t0[:4])  # user, system, children's user and system
    return t


def local_cluster(n: int, warm: list[Path], scratch: Path):
    from distributed import Client, LocalCluster

    w0 = time.perf_counter()
    cluster = LocalCluster(
        n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
    )
    client = Client(cluster)
    start = time.perf_counter() - w0
    pids = [os.getpid(), *client.run(os.getpid).values()]
    sweep(warm[:n], scratch, pids, client=client)  # imports and first calls in every worker
    return cluster, client, pids, start


@contextlib.contextmanager
def external_cluster(folder: Path, workers: int):
    """``dask scheduler`` + ``dask worker`` processes on this machine; stopped on exit."""
    dask = str(Path(sys.executable).with_name("dask"))
    sched_file = folder / "scheduler.json"
    log = open(folder / "cluster.log", "w")  # noqa: SIM115  # closed below
    scheduler = [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard"]
    worker = [dask, "worker", "--nworkers", str(workers), "--nthreads", "1", "--no-dashboard"]
    procs = [subprocess.Popen([*scheduler, "--scheduler-file", str(sched_file)], stdout=log, stderr=log)]
    try:
        deadline = time.monotonic() + 60
        while not sched_file.is_file():
            if time.monotonic() > deadline or procs[0].poll() is not None:
                raise RuntimeError(f"dask scheduler did not start; see {folder / 'cluster.log'}")
            time.sleep(0.1)
        procs.append(subprocess.Popen([*worker, "--scheduler-file", str(sched_file)], stdout=log, stderr=log))
        from distributed import Client

        address = json.loads(sched_file.read_text())["address"]
        with Client(address) as client:
            client.wait_for_workers(workers, timeout=120)
        yield address, [os.getpid()] + [p.pid for p in procs]
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


def median_row(name: str, runs: list[Timer], n: int) -> str:
    wall = statistics.median(t.wall for t in runs)
    best = min(t.wall for t in runs)
    cpu = statistics.median(t.cpu for t in runs)
    each = " ".join(f"{t.wall:.1f}" for t in runs)
    return f"{name:36s}{wall:9.2f}{best:9.2f}{wall / n:9.3f}{cpu:9.2f}{cpu / n:9.3f}   {each}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--files", type=int, default=32)
    ap.add_argument("--rings", type=int, default=166, help="rings of the disc mesh (166: ~200 000 nodes)")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    logging.disable(logging.WARNING)  # clusters that close log their shutdown at INFO and WARNING

    with tempfile.TemporaryDirectory(prefix="bench_sweep.") as tmp_name:
        tmp = Path(tmp_name)
        inputs = tmp / "inputs"
        inputs.mkdir()
        paths = make_inputs(inputs, args.files, args.rings)
        n = len(paths)
        from fepost.reader import read_contact

        nodes = read_contact(paths[0]).n_points
        load0 = os.getloadavg()[0]
        in_process(paths[:1], tmp)  # imports and first-call set-up outside the timing

        c1, cl1, pids1, start1 = local_cluster(1, paths, tmp / "warm1")
        c2, cl2, pids2, start2 = local_cluster(2, paths, tmp / "warm2")
        runs: dict[str, list[Timer]] = {"in-process": [], "sweep, 1 worker": [], "sweep, 2 workers": []}
        try:
            for r in range(args.repeats):
                runs["in-process"].append(in_process(paths, tmp))
                runs["sweep, 1 worker"].append(sweep(paths, tmp / f"s1-{r}", pids1, client=cl1))
                runs["sweep, 2 workers"].append(sweep(paths, tmp / f"s2-{r}", pids2, client=cl2))
        finally:
            w0 = time.perf_counter()
            cl1.close()
            c1.close()
            stop1 = time.perf_counter() - w0
            cl2.close()
            c2.close()
        runs["run_sweep(workers=2), whole"] = [
            whole_command(paths, tmp / f"w-{r}", 2) for r in range(args.repeats)
        ]
        with external_cluster(tmp, 2) as (address, pids):
            sweep(paths[:2], tmp / "xwarm", pids, scheduler=address)
            runs["external dask cluster, 2 workers"] = [
                sweep(paths, tmp / f"x-{r}", pids, scheduler=address) for r in range(args.repeats)
            ]

        med = {k: statistics.median(t.wall for t in v) for k, v in runs.items()}
        cpu = {k: statistics.median(t.cpu for t in v) for k, v in runs.items()}
        load1 = os.getloadavg()[0]
        cpus = os.cpu_count()
        print(f"{n} files of {nodes} nodes; {cpus} CPUs; load average {load0:.1f} before, {load1:.1f} after")
        print(f"medians of {args.repeats} interleaved runs; wall times swing with the machine's other load\n")
        print(f"{'':36s}{'wall s':>9s}{'best':>9s}{'/file':>9s}{'CPU s':>9s}{'/file':>9s}   wall of each run")
        for k, v in runs.items():
            print(median_row(k, v, n))
        print(
            f"\nembedded cluster start: 1 worker {start1:.2f} s, 2 workers {start2:.2f} s; "
            f"stop {stop1:.2f} s (worker imports come with the first rows)"
        )
        one, base = "sweep, 1 worker", "in-process"
        print(
            f"per-file overhead, sweep on 1 worker / in-process: wall {med[one] / med[base]:.3f}, "
            f"CPU {cpu[one] / cpu[base]:.3f}  (target < 1.2)"
        )
        best = {k: min(t.wall for t in v) for k, v in runs.items()}
        two = "sweep, 2 workers"
        print(
            f"throughput, 2 local workers / 1 worker:            wall {med[one] / med[two]:.3f}, "
            f"best of each {best[one] / best[two]:.3f}  (target >= 1.7)"
        )
        ext = "external dask cluster, 2 workers"
        print(
            f"throughput, external 2-worker cluster / 1 worker:  wall {med[one] / med[ext]:.3f}, "
            f"best of each {best[one] / best[ext]:.3f}"
        )
        whole = "run_sweep(workers=2), whole"
        print(f"whole sweep incl. cluster start and stop / in-process: wall {med[whole] / med[base]:.3f}")


if __name__ == "__main__":
    main()
