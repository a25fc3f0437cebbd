"""Speed and accuracy of ``fepost diagnose``.

Requirements: 400 points, every candidate fitted robustly and by maximum
likelihood and cross-validated, under 60 s on a 2-core machine; the second-cause
search must not multiply that time by more than 3; a CSV of a million rows is
refused in seconds (the row limit of :mod:`fepost.diagnose.measured`).

1. Fit-grid accuracy: exact resultants on the 24 x 48 fit grid against a
   128 x 256 grid, max |ΔF|/(fN) and |ΔMz|/(fNR), on Hertzian and tire-like maps.
2. Wall time of ``diagnose`` with 400 points for each hidden cause and for two
   causes at once (tire map, loads 0.7/1.0/1.3), with and without the pair
   search (``pairs=False``), each the median of ``--repeats`` runs, and their
   ratio; the exact evaluations used.
3. Time per test point at growing sizes (``--sizes``), up to the row limit.
4. Time to refuse a 1 000 000-row CSV.

The machine is usually shared: compare the ratios, not the absolute times.

Run: ``.venv/bin/python benchmarks/bench_diagnose.py [--points 400] [--repeats 3] [--sizes 400 2000 5000]``
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from fepost.analytic import pressure_function
from fepost.diagnose import diagnose
from fepost.diagnose.measured import MAX_ROWS, read_measured
from fepost.diagnose.synthetic import VALIDATION_SET_A, rig_programme, synthesize
from fepost.errors import DataError
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.polar import PolarGrid, PolarMap

CASES = (
    ("none", {}),
    *VALIDATION_SET_A,
    (
        ("friction_level", "sensor_offset"),
        {"f": 0.27, "offset_Fx": -120.0, "offset_Fy": 90.0, "offset_Mz": -6.0},
    ),
    (("anisotropic_friction", "pressure_shift"), {"alpha": 1.12, "dx": -0.003, "dy": 0.0025}),
)


def grid_accuracy() -> None:
    print("fit grid accuracy (24 x 48 vs 128 x 256, 400 rig points):")
    for profile in ("hertz", "tire", "paraboloid"):
        R = 0.1
        fn = pressure_function(profile, R, peak=3e5)
        kin = rig_programme(R, 400, seed=0)
        out = []
        for nr, nphi in ((24, 48), (128, 256)):
            quad = PressureQuadrature.from_polar(PolarMap.from_function(fn, R, edge_grid(nr, nphi)))
            r = friction_resultants(quad, kin.vx, kin.vy, kin.wz, FrictionLaw(1.0))
            out.append(np.column_stack([r.Fx, r.Fy, r.Mz / R]) / quad.load)
        err = np.abs(out[0] - out[1]).max(axis=0)
        print(
            f"  {profile:<11} max |dFx|, |dFy| /fN = {err[0]:.2e}, {err[1]:.2e};  "
            f"max |dMz|/fNR = {err[2]:.2e}"
        )


def _timed(pmap, data, seed, pairs):
    t = time.perf_counter()
    d = diagnose(pmap, data, friction=0.3, seed=seed, pairs=pairs)
    return time.perf_counter() - t, d


def run_times(pmap, points: int, repeats: int) -> None:
    print(
        f"\ndiagnose, {points} points, tire map, loads 0.7/1.0/1.3, 8 candidates robust + ML + 5-fold CV; "
        f"median of {repeats} runs, without / with the pair search:"
    )
    ratios, eval_ratios, worst = [], [], 0.0
    for i, (effect, params) in enumerate(CASES):
        syn = synthesize(pmap, effect, params, n=points, seed=500 + i, loads=(0.7, 1.0, 1.3))
        t_off, t_on = [], []
        for _ in range(repeats):  # alternate, so that load changes hit both alike
            t, d_off = _timed(pmap, syn.data, 500 + i, False)
            t_off.append(t)
            t, d = _timed(pmap, syn.data, 500 + i, True)
            t_on.append(t)
        off, on = float(np.median(t_off)), float(np.median(t_on))
        e_off, e_on = d_off.info["exact_evaluations"], d.info["exact_evaluations"]
        ratios.append(on / off)
        eval_ratios.append(e_on / e_off)
        worst = max(worst, max(t_on))
        label = "+".join(effect) if isinstance(effect, tuple) else effect
        print(
            f"  {label:<36} -> {'+'.join(d.causes):<36} {off:5.1f} s / {on:5.1f} s  ratio {on / off:4.2f};  "
            f"exact evaluations {e_off:3d} / {e_on:3d}  ratio {e_on / e_off:4.2f}",
            flush=True,
        )
    print(
        f"  slowest run with pairs {worst:.1f} s (requirement < 60 s); with/without pairs: time ratio "
        f"median {np.median(ratios):.2f}, max {np.max(ratios):.2f}; exact-evaluation ratio median "
        f"{np.median(eval_ratios):.2f}, max {np.max(eval_ratios):.2f} (requirement <= 3)"
    )


def per_row(pmap, sizes) -> None:
    print("\ntime per test point (pressure-dependent friction, median of 3 runs):")
    for n in sizes:
        syn = synthesize(
            pmap, "pressure_dependent_friction", {"c_p": 0.25}, n=n, seed=600, loads=(0.7, 1.0, 1.3)
        )
        t = float(np.median([_timed(pmap, syn.data, 600, True)[0] for _ in range(3)]))
        print(f"  {n:6d} points: {t:7.1f} s = {1e3 * t / n:5.1f} ms per point", flush=True)


def refusal() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "million.csv"
        path.write_text("vx,vy,wz,Fx,Fy,Mz\n" + "0.1,0,1,-900,1,2\n" * 1_000_000)
        t = time.perf_counter()
        try:
            read_measured(path)
        except DataError as exc:
            message = str(exc)
        dt = time.perf_counter() - t
    print(f"\n1 000 000-row CSV ({MAX_ROWS} allowed): refused in {dt:.2f} s: {message}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=400)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--sizes", type=int, nargs="*", default=[400, 1000, 2000])
    args = parser.parse_args(argv)
    grid_accuracy()
    R = 0.12
    pmap = PolarMap.from_function(pressure_function("tire", R, peak=2.5e5), R, PolarGrid.make())
    refusal()
    run_times(pmap, args.points, args.repeats)
    if args.sizes:
        per_row(pmap, args.sizes)


if __name__ == "__main__":
    main()
