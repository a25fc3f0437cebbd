"""Exact friction integrals (fepost.friction.exact) against references and identities.

Tolerance tiers:
- IDENTITY (1e-12): relations that hold node by node (symmetries of the grid,
  pure sliding, shift covariance), up to round-off.
- TABLE (1e-5): the reference values of docs/theory.md (adaptive quadrature, trusted to
  ~1e-7); the brief asks for 1e-5 relative; the 64x128 sine grid measures ~1e-7.
- BRUTE (2e-6 of fN): scipy dblquad in polar coordinates about the ICR, an
  independent computation; our discretisation error on 64x128 is ~1e-7.
"""

from __future__ import annotations

import queue

import numpy as np
import pytest
from scipy import integrate

from fepost.analytic import pressure_function
from fepost.errors import ArgumentError
from fepost.friction.exact import Resultants, friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature, edge_grid
from fepost.polar import PolarGrid, PolarMap

IDENTITY = 1e-12
TABLE = 1e-5
BRUTE = 2e-6

EPS = [0.0, 0.25, 0.5, 0.75, 1.5, 2.0, 5.0]
REFERENCE = {  # reference table (docs/theory.md): |F|/fN, |M|/fNR for sliding along x at v = ε ω R
    "uniform": (
        [0, 0.24803131, 0.48384376, 0.69267323, 0.94081938, 0.96768751, 0.99497468],
        [0.66666667, 0.63578612, 0.54774835, 0.41798322, 0.17379811, 0.12780920, 0.05016857],
    ),
    "hertz": (
        [0, 0.28992237, 0.55223308, 0.75932049, 0.95311839, 0.97427858, 0.99598266],
        [0.58904862, 0.55309595, 0.45559229, 0.32760077, 0.13813766, 0.10190933, 0.04011545],
    ),
}


def make_quad(profile="hertz", radius=1.0, nr=64, nphi=128, k_x=0.0, peak=1.0):
    fn = pressure_function(profile, radius, peak=peak, k_x=k_x)
    return PressureQuadrature.from_polar(PolarMap.from_function(fn, radius, edge_grid(nr, nphi)))


@pytest.mark.parametrize("profile", ["uniform", "hertz"])
def test_reference_table(profile):
    quad = make_quad(profile, radius=1.0)
    law = FrictionLaw(f=1.0)
    n = quad.load
    eps = np.array(EPS)
    res = friction_resultants(quad, eps, 0.0, 1.0, law)
    force = np.hypot(res.Fx, res.Fy) / n
    torque = np.abs(res.Mz) / n
    ref_f, ref_m = (np.array(v) for v in REFERENCE[profile])
    assert force[0] < IDENTITY
    np.testing.assert_allclose(force[1:], ref_f[1:], rtol=TABLE)
    np.testing.assert_allclose(torque, ref_m, rtol=TABLE)


def test_reference_table_scales_with_radius_and_f():
    """Same table on R = 0.12 m, f = 0.7, σmax = 3e5 Pa, with ω = 4 rad/s."""
    R, f, w = 0.12, 0.7, 4.0
    quad = make_quad("hertz", radius=R, peak=3e5)
    res = friction_resultants(quad, 0.5 * w * R, 0.0, w, FrictionLaw(f=f))
    fn = f * quad.load
    assert np.hypot(res.Fx, res.Fy) / fn == pytest.approx(REFERENCE["hertz"][0][2], rel=TABLE)
    assert abs(res.Mz) / (fn * R) == pytest.approx(REFERENCE["hertz"][1][2], rel=TABLE)


def test_pure_spin_lateral_force_of_shifted_hertz():
    k, R, f = 0.13, 0.1, 0.3
    quad = make_quad("hertz", radius=R, k_x=k, peak=2e5)
    law = FrictionLaw(f=f)
    m0 = f * float(quad.sigma @ (np.hypot(quad.x, quad.y) * quad.dA))
    for w in (2.0, -3.0):
        res = friction_resultants(quad, 0.0, 0.0, w, law)
        expected = -np.sign(w) * k * m0 / (2 * R)
        assert float(res.Fy) == pytest.approx(expected, rel=TABLE)
        assert abs(float(res.Fx)) < IDENTITY * f * quad.load


@pytest.mark.parametrize("profile", ["uniform", "hertz", "tire"])
def test_pure_sliding_gives_fN_in_every_direction(profile):
    quad = make_quad(profile, radius=0.1, peak=1e5)
    f = 0.4
    beta = np.arange(8) * np.pi / 4
    res = friction_resultants(quad, 2.0 * np.cos(beta), 2.0 * np.sin(beta), 0.0, FrictionLaw(f=f))
    fn = f * quad.load
    np.testing.assert_allclose(res.Fx, -fn * np.cos(beta), atol=IDENTITY * fn)
    np.testing.assert_allclose(res.Fy, -fn * np.sin(beta), atol=IDENTITY * fn)
    np.testing.assert_allclose(res.Mz, 0.0, atol=IDENTITY * fn * 0.1)


def test_no_motion_gives_zero_without_nan():
    res = friction_resultants(make_quad(), [0.0, 0.0], [0.0, 0.0], [0.0, 0.0])
    for comp in (res.Fx, res.Fy, res.Mz):
        assert np.all(comp == 0.0)


def kinematic_set():
    rng = np.random.default_rng(7)
    wz = rng.uniform(-5, 5, 12)
    vx = rng.uniform(-2, 2, 12)
    vy = rng.uniform(-2, 2, 12)
    return vx, vy, wz


def test_reversing_all_velocities_flips_every_resultant():
    # w → −w node by node, so τ → −τ: an identity of the discretisation.
    quad = make_quad("hertz", k_x=0.13)
    vx, vy, wz = kinematic_set()
    a = friction_resultants(quad, vx, vy, wz)
    b = friction_resultants(quad, -vx, -vy, -wz)
    for p, q in ((a.Fx, b.Fx), (a.Fy, b.Fy), (a.Mz, b.Mz)):
        np.testing.assert_allclose(q, -p, atol=IDENTITY * quad.load)


def test_mirror_y_flips_lateral_force_and_torque():
    # σ0(1 + k x/R) is even in y. Mirroring y → −y maps (vx, vy, ω) to (vx, −vy, −ω)
    # and (Fx, Fy, Mz) to (Fx, −Fy, −Mz): reversing ω_z alone (vy = 0) flips M_z and
    # the shift's lateral force F_y, and keeps F_x.
    quad = make_quad("hertz", k_x=0.13)
    vx, vy, wz = kinematic_set()
    a = friction_resultants(quad, vx, vy, wz)
    b = friction_resultants(quad, vx, -vy, -wz)
    tol = IDENTITY * quad.load
    np.testing.assert_allclose(b.Fx, a.Fx, atol=tol)
    np.testing.assert_allclose(b.Fy, -a.Fy, atol=tol)
    np.testing.assert_allclose(b.Mz, -a.Mz, atol=tol)


def test_mirror_x_on_axisymmetric_map():
    # x → −x maps (vx, vy, ω) to (−vx, vy, −ω) and (Fx, Fy, Mz) to (−Fx, Fy, −Mz).
    quad = make_quad("hertz")
    vx, vy, wz = kinematic_set()
    a = friction_resultants(quad, vx, vy, wz)
    b = friction_resultants(quad, -vx, vy, -wz)
    tol = IDENTITY * quad.load
    np.testing.assert_allclose(b.Fx, -a.Fx, atol=tol)
    np.testing.assert_allclose(b.Fy, a.Fy, atol=tol)
    np.testing.assert_allclose(b.Mz, -a.Mz, atol=tol)


def test_rotation_invariance_of_axisymmetric_map():
    # Rotating v by β (not a grid symmetry) rotates F and keeps M_z, up to the
    # discretisation error of the 64x128 grid: ~1e-7 of fN with the ICR well inside
    # or outside, ~1e-6 when it lies just outside the edge (benchmarks/bench_friction.py).
    quad = make_quad("hertz")
    vx, vy, wz = kinematic_set()
    beta = 0.3
    c, s = np.cos(beta), np.sin(beta)
    a = friction_resultants(quad, vx, vy, wz)
    b = friction_resultants(quad, c * vx - s * vy, s * vx + c * vy, wz)
    tol = 1e-5 * 0.3 * quad.load
    np.testing.assert_allclose(b.Fx, c * a.Fx - s * a.Fy, atol=tol)
    np.testing.assert_allclose(b.Fy, s * a.Fx + c * a.Fy, atol=tol)
    np.testing.assert_allclose(b.Mz, a.Mz, atol=tol)


def test_shifted_field_equals_moved_kinematics():
    # σ'(p) = σ(p − d): F'(v, ω) = F(v + ω J d, ω), M'(v, ω) = M(v + ω J d, ω) + d × F.
    quad = make_quad("hertz", radius=0.1, k_x=0.13, peak=2e5)
    dx, dy = 0.013, -0.021
    moved = quad.shifted(dx, dy)
    vx, vy, wz = kinematic_set()
    vx, vy = 0.05 * vx, 0.05 * vy
    a = friction_resultants(moved, vx, vy, wz)
    b = friction_resultants(quad, vx - wz * dy, vy + wz * dx, wz)
    tol = 1e-10 * quad.load
    np.testing.assert_allclose(a.Fx, b.Fx, atol=tol)
    np.testing.assert_allclose(a.Fy, b.Fy, atol=tol)
    np.testing.assert_allclose(a.Mz, b.Mz + dx * b.Fy - dy * b.Fx, atol=tol * 0.1)


def test_stretched_uniform_patch_pure_spin_torque():
    # Pure spin about the centre of an ellipse (semi-axes sR, R/s) with uniform σ:
    # M = −f σ ∬ r dA = −f σ ∫ ρ_max(θ)³/3 dθ, ρ_max = (cos²/ax² + sin²/ay²)^(-1/2).
    R, s, sig, f = 0.1, 1.4, 2e5, 0.5
    quad = make_quad("uniform", radius=R, peak=sig).stretched(s)
    ax, ay = s * R, R / s
    ref, _ = integrate.quad(
        lambda t: (np.cos(t) ** 2 / ax**2 + np.sin(t) ** 2 / ay**2) ** -1.5 / 3,
        0,
        2 * np.pi,
        epsabs=0,
        epsrel=1e-12,
    )
    res = friction_resultants(quad, 0.0, 0.0, 3.0, FrictionLaw(f=f))
    assert float(res.Mz) == pytest.approx(-f * sig * ref, rel=TABLE)
    assert quad.load == pytest.approx(sig * np.pi * R**2, rel=1e-12)


def _icr_errors(nr, subtract, reference):
    quad = make_quad("hertz", nr=nr, nphi=2 * nr)
    res = friction_resultants(quad, *CONVERGENCE_KINEMATICS, FrictionLaw(f=1.0), subtract=subtract)
    got = np.stack([res.Fx, res.Fy, res.Mz])
    return np.max(np.abs(got - reference)) / quad.load


# ICR inside the patch at three positions (ρ = 0.5, 0.75, 0.6).
CONVERGENCE_KINEMATICS = (
    np.array([0.5, 0.6, 0.3]),
    np.array([0.0, -0.45, 0.52]),
    np.array([1.0, 1.0, -1.0]),
)
SIZES = (16, 24, 32, 48, 64)


@pytest.fixture(scope="module")
def convergence_reference():
    quad = make_quad("hertz", nr=256, nphi=512)
    res = friction_resultants(quad, *CONVERGENCE_KINEMATICS, FrictionLaw(f=1.0))
    return np.stack([res.Fx, res.Fy, res.Mz])


def observed_order(errors):
    slope, _ = np.polyfit(np.log(SIZES), np.log(errors), 1)
    return -slope


def test_convergence_order_with_icr_inside(convergence_reference):
    # Subtracting g(p0) + ∇g(p0)·(p − p0) leaves a remainder ~|p − p0|² times a
    # bounded direction field: expected order 4 in the node spacing; the raw
    # discontinuous field converges like order 2. Assert with margin.
    with_sub = [_icr_errors(n, True, convergence_reference) for n in SIZES]
    first = [_icr_errors(n, 1, convergence_reference) for n in SIZES]
    without = [_icr_errors(n, False, convergence_reference) for n in SIZES]
    assert observed_order(with_sub) > 3.3
    assert observed_order(without) < 2.6
    assert observed_order(first) > 2.3
    for e_sub, e_first, e_raw in zip(with_sub, first, without, strict=True):
        assert e_sub < e_first < e_raw
    assert with_sub[-1] < 1e-3 * without[-1]


def _brute_force(law, sigma, vx, vy, wz, sigma_ref):
    """dblquad in polar coordinates (ρ, θ) about the ICR on the unit disc (R = 1)."""
    p0x, p0y = -vy / wz, vx / wz

    def rho_max(t):
        b = p0x * np.cos(t) + p0y * np.sin(t)
        return -b + np.sqrt(b * b - (p0x**2 + p0y**2 - 1.0))

    def traction(r, t, comp):
        x, y = p0x + r * np.cos(t), p0y + r * np.sin(t)
        wx, wy = vx - wz * y, vy + wz * x
        speed = np.hypot(wx, wy)
        s = sigma(x, y)
        mu = (
            law.f
            * max(0.0, 1 + law.pressure_coef * (s / sigma_ref - 1))
            * max(0.0, 1 + law.speed_coef * speed)
        )
        tx, ty = -mu * s * wx / speed, -mu * s * law.anisotropy * wy / speed
        return r * (tx, ty, x * ty - y * tx)[comp]

    out = []
    for comp in range(3):
        val, _ = integrate.dblquad(
            lambda r, t, c=comp: traction(r, t, c),
            0,
            2 * np.pi,
            0,
            rho_max,
            epsabs=1e-11,
            epsrel=1e-10,
        )
        out.append(val)
    return np.array(out)


@pytest.mark.slow
@pytest.mark.parametrize(
    "law",
    [FrictionLaw(f=0.5, pressure_coef=-0.4), FrictionLaw(f=0.5, speed_coef=-0.3, anisotropy=0.8)],
    ids=["pressure", "speed+anisotropy"],
)
def test_law_against_brute_force(law):
    fn = pressure_function("hertz", 1.0)
    quad = PressureQuadrature.from_polar(PolarMap.from_function(fn, 1.0, edge_grid(64, 128)))
    sigma_ref = 2.0 / 3.0  # Hertz mean pressure N/area = (2π/3)/π for σmax = 1
    vx, vy, wz = 0.3, -0.2, 0.8  # ICR at (0.25, 0.375), inside
    ref = _brute_force(law, lambda x, y: float(fn(x, y)), vx, vy, wz, sigma_ref)
    res = friction_resultants(quad, vx, vy, wz, law)
    got = np.array([float(res.Fx), float(res.Fy), float(res.Mz)])
    np.testing.assert_allclose(got, ref, atol=BRUTE * law.f * quad.load)


def test_anisotropy_pure_sliding():
    quad = make_quad("tire", radius=0.1, peak=1e5)
    law = FrictionLaw(f=0.6, anisotropy=0.7)
    fn = law.f * quad.load
    along_x = friction_resultants(quad, 1.0, 0.0, 0.0, law)
    along_y = friction_resultants(quad, 0.0, 1.0, 0.0, law)
    assert float(along_x.Fx) == pytest.approx(-fn, rel=IDENTITY)
    assert float(along_y.Fy) == pytest.approx(-0.7 * fn, rel=IDENTITY)


def test_default_law_is_coulomb():
    quad = make_quad("hertz")
    vx, vy, wz = kinematic_set()
    a = friction_resultants(quad, vx, vy, wz, FrictionLaw(f=0.3))
    b = friction_resultants(quad, vx, vy, wz, FrictionLaw(0.3, 0.0, 0.0, 1.0, 2.5))
    np.testing.assert_array_equal(a.Fx, b.Fx)
    np.testing.assert_array_equal(a.Mz, b.Mz)


def test_results_are_read_only_shaped_and_serialisable():
    quad = make_quad("hertz", nr=16, nphi=32)
    vx = np.zeros((2, 3)) + 0.1
    before = vx.copy()
    res = friction_resultants(quad, vx, 0.0, 1.0)
    assert isinstance(res, Resultants)
    assert res.Fx.shape == (2, 3) and res.Mz.shape == (2, 3)
    with pytest.raises(ValueError):
        res.Fx[0, 0] = 1.0
    assert set(res.to_dict()) == {"Fx", "Fy", "Mz"}
    np.testing.assert_array_equal(vx, before)


@pytest.mark.parametrize(
    "law", [FrictionLaw(f=0.5), FrictionLaw(f=0.5, speed_coef=-0.3)], ids=["coulomb", "speed"]
)
def test_threads_and_chunks_do_not_change_results(monkeypatch, law):
    """Many chunks of three points on two threads: the same numbers as one chunk, the
    working arrays reused from chunk to chunk (at most one set per thread) and by the
    next call (none made)."""
    from fepost.friction import chunksums

    quad = make_quad("hertz", nr=16, nphi=32)
    vx, vy, wz = kinematic_set()
    a = friction_resultants(quad, vx, vy, wz, law, threads=1, backend="numpy")
    made = []

    class Counted(chunksums.Scratch):
        def __init__(self, elements: int) -> None:
            made.append(elements)
            super().__init__(elements)

    monkeypatch.setattr(chunksums, "Scratch", Counted)
    monkeypatch.setattr(chunksums, "_SPARE", queue.SimpleQueue())
    monkeypatch.setattr(chunksums, "CHUNK_ELEMENTS", 3 * quad.x.size)
    b = friction_resultants(quad, vx, vy, wz, law, threads=2, backend="numpy")
    assert vx.size >= 12 and 1 <= len(made) <= 2 and set(made) == {3 * quad.x.size}  # 4+ chunks
    c = friction_resultants(quad, vx, vy, wz, law, threads=2, backend="numpy")
    assert len(made) <= 2
    for name in ("Fx", "Fy", "Mz"):
        for r in (b, c):
            np.testing.assert_allclose(
                getattr(r, name), getattr(a, name), rtol=1e-13, atol=1e-13 * abs(a.Mz).max()
            )


def test_nan_kinematics_rejected():
    with pytest.raises(ArgumentError, match=r"^vy must be finite \(m/s\), got nan at index \(1,\)$"):
        friction_resultants(make_quad(nr=8, nphi=16), [1.0, 2.0], [0.0, np.nan], 1.0)


def test_mismatched_shapes_rejected():
    with pytest.raises(ArgumentError, match=r"^wz has shape \(4,\), which does not broadcast with \(3,\)$"):
        friction_resultants(make_quad(nr=8, nphi=16), np.zeros(3), 0.0, np.zeros(4))


def test_bad_law_and_quad_rejected():
    quad = make_quad(nr=8, nphi=16)
    with pytest.raises(ArgumentError, match=r"^law must be a FrictionLaw, got dict$"):
        friction_resultants(quad, 1.0, 0.0, 0.0, law={})
    with pytest.raises(ArgumentError, match=r"^quad must be a PressureQuadrature, got PolarMap$"):
        friction_resultants(
            PolarMap.from_function(lambda x, y: 1 + 0 * x, 1.0, PolarGrid.make(8, 16)), 1, 0, 0
        )
    with pytest.raises(ArgumentError, match=r"^subtract must be True, False, 0, 1 or 2, got 3$"):
        friction_resultants(quad, 1.0, 0.0, 1.0, subtract=3)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"f": -0.1}, "f must be a friction coefficient in [0.001, 10], got -0.1"),
        ({"anisotropy": 0.0}, "anisotropy must be > 0 (f_y/f_x), got 0.0"),
        ({"speed_coef": float("nan")}, "speed_coef must be finite, got nan"),
        ({"pressure_ref": -1.0}, "pressure_ref must be a positive finite pressure in Pa, got -1.0"),
        ({"pressure_coef": "big"}, "pressure_coef must be a real number, got 'big'"),
    ],
)
def test_law_validation(kwargs, message):
    with pytest.raises(ArgumentError) as err:
        FrictionLaw(**kwargs)
    assert str(err.value) == message


def test_quadrature_transforms_preserve_load_and_compose_sigma_at():
    quad = make_quad("hertz", radius=0.1, nr=16, nphi=32, k_x=0.13, peak=2e5)
    for other in (
        quad.stretched(1.3),
        quad.shifted(0.01, -0.02),
        quad.stretched(0.8).shifted(0.003, 0.0),
    ):
        assert other.load == pytest.approx(quad.load, rel=IDENTITY)
        assert other.contact_area == pytest.approx(quad.contact_area, rel=IDENTITY)
        # Nodes map to nodes, where the bilinear interpolation is exact.
        np.testing.assert_allclose(other.sigma_at(other.x, other.y), other.sigma, rtol=1e-9, atol=1e-6)
    assert quad.stretched(1.3).domain.ax == pytest.approx(0.13)
    with pytest.raises(ValueError):
        quad.x[0] = 0.0
    with pytest.raises(ArgumentError, match=r"^s must be a positive finite stretch factor, got 0$"):
        quad.stretched(0)


def test_edge_grid_integrates_hertz_load_spectrally():
    # ∫₀¹ √(1−ρ²) ρ dρ = 1/3; plain Gauss–Legendre in ρ converges like nr⁻³ here.
    for nr in (12, 24):
        g = edge_grid(nr, 8)
        sine = np.sum(np.sqrt(1 - g.rho**2) * g.rho * g.w_rho)
        gauss = PolarGrid.make(nr, 8)
        plain = np.sum(np.sqrt(1 - gauss.rho**2) * gauss.rho * gauss.w_rho)
        assert abs(sine - 1 / 3) < 1e-14
        assert abs(plain - 1 / 3) > 1e-6
