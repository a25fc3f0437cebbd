"""Monte-Carlo coverage of the Table 1 intervals.

For each seed, make closed-form test curves with the paper's noise, fit them with
:func:`fepost.identify.fit_table1`, and count whether each 95 % interval holds the
true coefficient. A calibrated method covers 95 %; with S seeds the Monte-Carlo
standard error is √(0.95·0.05/S) (0.49 % at S = 2000), so the acceptance band
93–97 % is about ±4 standard errors.

Two truth sets: ``hertz`` (a Hertzian disc, R = 0.1 m, 200 kPa peak, f = 0.3,
k_x = 0.13) and ``paper`` (Table 1's theoretical values, R = 0.07 m, the radius
the paper's M0/F0 implies, N = F0/f).

``--form generalised``: the generalised friction model instead, fitted to curves
made by the exact Coulomb integrals (the ground truth it approximates) over a
non-circular map (Hertz ellipse, aspect 1.5, with its rolling model
σ0(1 + k x/R), k = 0.13), each seed adding fresh noise to the same exact curves.
The truth is then the FE map's F0, M0, a and m along x, k_x. For contrast the
paper's closed forms are fitted to the same data, their intervals checked
against the paper's (asymptotic) values of the same map.

    .venv/bin/python benchmarks/bench_coverage.py [--seeds 2000] [--noise uniform|gaussian] \
        [--profile] [--form paper|generalised]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fepost import analytic
from fepost.identify import PARAMETERS, fit_table1, make_test_curves, with_noise

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


def generalised_setup():
    from fepost.friction.build import build_model
    from fepost.friction.law import FrictionLaw
    from fepost.friction.reference_maps import ellipse_quad
    from fepost.friction.tensors import map_tensors
    from fepost.identify import GeneralisedCurves, rolling_model

    f, k = 0.3, 0.13
    quad = ellipse_quad("hertz", 1.5)
    R = quad.radius
    roll = rolling_model(quad, k, R)
    law = FrictionLaw(f=f)
    form = GeneralisedCurves(build_model(quad, law), build_model(roll, law, radius=R), k_ref=k)
    t = map_tensors(quad)
    paper_truth = {
        "F0": f * t.N,
        "M0": f * t.polar,
        "a": (2 * t.N / (R * np.trace(t.inverse))) ** 2,
        "m": (2 * R * t.polar / np.trace(t.second)) ** 2,
        "k_x": k,
        "R": R,
        "N": t.N,
    }
    clean = make_test_curves("exact", paper_truth, quad=quad, rolling_quad=roll, amplitude=0.0)
    truth = {**form.theory(), "R": R, "N": t.N}
    return form, clean, truth, paper_truth


def generalised_coverage(args) -> bool:
    form, clean, truth, paper_truth = generalised_setup()
    hits = {"generalised": {n: 0 for n in NAMES}, "paper": {n: 0 for n in NAMES}}
    t0 = time.perf_counter()
    for seed in range(args.seeds):
        data = with_noise(clean, noise=args.noise, seed=seed)
        for tag, fm, tr in (("generalised", form, truth), ("paper", None, paper_truth)):
            fit = fit_table1(data, truth["N"], form=fm, profile=False)
            for n in NAMES:
                lo, hi = fit.interval(n)
                t = tr["F0"] / tr["N"] if n == "f" else tr[n]
                hits[tag][n] += lo <= t <= hi
    dt = time.perf_counter() - t0
    print(f"\n[Hertz ellipse aspect 1.5, exact-integral curves]  ({dt:.1f} s for {2 * args.seeds} fits)")
    print(f"  {'coef':<5} {'truth (map)':>12} {'generalised':>12} {'paper forms':>12} {'paper truth':>12}")
    ok = True
    for n in NAMES:
        c = hits["generalised"][n] / args.seeds
        p = hits["paper"][n] / args.seeds
        good = BAND[0] <= c <= BAND[1]
        ok &= good
        t = truth["F0"] / truth["N"] if n == "f" else truth[n]
        pt = paper_truth["F0"] / paper_truth["N"] if n == "f" else paper_truth[n]
        print(f"  {n:<5} {t:>12.6g} {c:>11.2%}{'' if good else '!'} {p:>12.2%} {pt:>12.6g}")
    print("  (the paper's column: its closed forms on the same exact data; not held to the band)")
    return ok


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=2000)
    ap.add_argument("--noise", choices=("uniform", "gaussian"), default="uniform")
    ap.add_argument("--n-points", type=int, default=50)
    ap.add_argument("--profile", action="store_true", help="also check the profile bounds of a and m")
    ap.add_argument("--form", choices=("paper", "generalised"), default="paper")
    args = ap.parse_args()
    se = np.sqrt(0.95 * 0.05 / args.seeds)
    print(
        f"coverage of 95 % intervals, {args.seeds} seeds, {args.noise} noise (amplitude 0.2 max), "
        f"{args.n_points} points per curve; Monte-Carlo s.e. {se:.2%}; "
        f"band {BAND[0]:.0%}-{BAND[1]:.0%}"
    )
    if args.form == "generalised":
        ok = generalised_coverage(args)
        print("\nall inside the band" if ok else "\nSOME COVERAGE OUTSIDE THE BAND (marked !)")
        return 0 if ok else 1
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
