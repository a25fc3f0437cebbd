"""sensor_crosstalk and load_transfer: exact models, named when hidden, intervals covering the truth."""

from __future__ import annotations

import numpy as np
import pytest

from fepost.diagnose import diagnose
from fepost.diagnose.causes import Predictor, build_candidates, combinable, joint_candidate
from fepost.diagnose.models import CROSSTALK, apply_sensor
from fepost.diagnose.simulation import load_simulation
from fepost.diagnose.synthetic import CROSSTALK_TERMS, analytic_map, synthesize
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw

CROSSTALK_TRUTH = {"c_xy": 0.0, "c_xz": 0.0, "c_yx": 0.06, "c_yz": 0.0, "c_zx": 0.002, "c_zy": -0.0015}
TRANSFER_TRUTH = {"h_x": 0.03, "h_y": 0.02}


@pytest.fixture(scope="module")
def pmap():
    return analytic_map("hertz", 0.1, 3.0e5)


@pytest.fixture(scope="module")
def sim(pmap):
    return load_simulation(pmap, None, friction=0.3)


def test_moving_the_kinematics_equals_moving_the_map(pmap, sim):
    """A map moved by d_i per row = the unmoved map at v + ω×d_i, torque + d×F (to rounding)."""
    syn = synthesize(pmap, "none", {}, n=40, seed=1)
    pred = Predictor(sim, syn.data)
    rng = np.random.default_rng(0)
    dx, dy = rng.uniform(-0.01, 0.01, 40), rng.uniform(-0.01, 0.01, 40)
    got = pred.coulomb_moved(dx, dy)
    law = FrictionLaw(f=1.0, pressure_ref=sim.pressure_ref)
    q = sim.quads[0]
    want = np.array([
        [getattr(friction_resultants(q.shifted(dx[i], dy[i]), syn.data.vx[i], syn.data.vy[i], syn.data.wz[i],
                                     law), c) for c in ("Fx", "Fy", "Mz")]
        for i in range(40)
    ]) / sim.scales()  # fmt: skip
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_crosstalk_model_matches_the_generator_matrix(sim):
    """The model's C (scaled channels) applied to true forces = the generator's C in SI."""
    rng = np.random.default_rng(2)
    true = rng.normal(size=(10, 3)) * sim.scales()
    C = np.eye(3)
    for name, (a, b) in CROSSTALK_TERMS.items():
        C[a, b] = CROSSTALK_TRUTH[name]
    index = {name: j for j, name in enumerate(CROSSTALK)}
    p = np.array([CROSSTALK_TRUTH[n] for n in CROSSTALK])
    got = apply_sensor(index, p, true / sim.scales(), sim.scales()) * sim.scales()
    np.testing.assert_allclose(got, true @ C.T, rtol=1e-12)


def test_load_transfer_combines_only_with_sensor_causes(pmap, sim):
    syn = synthesize(pmap, "none", {}, n=30, seed=1)
    pred = Predictor(sim, syn.data)
    assert combinable(("load_transfer", "sensor_offset")) and not combinable(
        ("load_transfer", "pressure_shift")
    )
    with pytest.raises(ValueError, match="load_transfer combines only with"):
        joint_candidate(pred, ("pressure_shift", "load_transfer"))
    joint = joint_candidate(pred, ("load_transfer", "sensor_crosstalk"))
    assert joint.names == ("f", "h_x", "h_y", *CROSSTALK)
    cands = build_candidates(pred)
    assert {"sensor_crosstalk", "load_transfer"} <= set(cands)
    # at no effect both reduce to friction_level
    f0 = [0.3]
    for name, extra in (("sensor_crosstalk", 6), ("load_transfer", 2)):
        np.testing.assert_allclose(
            cands[name].predict(np.array(f0 + [0.0] * extra)), cands["friction_level"].predict(np.array(f0)),
            atol=1e-12,
        )  # fmt: skip


def _covered(d, truth):
    return {
        k: (d.parameters[k].ci95, v)
        for k, v in truth.items()
        if not d.parameters[k].ci95[0] <= v <= d.parameters[k].ci95[1]
    }


def test_crosstalk_is_named_with_intervals_covering_the_truth(pmap):
    syn = synthesize(pmap, "sensor_crosstalk", CROSSTALK_TRUTH, n=300, seed=2)
    d = diagnose(pmap, syn.data, friction=0.3)
    assert d.cause == "sensor_crosstalk", [s.name for s in d.candidates[:3]]
    assert not _covered(d, CROSSTALK_TRUTH)
    assert not d.lack_of_fit["detected"]


def test_load_transfer_is_named_with_intervals_covering_the_truth(pmap):
    syn = synthesize(pmap, "load_transfer", TRANSFER_TRUTH, n=150, seed=2)
    d = diagnose(pmap, syn.data, friction=0.3)
    assert d.cause == "load_transfer", [s.name for s in d.candidates[:3]]
    assert not _covered(d, TRANSFER_TRUTH)
    assert d.parameters["h_x"].unit == "m"
    assert not d.lack_of_fit["detected"]


def test_moved_resultants_are_kept_per_shift(pmap, sim, monkeypatch):
    """A shift asked for again (the load-transfer fit's derivatives) is not integrated again;
    the answer is the same numbers, in an array of its own."""
    from fepost.diagnose import models

    syn = synthesize(pmap, "none", {}, n=30, seed=4)
    pred = Predictor(sim, syn.data)
    rng = np.random.default_rng(1)
    dx, dy = rng.uniform(-0.005, 0.005, 30), rng.uniform(-0.005, 0.005, 30)
    first = pred.coulomb_moved(dx, dy)
    calls = []
    real = models.friction_resultants
    monkeypatch.setattr(models, "friction_resultants", lambda *a, **k: calls.append(1) or real(*a, **k))
    again = pred.coulomb_moved(dx.copy(), dy.copy())
    assert calls == [] and again is not first
    np.testing.assert_array_equal(again, first)
    again[:] = 0.0  # the caller's array: the kept one is untouched
    np.testing.assert_array_equal(pred.coulomb_moved(dx, dy), first)
    other = pred.coulomb_moved(dx, dy + 1e-4)  # another shift is integrated
    assert len(calls) == len(pred.groups) and not np.array_equal(other, first)
