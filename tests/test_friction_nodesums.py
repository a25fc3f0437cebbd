"""The compiled node sums of the exact friction integrals (fepost.friction.nodesums)
against the numpy path, on many kinematic points including the singular ones.

Tolerance: SAME (1e-12 of fN for forces, of M0 for the torque): the two paths sum
the same 8192 node terms in another order (the compiled loop in vector partial
sums), which moves the result by ~1e-16·√nodes of the sum of |terms| ≤ fN;
measured ≤ 3e-14.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from fepost.analytic import pressure_function
from fepost.errors import ArgumentError
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.polar import PolarMap

pytest.importorskip("numba", reason="numba (the optional 'fast' extra) is not installed")

SAME = 1e-12
RADIUS = 0.1

LAWS = {
    "coulomb": FrictionLaw(f=0.8),
    "pressure": FrictionLaw(f=0.5, pressure_coef=0.3),
    "speed": FrictionLaw(f=0.5, speed_coef=-0.2),
    "anisotropic": FrictionLaw(f=0.4, anisotropy=0.6),
}


def quadrature(profile: str, k_x: float = 0.0) -> PressureQuadrature:
    fn = pressure_function(profile, RADIUS, peak=2e5, k_x=k_x)
    return PressureQuadrature.from_polar(PolarMap.from_function(fn, RADIUS, edge_grid()))


def kinematics(quad: PressureQuadrature) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ICR inside and outside the patch, on the boundary and exactly on nodes; pure
    spin, pure sliding, zero velocity; extreme magnitudes."""
    rng = np.random.default_rng(11)
    n = 400
    wz = rng.choice([-1.0, 1.0], n) * np.exp(rng.uniform(-3, 4, n))
    dist = RADIUS * rng.uniform(0.0, 3.0, n)
    ang = rng.uniform(0.0, 2.0 * np.pi, n)
    p0x, p0y = dist * np.cos(ang), dist * np.sin(ang)
    p0x[:5], p0y[:5] = quad.x[:5], quad.y[:5]  # ICR on a node
    p0x[5:9], p0y[5:9] = RADIUS * np.array([1.0, -1.0, 0.0, 0.0]), RADIUS * np.array([0.0, 0.0, 1.0, -1.0])
    vx, vy = wz * p0y, -wz * p0x  # p0 = (−vy/ω, vx/ω)
    extra = [(0.0, 0.0, 0.0), (0.0, 0.0, 5.0), (0.0, 0.0, -5.0), (1.0, 0.0, 0.0), (-0.3, 0.7, 0.0)]
    extra += [(1e-100, 0.0, 3e-99), (1e100, -1e100, 1e100), (3e-9, 0.0, 1e-7), (2.0, 1.0, 1e-13)]
    ex = np.array(extra).T
    return np.concatenate([vx, ex[0]]), np.concatenate([vy, ex[1]]), np.concatenate([wz, ex[2]])


def assert_same(got, ref, law, quad):
    fn = law.f * quad.load
    m0 = law.f * float(quad.sigma @ (np.hypot(quad.x, quad.y) * quad.dA))
    for name, scale in (("Fx", fn), ("Fy", fn), ("Mz", m0)):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.all(np.isfinite(a)), name
        err = float(np.max(np.abs(a - b))) / scale
        assert err <= SAME, f"{name}: {err:.3g}"


@pytest.mark.parametrize("law_name", list(LAWS))
@pytest.mark.parametrize("profile,k_x", [("hertz", 0.0), ("tire", 0.13), ("uniform", 0.0)])
def test_compiled_sums_equal_numpy(law_name, profile, k_x):
    law = LAWS[law_name]
    quad = quadrature(profile, k_x)
    vx, vy, wz = kinematics(quad)
    ref = friction_resultants(quad, vx, vy, wz, law, backend="numpy")
    got = friction_resultants(quad, vx, vy, wz, law, backend="numba")
    assert_same(got, ref, law, quad)


@pytest.mark.parametrize("subtract", [0, 1, 2])
def test_every_subtraction_order(subtract):
    """Without subtraction (0) the field ŵ is undefined at the ICR: an ICR exactly on a
    node gets an arbitrary direction there (the two paths' round-off picks different
    ones), so those points are left out of that case only."""
    law = LAWS["pressure"]
    quad = quadrature("tire", 0.13)
    vx, vy, wz = kinematics(quad)
    if subtract == 0:
        vx, vy, wz = vx[5:], vy[5:], wz[5:]
    ref = friction_resultants(quad, vx, vy, wz, law, subtract=subtract, backend="numpy")
    got = friction_resultants(quad, vx, vy, wz, law, subtract=subtract, backend="numba", threads=1)
    assert_same(got, ref, law, quad)


@pytest.mark.parametrize("scale", [1e-150, 1e150, 1e250])
def test_coulomb_resultants_do_not_depend_on_the_speed_scale(scale):
    """Without speed dependence the resultants are of degree 0 in (v, ω_z): the
    compiled sums at extreme magnitudes (where the numpy path's squares would
    overflow or underflow) equal the numpy path at ordinary ones. Left out: ICRs
    exactly on the boundary (scaling moves them across it by round-off, and the
    subtraction is applied on one side only) and the extreme rows."""
    law = LAWS["anisotropic"]
    quad = quadrature("tire", 0.13)
    vx, vy, wz = kinematics(quad)
    keep = np.ones(vx.size, bool)
    keep[5:9] = False
    keep &= np.abs(vx) + np.abs(vy) + np.abs(wz) < 1e50
    keep &= np.abs(vx) + np.abs(vy) + np.abs(wz) > 1e-50
    vx, vy, wz = vx[keep], vy[keep], wz[keep]
    ref = friction_resultants(quad, vx, vy, wz, law, backend="numpy")
    got = friction_resultants(quad, vx * scale, vy * scale, wz * scale, law, backend="numba")
    assert_same(got, ref, law, quad)


def test_inputs_untouched_and_shapes_kept():
    quad = quadrature("hertz")
    vx = np.linspace(-1.0, 1.0, 6).reshape(2, 3)
    wz = np.array([[2.0], [-3.0]])
    keep = vx.copy(), wz.copy()
    res = friction_resultants(quad, vx, 0.2, wz, backend="numba")
    assert res.Fx.shape == res.Fy.shape == res.Mz.shape == (2, 3)
    np.testing.assert_array_equal(vx, keep[0])
    np.testing.assert_array_equal(wz, keep[1])


def test_auto_takes_the_compiled_sums_for_large_jobs(monkeypatch):
    import fepost.friction.exact as exact

    quad = quadrature("hertz")
    vx, vy, wz = kinematics(quad)
    monkeypatch.setattr(exact, "KERNEL_MIN_ELEMENTS", vx.size * quad.x.size)
    big = friction_resultants(quad, vx, vy, wz, backend="auto")
    compiled = friction_resultants(quad, vx, vy, wz, backend="numba")
    small = friction_resultants(quad, vx[1:], vy[1:], wz[1:], backend="auto")
    numpy = friction_resultants(quad, vx[1:], vy[1:], wz[1:], backend="numpy")
    for name in ("Fx", "Fy", "Mz"):
        np.testing.assert_array_equal(getattr(big, name), getattr(compiled, name))
        np.testing.assert_array_equal(getattr(small, name), getattr(numpy, name))


def test_bad_backend_names_the_argument():
    with pytest.raises(ArgumentError, match=re.escape("backend must be one of auto, numba, numpy, got 'c'")):
        friction_resultants(quadrature("hertz"), 0.1, 0.0, 1.0, backend="c")
