"""The generalised friction model (fepost.friction.model/.build/.tensors).

Tolerance tiers:
- IDENTITY (1e-12): algebraic identities of the model (Euler, symmetry, JSON
  round trip, a re-implementation from the export).
- INTEGRAL (1e-6): pressure integrals against scipy quad of their closed radial
  parts (model_maps.py); the 64x128 sine grid is spectrally accurate on these maps.
- LIMIT: exact limits. The model's own limits are identities of its formulas
  (checked with a step h = 1e-7 in ε or 1/ε: the next order leaves O(h) ~ 1e-6);
  the exact integrals' limits are checked at h = 1e-3 (next order O(h), plus
  the quadrature's ~1e-7).
- GOAL (0.03): the issue's accuracy goal, max over the sphere, of F0 and M0.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from fepost.errors import ArgumentError, DataError
from fepost.friction.build import AUTO_TARGET, DEFAULT_ORDER, build_model
from fepost.friction.closed_form import paper_coefficients, paper_model
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.model import GeneralisedModel
from fepost.friction.reference_maps import RADIUS, asymmetric, ellipse_quad, reference_tensors, tire_like
from fepost.friction.sphere import error_map
from fepost.friction.tensors import effective_quadrature, map_tensors

IDENTITY = 1e-12
INTEGRAL = 1e-6
GOAL = 0.03
F = 0.3
LAW = FrictionLaw(f=F)

MAPS = [("uniform", 1.0), ("hertz", 1.0), ("uniform", 2.0), ("hertz", 1.5), ("hertz", 3.0)]


@pytest.fixture(scope="module")
def models():
    """Built once: (quad, model) per (profile, aspect)."""
    out = {}
    for profile, aspect in MAPS:
        quad = ellipse_quad(profile, aspect)
        out[profile, aspect] = (quad, build_model(quad, LAW, order=DEFAULT_ORDER, check=False))
    return out


# -- pressure integrals ---------------------------------------------------------------
@pytest.mark.parametrize(
    "profile,aspect", [("uniform", 1.0), ("hertz", 1.0), ("uniform", 2.0), ("hertz", 3.0)]
)
def test_tensors_against_scipy_quad(profile, aspect):
    t = map_tensors(ellipse_quad(profile, aspect))
    ref = reference_tensors(profile, aspect)
    assert t.N == pytest.approx(ref["N"], rel=INTEGRAL)
    assert t.polar == pytest.approx(ref["polar"], rel=INTEGRAL)
    np.testing.assert_allclose(t.second, ref["Q"], rtol=INTEGRAL, atol=INTEGRAL * ref["Q"].max())
    np.testing.assert_allclose(t.inverse, ref["S"], rtol=INTEGRAL, atol=INTEGRAL * ref["S"].max())
    np.testing.assert_allclose(t.radial, 0.0, atol=INTEGRAL * t.N)
    np.testing.assert_allclose(t.cross, 0.0, atol=INTEGRAL * t.N)
    np.testing.assert_allclose(t.first, 0.0, atol=INTEGRAL * t.N * RADIUS)


def test_tensors_of_a_moved_map_use_the_subtraction():
    """Off-centre: 1/r and ê_r integrands are singular/discontinuous inside the patch."""
    quad = ellipse_quad("hertz", 1.0).shifted(0.02, -0.01)
    got = map_tensors(quad)
    # Independent: the same map on a polar grid centred on the new origin.
    from fepost.analytic import pressure_function
    from fepost.friction.quadrature import PressureQuadrature, edge_grid
    from fepost.polar import PolarMap

    fn = pressure_function("hertz", RADIUS, peak=quad.sigma.max())
    centred = PressureQuadrature.from_polar(
        PolarMap.from_function(lambda x, y: fn(x - 0.02, y + 0.01), 0.13, edge_grid(256, 512))
    )
    ref = map_tensors(centred)
    for name in ("inverse", "radial"):
        np.testing.assert_allclose(
            getattr(got, name), getattr(ref, name), rtol=2e-4, atol=2e-4 * abs(getattr(ref, name)).max()
        )


def test_pressure_dependent_law_is_folded_into_the_pressure():
    quad = ellipse_quad("hertz", 1.5)
    law = FrictionLaw(f=F, pressure_coef=-0.4)
    eq = effective_quadrature(quad, law)
    ref = law.reference_pressure(quad.mean_pressure)
    np.testing.assert_allclose(eq.sigma, law.pressure_factor(quad.sigma, ref) * quad.sigma, rtol=IDENTITY)
    a = friction_resultants(quad, 0.3, 0.1, 2.0, law)
    b = friction_resultants(eq, 0.3, 0.1, 2.0, FrictionLaw(f=F))
    for p, q in ((a.Fx, b.Fx), (a.Fy, b.Fy), (a.Mz, b.Mz)):
        assert float(p) == pytest.approx(float(q), rel=1e-9)


def test_speed_dependent_law_is_refused():
    with pytest.raises(ArgumentError, match="speed_coef"):
        build_model(ellipse_quad(), FrictionLaw(f=F, speed_coef=0.1))
    with pytest.raises(ArgumentError, match="order must be"):
        build_model(ellipse_quad(), LAW, order="best")
    with pytest.raises(ArgumentError, match="too coarse"):
        build_model(ellipse_quad(), LAW, order=(4, 8), grid=(8, 8))


# -- exact limits -----------------------------------------------------------------------
def _spin_and_slide(model, R, beta, h):
    """Resultants at pure spin, ε = h, pure sliding and 1/ε = h along β, ω_z = ±1/R."""
    c, s = np.cos(beta), np.sin(beta)
    out = {}
    for sgn in (1.0, -1.0):
        out["spin", sgn] = model(0.0, 0.0, sgn / R)
        out["near_spin", sgn] = model(h * c, h * s, sgn / R)
        out["slide", sgn] = model(c, s, 0.0)
        out["near_slide", sgn] = model(c, s, sgn * h / R)
    return out


@pytest.mark.parametrize("profile,aspect", MAPS)
@pytest.mark.parametrize("beta", [0.0, 0.6, np.pi / 2, 2.2])
def test_model_limits_equal_the_analytic_ones(models, profile, aspect, beta):
    quad, model = models[profile, aspect]
    ref = reference_tensors(profile, aspect)
    R, h = model.R, 1e-7
    N, M0 = ref["N"], F * ref["polar"]
    vh = np.array([np.cos(beta), np.sin(beta)])
    r = _spin_and_slide(model, R, beta, h)
    for sgn in (1.0, -1.0):
        fx, fy, mz = (float(v) for v in r["spin", sgn])
        assert abs(fx) + abs(fy) < 1e-9 * F * N
        assert mz == pytest.approx(-sgn * M0, rel=INTEGRAL)
        # slope at pure spin: F = −(f/|ω|) S v, torque flat
        fx, fy, mz = (float(v) for v in r["near_spin", sgn])
        slope = -F * R * (ref["S"] @ vh)  # |ω| = 1/R, v = h v̂
        np.testing.assert_allclose([fx / h, fy / h], slope, rtol=1e-5, atol=1e-5 * F * N)
        assert (mz + sgn * M0) / h == pytest.approx(0.0, abs=1e-4 * M0)
        # pure sliding: F = −fN v̂, M = 0; slope: M = −(f ω/|v|) v̂ᵀQv̂
        fx, fy, mz = (float(v) for v in r["slide", sgn])
        np.testing.assert_allclose([fx, fy], -F * N * vh, rtol=IDENTITY, atol=INTEGRAL * F * N)
        assert abs(mz) < IDENTITY * M0
        fx, fy, mz = (float(v) for v in r["near_slide", sgn])
        torque_slope = -sgn * F / R * (vh @ ref["Q"] @ vh)
        assert mz / h == pytest.approx(torque_slope, rel=1e-5)
        np.testing.assert_allclose(
            [(fx + F * N * vh[0]) / h, (fy + F * N * vh[1]) / h], 0.0, atol=1e-5 * F * N
        )


def test_exact_integrals_have_the_same_limits():
    """The limits the model is built to hold, seen in the exact integrals (h = 1e-3)."""
    profile, aspect = "uniform", 2.0
    quad = ellipse_quad(profile, aspect)
    ref = reference_tensors(profile, aspect)
    R, h = quad.radius, 1e-3
    for beta in (0.0, 0.6, np.pi / 2):
        vh = np.array([np.cos(beta), np.sin(beta)])
        e = friction_resultants(quad, h * vh[0], h * vh[1], 1.0 / R, LAW)
        slope = -F * R * (ref["S"] @ vh)
        np.testing.assert_allclose(
            [float(e.Fx) / h, float(e.Fy) / h], slope, rtol=5e-3, atol=5e-3 * abs(slope).max()
        )
        e = friction_resultants(quad, vh[0], vh[1], h / R, LAW)
        assert float(e.Mz) / h == pytest.approx(-F / R * (vh @ ref["Q"] @ vh), rel=5e-3)


def test_asymmetric_limits_rolling_shift():
    """σ0(1 + k x/R) Hertz disc: pure spin F_y = −sgn(ω) k M0/(2R); pure sliding
    M_z = −f N x_c × v̂ with x_c = k ⟨x²⟩/R."""
    k = 0.13
    quad = ellipse_quad("hertz", 1.0, k_x=k)
    model = build_model(quad, LAW, order=DEFAULT_ORDER, check=False)
    ref = reference_tensors("hertz", 1.0)
    R, N, M0 = RADIUS, ref["N"], F * ref["polar"]
    for sgn in (1.0, -1.0):
        fx, fy, mz = (float(v) for v in model(0.0, 0.0, sgn * 2.0))
        assert fy == pytest.approx(-sgn * k * M0 / (2 * R), rel=1e-6)
        assert abs(fx) < 1e-9 * F * N
    xc = k * ref["Q"][0, 0] / N / R
    for beta in (0.3, 1.2, 2.5):
        vh = np.array([np.cos(beta), np.sin(beta)])
        mz = float(model(vh[0], vh[1], 0.0)[2])
        assert mz == pytest.approx(-F * N * xc * vh[1], rel=1e-6)


def test_anisotropic_limits():
    alpha = 0.6
    quad = ellipse_quad("hertz", 1.5)
    law = FrictionLaw(f=F, anisotropy=alpha)
    model = build_model(quad, law, check=False)
    N = quad.load
    for beta in (0.0, 0.7, 2.0):
        vh = np.array([np.cos(beta), np.sin(beta)])
        fx, fy, mz = (float(v) for v in model(vh[0], vh[1], 0.0))
        np.testing.assert_allclose([fx, fy], -F * N * vh * [1.0, alpha], rtol=1e-9, atol=1e-9 * F * N)
    ex = friction_resultants(quad, 0.0, 0.0, [3.0, -3.0], law)
    got = model(0.0, 0.0, np.array([3.0, -3.0]))[2]
    np.testing.assert_allclose(got, ex.Mz, rtol=1e-6)
    # slope at pure spin and at pure sliding, against the exact integrals (h = 1e-3)
    h, R = 1e-3, model.R
    for beta in (0.4, 1.9):
        vh = np.array([np.cos(beta), np.sin(beta)])
        ex = friction_resultants(quad, h * vh[0], h * vh[1], 1.0 / R, law)
        mz0 = float(friction_resultants(quad, 0.0, 0.0, 1.0 / R, law).Mz)
        got = model(h * vh[0], h * vh[1], 1.0 / R)[2]
        assert (float(got) - mz0) / h == pytest.approx((float(ex.Mz) - mz0) / h, abs=5e-3 * model.M0)


# -- the circular reduction ------------------------------------------------------------------
def test_reduction_on_a_circular_map(models):
    """Axisymmetric map: Q̂ = Ŝ... isotropic, and the base is the documented sextic form in
    the paper's F0, M0, a, m: D⁶ = (F0 v)⁶ + 3κ1 (F0 v)⁴ (M0 ω)² + 3κ2 (F0 v)² (M0 ω)⁴ + (M0 ω)⁶,
    κ1 = F0 R/(√m M0), κ2 = M0/(√a F0 R)."""
    quad, model = models["hertz", 1.0]
    paper = paper_coefficients(map_tensors(quad), F)
    F0, M0, a, m, R = paper["F0"], paper["M0"], paper["a"], paper["m"], paper["radius"]
    assert a == pytest.approx((8 / (3 * np.pi)) ** 2, rel=INTEGRAL)  # the reference values of docs/theory.md
    assert m == pytest.approx((15 * np.pi / 16) ** 2, rel=INTEGRAL)
    d = model.direction_coefficients(np.linspace(0, np.pi, 7))
    np.testing.assert_allclose(d["a"], a, rtol=INTEGRAL)
    np.testing.assert_allclose(d["m"], m, rtol=INTEGRAL)
    k1, k2 = F0 * R / (np.sqrt(m) * M0), M0 / (np.sqrt(a) * F0 * R)
    np.testing.assert_allclose(d["kappa1"], k1, rtol=INTEGRAL)
    np.testing.assert_allclose(d["kappa2"], k2, rtol=INTEGRAL)
    np.testing.assert_allclose(model.g, 0.0, atol=1e-9)
    np.testing.assert_allclose(model.xc, 0.0, atol=1e-9)

    def D(v, w):
        x, y = F0 * v, M0 * np.abs(w)
        return (x**6 + 3 * k1 * x**4 * y**2 + 3 * k2 * x**2 * y**4 + y**6) ** (1 / 6)

    v = np.array([0.05, 0.3, 1.0, 2.0])
    w = np.array([3.0, -2.0, 0.7, 0.1])
    hv, hw = 1e-6, 1e-6
    fpar = -(D(v + hv, w) - D(v - hv, w)) / (2 * hv)
    mz = -(D(v, w + hw) - D(v, w - hw)) / (2 * hw)
    fx, fy, got_m = model.without_correction()(v, 0.0 * v, w)
    np.testing.assert_allclose(fx, fpar, rtol=1e-6)
    np.testing.assert_allclose(got_m, mz, rtol=1e-6)
    np.testing.assert_allclose(fy, 0.0, atol=1e-9 * F0)


@pytest.mark.parametrize("profile", ["uniform", "hertz"])
def test_circular_model_beats_the_paper(models, profile):
    quad, model = models[profile, 1.0]
    p = paper_coefficients(map_tensors(quad), F)
    em = error_map(
        quad,
        {"paper": paper_model(**p), "base": model.without_correction(), "model": model},
        law=LAW,
        F0=model.F0,
        M0=model.M0,
        R=model.R,
        n_beta=3,
        n_t=81,
    )
    paper, base, full = em.worst("paper"), em.worst("base"), em.worst("model")
    assert paper["force"] > 0.10 and paper["torque"] > 0.20  # the theory note quotes 0.12 / 0.21
    assert base["force"] < 0.035 and base["torque"] < 0.045
    assert full["force"] < 0.01 and full["torque"] < 0.01


# -- accuracy goal ---------------------------------------------------------------------------
GOAL_MAPS = {
    "uniform a1.5": lambda: ellipse_quad("uniform", 1.5),
    "uniform a2": lambda: ellipse_quad("uniform", 2.0),
    "hertz a2": lambda: ellipse_quad("hertz", 2.0),
    "tire-like a1.6": lambda: tire_like(1.6),
    "tire-like a2": lambda: tire_like(2.0),
    "asymmetric a1.5": lambda: asymmetric(1.5),
    "asymmetric a2": lambda: asymmetric(2.0, k=0.2, shift=(-0.008, 0.005)),
}


@pytest.mark.parametrize("name", list(GOAL_MAPS))
def test_accuracy_goal_over_the_sphere(name):
    quad = GOAL_MAPS[name]()
    model = build_model(quad, LAW, order=DEFAULT_ORDER, check=False)
    em = error_map(quad, {"model": model}, law=LAW, F0=model.F0, M0=model.M0, R=model.R, n_beta=13, n_t=41)
    worst = em.worst("model")
    assert worst["force"] <= GOAL, worst
    assert worst["torque"] <= GOAL, worst


def test_auto_order_climbs_where_the_patch_is_long():
    short = build_model(ellipse_quad("hertz", 1.5), LAW)
    assert short.order == DEFAULT_ORDER
    long = build_model(ellipse_quad("uniform", 3.0), LAW)
    assert long.order > DEFAULT_ORDER
    assert max(long.accuracy["model_force"], long.accuracy["model_torque"]) <= AUTO_TARGET
    quad = ellipse_quad("uniform", 3.0)
    em = error_map(quad, {"m": long}, law=LAW, F0=long.F0, M0=long.M0, R=long.R, n_beta=7, n_t=41)
    assert em.worst("m")["torque"] <= GOAL


def test_build_measures_its_own_accuracy():
    quad = tire_like(2.0)
    model = build_model(quad, LAW, order=DEFAULT_ORDER)
    acc = model.accuracy
    assert acc["model_force"] <= GOAL and acc["model_torque"] <= GOAL
    assert acc["base_force"] > acc["model_force"] and acc["base_torque"] > acc["model_torque"]
    em = error_map(quad, {"model": model}, law=LAW, F0=model.F0, M0=model.M0, R=model.R, n_beta=7, n_t=33)
    # a different grid, the same size of error (the check grid is not cherry-picked)
    assert em.worst("model")["torque"] == pytest.approx(acc["model_torque"], rel=0.5)


# -- structure: power, reciprocity, symmetry, export ---------------------------------------
def test_dissipation_power_identity_and_reciprocity(models):
    _, model = models["hertz", 1.5]
    rng = np.random.default_rng(3)
    vx, vy, wz = rng.normal(size=(3, 50)) * [[1.0], [1.0], [10.0]]
    fx, fy, mz = model(vx, vy, wz)
    D = model.dissipation(vx, vy, wz)
    np.testing.assert_allclose(fx * vx + fy * vy + mz * wz, -D, rtol=1e-10, atol=1e-12 * model.F0)
    assert np.all(D > 0)
    h = 1e-6
    dFx_dw = (model(vx, vy, wz + h)[0] - model(vx, vy, wz - h)[0]) / (2 * h)
    dM_dvx = (model(vx + h, vy, wz)[2] - model(vx - h, vy, wz)[2]) / (2 * h)
    np.testing.assert_allclose(dFx_dw, dM_dvx, rtol=1e-5, atol=1e-7 * model.F0)


def test_reversing_the_kinematics_flips_every_resultant(models):
    _, model = models["uniform", 2.0]
    rng = np.random.default_rng(5)
    vx, vy, wz = rng.normal(size=(3, 40))
    a, b = model(vx, vy, wz), model(-vx, -vy, -wz)
    for p, q in zip(a, b, strict=True):
        np.testing.assert_allclose(q, -p, rtol=IDENTITY, atol=IDENTITY * model.F0)


def test_zero_kinematics_and_shapes(models):
    _, model = models["uniform", 1.0]
    fx, fy, mz = model(np.zeros((2, 3)), 0.0, 0.0)
    assert fx.shape == (2, 3) and not np.any(fx) and not np.any(fy) and not np.any(mz)
    res = model.resultants([0.1, 0.2], 0.0, 1.0)
    assert res.Fx.shape == (2,) and not res.Fx.flags.writeable
    with pytest.raises(ArgumentError, match="wz must be finite"):
        model.resultants(0.1, 0.0, np.nan)


@pytest.mark.parametrize(
    "change,message",
    [
        ({"R": "0.1"}, "R must be a real number, got '0.1'"),
        ({"F0": True}, "F0 must be a real number, got True"),
        ({"g0": float("inf")}, "g0 must be finite, got inf"),
        ({"M0": -1.0}, "M0 must be positive, got -1.0"),
    ],
)
def test_scalar_fields_are_checked_and_stored_as_floats(models, change, message):
    from dataclasses import replace

    _, model = models["uniform", 1.0]
    with pytest.raises(ArgumentError, match=f"^{re.escape(message)}$"):
        replace(model, **change)
    again = replace(model, R=np.float32(model.R), f=1)
    assert type(again.R) is float and type(again.f) is float and again.f == 1.0


def test_json_round_trip(models):
    _, model = models["hertz", 1.5]
    again = GeneralisedModel.from_json(model.to_json())
    v = np.linspace(-1, 1, 7)
    for p, q in zip(model(v, 0.3 * v, 2.0 - v), again(v, 0.3 * v, 2.0 - v), strict=True):
        np.testing.assert_array_equal(p, q)
    with pytest.raises(DataError, match="format"):
        GeneralisedModel.from_dict({"format": "other"})
    with pytest.raises(DataError, match="missing key"):
        GeneralisedModel.from_dict({"format": "fepost-friction-model/1"})
    with pytest.raises(DataError, match="not valid JSON"):
        GeneralisedModel.from_json("{")
    bad = model.to_dict() | {"Q": [[1.0, 0.0]]}
    with pytest.raises(DataError, match="Q must have shape"):
        GeneralisedModel.from_dict(bad)


def reimplementation(d: dict, vx, vy, wz):
    """The model from its JSON export alone, written from docs/model.md with plain numpy
    (autodiff-free: the potential's gradient by hand, Chebyshev by numpy.polynomial)."""
    R, F0, U0 = d["R"], d["F0"], d["U0"]
    Q, S, g, xc = (np.array(d[k]) for k in ("Q", "S", "g", "xc"))
    C = np.array(d["correction"])
    K = (C.shape[0] - 1) // 2
    u = wz * R
    v = np.stack([vx, vy], -1)
    v2 = vx**2 + vy**2

    def D(v, u):
        v2 = np.sum(v * v, -1)
        qv = np.einsum("...i,ij,...j", v, Q, v)
        sv = np.einsum("...i,ij,...j", v, S, v)
        P = v2**3 + 3 * u**2 * v2 * qv + 3 * U0**5 * u**4 * sv + U0**6 * u**6
        Jv = np.stack([-v[..., 1], v[..., 0]], -1)
        a = u**2 + v2
        t1 = (Jv @ g) * u * np.abs(u) ** 3 / a**2
        t2 = -(Jv @ xc) * u * v2 / a**1.5
        # correction: F0 |u| w(t) Σ C B_k(θ) T_l(2t − 1)
        t = 2 / np.pi * np.arctan2(np.sqrt(v2), np.abs(u))
        theta = np.arctan2(np.sign(u) * v[..., 0], -np.sign(u) * v[..., 1])
        B = [np.ones_like(theta)] + [f(k * theta) for k in range(1, K + 1) for f in (np.cos, np.sin)]
        corr = sum(Bk * np.polynomial.chebyshev.chebval(2 * t - 1, C[i]) for i, Bk in enumerate(B))
        corr = np.abs(u) * t**3 * (1 - t) ** 2 * corr
        return F0 * (P ** (1 / 6) + t1 + t2 + corr)

    h = 1e-6
    ex, ey = np.array([h, 0.0]), np.array([0.0, h])
    fx = -(D(v + ex, u) - D(v - ex, u)) / (2 * h)
    fy = -(D(v + ey, u) - D(v - ey, u)) / (2 * h)
    mz = -R * (D(v, u + h * R / R) - D(v, u - h * R / R)) / (2 * h)
    del v2
    return fx, fy, mz


def test_reimplementation_from_the_json_alone(models):
    import json

    quad, model = models["hertz", 1.5]
    d = json.loads(model.to_json())
    rng = np.random.default_rng(11)
    vx, vy = rng.normal(size=(2, 200))
    wz = rng.normal(size=200) * 20.0
    got = model(vx, vy, wz)
    ref = reimplementation(d, vx, vy, wz)
    for p, q in zip(got, ref, strict=True):
        np.testing.assert_allclose(p, q, rtol=1e-6, atol=1e-7 * model.F0)
