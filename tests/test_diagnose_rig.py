"""Rig data as they come: gross outliers, proportional noise, drift, two causes, other laws.

Every case hides its effect in data made by the project's generator
(:func:`fepost.diagnose.synthetic.synthesize`) on the tire-like map of the
detection tests' set A (R = 0.12 m, peak 2.5e5 Pa, loads 0.7/1.0/1.3 × N), with
the set-A effect sizes, 300 points unless said otherwise. The seeds are fixed per
case (base + index), chosen before the first run and never changed.

* each cause with **four gross errors** (sign flips and 2.5× spikes of a whole
  row) **and noise proportional to the reading** (3 % of |F|, no floor): the
  cause is named alone, exactly the glitched rows are flagged, every channel's
  noise model is the proportional one, no lack of fit, and the true parameters
  lie in their intervals;
* the null with proportional noise and no glitch (the false positive of the
  issue: ``anisotropic_friction`` named);
* a strong pressure effect hidden by four glitches in 288 points (the miss of
  the issue: ``none`` named), under constant noise;
* a friction level falling by 10 % along the run order: lack of fit detected
  (the miss of the issue: "the misfit is within the noise"); the same drift
  against a ``time`` column, with the file sorted by test condition;
* two causes at once: a friction level with sensor offsets, anisotropy with a
  pressure shift;
* an exponential (Stribeck-type) fall of friction with sliding speed, which
  fepost fits as linear: still ``speed_dependent_friction``.

Known interval misses (:data:`KNOWN_MISSES`): the intervals' coverage is
measured by ``benchmarks/bench_diagnose_coverage.py --sets rig pairs`` (200 noise
draws per case at its own design); a case must miss exactly its listed
parameters at its committed seed (any other miss, or a listed one that starts
covering, fails) and is then reported as xfail, as in test_diagnose_detect.py.
"""

from __future__ import annotations

import pytest

from fepost.diagnose import diagnose
from fepost.diagnose.lackfit import PREFIX
from fepost.diagnose.synthetic import VALIDATION_SET_A, analytic_map, synthesize

pytestmark = pytest.mark.slow

LOADS = (0.7, 1.0, 1.3)
CASES = (("none", {}), *VALIDATION_SET_A)

#: Parameters whose truth lies outside the 95 % interval at the committed seed, with
#: z = (estimate − truth)/SE there and the interval's coverage over 200 noise draws.
KNOWN_MISSES = {
    "friction_level+sensor_offset": {"offset_Mz": "z = +2.07; coverage 95.5 +- 1.5 %"},
}


def _assert_misses(case, misses):
    known = KNOWN_MISSES.get(case, {})
    assert set(misses) == set(known), f"interval misses {misses}; known at this seed: {sorted(known)}"
    if known:
        pytest.xfail(f"known 1-in-20 interval miss at this seed: {known}")


@pytest.fixture(scope="module")
def tire():
    return analytic_map("tire", 0.12, 2.5e5)


def _covers(d, syn, effect):
    """{parameter: why} for every true parameter outside its interval."""
    misses = {}
    for name, truth in syn.truth.items():
        if name == "f" and "friction_level" not in syn.effects:
            truth = syn.friction
        if name in d.parameters and not d.parameters[name].covers(truth):
            misses[name] = f"{name} = {truth} outside {d.parameters[name].ci95}"
    return misses


@pytest.mark.parametrize(("i", "effect", "params"), [(i, *c) for i, c in enumerate(CASES)])
def test_outliers_and_proportional_noise_on_each_cause(tire, i, effect, params):
    seed = 1100 + i
    syn = synthesize(
        tire, effect, params, n=300, seed=seed, loads=LOADS, noise=0.0, noise_proportional=0.03, outliers=4
    )
    d = diagnose(tire, syn.data, friction=0.3, seed=seed)
    assert d.causes == (effect,), d.summary()
    assert list(d.outliers) == list(syn.outliers)
    assert [d.noise[c]["model"] for c in ("Fx", "Fy", "Mz")] == ["proportional"] * 3
    assert not d.lack_of_fit["detected"], d.lack_of_fit
    if effect != "none":
        assert d.gain["rmse_after"] < d.gain["rmse_before"] and d.gain["delta_bic"] < -10
    _assert_misses(effect, _covers(d, syn, effect))


def test_proportional_noise_alone_gives_none(tire):
    syn = synthesize(tire, "none", {}, n=288, seed=1201, loads=LOADS, noise=0.0, noise_proportional=0.03)
    d = diagnose(tire, syn.data, friction=0.3, seed=1201)
    assert d.causes == ("none",) and not d.outliers and not d.lack_of_fit["detected"]


def test_four_glitches_do_not_hide_a_pressure_effect(tire):
    syn = synthesize(
        tire, "pressure_dependent_friction", {"c_p": 0.3}, n=288, seed=1202, loads=LOADS, outliers=4
    )
    d = diagnose(tire, syn.data, friction=0.3, seed=1202)
    assert d.causes == ("pressure_dependent_friction",)
    assert list(d.outliers) == list(syn.outliers)
    assert d.parameters["c_p"].covers(0.3)
    assert "outliers: 4 row(s) no candidate explains" in d.summary()


@pytest.mark.parametrize("time_column", [False, True], ids=["run-order", "time-column"])
def test_drifting_friction_level_is_lack_of_fit(tire, time_column):
    syn = synthesize(tire, "none", {}, n=300, seed=1203, loads=LOADS, drift=-0.1, time_column=time_column)
    d = diagnose(tire, syn.data, friction=0.3, seed=1203)
    lof = d.lack_of_fit
    assert lof["detected"] and lof["p_value"] < 1e-6, lof
    where = "time" if time_column else "run order"
    assert lof["message"].startswith(PREFIX + f"the residuals drift with {where}")
    assert lof["test"] == ("run-order trend (time column)" if time_column else "run-order trend (file order)")
    if time_column:  # the file is sorted by condition: its row order shows no drift
        assert lof["tests"]["trend_file"]["p"] > 1e-3
    assert "lack of fit: DETECTED: " + PREFIX in d.summary()
    assert not d.outliers  # a drift is structure, not glitches


@pytest.mark.parametrize(
    ("effects", "params", "seed"),
    [
        (("friction_level", "sensor_offset"), {"f": 0.27, "offset_Fx": -120.0, "offset_Fy": 90.0,
                                               "offset_Mz": -6.0}, 1204),
        (("anisotropic_friction", "pressure_shift"), {"alpha": 1.12, "dx": -0.003, "dy": 0.0025}, 1205),
    ],
    ids=["friction_level+sensor_offset", "anisotropic_friction+pressure_shift"],
)  # fmt: skip
def test_two_causes_at_once(tire, effects, params, seed):
    syn = synthesize(tire, effects, params, n=400, seed=seed, loads=LOADS)
    d = diagnose(tire, syn.data, friction=0.3, seed=seed)
    assert set(d.causes) == set(effects) and len(d.causes) == 2, d.summary()
    assert d.cause == d.causes[0]
    assert set(d.parameters) == set(syn.truth) | {"f"}
    assert d.gain["model"] in ("+".join(effects), "+".join(effects[::-1]), "sensor_offset")
    assert not d.lack_of_fit["detected"]
    summary = d.summary()
    assert f"causes: {', '.join(d.causes)}" in summary
    js = d.to_dict()
    assert js["causes"] == list(d.causes) and js["cause"] == d.causes[0]
    assert {p["cause"] for p in js["parameters"].values()} >= set(effects) - {"friction_level"}
    _assert_misses("+".join(effects), _covers(d, syn, effects))


def test_exponential_speed_law_is_still_speed_dependent(tire):
    syn = synthesize(
        tire, "speed_dependent_friction", {"stribeck_ratio": 0.7, "stribeck_speed": 0.3}, n=300, seed=1206,
        loads=LOADS,
    )  # fmt: skip
    d = diagnose(tire, syn.data, friction=0.3, seed=1206)
    assert d.cause == "speed_dependent_friction", d.summary()
    assert d.parameters["c_v"].value < 0  # friction falls with speed
