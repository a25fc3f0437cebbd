"""Turned kinematics (fepost.friction.turns): the exact integrals of groups of points turned
about the patch origin, from the first group's, against the direct sums.

Tolerance tiers:
- IDENTITY (1e-12 of F0, M0): the turned sums and the direct ones are the same numbers
  in another order (FFT correlations, turned node coordinates in the last bit); measured
  up to 4e-14 (the ICR subtraction's finite-difference gradient amplifies round-off).
- TRAPEZOID (1e-9 relative): polar moments about a centre turned by an angle that does not
  carry the trapezoid onto itself differ by the trapezoid's own error, e^-25 by design
  (`fepost.friction.exact.THETA_DECAY`); a margin of 70 on it.
"""

from __future__ import annotations

import numpy as np
import pytest

from fepost.analytic import pressure_function
from fepost.errors import ArgumentError
from fepost.friction import build, turns
from fepost.friction.exact import friction_resultants, ray_integrals
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import Ellipse, PressureQuadrature, edge_grid
from fepost.friction.tensors import effective_quadrature
from fepost.polar import PolarMap

IDENTITY = 1e-12
TRAPEZOID = 1e-9
R = 0.12


def oblong_quad(nr=64, nphi=128) -> PressureQuadrature:
    """An asymmetric, oblong map (no symmetry the turned sums could lean on)."""
    hertz = pressure_function("hertz", R, peak=1.2e6, k_x=0.3, aspect=1.6)
    return PressureQuadrature.from_polar(
        PolarMap.from_function(lambda x, y: hertz(x, y) * (1.0 + 2.0 * y / R), R, edge_grid(nr, nphi))
    )


def sphere(n_theta: int, n_t: int, stagger: float = 0.0):
    nodes, _ = np.polynomial.legendre.leggauss(n_t)
    vx, vy, u, _, _ = build.sphere_nodes(n_theta, 0.5 * (nodes + 1.0))
    c, s = np.cos(stagger), np.sin(stagger)
    return c * vx - s * vy, s * vx + c * vy, u / R


def assert_same(a, b, quad, law):
    F0 = law.f * quad.load
    M0 = float(np.max(np.abs(a.Mz)))
    assert np.max(np.abs(a.Fx - b.Fx)) <= IDENTITY * F0
    assert np.max(np.abs(a.Fy - b.Fy)) <= IDENTITY * F0
    assert np.max(np.abs(a.Mz - b.Mz)) <= IDENTITY * M0


LAWS = {
    "coulomb": FrictionLaw(f=0.3),
    "anisotropic": FrictionLaw(f=0.3, anisotropy=1.7),
    "speed": FrictionLaw(f=0.3, speed_coef=-0.5),
    "pressure": FrictionLaw(f=0.3, pressure_coef=0.2),
}


@pytest.mark.parametrize("law", LAWS.values(), ids=LAWS.keys())
@pytest.mark.parametrize("subtract", [2, 1, 0])
def test_turned_sums_equal_direct(law, subtract, monkeypatch):
    quad = oblong_quad()
    vx, vy, wz = sphere(32, 33, stagger=np.pi / 32)
    direct = friction_resultants(quad, vx, vy, wz, law, subtract=subtract)
    calls = []
    real = turns.correlated_sums
    monkeypatch.setattr(turns, "correlated_sums", lambda *a: calls.append(a[0][0].shape) or real(*a))
    turned = friction_resultants(quad, vx, vy, wz, law, subtract=subtract, turns=32)
    assert calls == [(33, 64 * 128)]  # the direction fields of the first group only
    assert_same(direct, turned, quad, law)


@pytest.mark.parametrize(("n_theta", "nphi"), [(16, 128), (64, 128), (8, 48), (2, 2 * 31)])
def test_turned_sums_other_group_counts(n_theta, nphi):
    quad = oblong_quad(nr=24, nphi=nphi)
    vx, vy, wz = sphere(n_theta, 11, stagger=0.3)
    law = LAWS["coulomb"]
    assert turns.polar_layout(quad, n_theta) == (24, nphi)
    assert_same(
        friction_resultants(quad, vx, vy, wz, law),
        friction_resultants(quad, vx, vy, wz, law, turns=n_theta),
        quad,
        law,
    )


def test_no_symmetry_to_use_gives_the_direct_numbers_bit_for_bit():
    """A hint the quadrature cannot use (angle count not a multiple, a grid off the origin,
    a stretched grid) changes nothing."""
    law = LAWS["coulomb"]
    quad = oblong_quad()
    for q, n_theta in ((quad, 40), (quad.shifted(0.01, -0.02), 32), (quad.stretched(1.3), 32)):
        vx, vy, wz = sphere(n_theta, 9)
        assert turns.polar_layout(q, n_theta) is None
        a = friction_resultants(q, vx, vy, wz, law)
        b = friction_resultants(q, vx, vy, wz, law, turns=n_theta)
        for name in ("Fx", "Fy", "Mz"):
            assert np.array_equal(getattr(a, name), getattr(b, name))


def test_turned_polar_moments_of_a_disc():
    domain = Ellipse(0.0, 0.0, R, R)
    rng = np.random.default_rng(3)
    r = R * np.sqrt(rng.uniform(0.0, 0.999, 40))
    a = rng.uniform(0.0, 2.0 * np.pi, 40)
    px, py = r * np.cos(a), r * np.sin(a)
    base = ray_integrals(domain, px, py)
    scale = np.abs(base).max(axis=0)
    for angle, tol in ((2.0 * np.pi * 5 / 64, IDENTITY), (0.7, TRAPEZOID)):
        c, s = np.full(40, np.cos(angle)), np.full(40, np.sin(angle))
        direct = ray_integrals(domain, c * px - s * py, s * px + c * py)
        assert np.max(np.abs(turns.turn_rays(base, c, s) - direct) / scale) <= tol


def test_model_built_with_turned_sums_is_the_direct_model(monkeypatch):
    quad = oblong_quad()
    law = FrictionLaw(f=0.3, anisotropy=1.5)
    fast = build.build_model(quad, law, radius=R, order=(4, 8))
    monkeypatch.setattr(turns, "polar_layout", lambda quad, n: None)
    slow = build.build_model(quad, law, radius=R, order=(4, 8))
    # the correction fits 2304 equations of exact values equal to 1e-14: the same to 1e-10
    np.testing.assert_allclose(fast.correction, slow.correction, rtol=0, atol=1e-10)
    np.testing.assert_allclose(fast.correction_g, slow.correction_g, rtol=0, atol=1e-10)
    for key in ("model_force", "model_torque", "base_force", "base_torque"):
        assert fast.accuracy[key] == pytest.approx(slow.accuracy[key], rel=0, abs=IDENTITY)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (0, "turns must be a positive integer, got 0"),
        (True, "turns must be a positive integer, got True"),
        (2.5, "turns must be a positive integer, got 2.5"),
        (5, "turns=5 does not divide the 32 kinematic points into groups"),
    ],
)
def test_bad_turns_refused(value, message):
    vx, vy, wz = sphere(8, 4)
    with pytest.raises(ArgumentError, match=f"^{message}$"):
        friction_resultants(oblong_quad(8, 16), vx, vy, wz, turns=value)


def test_points_that_are_not_turned_groups_refused():
    vx, vy, wz = sphere(8, 4)
    vx = vx.copy()
    vx[9] += 1e-3
    with pytest.raises(
        ArgumentError,
        match=r"^turns=8: the kinematic points are not 8 groups of 4, group k the first turned by "
        r"2pi k/8 \(off by 0.001\)$",
    ):
        friction_resultants(oblong_quad(8, 16), vx, vy, wz, turns=8)


def test_polar_layout_is_kept_only_where_the_nodes_stay_polar():
    quad = oblong_quad(16, 32)
    assert quad.polar == (16, 32)
    assert effective_quadrature(quad, FrictionLaw(pressure_coef=0.2)).polar == (16, 32)
    assert quad.shifted(0.01, 0.0).polar is None
    assert quad.stretched(1.2).polar is None
    with pytest.raises(ArgumentError, match=r"^polar \(16, 16\) does not lay out the 512 nodes$"):
        PressureQuadrature(quad.x, quad.y, quad.dA, quad.sigma, quad.domain, quad.sigma_at, polar=(16, 16))
    with pytest.raises(ArgumentError, match=r"^polar \(32, 16\): the nodes are not a polar grid about the"):
        PressureQuadrature(quad.x, quad.y, quad.dA, quad.sigma, quad.domain, quad.sigma_at, polar=(32, 16))
    swapped = np.arange(512).reshape(16, 32)[:, ::-1].ravel()  # each ring turning the other way
    with pytest.raises(ArgumentError, match=r"^polar \(16, 32\): the nodes are not a polar grid about the"):
        PressureQuadrature(
            quad.x[swapped], quad.y[swapped], quad.dA, quad.sigma, quad.domain, quad.sigma_at, polar=(16, 32)
        )
    with pytest.raises(ArgumentError, match=r"^polar must be \(n_r, n_phi\) or None, got 'ab'$"):
        PressureQuadrature(quad.x, quad.y, quad.dA, quad.sigma, quad.domain, quad.sigma_at, polar="ab")
