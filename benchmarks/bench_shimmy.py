"""Speed of the shimmy study (fepost.shimmy) on the aircraft tire at its rated load.

Times, for each friction model (the paper's closed forms, the generalised model,
the exact integrals over the rolling map), medians of ``--repeat`` runs:

* ``linearise``: the steady state and the contact's Jacobian (complex step for the
  closed forms, adaptive high-order differences for the others);
* ``map``: the stability map over 200 speeds (eigenvalues, critical speeds by Brent);
* ``table``: the tabulation over the sphere of directions a time integration uses
  (map-based models only);
* ``simulation``: 10 s of motion at 1.2 times the critical speed (wall and process CPU time:
  on a shared machine the CPU time is the cost, the wall time what a user waits);

and the whole process: ``fepost shimmy`` on the sample with the example gear, in a
fresh process (reading, the three models, intervals, six time histories, figures).
Targets (issue 32): a 200-speed map in at most 10 s, 10 s of motion in at most 5 s.

Run: ``.venv/bin/python benchmarks/bench_shimmy.py [--repeat 3] [--no-cli]``
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
STATIC = REPO / "meshes" / "aircraft" / "static_100.vtu"
ROLLING = REPO / "meshes" / "aircraft" / "rolling_100.vtu"
GEAR = REPO / "examples" / "gear_a320_main.json"


def _median(fun, repeat: int, cpu: list | None = None) -> tuple[float, object]:
    """Median wall time of ``repeat`` calls (and their median CPU time appended to ``cpu``)."""
    times, cpus, out = [], [], None
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fun()
        times.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    if cpu is not None:
        cpu.append(float(np.median(cpus)))
    return float(np.median(times)), out


def bench_models(repeat: int) -> None:
    import fepost
    from fepost.shimmy import load_gear
    from fepost.shimmy.linear import Linearisation, stability_map
    from fepost.shimmy.simulate import simulate
    from fepost.shimmy.study import contacts
    from fepost.shimmy.table import DirectionTable

    an = fepost.analyse(STATIC, ROLLING)
    gear = load_gear(GEAR)
    speeds = np.linspace(1.0, 150.0, 200)
    print(
        f"{'model':<14}{'linearise':>11}{'map 200 V':>11}{'table':>9}"
        f"{'10 s sim (wall, CPU)':>25}  V_c (m/s)  verdict"
    )
    for name, contact in contacts(an).items():
        t_lin, lin = _median(lambda c=contact: Linearisation.of(gear, c), repeat)
        t_map, smap = _median(lambda lin=lin: stability_map(lin, speeds), repeat)
        if contact.scalar is None:
            t_tab, table = _median(lambda c=contact: DirectionTable.build(c).as_contact(), repeat)
        else:
            t_tab, table = 0.0, contact
        vc = smap.critical_speed or 150.0

        def run(table=table, vc=vc, lin=lin, name=name):
            return simulate(gear, table, 1.2 * vc, equilibrium=lin.state, name=name)

        cpu: list[float] = []
        t_sim, hist = _median(run, repeat, cpu)
        print(
            f"{name:<14}{t_lin:>10.3f}s{t_map:>10.3f}s{t_tab:>8.2f}s{t_sim:>9.2f}s ({cpu[0]:.2f}s CPU)"
            f"  {vc:9.2f}  {hist.verdict}"
        )


def bench_cli(repeat: int) -> None:
    times = []
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as tmp:
            cmd = [sys.executable, "-m", "fepost", "shimmy", str(STATIC), "--rolling", str(ROLLING),
                   "--gear", str(GEAR), "--out", str(Path(tmp) / "out")]  # fmt: skip
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            times.append(time.perf_counter() - t0)
    print(f"fepost shimmy (3 models, intervals, 6 time histories, figures): median {np.median(times):.1f} s "
          f"of {repeat} runs (min {min(times):.1f} s)")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-cli", action="store_true")
    args = ap.parse_args()
    bench_models(args.repeat)
    if not args.no_cli:
        bench_cli(args.repeat)


if __name__ == "__main__":
    main()
