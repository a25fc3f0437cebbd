"""Monte-Carlo coverage of the 95 % intervals of ``fepost diagnose``, per cause and parameter.

For each cause the synthetic data of the detection tests (tests/test_diagnose_detect.py)
are made once at the test's design seed with :func:`fepost.diagnose.synthetic.synthesize`
(kinematics, loads, rolls and the clean exact resultants of the fine generator grid),
then the noise is redrawn ``--seeds`` times with
:func:`fepost.diagnose.synthetic.renoised` (same noise model and SD). Each replicate
is fitted with the TRUE cause's model only (no selection, so the figure is the
intervals' own coverage) and each parameter's 95 % interval is checked against the
truth. Printed per parameter: coverage with its Monte-Carlo standard error
√(p(1−p)/K), and the mean and SD of z = (estimate − truth)/stderr (nominal 0 and 1:
a mean ≠ 0 is a bias, e.g. a model error of the fit grid; an SD > 1 intervals too
narrow).

Sets (as in the tests): ``A`` tire-like map R = 0.12 m, loads 0.7/1.0/1.3, 400
points, noise 1.5 %; ``B`` paraboloid R = 0.09 m with a rolling map (k_x = 0.1),
roll −1/0/+1, 300 points, noise 2 %; ``rig`` the set-A map and effects as in
tests/test_diagnose_rig.py: 300 points, noise 3 % of |reading| (no floor) and four
gross errors per data set (the same rows in every replicate); ``rig-combined``
the same with noise SD² = (0.75 % of range)² + (2 % of |reading|)²; ``new`` the
causes ``sensor_crosstalk`` and ``load_transfer`` on a Hertzian map R = 0.1 m, 300
points, noise 1.5 %; ``pairs`` the two
two-cause cases of that file (friction level with sensor offsets, anisotropy
with a pressure shift; 400 points, noise 1.5 %), their joint model fitted.

For sets with gross errors or proportional noise each replicate goes through the
pipeline's own screen (:func:`fepost.diagnose.pipeline.screen`: robust fits,
outlier rule, noise model chosen per channel) before the true model is fitted to
the rows kept; the rate at which exactly the glitched rows were flagged is printed.

Run: ``.venv/bin/python benchmarks/bench_diagnose_coverage.py [--sets A B rig pairs]
[--seeds 200] [--nr 24 --nphi 48] [--causes ...] [--jobs 2]``
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time

import numpy as np

from fepost.diagnose.causes import Predictor, build_candidates, joint_candidate
from fepost.diagnose.fitting import fit
from fepost.diagnose.pipeline import screen
from fepost.diagnose.simulation import FIT_NPHI, FIT_NR, simulation_from_maps
from fepost.diagnose.synthetic import (
    VALIDATION_SET_A,
    VALIDATION_SET_B,
    analytic_map,
    renoised,
    synthesize,
)

SET_A = VALIDATION_SET_A
SET_B = VALIDATION_SET_B
_map = analytic_map


PAIRS = (
    (
        ("friction_level", "sensor_offset"),
        {"f": 0.27, "offset_Fx": -120.0, "offset_Fy": 90.0, "offset_Mz": -6.0},
    ),
    (("anisotropic_friction", "pressure_shift"), {"alpha": 1.12, "dx": -0.003, "dy": 0.0025}),
)


def set_up(name: str):
    """(cases, base seed, synthesize kwargs, static, rolling) of test set ``name``."""
    if name == "A":
        pmap = _map("tire", 0.12, 2.5e5)
        return SET_A, 100, {"n": 400, "noise": 0.015, "loads": (0.7, 1.0, 1.3)}, pmap, None
    if name == "rig":
        pmap = _map("tire", 0.12, 2.5e5)
        kw = {"n": 300, "noise": 0.0, "noise_proportional": 0.03, "outliers": 4, "loads": (0.7, 1.0, 1.3)}
        return SET_A, 1101, kw, pmap, None
    if name == "rig-combined":  # as "rig" with a noise floor: (0.75 % of range)² + (2 % of |reading|)²
        pmap = _map("tire", 0.12, 2.5e5)
        kw = {"n": 300, "noise": 0.0075, "noise_proportional": 0.02, "outliers": 4, "loads": (0.7, 1.0, 1.3)}
        return SET_A, 1101, kw, pmap, None
    if name == "pairs":
        pmap = _map("tire", 0.12, 2.5e5)
        return PAIRS, 1204, {"n": 400, "noise": 0.015, "loads": (0.7, 1.0, 1.3)}, pmap, None
    if name == "new":
        return NEW, 300, {"n": 300, "noise": 0.015}, _map("hertz", 0.1, 3.0e5), None
    if name == "B":
        static, rolling = _map("paraboloid", 0.09, 4e5), _map("paraboloid", 0.09, 4e5, k_x=0.1)
        return SET_B, 200, {"n": 300, "noise": 0.02}, static, rolling
    raise SystemExit(f"unknown set {name!r}")


#: The causes added with rig recordings (set ``new``): a load-cell crosstalk and a load transfer.
NEW = (
    (
        "sensor_crosstalk",
        {"c_xy": 0.0, "c_xz": 0.0, "c_yx": 0.06, "c_yz": 0.0, "c_zx": 0.002, "c_zy": -0.0015},
    ),
    ("load_transfer", {"h_x": 0.03, "h_y": 0.02}),
)


# Fork-shared state of one (set, cause) study: the workers inherit it.
_STATE: dict = {}


def _model(pred, effect):
    """The model of the hidden effect(s): a single cause, or the joint model of two."""
    if not isinstance(effect, tuple):
        return build_candidates(pred)[effect]
    exts = tuple(e for e in effect if e != "friction_level")
    return joint_candidate(pred, exts)


def _one(seed: int):
    if _STATE["vary"]:
        # a new test design (kinematics, rolls, loads) and noise per replicate
        syn = synthesize(*_STATE["args"], seed=seed, **_STATE["kwargs"])
        pred = Predictor(_STATE["sim"], syn.data)
        cand = _model(pred, _STATE["effect"])
        cands = build_candidates(pred)
    else:
        syn = renoised(_STATE["syn"], seed)
        pred, cand, cands = _STATE["pred"], _STATE["cand"], _STATE["cands"]
    Y = syn.data.forces / pred.scale
    exact = True
    if _STATE["screen"]:
        rob, rows, noise, _ = screen(cands, Y)
        exact = rob.outliers.tolist() == list(syn.outliers)
        ft = fit(cand, Y, rows, noise=noise)
    else:
        ft = fit(cand, Y)
    truth = np.array([_STATE["truth"][n] for n in ft.names])
    covered = (ft.ci95[:, 0] <= truth) & (truth <= ft.ci95[:, 1])
    z = (ft.values - truth) / ft.stderr
    return covered, z, exact


def study(set_name, effect, params, seed, kwargs, static, rolling, sim, seeds, jobs, vary=False):
    syn = synthesize(static, effect, params, rolling=rolling, seed=seed, **kwargs)
    pred = Predictor(sim, syn.data)
    cand = _model(pred, effect)
    truth = {**syn.truth}
    if "friction_level" not in syn.effects:
        truth["f"] = syn.friction
    needs_screen = bool(kwargs.get("outliers") or kwargs.get("noise_proportional"))
    _STATE.update(
        syn=syn, pred=pred, cand=cand, truth=truth, vary=vary, sim=sim, effect=effect,
        args=(static, effect, params), kwargs={"rolling": rolling, **kwargs}, screen=needs_screen,
        cands=build_candidates(pred),
    )  # fmt: skip
    noise_seeds = [50_000 + k for k in range(seeds)]
    if jobs > 1:
        with mp.get_context("fork").Pool(jobs) as pool:
            out = pool.map(_one, noise_seeds, chunksize=max(1, seeds // (4 * jobs)))
    else:
        out = [_one(s) for s in noise_seeds]
    cov = np.array([o[0] for o in out], float)
    z = np.array([o[1] for o in out])
    exact = np.mean([o[2] for o in out])
    names = tuple(p.name for p in cand.parameters)
    label = "+".join(effect) if isinstance(effect, tuple) else effect
    rows = []
    for j, name in enumerate(names):
        p = cov[:, j].mean()
        se = np.sqrt(p * (1 - p) / seeds)
        rows.append((set_name, label, name, p, se, z[:, j].mean(), z[:, j].std(ddof=1)))
    if needs_screen:
        print(
            f"    ({label}: exactly the glitched rows flagged in {exact:.1%} of the replicates)", flush=True
        )
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", nargs="+", default=["A", "B"])
    parser.add_argument("--seeds", type=int, default=200)
    parser.add_argument("--nr", type=int, default=FIT_NR)
    parser.add_argument("--nphi", type=int, default=FIT_NPHI)
    parser.add_argument("--causes", nargs="*", default=None)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument(
        "--vary-design",
        action="store_true",
        help="draw new kinematics/rolls/loads per replicate too (slow: new exact integrals)",
    )
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    print(
        f"coverage of the 95 % intervals, true cause fitted, {args.seeds} replicates per cause, "
        f"fit grid {args.nr} x {args.nphi}"
        + (", new design per replicate" if args.vary_design else ", design of the test seed")
    )
    print(f"{'set':<5} {'cause':<36} {'param':<10} {'coverage':>9} {'MC se':>6} {'mean z':>7} {'SD z':>6}")
    low = []
    for set_name in args.sets:
        cases, base, kwargs, static, rolling = set_up(set_name)
        sim = simulation_from_maps(static, rolling, friction=0.3, nr=args.nr, nphi=args.nphi)
        for i, (effect, params) in enumerate(cases):
            label = "+".join(effect) if isinstance(effect, tuple) else effect
            if args.causes and label not in args.causes:
                continue
            rows = study(
                set_name, effect, params, base + i, kwargs, static, rolling, sim,
                args.seeds, args.jobs, args.vary_design,
            )  # fmt: skip
            for s, e, n, p, se, mz, sz in rows:
                se0 = np.sqrt(0.95 * 0.05 / args.seeds)  # the MC se at nominal coverage
                flag = "" if abs(p - 0.95) <= 2 * se0 else "  <--"
                if flag:
                    low.append(f"{s}:{e}:{n}")
                print(f"{s:<5} {e:<36} {n:<10} {p:9.1%} {se:6.1%} {mz:+7.2f} {sz:6.2f}{flag}", flush=True)
    print(f"\noutside 95 % ± 2 MC se (nominal): {low or 'none'}")
    print(f"elapsed {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
