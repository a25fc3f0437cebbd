"""diagnose names each hidden cause and recovers its parameters within the 95 % interval.

Tuning vs test sets
-------------------
The thresholds (level 0.05/7, ΔBIC 10, 5 folds, fit grid 24 x 48) were tuned during
development on the **tuning set** only: a Hertzian disc, R = 0.10 m, peak 3e5 Pa,
one load, no rolling map, seed 1, with f = 0.33, c_p = −0.3, c_v = −0.1 s/m,
s = 1.15, α = 0.85, (dx, dy) = (4, −3) mm, offsets (200 N, −150 N, 10 N·m).

The tests below use **other maps and other values** (never tuned on):
* set A: the tire-like profile (raised shoulders), R = 0.12 m, peak 2.5e5 Pa,
  loads 0.7/1.0/1.3 × N, 400 points, noise 1.5 % of range;
* set B: a paraboloid, R = 0.09 m, peak 4e5 Pa, with a rolling map (k_x = 0.1)
  and rows at roll = −1/0/+1, one load, 300 points, noise 2 % of range;
* set C: the CalculiX sample map ``meshes/static.vtu`` (skipped until it exists).
Seeds are fixed per case (set base + index), chosen before the first run. Each
case must name the cause with no rival, land within ~4 standard errors, gain in
held-out RMSE and leave noise-like residuals; the 95 % intervals must hold the
truth at the nominal rate (see MAX_MISSES). Set B misses 3 of 11 on its seeds
(f of friction_level, α, offset_Fy; each |z| ≈ 2.2–2.5); over 40 seeds each the
z-scores of those parameters have SD 0.8–1.1.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fepost.analytic import pressure_function
from fepost.diagnose import diagnose
from fepost.diagnose.synthetic import synthesize
from fepost.polar import PolarGrid, PolarMap

pytestmark = pytest.mark.slow

MESHES = Path(__file__).resolve().parents[1] / "meshes"

SET_A = [
    ("friction_level", {"f": 0.27}),
    ("pressure_dependent_friction", {"c_p": 0.25}),
    ("speed_dependent_friction", {"c_v": 0.08}),
    ("elliptic_patch", {"s": 0.88}),
    ("anisotropic_friction", {"alpha": 1.12}),
    ("pressure_shift", {"dx": -0.003, "dy": 0.0025}),
    ("sensor_offset", {"offset_Fx": -120.0, "offset_Fy": 90.0, "offset_Mz": -6.0}),
]
SET_B = [
    ("friction_level", {"f": 0.34}),
    ("pressure_dependent_friction", {"c_p": -0.35}),
    ("speed_dependent_friction", {"c_v": -0.15}),
    ("elliptic_patch", {"s": 1.1}),
    ("anisotropic_friction", {"alpha": 0.9}),
    ("pressure_shift", {"dx": 0.0025, "dy": 0.0035}),
    ("sensor_offset", {"offset_Fx": 80.0, "offset_Fy": 60.0, "offset_Mz": -4.0}),
]


def _map(profile, radius, peak, k_x=0.0):
    fn = pressure_function(profile, radius, peak=peak, k_x=k_x)
    return PolarMap.from_function(fn, radius, PolarGrid.make(), source=profile)


#: A 95 % interval misses the truth one time in twenty. Each set checks 11
#: parameters; under nominal coverage the misses are Binomial(11, 0.05), and
#: P(misses >= 4) = 0.2 %. So a set may miss at most 3; more means the intervals
#: are too narrow or biased. (Per-seed coverage rates: benchmarks/bench_diagnose.py.)
MAX_MISSES = 3


def _check(diag, syn, effect) -> tuple[list[str], list[str]]:
    """(problems, interval misses) of one diagnosis of data with ``effect`` hidden."""
    problems, misses = [], []
    if diag.cause != effect:
        return [f"{effect}: named {diag.cause}"], []
    if diag.indistinguishable:
        problems.append(f"{effect}: indistinguishable {diag.indistinguishable}")
    for name, truth in syn.truth.items():
        if effect != "friction_level" and name == "f":
            truth = syn.friction
        est = diag.parameters[name]
        half = 0.5 * (est.ci95[1] - est.ci95[0])
        if not est.covers(truth):
            misses.append(f"{effect}: {name} = {truth} outside {est.ci95}")
        if abs(est.value - truth) > 2.0 * half:  # beyond ~4 standard errors: a gross error
            problems.append(
                f"{effect}: {name} = {est.value} far from {truth} (95 % half-width {half:.3g})"
            )
    g = diag.gain
    if not (g["rmse_after"] < g["rmse_before"] and g["delta_bic"] < -10.0):
        problems.append(f"{effect}: no gain {g}")
    after = {ch: st["verdict"] for ch, st in diag.residuals["after"].items()}
    if any(v != "noise" for v in after.values()):
        problems.append(f"{effect}: residuals after the extension {after}")
    return problems, misses


def _run_set(cases, make, base_seed):
    problems, misses = [], []
    for i, (effect, params) in enumerate(cases):
        p, m = make(effect, params, base_seed + i)
        problems += p
        misses += m
    assert not problems, problems
    assert len(misses) <= MAX_MISSES, misses


def test_set_a_tire_map_with_loads():
    pmap = _map("tire", 0.12, 2.5e5)

    def make(effect, params, seed):
        syn = synthesize(pmap, effect, params, n=400, seed=seed, noise=0.015, loads=(0.7, 1.0, 1.3))
        return _check(diagnose(pmap, syn.data, friction=0.3, seed=seed), syn, effect)

    _run_set(SET_A, make, 100)


def test_set_b_paraboloid_with_rolling_map():
    static, rolling = _map("paraboloid", 0.09, 4e5), _map("paraboloid", 0.09, 4e5, k_x=0.1)

    def make(effect, params, seed):
        syn = synthesize(static, effect, params, rolling=rolling, n=300, seed=seed, noise=0.02)
        return _check(
            diagnose(static, syn.data, rolling=rolling, friction=0.3, seed=seed), syn, effect
        )

    _run_set(SET_B, make, 200)


@pytest.mark.parametrize("seed", [301, 302])
def test_null_data_give_none(seed):
    pmap = _map("tire", 0.12, 2.5e5)
    syn = synthesize(pmap, "none", {}, n=400, seed=seed, loads=(0.7, 1.0, 1.3))
    d = diagnose(pmap, syn.data, friction=0.3, seed=seed)
    assert d.cause == "none"
    assert d.parameters == {}
    assert d.gain["rmse_after"] == d.gain["rmse_before"] and d.gain["delta_bic"] == 0.0
    assert all(st["verdict"] == "noise" for st in d.residuals["before"].values())


def test_speed_effect_without_speed_spread_is_flagged():
    """One absolute speed per ratio: the output says speed dependence cannot be separated."""
    from fepost.diagnose.synthetic import rig_programme

    pmap = _map("tire", 0.12, 2.5e5)
    kin = rig_programme(0.12, 300, seed=5, speeds=(0.3,))
    syn = synthesize(pmap, "speed_dependent_friction", {"c_v": 0.1}, kinematics=kin, seed=5)
    d = diagnose(pmap, syn.data, friction=0.3, seed=5)
    assert any("speed_dependent_friction cannot be told" in n for n in d.design_notes)
    assert "speed_dependent_friction cannot be told" in d.summary()


def test_closed_forms_are_compared():
    pmap = _map("hertz", 0.1, 3e5)
    syn = synthesize(pmap, "none", {}, n=200, seed=9)
    d = diagnose(pmap, syn.data, friction=0.3, seed=9)
    cf = d.closed_form
    # THEORY.md §4: the square-root forms are off by up to ~0.1-0.2 of F0, M0 near υ ≈ 0.5-1
    assert 0.01 < cf["rmse_vs_exact"] < 0.2
    assert cf["rmse_vs_data"] > cf["exact_rmse_vs_data"]
    assert np.all(np.isfinite(d.predictions["closed_form"]))


@pytest.mark.skipif(
    not (MESHES / "static.vtu").is_file(),
    reason="CalculiX sample map meshes/static.vtu not yet built",
)
@pytest.mark.parametrize(
    ("effect", "params"),
    [
        ("anisotropic_friction", {"alpha": 1.08}),
        ("pressure_shift", {"dx": 0.002, "dy": -0.002}),
        ("none", {}),
    ],
)
def test_set_c_calculix_map(effect, params):
    from fepost.analysis import analyse

    a = analyse(MESHES / "static.vtu", friction=0.3)
    seed = 400 + len(params)
    syn = synthesize(a.static_map, effect, params, n=400, seed=seed, loads=(0.8, 1.0, 1.2))
    d = diagnose(MESHES / "static.vtu", syn.data, friction=0.3, seed=seed)
    if effect == "none":
        assert d.cause == "none"
    else:
        problems, misses = _check(d, syn, effect)
        assert not problems, problems
        assert len(misses) <= 1, misses
