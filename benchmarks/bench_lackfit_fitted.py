"""False alarms of the lack-of-fit verdict on data drawn from the fitted model (a parametric bootstrap).

The documented example (``fepost diagnose --make-example ... --cause C --seed S``
over ``meshes/static.vtu``) is made, screened and fitted with the candidate of its
named cause, as ``diagnose`` fits its chosen model. Then ``--draws`` data sets are
drawn from that fit: the fitted prediction on the rows kept plus Gaussian noise
with the fitted noise model's σ (the same test points, so the same replicates).
Each is fitted again with the same candidate and the same noise structure, and
`lack_of_fit` is run on its residuals. Every verdict "detected" is a false
alarm: the data have no structure beyond the model and its noise. The rate, with
its Wilson 95 % interval, is set against the stated level `LOF_LEVEL`, overall
and per channel.

``--seeds``: also the named cause's own example over that many seeds (the data of
the generator, finer map, with its gross errors), fitted the same way: how often
the verdict fires there (a rate above the bootstrap's is misfit between the
generator's map and the fit grid, not chance).

Run: ``python benchmarks/bench_lackfit_fitted.py [--cause elliptic_patch] [--seed 4]
[--draws 200] [--seeds 0] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

from fepost.analysis import analyse
from fepost.diagnose.calibration import false_alarms, fit_cause
from fepost.diagnose.example import (
    EXAMPLE_LOADS,
    EXAMPLE_NOISE,
    EXAMPLE_OUTLIERS,
    EXAMPLE_POINTS,
    example_parameters,
)
from fepost.diagnose.lackfit import LOF_LEVEL
from fepost.diagnose.simulation import load_simulation
from fepost.diagnose.synthetic import synthesize

REPO = Path(__file__).resolve().parents[1]
_STATE: dict = {}


def wilson(k: int, n: int) -> str:
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return f"{k}/{n} = {k / n:.1%} (Wilson 95 % CI {ci.low:.1%} .. {ci.high:.1%})"


def _example_data(seed: int):
    static, sim, cause = _STATE["static"], _STATE["sim"], _STATE["cause"]
    params = example_parameters(cause, sim.friction, sim.load, sim.radius)
    return synthesize(
        static, cause, params, friction=sim.friction, n=EXAMPLE_POINTS, noise=EXAMPLE_NOISE,
        outliers=EXAMPLE_OUTLIERS, seed=seed, loads=EXAMPLE_LOADS,
    ).data  # fmt: skip


def _draws(chunk: tuple[int, int]) -> dict:
    """``chunk`` = (seed, count): that many data sets drawn from the example's fit."""
    got = false_alarms(_STATE["fitted"], chunk[1], seed=chunk[0])
    return {"n": got.draws, "detected": got.detected, "channels": got.channels}


def _example(seed: int) -> dict:
    """The named cause's own example at ``seed``, fitted with its candidate."""
    lof = fit_cause(_example_data(seed), _STATE["sim"], _STATE["cause"]).verdict()
    channels = {c: int(v["detected"]) for c, v in lof["channels"].items()}
    return {"n": 1, "detected": int(lof["detected"]), "channels": channels}


def _run(func, items, jobs):
    if jobs > 1:
        with mp.get_context("fork").Pool(jobs) as pool:
            return pool.map(func, items)
    return [func(s) for s in items]


def _show(title: str, out: list[dict]) -> None:
    n = sum(o["n"] for o in out)
    print(f"{title}: {wilson(sum(o['detected'] for o in out), n)}")
    per = {ch: sum(o["channels"][ch] for o in out) for ch in ("Fx", "Fy", "Mz")}
    print(f"    per channel (Holm-adjusted, level {LOF_LEVEL}): {per}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--simulation", default=str(REPO / "meshes" / "static.vtu"))
    parser.add_argument("--cause", default="elliptic_patch")
    parser.add_argument("--seed", type=int, default=4, help="the example fitted (make-example's --seed)")
    parser.add_argument("--draws", type=int, default=200)
    parser.add_argument("--seeds", type=int, default=0, help="also the cause's own examples, seeds 1..N")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    result = analyse(args.simulation)
    sim = load_simulation(result.static_map, None, friction=0.3)
    _STATE.update(static=result.static_map, sim=sim, cause=args.cause)
    fitted = fit_cause(_example_data(args.seed), sim, args.cause)
    _STATE["fitted"] = fitted
    lof = fitted.verdict()
    shown = ", ".join(f"{n} = {v:.5g}" for n, v in zip(fitted.fit.names, fitted.fit.values, strict=True))
    print(f"example: cause {args.cause}, seed {args.seed}, {fitted.rows.size} rows kept; fit {shown}")
    print(f"    its verdict: detected {lof['detected']} ({lof['test']}, Holm p = {lof['p_value']:.3g})")
    chunks = [(10_000 + i, len(part)) for i, part in enumerate(np.array_split(np.arange(args.draws), 8))]
    out = _run(_draws, chunks, args.jobs)
    _show(f"data drawn from the fitted model, false alarms at level {LOF_LEVEL}", out)
    if args.seeds:
        out = _run(_example, range(1, args.seeds + 1), args.jobs)
        _show(f"the cause's own examples (seeds 1..{args.seeds}), verdict detected", out)
    print(f"elapsed {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
