"""False-positive rate of ``fepost diagnose`` on data with no hidden effect, under each noise model.

For each seed, synthetic rig data (400 points, the default test programme) are made
by the exact integrals over a map with the nominal f = 0.3 and nothing else, and
diagnosed. A false positive is any cause other than ``none``. Also counted: a
lack of fit detected, rows flagged as outliers, and a second cause named.

Noise models (``--noise-models``, each with ``--seeds`` data sets):

* ``constant``: Gaussian, SD 1.5 % of each channel's range;
* ``proportional``: SD 3 % of |reading| (a load cell specified in % of reading);
* ``combined``: SD² = (0.75 % of range)² + (2 % of |reading|)².

Reports each rate with a Wilson 95 % interval, the causes named, and how often
each candidate passed the nesting test alone. The maps alternate between a
Hertzian disc (R = 0.1 m) and the tire-like profile (R = 0.12 m), so the figure
is not tied to one map.

Run: ``.venv/bin/python benchmarks/bench_false_positive.py [--seeds 100] [--points 400]
[--noise-models constant proportional combined] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import collections
import multiprocessing as mp
import time

import numpy as np
from scipy.stats import binomtest

from fepost.analytic import pressure_function
from fepost.diagnose import diagnose
from fepost.diagnose.synthetic import synthesize
from fepost.polar import PolarGrid, PolarMap

MAPS = (("hertz", 0.10, 3.0e5), ("tire", 0.12, 2.5e5))
NOISE_MODELS = {
    "constant": {"noise": 0.015, "noise_proportional": 0.0},
    "proportional": {"noise": 0.0, "noise_proportional": 0.03},
    "combined": {"noise": 0.0075, "noise_proportional": 0.02},
}


def wilson(k: int, n: int) -> tuple[float, float]:
    """Wilson 95 % interval of the proportion k/n."""
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return float(ci.low), float(ci.high)


_MAPS: list = []


def _one(job):
    model, seed, i, points = job
    pmap = _MAPS[i % len(_MAPS)]
    syn = synthesize(pmap, "none", {}, friction=0.3, n=points, seed=seed, **NOISE_MODELS[model])
    t = time.perf_counter()
    d = diagnose(pmap, syn.data, friction=0.3, seed=seed)
    passed = [s.name for s in d.candidates if s.lrt_p and all(p < 0.05 / 7 for p in s.lrt_p.values())]
    return {
        "model": model,
        "seed": seed,
        "map": pmap.source,
        "cause": d.cause,
        "causes": d.causes,
        "lof": d.lack_of_fit["detected"],
        "outliers": len(d.outliers),
        "noise": tuple(d.noise[c]["model"] for c in ("Fx", "Fy", "Mz")),
        "passed": passed,
        "seconds": time.perf_counter() - t,
    }


def rate(name: str, k: int, n: int) -> str:
    lo, hi = wilson(k, n)
    return f"{name} {k}/{n} = {k / n:.1%} (Wilson 95 % CI {lo:.1%} .. {hi:.1%})"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--points", type=int, default=400)
    parser.add_argument("--first-seed", type=int, default=1000)
    parser.add_argument("--noise-models", nargs="+", default=list(NOISE_MODELS), choices=list(NOISE_MODELS))
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    _MAPS.extend(
        PolarMap.from_function(
            pressure_function(name, radius, peak=peak), radius, PolarGrid.make(), source=name
        )
        for name, radius, peak in MAPS
    )
    t0 = time.perf_counter()
    for model in args.noise_models:
        jobs = [(model, args.first_seed + i, i, args.points) for i in range(args.seeds)]
        if args.jobs > 1:
            with mp.get_context("fork").Pool(args.jobs) as pool:
                out = pool.map(_one, jobs, chunksize=1)
        else:
            out = [_one(j) for j in jobs]
        n = len(out)
        named = collections.Counter(o["cause"] for o in out)
        passed = collections.Counter(p for o in out for p in o["passed"])
        noise = collections.Counter(o["noise"] for o in out)
        print(f"\nnoise model: {model} ({NOISE_MODELS[model]}), {n} data sets of {args.points} points")
        print("  " + rate("false positives (cause other than none):", n - named["none"], n))
        print("  " + rate("lack of fit detected:", sum(o["lof"] for o in out), n))
        print("  " + rate("any row flagged as outlier:", sum(o["outliers"] > 0 for o in out), n))
        print("  " + rate("more than one cause:", sum(len(o["causes"]) > 1 for o in out), n))
        print(f"  causes named: {dict(named)}")
        print(f"  noise models chosen (Fx, Fy, Mz): {dict(noise)}")
        print(f"  passed the nesting LRT alone (per candidate): {dict(passed)}")
        secs = [o["seconds"] for o in out]
        print(f"  diagnose time per data set: median {np.median(secs):.1f} s, max {np.max(secs):.1f} s")
        for o in out:
            if o["cause"] != "none" or o["lof"]:
                print(f"    seed {o['seed']} ({o['map']}): {'+'.join(o['causes'])}, lack of fit {o['lof']}")
    print(f"\nelapsed {time.perf_counter() - t0:.0f} s (machine shared: times are indicative)")


if __name__ == "__main__":
    main()
