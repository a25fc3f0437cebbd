"""The per-channel lack-of-fit test: false-positive rate without misfit, detection rate with one.

For each seed, synthetic rig data are made by the exact integrals over a map with
the nominal f and nothing else (``--points`` test points drawn from the default
programme: with 150 of its 360 points few are replicated), then diagnosed the
way ``diagnose`` treats its chosen model when that model is ``friction_level``:
the robust screen (outliers, noise structure per channel), the Gaussian fit of
``friction_level`` on the kept rows, and ``lack_of_fit`` on its residuals. This
isolates the test from the cause selection (which ``bench_false_positive.py``
measures with the whole pipeline) and is ~10× faster.

* Null: no misfit; a false positive is ``lack_of_fit.detected``. Reported per
  noise model with a Wilson 95 % interval, and the per-channel rejection rates.
* Detection: a one-channel misfit outside the model, the load-cell crosstalk
  measured Fy = Fy + c·Fx, for each c of ``--sizes`` (c·f·N is its size in % of
  f·N at full sliding); reported as the rate at which ``lack_of_fit`` is
  detected and names Fy, and for comparison the rate of the pooled
  three-channel test of earlier versions (``pure_error_test``) at the same level.

``--recording``: instead of test points, each data set is a rig recording of
the points (`fepost.diagnose.synthetic_recording`: 3 s holds at 200 Hz, 1 s
ramps, AR(1) noise with ρ = 0.9 and a per-sample SD of 3 % of f·N in Fx, Fy
and of f·N·R in Mz), read back and reduced to its holds
(`fepost.diagnose.holds.find_holds`); the test then takes its pure error from
the scatter within the holds.

Run: ``python benchmarks/bench_lackfit_channels.py [--recording] [--seeds 100] [--points 150]
[--sizes 0.01 0.02 0.03 0.06] [--noise-factor 1] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import dataclasses
import multiprocessing as mp
import time

import numpy as np
from scipy.stats import binomtest

from fepost.analytic import pressure_function
from fepost.diagnose.causes import Predictor, build_candidates
from fepost.diagnose.fitting import fit
from fepost.diagnose.lackfit import LOF_LEVEL, lack_of_fit, pure_error_test
from fepost.diagnose.measured import point_keys
from fepost.diagnose.noise import NOISE_FLOOR
from fepost.diagnose.pipeline import screen
from fepost.diagnose.simulation import load_simulation
from fepost.diagnose.synthetic import synthesize
from fepost.polar import PolarGrid, PolarMap

MAPS = (("hertz", 0.10, 3.0e5), ("tire", 0.12, 2.5e5))
NOISE_MODELS = {
    "constant": {"noise": 0.015, "noise_proportional": 0.0},
    "proportional": {"noise": 0.0, "noise_proportional": 0.03},
    "combined": {"noise": 0.0075, "noise_proportional": 0.02},
}
_MAPS: list = []
_SIMS: list = []


def wilson(k: int, n: int) -> str:
    ci = binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    return f"{k}/{n} = {k / n:.1%} (Wilson 95 % CI {ci.low:.1%} .. {ci.high:.1%})"


def _holds(syn, size, seed):
    """The data set as a recording's hold means (module docstring, ``--recording``)."""
    import tempfile

    from fepost.diagnose.holds import find_holds
    from fepost.diagnose.synthetic_recording import synthetic_recording, write_recording

    scale = np.array([1.0, 1.0, syn.meta["R"]]) * syn.friction * syn.meta["N"]
    rec = synthetic_recording(syn, sd=0.03 * scale, rho=0.9, seed=seed)
    if size:
        rec["Fy"] = rec["Fy"] + size * rec["Fx"]
    with tempfile.TemporaryDirectory() as tmp:
        return find_holds(write_recording(rec, f"{tmp}/rec.parquet"))


def _verdict(data, sim, pure=None):
    pred = Predictor(sim, data)
    cands = build_candidates(pred)
    cands = {k: cands[k] for k in ("none", "friction_level")}
    Y = data.forces / pred.scale
    rob, rows, noise, _ = screen(cands, Y)
    cand = cands["friction_level"]
    f = fit(cand, Y, rows, start=rob.fits["friction_level"].values, noise=noise)
    prediction = cand.predict(f.values)
    sigma = f.noise.sigma()[rows]
    res = (Y - prediction)[rows]
    pe = None if pure is None else (pure[0][rows] / pred.scale, pure[1][rows])
    lof = lack_of_fit(data, rows, res, prediction[rows], sigma, f.jacobian, pure_error=pe)
    used = sigma >= 2.0 * NOISE_FLOOR
    pooled = pure_error_test(np.where(used, res / sigma, 0.0), point_keys(data)[rows], 1, used)
    return lof, pooled


def _one(job):
    model, seed, i, points, size, factor = job
    pmap, sim = _MAPS[i % len(_MAPS)], _SIMS[i % len(_SIMS)]
    t = time.perf_counter()
    if model == "recording":
        syn = synthesize(pmap, "none", {}, friction=0.3, n=points, seed=seed, noise=0.0)
        holds = _holds(syn, size, seed)
        lof, pooled = _verdict(holds.data, sim, holds.pure_error())
    else:
        noise = {k: factor * v for k, v in NOISE_MODELS[model].items()}
        syn = synthesize(pmap, "none", {}, friction=0.3, n=points, seed=seed, **noise)
        data = syn.data
        if size:
            data = dataclasses.replace(data, Fy=data.Fy + size * data.Fx)
        lof, pooled = _verdict(data, sim)
    return {
        "detected": lof["detected"],
        "channels": {ch: v["detected"] for ch, v in lof["channels"].items()},
        "pooled": pooled is not None and pooled["p"] < LOF_LEVEL,
        "seconds": time.perf_counter() - t,
        "test": lof["test"],
    }


def _run(jobs, n_jobs):
    if n_jobs > 1:
        with mp.get_context("fork").Pool(n_jobs) as pool:
            return pool.map(_one, jobs, chunksize=2)
    return [_one(j) for j in jobs]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=100)
    parser.add_argument("--points", type=int, default=150)
    parser.add_argument("--first-seed", type=int, default=5000)
    parser.add_argument("--sizes", type=float, nargs="*", default=[0.01, 0.02, 0.03, 0.06])
    parser.add_argument("--noise-models", nargs="+", default=list(NOISE_MODELS), choices=list(NOISE_MODELS))
    parser.add_argument("--noise-factor", type=float, default=1.0, help="multiplies every noise SD")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--recording", action="store_true", help="hold means of recordings (docstring)")
    args = parser.parse_args(argv)
    if args.recording:
        args.noise_models = ["recording"]
        NOISE_MODELS["recording"] = {"per-sample SD": 0.03, "AR(1) rho": 0.9}
    for name, radius, peak in MAPS:
        pmap = PolarMap.from_function(
            pressure_function(name, radius, peak=peak), radius, PolarGrid.make(), source=name
        )
        _MAPS.append(pmap)
        _SIMS.append(load_simulation(pmap, None, friction=0.3))
    t0 = time.perf_counter()
    for model in args.noise_models:
        what = f"{model} {NOISE_MODELS[model]} x {args.noise_factor:g}"
        print(f"\nnoise model {what}, {args.points} points, level {LOF_LEVEL} (Holm)")
        for size in [0.0, *args.sizes]:
            jobs = [
                (model, args.first_seed + i, i, args.points, size, args.noise_factor)
                for i in range(args.seeds)
            ]
            out = _run(jobs, args.jobs)
            n = len(out)
            what = "false positives" if size == 0 else f"Fy += {size:g} Fx: detected"
            print(f"  {what}: {wilson(sum(o['detected'] for o in out), n)}")
            per = {ch: sum(o["channels"][ch] for o in out) for ch in ("Fx", "Fy", "Mz")}
            print(f"    per channel (Holm): {per}; pooled 3-channel test at {LOF_LEVEL}: "
                  f"{sum(o['pooled'] for o in out)}/{n}; "
                  f"median {np.median([o['seconds'] for o in out]):.2f} s per data set")  # fmt: skip
    print(f"\nelapsed {time.perf_counter() - t0:.0f} s (machine shared by other jobs: times indicative)")


if __name__ == "__main__":
    main()
