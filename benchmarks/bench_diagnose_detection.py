"""Detection rate of ``fepost diagnose`` per cause, with gross outliers in the data.

For each cause (set-A effect sizes on the tire-like map of the tests: R = 0.12 m,
loads 0.7/1.0/1.3 × N) and each seed, a new programme of ``--points`` points is
drawn, ``--outliers`` rows get a gross error (a sign flip or a 2.5× spike of the
whole row) and noise is added, either 1.5 % of each channel's range
(``constant``) or 3 % of |reading| (``proportional``). Printed per cause: how
often the cause was named alone (the detection rate, with its Wilson 95 %
interval), how often exactly the glitched rows were flagged, how often a lack of
fit was (wrongly) detected, how often every true parameter lay in its 95 %
interval, and the median time.

Run: ``.venv/bin/python benchmarks/bench_diagnose_detection.py [--seeds 20] [--points 300]
[--outliers 4] [--noise-models constant proportional] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time

import numpy as np
from scipy.stats import binomtest

from fepost.diagnose import diagnose
from fepost.diagnose.synthetic import VALIDATION_SET_A, analytic_map, synthesize

CASES = (("none", {}), *VALIDATION_SET_A)
NOISE = {"constant": {"noise": 0.015}, "proportional": {"noise": 0.0, "noise_proportional": 0.03}}
_MAP: list = []


def wilson(k: int, n: int) -> tuple[float, float]:
    """Wilson 95 % interval of the proportion k/n."""
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return float(ci.low), float(ci.high)


def _one(job):
    effect, params, seed, points, outliers, model = job
    pmap = _MAP[0]
    syn = synthesize(
        pmap, effect, params, n=points, seed=seed, loads=(0.7, 1.0, 1.3), outliers=outliers, **NOISE[model]
    )
    t = time.perf_counter()
    d = diagnose(pmap, syn.data, friction=0.3, seed=seed)
    covered = True
    if d.causes == (effect,):
        for name, truth in syn.truth.items():
            if name in d.parameters:  # none has no parameters
                truth = syn.friction if (name == "f" and effect != "friction_level") else truth
                covered &= d.parameters[name].covers(truth)
    return {
        "named": d.causes == (effect,),
        "outliers": list(d.outliers) == list(syn.outliers),
        "lof": d.lack_of_fit["detected"],
        "covered": bool(covered) and d.causes == (effect,),
        "causes": d.causes,
        "seconds": time.perf_counter() - t,
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--points", type=int, default=300)
    parser.add_argument("--outliers", type=int, default=4)
    parser.add_argument("--noise-models", nargs="+", default=list(NOISE), choices=list(NOISE))
    parser.add_argument("--first-seed", type=int, default=3000)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    _MAP.append(analytic_map("tire", 0.12, 2.5e5))
    t0 = time.perf_counter()
    for model in args.noise_models:
        print(
            f"\nnoise {model} {NOISE[model]}, {args.points} points, {args.outliers} gross errors, "
            f"{args.seeds} data sets per cause"
        )
        print(f"  {'cause':<28} {'named alone':>26} {'outliers exact':>15} {'lack of fit':>12} "
              f"{'all in CI':>10} {'median s':>9}")  # fmt: skip
        for i, (effect, params) in enumerate(CASES):
            jobs = [
                (effect, params, args.first_seed + 100 * i + k, args.points, args.outliers, model)
                for k in range(args.seeds)
            ]
            if args.jobs > 1:
                with mp.get_context("fork").Pool(args.jobs) as pool:
                    out = pool.map(_one, jobs, chunksize=1)
            else:
                out = [_one(j) for j in jobs]
            n = len(out)
            k = sum(o["named"] for o in out)
            lo, hi = wilson(k, n)
            wrong = sorted({"+".join(o["causes"]) for o in out if not o["named"]})
            print(
                f"  {effect:<28} {k:3d}/{n} = {k / n:5.0%} ({lo:4.0%}..{hi:4.0%}) "
                f"{sum(o['outliers'] for o in out):9d}/{n} {sum(o['lof'] for o in out):9d}/{n} "
                f"{sum(o['covered'] for o in out):7d}/{n} {np.median([o['seconds'] for o in out]):9.1f}"
                + (f"   named instead: {', '.join(wrong)}" if wrong else ""),
                flush=True,
            )
    print(f"\nelapsed {time.perf_counter() - t0:.0f} s (machine shared: times are indicative)")


if __name__ == "__main__":
    main()
