"""The candidate models equal the exact integrals with the effect applied directly.

The diagnosis builds pressure-, speed- and direction-dependent friction by linear
superposition of four exact evaluations, the load column by scaling, and the
reversed rolling map by mirroring the map. The synthetic generator applies the
same effects independently (FrictionLaw, scaled maps, mirrored kinematics). On
the same quadrature grid the two must agree to rounding: tolerance 1e-9 of the
channel scale (identities, up to the summation order of ~4600 nodes).
"""

from __future__ import annotations

import numpy as np
import pytest

from fepost.analytic import pressure_function
from fepost.diagnose.causes import CAUSES, Predictor, build_candidates
from fepost.diagnose.simulation import regrid, simulation_from_maps
from fepost.diagnose.synthetic import GEN_NPHI, GEN_NR, rig_programme, synthesize
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.polar import PolarGrid, PolarMap

R = 0.11
TOL = 1e-9


def _map(k_x=0.0, profile="paraboloid"):
    return PolarMap.from_function(pressure_function(profile, R, peak=2.0e5, k_x=k_x), R, PolarGrid.make())


CASES = [
    ("friction_level", {"f": 0.41}, [0.41]),
    ("pressure_dependent_friction", {"c_p": 0.35}, [0.3, 0.35]),
    ("pressure_dependent_friction", {"c_p": -0.4}, [0.3, -0.4]),
    ("speed_dependent_friction", {"c_v": -0.12}, [0.3, -0.12]),
    ("anisotropic_friction", {"alpha": 1.3}, [0.3, 1.3]),
    ("elliptic_patch", {"s": 1.2}, [0.3, 1.2]),
    ("pressure_shift", {"dx": 0.006, "dy": -0.004}, [0.3, 0.006, -0.004]),
    (
        "sensor_offset",
        {"offset_Fx": 50.0, "offset_Fy": -20.0, "offset_Mz": 3.0},
        [0.3, 50.0, -20.0, 3.0],
    ),
]


@pytest.mark.parametrize(("effect", "params", "values"), CASES, ids=[f"{c[0]}{c[2]}" for c in CASES])
@pytest.mark.parametrize("loads", [None, (0.8, 1.0, 1.25)], ids=["one-load", "loads"])
def test_candidate_equals_direct_effect(effect, params, values, loads):
    static, rolling = _map(), _map(k_x=0.15)
    syn = synthesize(static, effect, params, rolling=rolling, n=60, noise=0.0, seed=3, loads=loads)
    sim = simulation_from_maps(static, rolling, friction=0.3, nr=GEN_NR, nphi=GEN_NPHI)
    pred = Predictor(sim, syn.data)
    cand = build_candidates(pred)[effect]
    got = cand.predict(np.array(values)) * pred.scale
    assert set(syn.data.roll.tolist()) == {-1, 0, 1}
    np.testing.assert_allclose(got, syn.clean, rtol=0, atol=TOL * pred.scale.max())


def test_none_is_the_exact_integral_with_nominal_friction():
    static = _map()
    syn = synthesize(static, "none", {}, n=30, noise=0.0, seed=1)
    sim = simulation_from_maps(static, friction=0.3, nr=GEN_NR, nphi=GEN_NPHI)
    pred = Predictor(sim, syn.data)
    got = build_candidates(pred)["none"].predict(np.empty(0)) * pred.scale
    np.testing.assert_allclose(got, syn.clean, rtol=0, atol=TOL * pred.scale.max())
    assert set(build_candidates(pred)) == set(CAUSES)


def test_mirrored_rolling_map_is_the_mirror_image():
    """roll = −1 uses σ(−x, y): Fx and Mz flip with vx and ω_z; Fy keeps its sign."""
    rolling = _map(k_x=0.2)
    quad = PressureQuadrature.from_polar(regrid(rolling, edge_grid(32, 64)))
    mirror = PressureQuadrature.from_polar(regrid(rolling, edge_grid(32, 64), mirror=True))
    kin = rig_programme(R, 50, seed=2)
    a = friction_resultants(mirror, kin.vx, kin.vy, kin.wz, FrictionLaw(0.3))
    b = friction_resultants(quad, -kin.vx, kin.vy, -kin.wz, FrictionLaw(0.3))
    scale = 0.3 * quad.load
    np.testing.assert_allclose(a.Fx, -b.Fx, atol=TOL * scale)
    np.testing.assert_allclose(a.Fy, b.Fy, atol=TOL * scale)
    np.testing.assert_allclose(a.Mz, -b.Mz, atol=TOL * scale * R)


def test_fit_grid_accuracy_against_a_fine_grid():
    """24 x 48 fit grid vs the generator's 48 x 96: under 5e-4 of f·N (and f·N·R) on a tire map.

    The bound is the module's stated accuracy (2e-4 against 128 x 256, measured in
    benchmarks/bench_diagnose.py) with room for the finer reference here; rig noise
    is 1-2 % of range, 30x larger.
    """
    static = _map(profile="tire")
    syn = synthesize(static, "none", {}, n=120, noise=0.0, seed=4)
    pred = Predictor(simulation_from_maps(static, friction=0.3), syn.data)
    got = build_candidates(pred)["none"].predict(np.empty(0))
    err = np.abs(got - syn.clean / pred.scale).max(axis=0)
    assert np.all(err < 5e-4), err


def test_test_matrix_has_the_required_structure():
    kin = rig_programme(0.1, 400, seed=0)
    v = np.hypot(kin.vx, kin.vy)
    u = np.abs(kin.wz) * 0.1
    assert kin.vx.size == 400
    assert np.any((v == 0) & (u > 0)), "pure spin"
    assert np.any((u == 0) & (v > 0)), "pure sliding"
    assert np.any(kin.wz > 0) and np.any(kin.wz < 0), "both spin signs"
    assert np.unique(np.round(np.degrees(np.arctan2(kin.vy, kin.vx)[v > 0]))).size >= 8, "directions"
    both = (u > 0) & (v > 0)
    ratios = np.round(v[both] / u[both], 6)
    speeds_at_half = np.unique(np.round(u[both][ratios == 0.5], 6))
    assert speeds_at_half.size >= 3, "several absolute speeds at one ratio"


def test_synthesize_rejects_unknown_effects_and_parameters():
    from fepost.errors import ArgumentError

    with pytest.raises(ArgumentError, match="effect must be one of"):
        synthesize(_map(), "wet_road", {})
    with pytest.raises(ArgumentError, match=r"unknown parameter\(s\) \['beta'\]"):
        synthesize(_map(), "anisotropic_friction", {"beta": 2.0})
    with pytest.raises(ArgumentError, match=r"needs parameter\(s\) \['s'\]"):
        synthesize(_map(), "elliptic_patch", {})


PAIRS = [
    (
        ("pressure_dependent_friction", "speed_dependent_friction"),
        {"c_p": 0.3, "c_v": -0.1},
        [0.3, 0.3, -0.1],
    ),
    (("pressure_dependent_friction", "anisotropic_friction"), {"c_p": -0.3, "alpha": 1.2}, [0.3, -0.3, 1.2]),
    (("anisotropic_friction", "speed_dependent_friction"), {"alpha": 0.85, "c_v": 0.08}, [0.3, 0.85, 0.08]),
    (
        ("elliptic_patch", "pressure_shift"),
        {"s": 1.15, "dx": 0.004, "dy": -0.003},
        [0.3, 1.15, 0.004, -0.003],
    ),
    (
        ("pressure_shift", "anisotropic_friction"),
        {"dx": -0.005, "dy": 0.002, "alpha": 1.1},
        [0.3, -0.005, 0.002, 1.1],
    ),
    (("elliptic_patch", "pressure_dependent_friction"), {"s": 0.9, "c_p": 0.25}, [0.3, 0.9, 0.25]),
    (
        ("friction_level", "sensor_offset"),
        {"f": 0.27, "offset_Fx": 30.0, "offset_Fy": -10.0, "offset_Mz": 2.0},
        [0.27, 30.0, -10.0, 2.0],
    ),
]


@pytest.mark.parametrize(("effects", "params", "values"), PAIRS, ids=["+".join(p[0]) for p in PAIRS])
def test_joint_model_equals_both_effects_applied_directly(effects, params, values):
    """Two causes at once: the joint model's cross terms (bilinear in c_p, c_v; affine in α;
    stretch then shift) equal the generator's exact integrals with both effects."""
    from fepost.diagnose.causes import joint_candidate

    static, rolling = _map(), _map(k_x=0.15)
    syn = synthesize(
        static, effects, params, rolling=rolling, n=60, noise=0.0, seed=5, loads=(0.8, 1.0, 1.25)
    )
    sim = simulation_from_maps(static, rolling, friction=0.3, nr=GEN_NR, nphi=GEN_NPHI)
    pred = Predictor(sim, syn.data)
    exts = tuple(e for e in effects if e != "friction_level")
    cand = joint_candidate(pred, exts)
    got = cand.predict(np.array(values)) * pred.scale
    np.testing.assert_allclose(got, syn.clean, rtol=0, atol=TOL * pred.scale.max())
    if cand.expand is not None:  # the local model is exact at its expansion point
        local = cand.expand(np.array(values))
        np.testing.assert_allclose(
            local.predict(np.array(values)) * pred.scale, got, rtol=0, atol=1e-12 * got.max()
        )


def test_joint_models_nest_their_parts():
    from fepost.diagnose.causes import joint_candidate

    static = _map()
    syn = synthesize(static, "none", {}, n=40, noise=0.0, seed=2)
    pred = Predictor(simulation_from_maps(static, friction=0.3), syn.data)
    singles = build_candidates(pred)
    joint = joint_candidate(pred, ("anisotropic_friction", "pressure_dependent_friction"))
    assert joint.names == ("f", "alpha", "c_p")
    assert joint.nested == ("none", "friction_level", "anisotropic_friction", "pressure_dependent_friction")
    np.testing.assert_allclose(
        joint.predict(np.array([0.31, 1.2, 0.0])),
        singles["anisotropic_friction"].predict(np.array([0.31, 1.2])),
    )
    np.testing.assert_allclose(
        joint.predict(np.array([0.31, 1.0, 0.2])),
        singles["pressure_dependent_friction"].predict(np.array([0.31, 0.2])),
    )
