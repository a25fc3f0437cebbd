"""Exact friction integrals (fepost.friction.exact) with the centre of rotation at, just inside
and just outside the patch boundary.

The resultants are continuous in the kinematics, so their values on either side of the
boundary may differ only by the motion's own change. Before the subtraction was extended
outside the domain a uniform disc jumped by 1.2e-4 of fN there, and Hertz's gradient term
lost 1.9e-4 of fN just inside. Checked against independent computations: the closed form of
the uniform disc with the centre on its rim, and scipy's dblquad in polar coordinates about
the centre (the rays' part in the domain) or in Cartesian coordinates (the polar moments).

Tolerance tiers (of fN, fN·R for M_z):
- JUMP (1e-4): the brief's continuity bound; measured 2e-6 (a step of 1e-6 of R moves the
  resultants by about that much).
- EXACT (1e-10): the uniform disc, whose subtraction leaves nothing to the nodes (measured
  ~1e-14).
- EDGE (5e-5): Hertz's square-root edge on the default 64 x 128 grid, near the rim (measured
  at most 1.9e-5 against dblquad; the remaining error is the grid's, on either side).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from fepost.analytic import pressure_function
from fepost.friction import nodesums
from fepost.friction.exact import friction_resultants, ray_integrals
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import Ellipse, PressureQuadrature, edge_grid
from fepost.polar import PolarMap

#: Largest change allowed over a step of 1e-6 of the centre's ellipse level across the rim
#: (fraction of fN or fNR): measured 4.2e-7 (uniform) and 3.0e-7 (Hertz); the defect this
#: guards (the Hertz subtraction's gradient term at the rim) jumped by 1.2e-4, 24x above it.
JUMP = 5e-6
EXACT = 1e-10
EDGE = 5e-5

#: Ellipse levels of the centre: just inside, on, just outside the boundary.
STEP = 1e-6
LEVELS = (1.0 - STEP, 1.0, 1.0 + STEP)
#: Directions of the centre from the patch centre (not on the grid's angles).
DIRECTIONS = np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False) + 0.1234


def disc(profile: str, radius: float = 1.0) -> PressureQuadrature:
    fn = pressure_function(profile, radius, peak=1.0)
    return PressureQuadrature.from_polar(PolarMap.from_function(fn, radius, edge_grid()))


def kinematics_about(quad: PressureQuadrature, levels, angles, wz: float = 1.0):
    """(vx, vy, wz) whose centre of rotation p0 = (−vy/wz, vx/wz) lies at each ellipse level
    and direction (levels × angles, flat), and p0."""
    d = quad.domain
    lev, ang = np.meshgrid(np.asarray(levels, float), np.asarray(angles, float), indexing="ij")
    px = d.cx + lev.ravel() * d.ax * np.cos(ang.ravel())
    py = d.cy + lev.ravel() * d.ay * np.sin(ang.ravel())
    return py * wz, -px * wz, np.full(px.size, wz), px, py


def normalised(quad, res, law) -> np.ndarray:
    """(F_x, F_y, M_z/R) / fN, shape (3, points)."""
    fn = law.f * quad.load
    return np.array([res.Fx, res.Fy, res.Mz / quad.domain.ax]) / fn


def largest_jump(values: np.ndarray, n_levels: int) -> float:
    """Largest change between consecutive levels, over components and directions."""
    v = values.reshape(3, n_levels, -1)
    return float(np.abs(np.diff(v, axis=1)).max())


def polar_reference(sigma, p0x, p0y, law, d: Ellipse, tol: float = 1e-10) -> np.ndarray:
    """(F_x, F_y, M_z) of −μσ ê_θ (ω_z > 0) over the ellipse ``d`` by scipy's dblquad in
    polar coordinates (ρ, θ) about p0, over the rays' part in the ellipse: from p0 when it
    is inside, between the two crossings when outside; θ split where the rays turn fastest
    (towards the ellipse's centre and away from it)."""
    ux, uy = (p0x - d.cx) / d.ax, (p0y - d.cy) / d.ay
    level = np.hypot(ux, uy)
    towards = np.arctan2(-uy * d.ay, -ux * d.ax)
    if level < 1.0:
        pieces = [(towards - np.pi, towards), (towards, towards + np.pi)]
    else:
        half = np.arcsin(min(1.0, 1.0 / level))
        ends = [
            np.arctan2(d.ay * np.sin(a), d.ax * np.cos(a))
            for a in (np.arctan2(-uy, -ux) + k * half for k in (-1, 1))
        ]
        lo, hi = ends[0], ends[0] + np.mod(ends[1] - ends[0], 2.0 * np.pi)
        pieces = [(lo, 0.5 * (lo + hi)), (0.5 * (lo + hi), hi)]

    def crossing(t, sign):
        ex, ey = np.cos(t) / d.ax, np.sin(t) / d.ay
        a, b, c = ex * ex + ey * ey, ux * ex + uy * ey, ux * ux + uy * uy - 1.0
        return max(0.0, (-b + sign * np.sqrt(max(b * b - a * c, 0.0))) / a)

    def traction(r, t, comp):
        c, s = np.cos(t), np.sin(t)
        x, y = p0x + r * c, p0y + r * s
        g = law.f * sigma(x, y)
        tx, ty = g * s, -g * c  # −g ê_θ
        return r * (tx, ty, x * ty - y * tx)[comp]

    return np.array(
        [
            sum(
                integrate.dblquad(
                    lambda r, t, k=k: traction(r, t, k),
                    lo,
                    hi,
                    lambda t: crossing(t, -1.0),
                    lambda t: crossing(t, 1.0),
                    epsabs=tol,
                    epsrel=tol,
                )[0]
                for lo, hi in pieces
            )
            for k in range(3)
        ]
    )


def test_uniform_disc_on_its_rim_against_the_closed_form():
    """Centre on the rim of a uniform disc: the rays fill a half-plane's chords, ρ = 2R|sin|:
    |F| = 8/(3π) fN against the sliding of the patch centre, M_z = −8/(9π) fN R."""
    quad, law = disc("uniform", radius=0.2), FrictionLaw(f=0.7)
    vx, vy, wz, *_ = kinematics_about(quad, (1.0,), DIRECTIONS, wz=3.0)
    got = normalised(quad, friction_resultants(quad, vx, vy, wz, law), law)
    speed = np.hypot(vx, vy)
    np.testing.assert_allclose(got[0], -8.0 / (3.0 * np.pi) * vx / speed, atol=EXACT)
    np.testing.assert_allclose(got[1], -8.0 / (3.0 * np.pi) * vy / speed, atol=EXACT)
    np.testing.assert_allclose(got[2], -8.0 / (9.0 * np.pi), atol=EXACT)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("profile", ["uniform", "hertz"])
def test_continuous_across_the_rim(profile, backend):
    if backend == "numba" and not nodesums.AVAILABLE:
        pytest.skip("numba is not installed (the fast extra)")
    quad, law = disc(profile), FrictionLaw(f=1.0)
    vx, vy, wz, *_ = kinematics_about(quad, LEVELS, DIRECTIONS)
    got = normalised(quad, friction_resultants(quad, vx, vy, wz, law, backend=backend), law)
    assert largest_jump(got, len(LEVELS)) < JUMP


@pytest.mark.parametrize(
    ("profile", "level", "tol"),
    [
        ("uniform", 1.0 - 1e-3, EXACT),
        ("uniform", 1.0 + 1e-3, EXACT),
        ("uniform", 1.3, EXACT),
        ("hertz", 1.0 - 1e-4, EDGE),
        ("hertz", 1.0, EDGE),
        ("hertz", 1.0 + 1e-4, EDGE),
    ],
)
def test_near_the_rim_against_dblquad(profile, level, tol):
    """The subtracted integrals just inside and outside against dblquad about the centre
    (Hertz with order-2 subtraction was off by 1.2e-4 of fN at 1 − 1e-4 before its
    gradient term was tapered off towards the rim)."""
    quad, law = disc(profile), FrictionLaw(f=1.0)
    sigma = pressure_function(profile, 1.0, peak=1.0)
    vx, vy, wz, px, py = kinematics_about(quad, (level,), (1.3,))
    got = normalised(quad, friction_resultants(quad, vx, vy, wz, law), law)[:, 0]
    # the reference's own tolerance well below the one checked
    ref = polar_reference(lambda x, y: float(sigma(x, y)), px[0], py[0], law, quad.domain, tol=tol / 1e3)
    ref /= law.f * quad.load
    np.testing.assert_allclose(got, ref, atol=tol)


def test_turned_groups_agree_with_direct_sums_near_the_rim():
    """The rotation-symmetric path (`turns`) integrates centres outside the rim alike."""
    quad, law = disc("uniform"), FrictionLaw(f=1.0)
    turns = 8
    vx, vy, wz, *_ = kinematics_about(quad, (1.0 - STEP, 1.0, 1.0 + STEP, 1.5), np.arange(turns) * np.pi / 4)
    order = np.arange(vx.size).reshape(-1, turns).T.ravel()  # group k: the first turned k times
    vx, vy, wz = vx[order], vy[order], wz[order]
    turned = friction_resultants(quad, vx, vy, wz, law, turns=turns, backend="numpy")
    direct = friction_resultants(quad, vx, vy, wz, law, backend="numpy")
    for name in ("Fx", "Fy", "Mz"):
        np.testing.assert_allclose(getattr(turned, name), getattr(direct, name), atol=1e-12 * quad.load)


def test_stretched_uniform_patch_continuous_and_exact():
    """An elliptic patch (aspect 2.25, off centre): continuous across its boundary and, for a
    uniform field, equal to the same integral about the same centre by dblquad in
    Cartesian coordinates."""
    law = FrictionLaw(f=1.0)
    quad = disc("uniform", radius=0.1).stretched(1.5).shifted(0.01, -0.02)
    vx, vy, wz, px, py = kinematics_about(quad, LEVELS, DIRECTIONS)
    got = normalised(quad, friction_resultants(quad, vx, vy, wz, law), law)
    assert largest_jump(got, len(LEVELS)) < JUMP
    k = len(DIRECTIONS) + 3  # on the boundary, the fourth direction
    ref = polar_reference(lambda x, y: 1.0, px[k], py[k], law, quad.domain) / (law.f * quad.load)
    ref[2] /= quad.domain.ax
    np.testing.assert_allclose(got[:, k], ref, atol=1e-9)


def _ellipse_dblquad(d: Ellipse, f) -> float:
    def half(x):
        return d.ay * np.sqrt(max(0.0, 1.0 - ((x - d.cx) / d.ax) ** 2))

    val, _ = integrate.dblquad(
        lambda y, x: f(x, y),
        d.cx - d.ax,
        d.cx + d.ax,
        lambda x: d.cy - half(x),
        lambda x: d.cy + half(x),
        epsabs=1e-13,
        epsrel=1e-10,
    )
    return val


@pytest.mark.parametrize("level", [1.05, 1.4])
def test_polar_moments_outside_against_dblquad(level):
    """The moments about a centre outside an ellipse (ρ from ρ_in to ρ_out) against
    dblquad of their definitions ∬ ê^k ρ^(n−2) dA in Cartesian coordinates."""
    d = Ellipse(0.02, -0.01, 0.15, 0.09)
    angle = 2.2
    px = d.cx + level * d.ax * np.cos(angle)
    py = d.cy + level * d.ay * np.sin(angle)
    got = ray_integrals(d, np.array([px]), np.array([py]))[0]

    def column(k):
        def f(x, y):
            dx, dy = x - px, y - py
            r = np.hypot(dx, dy)
            if r == 0.0:
                return 0.0
            c, s = dx / r, dy / r
            return (
                c,
                s,
                c * c * r,
                c * s * r,
                s * s * r,
                c**3 * r * r,
                c * c * s * r * r,
                c * s * s * r * r,
                s**3 * r * r,
            )[k]

        return f

    ref = np.array([_ellipse_dblquad(d, column(k)) for k in range(9)])
    scale = np.array([d.ax**2] * 2 + [d.ax**3] * 3 + [d.ax**4] * 4)
    np.testing.assert_allclose(got / scale, ref / scale, atol=1e-9)


def test_fe_map_continuous_across_its_rim(aircraft):
    """The aircraft tire's static map (meshes/aircraft/static_100.vtu), centre in 16
    directions at 1 − 1e-6, 1 and 1 + 1e-6 of its radius, and 1 ± 1e-3."""
    quad, law = PressureQuadrature.from_polar(aircraft.static_map), FrictionLaw(f=0.8)
    levels = (1.0 - 1e-3, *LEVELS, 1.0 + 1e-3)
    vx, vy, wz, *_ = kinematics_about(quad, levels, DIRECTIONS, wz=2.0)
    got = normalised(quad, friction_resultants(quad, vx, vy, wz, law), law)
    v = got.reshape(3, len(levels), -1)
    assert float(np.abs(np.diff(v[:, 1:4], axis=1)).max()) < JUMP
    # a step of 1e-3 of R moves the resultants smoothly: by at most ~1e-3, both sides alike
    steps = np.abs(np.diff(v, axis=1))
    assert float(steps.max()) < 2e-3
    np.testing.assert_allclose(steps[:, 0], steps[:, 3], atol=JUMP)


@pytest.mark.parametrize("wz", [1e-300, -1e-300, 5e-320, 1e-200])
def test_vanishing_spin_is_pure_sliding(wz):
    """A spin so small that |v|/|wz| overflows (the centre of rotation at infinity) gives the
    pure-sliding resultants, F = −fN v/|v| and M_z of the sliding patch, with no floating-point
    warning (the tests turn RuntimeWarning into an error)."""
    quad, law = disc("hertz", radius=0.2), FrictionLaw(f=0.6)
    vx, vy = np.array([0.8, -0.3]), np.array([0.6, 0.4])
    tiny = friction_resultants(quad, vx, vy, np.full(2, wz), law)
    slide = friction_resultants(quad, vx, vy, np.zeros(2), law)
    got, ref = normalised(quad, tiny, law), normalised(quad, slide, law)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
    speed = np.hypot(vx, vy)
    np.testing.assert_allclose(got[0], -vx / speed, atol=1e-9)
    np.testing.assert_allclose(got[1], -vy / speed, atol=1e-9)
