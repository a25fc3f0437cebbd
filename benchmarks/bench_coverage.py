"""Monte-Carlo coverage of the Table 1 intervals (THEORY.md §6).

For each seed, make closed-form test curves with the paper's noise, fit them with
:func:`fepost.identify.fit_table1`, and count whether each 95 % interval holds the
true coefficient. A calibrated method covers 95 %; with S seeds the Monte-Carlo
standard error is √(0.95·0.05/S) (0.49 % at S = 2000), so the acceptance band
93–97 % is about ±4 standard errors.

Two truth sets: ``hertz`` (a Hertzian disc, R = 0.1 m, 200 kPa peak, f = 0.3,
k_x = 0.13) and ``paper`` (Table 1's theoretical values, R = 0.07 m from
THEORY.md §6's remark that M0/F0 implies R ≈ 7 cm, N = F0/f).

    .venv/bin/python benchmarks/bench_coverage.py [--seeds 2000] [--noise uniform|gaussian] \
        [--profile]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fepost import analytic
from fepost.identify import PARAMETERS, fit_table1, make_test_curves

NAMES = ("f",) + PARAMETERS
BAND = (0.93, 0.97)


def truths() -> dict[str, dict[str, float]]:
    R, peak, f = 0.1, 2.0e5, 0.3
    h = analytic.coefficients("hertz", R, peak, f)
    hertz = {
        "F0": h["F0"],
        "M0": h["M0"],
        "a": h["a"],
        "m": h["m"],
        "k_x": 0.13,
        "R": R,
        "N": analytic.load("hertz", R, peak),
    }
    paper = {
        "F0": 72219.0,
        "M0": 3215.0,
        "a": 0.690,
        "m": 1.595,
        "k_x": 0.130,
        "R": 0.07,
        "N": 72219.0 / 0.3,
    }
    return {"hertz": hertz, "paper": paper}


def coverage(truth, seeds, noise, profile, n_points):
    hits = {n: 0 for n in NAMES}
    phits = {"a": 0, "m": 0}
    width = {n: [] for n in NAMES}
    for seed in range(seeds):
        curves = make_test_curves("closed_form", truth, noise=noise, seed=seed, n_points=n_points)
        fit = fit_table1(curves, truth["N"], profile=profile)
        for n in NAMES:
            lo, hi = fit.interval(n)
            t = truth["F0"] / truth["N"] if n == "f" else truth[n]
            hits[n] += lo <= t <= hi
            width[n].append(hi - lo)
        if profile:
            for n in ("a", "m"):
                lo, hi = fit.profile_ci95[n]
                phits[n] += lo <= truth[n] <= hi
    return hits, phits, width


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=2000)
    ap.add_argument("--noise", choices=("uniform", "gaussian"), default="uniform")
    ap.add_argument("--n-points", type=int, default=50)
    ap.add_argument("--profile", action="store_true", help="also check the profile bounds of a and m")
    args = ap.parse_args()
    se = np.sqrt(0.95 * 0.05 / args.seeds)
    print(
        f"coverage of 95 % intervals, {args.seeds} seeds, {args.noise} noise (amplitude 0.2 max), "
        f"{args.n_points} points per curve; Monte-Carlo s.e. {se:.2%}; "
        f"band {BAND[0]:.0%}-{BAND[1]:.0%}"
    )
    ok = True
    for label, truth in truths().items():
        t0 = time.perf_counter()
        hits, phits, width = coverage(truth, args.seeds, args.noise, args.profile, args.n_points)
        dt = time.perf_counter() - t0
        print(f"\n[{label}]  ({dt:.1f} s, {1e3 * dt / args.seeds:.1f} ms per fit)")
        print(
            f"  {'coef':<5} {'truth':>12} {'Wald cover':>11} {'mean width':>12}"
            + ("  profile cover" if args.profile else "")
        )
        for n in NAMES:
            c = hits[n] / args.seeds
            t = truth["F0"] / truth["N"] if n == "f" else truth[n]
            good = BAND[0] <= c <= BAND[1]
            ok &= good
            line = f"  {n:<5} {t:>12.6g} {c:>10.2%}{'' if good else '!'} {np.mean(width[n]):>12.4g}"
            if args.profile and n in phits:
                pc = phits[n] / args.seeds
                ok &= BAND[0] <= pc <= BAND[1]
                line += f"  {pc:>12.2%}{'' if BAND[0] <= pc <= BAND[1] else '!'}"
            print(line)
    print("\nall inside the band" if ok else "\nSOME COVERAGE OUTSIDE THE BAND (marked !)")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
