"""scripts/real_study.py's own physics: the finite turn, point contacts and the friction fit."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import real_study as rs  # noqa: E402


def test_finite_turn_recovers_a_constant_twist():
    """A constant body twist (v, ω) for a unit time moves the point by ∫R(ωt)v dt in the start
    frame; the SE(2) logarithm of that displacement and the turn gives (v, ω) back."""
    rng = np.random.default_rng(1)
    rows = []
    want = []
    t = np.linspace(0.0, 1.0, 20001)
    for _ in range(5):
        v = rng.normal(scale=0.01, size=2)
        w = rng.uniform(-0.15, 0.15)
        c, s = np.cos(w * t), np.sin(w * t)
        d = np.trapezoid(np.column_stack([c * v[0] - s * v[1], s * v[0] + c * v[1]]), t, axis=0)
        rows.append([d[0], d[1], w])
        want.append([v[0], v[1], w])
    np.testing.assert_allclose(rs.finite_turn(np.array(rows)), want, rtol=0, atol=1e-11)
    # no turn: the displacement is the twist
    np.testing.assert_array_equal(rs.finite_turn(np.array([[0.01, 0.002, 0.0]])), [[0.01, 0.002, 0.0]])


def test_point_contacts_slide_and_spin():
    """Three legs with their statics loads: pure sliding gives −N v̂ and no torque about the centre
    of pressure; pure spin gives −Σ N_i |p_i| and, the legs not being symmetric, a net force
    −Σ N_i (ẑ × p̂_i)."""
    pts = np.array([[-0.04, -0.04], [0.08, -0.04], [-0.04, 0.08]])
    loads = rs.statics_loads(pts, np.zeros(2), 15.0)
    np.testing.assert_allclose(loads @ pts, [0.0, 0.0], atol=1e-12)
    W = rs.point_wrench(pts, loads, np.array([[0.01, 0.0, 0.0], [0.0, 0.0, 0.1]]))
    np.testing.assert_allclose(W[0], [-15.0, 0.0, 0.0], atol=1e-12)
    arms = np.linalg.norm(pts, axis=1)
    force = -(loads / arms) @ np.column_stack([-pts[:, 1], pts[:, 0]])
    np.testing.assert_allclose(W[1], [force[0], force[1], -(loads @ arms)], atol=1e-12)


def test_friction_fit_and_its_interval():
    """f of W = f P + noise: the estimate, and a 95 % interval that holds the truth in about 95 %."""
    rng = np.random.default_rng(3)
    P = rng.normal(size=(40, 3)) * np.array([1.0, 1.0, 0.05])
    hits = 0
    for k in range(200):
        W = 0.3 * P + np.random.default_rng(k).normal(scale=0.05, size=P.shape) * np.array([1.0, 1.0, 0.05])
        lo, hi = rs.fit_level(P, W)["ci95"]
        hits += lo <= 0.3 <= hi
    assert 180 <= hits <= 199, hits  # binomial(200, 0.95): 183-197 at 99.9 %
    exact = rs.fit_level(P, 0.3 * P)
    assert exact["f"] == pytest.approx(0.3, rel=1e-12) and exact["se"] < 1e-12
