"""Benchmark: what a user waits for at the command line (whole processes, wall clock).

Targets (issue 13): ``fepost --help`` < 0.3 s; ``fepost coefficients FILE`` at most
1.5x a bare ``python -c "import pyvista; pyvista.read(FILE)"`` process on the same
file. The CLI layer's own share is isolated by a third process that calls the
library (``fepost.analyse(FILE)``) without the CLI: CLI / library close to 1
means the shell adds nothing (making ``analyse`` itself fast is the reader's
benchmark, ``bench_coefficients.py``).

The processes are run interleaved, ``--repeat`` times each, and the medians are
compared (the machine may be shared: compare ratios, not seconds).

    .venv/bin/python benchmarks/bench_cli.py [--repeat 7] [--file meshes/static.vtu] [--nodes 1000000]

``--nodes N`` also times a generated N-node VTU map (the issue's 1 M-node case).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FEPOST = [sys.executable, "-m", "fepost"]


def wall(cmd: list[str]) -> float:
    t = time.perf_counter()
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return time.perf_counter() - t


def medians(commands: dict[str, list[str]], repeat: int) -> dict[str, float]:
    times: dict[str, list[float]] = {name: [] for name in commands}
    for cmd in commands.values():  # warm the file cache once
        wall(cmd)
    for _ in range(repeat):
        for name, cmd in commands.items():
            times[name].append(wall(cmd))
    return {name: statistics.median(t) for name, t in times.items()}


def compare_file(path: Path, repeat: int) -> None:
    commands = {
        "python -c pass": [sys.executable, "-c", "pass"],
        "bare pyvista.read": [sys.executable, "-c", f"import pyvista; pyvista.read({str(path)!r})"],
        "library fepost.analyse": [sys.executable, "-c", f"import fepost; fepost.analyse({str(path)!r})"],
        "fepost coefficients": [*FEPOST, "coefficients", str(path)],
    }
    m = medians(commands, repeat)
    print(f"\n{path}  ({path.stat().st_size / 1e6:.1f} MB), medians of {repeat} runs:")
    for name, t in m.items():
        print(f"  {name:<24} {t:6.2f} s")
    cli, lib, read = m["fepost coefficients"], m["library fepost.analyse"], m["bare pyvista.read"]
    print(f"  fepost coefficients / bare pyvista read = {cli / read:.2f}  (target <= 1.5)")
    print(f"  fepost coefficients / library analyse   = {cli / lib:.2f}  (the CLI layer's share; ~1)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--file", type=Path, default=ROOT / "meshes" / "static.vtu")
    ap.add_argument("--nodes", type=int, help="also time a generated map with about this many nodes")
    args = ap.parse_args()

    m = medians(
        {
            "python -c pass": [sys.executable, "-c", "pass"],
            "fepost --help": [*FEPOST, "--help"],
            "fepost coefficients --help": [*FEPOST, "coefficients", "--help"],
            "fepost --version": [*FEPOST, "--version"],
        },
        args.repeat,
    )
    print(f"start-up, medians of {args.repeat} runs:")
    for name, t in m.items():
        print(f"  {name:<28} {t:6.3f} s")
    print(f"  fepost --help: {m['fepost --help']:.3f} s (target < 0.3 s)")

    compare_file(args.file, args.repeat)
    if args.nodes:
        from fepost.synthetic import write_map

        rings = int(60 * (args.nodes / 24_000) ** 0.5)  # as bench_coefficients.py
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "big.vtu"
            write_map(path, "hertz", radius=0.15, peak=1e6, n_rings=rings)
            compare_file(path, args.repeat)
    print("\n(wall-clock of whole processes; the machine may have been shared)")


if __name__ == "__main__":
    main()
