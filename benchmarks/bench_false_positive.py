"""False-positive rate of ``fepost diagnose`` on data with no hidden effect.

For each seed, synthetic rig data (400 points, the default test programme, noise
1.5 % of each channel's range) are made by the exact integrals over a map with
the nominal f = 0.3 and nothing else, and diagnosed; a false positive is any
cause other than ``none``. Reports the rate with a Wilson 95 % interval, the
causes named, and how often each candidate passed the nesting test alone.

The maps alternate between a Hertzian disc (R = 0.1 m) and the tire-like
profile (R = 0.12 m), so the figure is not tied to one map.

Run: ``.venv/bin/python benchmarks/bench_false_positive.py [--seeds 50] [--points 400]``
"""

from __future__ import annotations

import argparse
import collections
import time

import numpy as np

from fepost.analytic import pressure_function
from fepost.diagnose import diagnose
from fepost.diagnose.synthetic import synthesize
from fepost.polar import PolarGrid, PolarMap

MAPS = (("hertz", 0.10, 3.0e5), ("tire", 0.12, 2.5e5))


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=50)
    parser.add_argument("--points", type=int, default=400)
    parser.add_argument("--noise", type=float, default=0.015)
    parser.add_argument("--first-seed", type=int, default=1000)
    args = parser.parse_args(argv)
    maps = [
        PolarMap.from_function(
            pressure_function(name, radius, peak=peak), radius, PolarGrid.make(), source=name
        )
        for name, radius, peak in MAPS
    ]
    named = collections.Counter()
    passed_lrt = collections.Counter()
    times = []
    for i in range(args.seeds):
        seed = args.first_seed + i
        pmap = maps[i % len(maps)]
        syn = synthesize(pmap, "none", {}, friction=0.3, n=args.points, noise=args.noise, seed=seed)
        t = time.perf_counter()
        d = diagnose(pmap, syn.data, friction=0.3, seed=seed)
        times.append(time.perf_counter() - t)
        named[d.cause] += 1
        for s in d.candidates:
            if s.lrt_p and all(p < 0.05 / 7 for p in s.lrt_p.values()):
                passed_lrt[s.name] += 1
        print(f"seed {seed} ({pmap.source}): {d.cause}  [{times[-1]:.1f} s]", flush=True)
    fp = args.seeds - named["none"]
    lo, hi = wilson(fp, args.seeds)
    print()
    print(f"false positives: {fp}/{args.seeds} = {fp / args.seeds:.1%} (Wilson 95 % CI {lo:.1%} .. {hi:.1%})")
    print(f"causes named: {dict(named)}")
    print(f"passed the nesting LRT alone (per candidate): {dict(passed_lrt)}")
    print(f"diagnose time per data set: median {np.median(times):.1f} s, max {np.max(times):.1f} s")


if __name__ == "__main__":
    main()
