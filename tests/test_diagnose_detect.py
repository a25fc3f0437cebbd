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
* set C: the CalculiX sample map ``meshes/static.vtu`` (committed: its absence fails).
Seeds are fixed per case (set base + index), chosen before the first run and
never changed. Each case must name the cause with no rival, gain in held-out
RMSE, leave noise-like residuals, and every parameter's truth must lie inside
its reported 95 % interval.

Known misses (:data:`KNOWN_MISSES`). The intervals are calibrated: over 200
noise draws at each case's own test design, fitting the true cause, every
parameter's coverage lies within 2 Monte-Carlo SE of 95 % and z = (estimate −
truth)/SE has mean within ±0.2 and SD 0.9–1.1, with the same figures on a fit grid
equal to the generator's (``benchmarks/bench_diagnose_coverage.py``). At the
committed seeds three set-B parameters nevertheless fall just outside their
intervals (|z| = 2.2–2.5): the 1-in-20 misses a 95 % interval must have (with
22 parameters, P(at least one miss) = 1 − 0.95²² ≈ 68 %). They are listed
exactly, not tolerated: a case must miss precisely its listed parameters (any
other miss, or a listed one that starts covering, fails) and is then reported
as xfail.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fepost.diagnose import diagnose
from fepost.diagnose.synthetic import VALIDATION_SET_A, VALIDATION_SET_B, analytic_map, synthesize

pytestmark = pytest.mark.slow

MESHES = Path(__file__).resolve().parents[1] / "meshes"

SET_A = VALIDATION_SET_A
SET_B = VALIDATION_SET_B
_map = analytic_map


#: Parameters whose truth lies outside the 95 % interval at the committed seed
#: (see the module docstring; z = (estimate − truth)/SE at that seed, and the
#: coverage of the parameter's interval over 200 noise draws at that test design).
KNOWN_MISSES = {
    ("B", "friction_level"): {"f": "z = -2.18; coverage 96.0 +- 1.4 %"},
    ("B", "anisotropic_friction"): {"alpha": "z = -2.18; coverage 96.5 +- 1.3 %"},
    ("B", "sensor_offset"): {"offset_Fy": "z = +2.50; coverage 95.5 +- 1.5 %"},
}


#: Rivals that are the same model on a case's map, listed exactly (as `KNOWN_MISSES`): on set
#: B's paraboloid at one load a pressure-dependent coefficient adds c_p σ(σ/σ_ref − 1) ∝
#: σ(1 − 2ρ²/R²) to the traction, a reshaped pressure adds c_rim σ r ∝ σ(3ρ²/R² − 1): with f
#: free both span {σ, σρ²}. Loads tell them apart (set A, tests/test_diagnose_pressure_shape.py).
KNOWN_RIVALS = {("B", "pressure_dependent_friction"): ("pressure_shape",)}


def _check(diag, syn, effect, rivals=()) -> tuple[list[str], dict[str, str]]:
    """(problems, interval misses by parameter) of one diagnosis of data with ``effect`` hidden."""
    problems, misses = [], {}
    if diag.cause != effect:
        return [f"{effect}: named {diag.cause}"], {}
    if tuple(r for r in diag.indistinguishable if r != effect) != tuple(rivals):
        problems.append(f"{effect}: indistinguishable {diag.indistinguishable}")
    if set(diag.parameters) != set(syn.truth):
        problems.append(f"{effect}: parameters {sorted(diag.parameters)} != {sorted(syn.truth)}")
        return problems, {}
    for name, truth in syn.truth.items():
        if effect != "friction_level" and name == "f":
            truth = syn.friction
        est = diag.parameters[name]
        if not est.covers(truth):
            misses[name] = f"{effect}: {name} = {truth} outside {est.ci95} (estimate {est.value})"
    g = diag.gain
    if not (g["rmse_after"] < g["rmse_before"] and g["delta_bic"] < -10.0):
        problems.append(f"{effect}: no gain {g}")
    after = {ch: st["verdict"] for ch, st in diag.residuals["after"].items()}
    if any(v != "noise" for v in after.values()):
        problems.append(f"{effect}: residuals after the extension {after}")
    if diag.causes != (effect,):
        problems.append(f"{effect}: causes {diag.causes}")
    if diag.lack_of_fit["detected"]:  # (a clean row may be flagged: the outlier rule's 5 % by design)
        problems.append(f"{effect}: lack of fit: {diag.lack_of_fit['message']}")
    return problems, misses


def _assert_case(set_name, effect, problems, misses):
    assert not problems, problems
    known = KNOWN_MISSES.get((set_name, effect), {})
    assert set(misses) == set(known), (
        f"interval misses {sorted(misses.values())}; known at this seed: {sorted(known)}"
    )
    if known:
        pytest.xfail(f"known 1-in-20 interval miss at this seed: {known}")


@pytest.mark.parametrize(("i", "effect", "params"), [(i, *c) for i, c in enumerate(SET_A)])
def test_set_a_tire_map_with_loads(i, effect, params):
    pmap = _map("tire", 0.12, 2.5e5)
    seed = 100 + i
    syn = synthesize(pmap, effect, params, n=400, seed=seed, noise=0.015, loads=(0.7, 1.0, 1.3))
    problems, misses = _check(diagnose(pmap, syn.data, friction=0.3, seed=seed), syn, effect)
    _assert_case("A", effect, problems, misses)


@pytest.mark.parametrize(("i", "effect", "params"), [(i, *c) for i, c in enumerate(SET_B)])
def test_set_b_paraboloid_with_rolling_map(i, effect, params):
    static, rolling = _map("paraboloid", 0.09, 4e5), _map("paraboloid", 0.09, 4e5, k_x=0.1)
    seed = 200 + i
    syn = synthesize(static, effect, params, rolling=rolling, n=300, seed=seed, noise=0.02)
    diag = diagnose(static, syn.data, rolling=rolling, friction=0.3, seed=seed)
    problems, misses = _check(diag, syn, effect, KNOWN_RIVALS.get(("B", effect), ()))
    _assert_case("B", effect, problems, misses)


@pytest.mark.parametrize("seed", [301, 302])
def test_null_data_give_none(seed):
    pmap = _map("tire", 0.12, 2.5e5)
    syn = synthesize(pmap, "none", {}, n=400, seed=seed, loads=(0.7, 1.0, 1.3))
    d = diagnose(pmap, syn.data, friction=0.3, seed=seed)
    assert d.cause == "none" and d.causes == ("none",)
    assert not d.lack_of_fit["detected"]
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
    # docs/theory.md: the square-root forms are off by up to ~0.1-0.2 of F0, M0 near υ ≈ 0.5-1
    assert 0.01 < cf["rmse_vs_exact"] < 0.2
    assert cf["rmse_vs_data"] > cf["exact_rmse_vs_data"]
    assert np.all(np.isfinite(d.predictions["closed_form"]))


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
        assert d.causes == ("none",) and not d.lack_of_fit["detected"]
    else:
        problems, misses = _check(d, syn, effect)
        assert not problems, problems
        assert not misses, sorted(misses.values())
