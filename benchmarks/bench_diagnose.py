"""Speed and accuracy of ``fepost diagnose`` (the requirement: 400 points, every
candidate fitted and cross-validated, under 60 s on a 2-core machine).

1. Fit-grid accuracy: exact resultants on the 24 x 48 fit grid against a
   128 x 256 grid, max |ΔF|/(fN) and |ΔMz|/(fNR), on Hertzian and tire-like maps.
2. Wall time of ``diagnose`` with 400 points for each hidden cause (tire map,
   loads 0.7/1.0/1.3), with the cause named and the exact evaluations used.
3. (``--coverage K``) coverage of the 95 % intervals of the named effect's
   parameters over K seeds per cause.

Run: ``.venv/bin/python benchmarks/bench_diagnose.py [--points 400] [--coverage 0]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fepost.analytic import pressure_function
from fepost.diagnose import diagnose
from fepost.diagnose.causes import Predictor, build_candidates
from fepost.diagnose.simulation import simulation_from_maps
from fepost.diagnose.synthetic import VALIDATION_SET_A, rig_programme, synthesize
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.polar import PolarGrid, PolarMap

CASES = (("none", {}), *VALIDATION_SET_A)


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


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=400)
    parser.add_argument("--coverage", type=int, default=0, help="seeds per cause for the coverage study")
    args = parser.parse_args(argv)
    grid_accuracy()
    R = 0.12
    pmap = PolarMap.from_function(pressure_function("tire", R, peak=2.5e5), R, PolarGrid.make())
    print(f"\ndiagnose, {args.points} points, tire map, loads 0.7/1.0/1.3, all 8 candidates + 5-fold CV:")
    times = []
    for i, (effect, params) in enumerate(CASES):
        syn = synthesize(pmap, effect, params, n=args.points, seed=500 + i, loads=(0.7, 1.0, 1.3))
        t = time.perf_counter()
        d = diagnose(pmap, syn.data, friction=0.3, seed=500 + i)
        times.append(time.perf_counter() - t)
        print(
            f"  {effect:<28} -> {d.cause:<28} {times[-1]:6.1f} s  "
            f"({d.info['exact_evaluations']} exact evaluations)"
        )
    print(f"  wall time: max {max(times):.1f} s, mean {np.mean(times):.1f} s (requirement: < 60 s)")
    if args.coverage:
        print(f"\ncoverage of the 95 % intervals over {args.coverage} seeds (fit of the true cause only):")
        sim = simulation_from_maps(pmap, friction=0.3)
        for effect, params in CASES[1:]:
            hits = total = 0
            for seed in range(args.coverage):
                syn = synthesize(
                    pmap, effect, params, n=args.points, seed=10_000 + seed, loads=(0.7, 1.0, 1.3)
                )
                from fepost.diagnose.fitting import fit

                pred = Predictor(sim, syn.data)
                cand = build_candidates(pred)[effect]
                ft = fit(cand, syn.data.forces / pred.scale)
                for name, (lo, hi) in zip(ft.names, ft.ci95, strict=True):
                    truth = syn.truth[name] if name in syn.truth else 0.3
                    hits += lo <= truth <= hi
                    total += 1
            print(f"  {effect:<28} {hits}/{total} = {hits / total:.1%}")


if __name__ == "__main__":
    main()
