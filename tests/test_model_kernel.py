"""The compiled kernel of the generalised friction model (fepost.friction.kernel) against
the numpy path, on many random kinematics and on the singular ones.

Tolerance: IDENTITY (1e-12 of F0 for forces, of M0 for the torque): the two paths
evaluate the same formulas in a different order (the kernel's P^(−5/6) by Newton
steps, its atan by Cephes' rational form, its t-derivative by Chebyshev derivative
coefficients), so they may differ by round-off only; measured ~3e-15.
"""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest
from numpy.polynomial import chebyshev

from fepost.errors import ArgumentError
from fepost.friction import basis, kernel, kernelpack
from fepost.friction import model as model_module
from fepost.friction.build import build_model
from fepost.friction.law import FrictionLaw
from fepost.friction.model import GeneralisedModel
from fepost.friction.reference_maps import asymmetric, ellipse_quad, tire_like

pytest.importorskip("numba", reason="numba (the optional 'fast' extra) is not installed")

IDENTITY = 1e-12


@pytest.fixture(scope="module")
def models() -> dict[str, GeneralisedModel]:
    hertz = build_model(ellipse_quad("hertz", 1.5), FrictionLaw(f=0.3), order=(4, 8), check=False)
    return {
        "hertz 72": hertz,
        "asymmetric 72": build_model(asymmetric(2.0), FrictionLaw(f=0.3), order=(4, 8), check=False),
        "tire-like 204": build_model(tire_like(2.5), FrictionLaw(f=0.5), order=(8, 12), check=False),
        "anisotropic": build_model(
            asymmetric(1.5), FrictionLaw(f=0.3, anisotropy=0.7), order=(4, 8), check=False
        ),
        "odd order (3, 5)": build_model(ellipse_quad("uniform", 2.0), FrictionLaw(f=0.4), order=(3, 5)),
        "base only": hertz.without_correction(),
        "substituted": hertz.substituted(F0=2.0 * hertz.F0, g=[0.05, -0.02], xc=[0.1, 0.03]),
    }


def singular_kinematics() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pure spin (both signs), pure sliding (all directions), zero velocity, their
    neighbourhoods (ε and 1/ε down to 1e-12) and extreme magnitudes."""
    ang = np.linspace(0.0, 2.0 * np.pi, 13)
    rows = [(0.0, 0.0, 0.0), (0.0, 0.0, 3.0), (0.0, 0.0, -3.0), (-0.0, 0.0, -0.0)]
    rows += [(np.cos(a), np.sin(a), 0.0) for a in ang]
    for eps in (1e-12, 1e-9, 1e-6, 1e-3):
        for a in ang[::3]:
            for s in (1.0, -1.0):
                rows.append((eps * np.cos(a), eps * np.sin(a), s * 10.0))  # near pure spin (R ~ 0.1 m)
                rows.append((np.cos(a), np.sin(a), s * eps))  # near pure sliding
    for scale in (1e-200, 1e-60, 1e60, 1e200):
        rows += [(scale, -0.5 * scale, 7.0 * scale), (0.0, 0.0, scale), (scale, 0.0, 0.0)]
    vx, vy, wz = np.array(rows, float).T
    return vx, vy, wz


def random_kinematics(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    vx, vy = rng.normal(size=(2, n)) * np.exp(rng.uniform(-5, 5, n))
    wz = rng.normal(size=n) * np.exp(rng.uniform(-3, 5, n))
    return vx, vy, wz


def assert_same(model, got, ref):
    for name, a, b in zip(("Fx", "Fy", "Mz"), got, ref, strict=True):
        scale = model.M0 if name == "Mz" else model.F0
        assert np.all(np.isfinite(a)), name
        err = np.max(np.abs(a - b)) / scale
        assert err <= IDENTITY, f"{name}: {err:.3g}"


@pytest.mark.parametrize(
    "name",
    [
        "hertz 72",
        "asymmetric 72",
        "tire-like 204",
        "anisotropic",
        "odd order (3, 5)",
        "base only",
        "substituted",
    ],
)
def test_kernel_equals_numpy_on_random_and_singular_kinematics(models, name):
    model = models[name]
    vx, vy, wz = random_kinematics(20_000, seed=len(name))
    svx, svy, swz = singular_kinematics()
    vx, vy, wz = (np.concatenate([a, b]) for a, b in ((vx, svx), (vy, svy), (wz, swz)))
    ref = model.evaluate(vx, vy, wz, backend="numpy")
    got = model.evaluate(vx, vy, wz, backend="numba")
    assert_same(model, got, ref)


@pytest.mark.parametrize("name", ["hertz 72", "tire-like 204", "anisotropic", "odd order (3, 5)"])
def test_a_point_gets_the_same_bits_wherever_it_sits(models, name):
    """The kernel contracts multiply-adds into FMAs: the vectorised body of each block loop
    and its scalar remainder must round alike, so that a point's forces do not depend
    on its position in the array (nor on the length of the array), bit for bit."""
    model = models[name]
    vx, vy, wz = random_kinematics(700, seed=11)
    svx, svy, swz = singular_kinematics()
    vx, vy, wz = (np.concatenate([a, b]) for a, b in ((vx, svx), (vy, svy), (wz, swz)))
    ref = model.evaluate(vx, vy, wz, backend="numba")
    for shift in (*range(1, 17), kernel.BLOCK - 1, kernel.BLOCK + 3):
        got = model.evaluate(vx[shift:], vy[shift:], wz[shift:], backend="numba")
        for a, b in zip(got, ref, strict=True):
            np.testing.assert_array_equal(a, b[shift:])
    for i in range(0, vx.size, 37):  # one point alone: the scalar remainder only
        got = model.evaluate(vx[i : i + 1], vy[i : i + 1], wz[i : i + 1], backend="numba")
        assert [float(a[0]) for a in got] == [float(b[i]) for b in ref]


def test_singular_points_have_their_exact_limits(models):
    """Independent of the numpy path (module docstring of fepost.friction.model): zero
    velocity gives zero, pure spin the torque −sgn(ω_z) M0, pure sliding along x the
    force −F0 along x and none across."""
    model = models["hertz 72"]
    fx, fy, mz = model.evaluate(
        [0.0, 0.0, 0.0, 2.0], [0.0, 0.0, 0.0, 0.0], [0.0, 5.0, -5.0, 0.0], backend="numba"
    )
    assert (fx[0], fy[0], mz[0]) == (0.0, 0.0, 0.0)
    assert mz[1] == pytest.approx(-model.M0, rel=IDENTITY)
    assert mz[2] == pytest.approx(model.M0, rel=IDENTITY)
    assert fx[3] == pytest.approx(-model.F0, rel=IDENTITY)
    assert abs(fy[3]) <= IDENTITY * model.F0


def test_auto_backend_switches_at_the_threshold(models, monkeypatch):
    monkeypatch.setattr(model_module, "KERNEL_MIN_POINTS", 64)
    model = models["asymmetric 72"]
    vx, vy, wz = random_kinematics(64, seed=3)
    big = model(vx, vy, wz)
    for a, b in zip(big, model.evaluate(vx, vy, wz, backend="numba"), strict=True):
        np.testing.assert_array_equal(a, b)
    small = model(vx[:10], vy[:10], wz[:10])
    for a, b in zip(small, model.evaluate(vx[:10], vy[:10], wz[:10], backend="numpy"), strict=True):
        np.testing.assert_array_equal(a, b)


def test_shapes_broadcast_and_inputs_stay_untouched(models):
    model = models["hertz 72"]
    vx = np.linspace(-1, 1, 6).reshape(2, 3)
    keep = vx.copy()
    fx, fy, mz = model.evaluate(vx, 0.1, np.array([[1.0], [-2.0]]), backend="numba")
    assert fx.shape == fy.shape == mz.shape == (2, 3)
    np.testing.assert_array_equal(vx, keep)
    ref = model.evaluate(vx, 0.1, np.array([[1.0], [-2.0]]), backend="numpy")
    assert_same(model, (fx, fy, mz), ref)


def test_substituted_model_is_repacked(models):
    model = models["hertz 72"]
    _ = model.kernel_coefficients  # packed and cached ...
    other = model.substituted(F0=3.0 * model.F0, M0=3.0 * model.M0)  # same Û0: the model scales
    vx, vy, wz = random_kinematics(100, seed=5)
    old = model.evaluate(vx, vy, wz, backend="numba")
    new = other.evaluate(vx, vy, wz, backend="numba")
    for a, b, scale in zip(new, old, (model.F0, model.F0, model.M0), strict=True):
        np.testing.assert_allclose(a, 3.0 * b, rtol=0, atol=IDENTITY * scale)


def test_bad_backend_names_the_argument(models):
    with pytest.raises(
        ArgumentError, match=re.escape("backend must be one of auto, numba, numpy, got 'gpu'")
    ):
        models["hertz 72"].evaluate(0.1, 0.0, 1.0, backend="gpu")


def test_newton_root_covers_every_normal_double():
    """The kernel's P^(−5/6) (bit-pattern guess + Newton) over the whole normal range
    and below `kernel._TINY` (where the kernel falls back to pow), against an
    extended-precision power: double pow itself is off by up to 3e-14 there (−5/6 is
    rounded, and ln P reaches 700), the Newton steps by at most 16 ulp (y to ~2 ulp: the
    round-off of P y⁶ in the fixed point; then 5x that in y⁵, plus its three roundings)."""
    if np.finfo(np.longdouble).eps > 1e-18:
        pytest.skip("needs an extended-precision long double for the reference")
    P = np.concatenate([np.exp(np.linspace(-700, 700, 20001)), [1e-300, 5e-310, 0.0, -1.0]])
    y = np.empty_like(P)
    y.view(np.int64)[:] = kernel._MAGIC - P.view(np.int64) // 6
    kernel.prepare()
    kernel._inverse(P, y, P.size)
    live = P > 0
    ref = P[live].astype(np.longdouble) ** (np.longdouble(-5) / np.longdouble(6))
    err = np.abs(y[live].astype(np.longdouble) / ref - 1)
    assert float(np.max(err[P[live] >= kernel._TINY])) <= 16 * np.finfo(float).eps
    assert float(np.max(err)) <= 1e-13  # pow where P < _TINY: its exponent's rounding x ln P
    assert np.all(y[~live] == 0.0)


def test_atan_matches_the_library_to_round_off():
    rng = np.random.default_rng(0)
    y = np.abs(rng.normal(size=5000)) * np.exp(rng.uniform(-30, 30, 5000))
    x = np.abs(rng.normal(size=5000)) * np.exp(rng.uniform(-30, 30, 5000))
    y[:3], x[:3] = (0.0, 1.0, 2.0), (1.0, 0.0, 2.0)
    kernel.prepare()
    got = np.array([kernel._atan_ratio(a, b) for a, b in zip(y, x, strict=True)])
    np.testing.assert_allclose(got, np.arctan2(y, x), rtol=4e-16, atol=0)


def test_short_jobs_do_not_import_numba():
    """numba's import (~1 s) stays off short commands: the model and the exact
    integrals at their default backend below the thresholds never load it."""
    code = (
        "import sys\n"
        "from fepost.friction.build import build_model\n"
        "from fepost.friction.law import FrictionLaw\n"
        "from fepost.friction.reference_maps import ellipse_quad\n"
        "m = build_model(ellipse_quad('hertz', 1.5), FrictionLaw(f=0.3), order=(4, 8))\n"
        "m([0.1] * 5000, 0.0, 1.0)\n"
        "assert 'numba' not in sys.modules, 'numba was imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=300)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_outputs_into_given_arrays(models, backend):
    """``out=``: a simulation loop reuses its arrays; the numbers are those of a fresh call,
    bit for bit, also when the outputs are the inputs themselves."""
    model = models["anisotropic"]
    vx, vy, wz = (a.reshape(40, 50) for a in random_kinematics(2000, seed=8))
    ref = model.evaluate(vx, vy, wz, backend=backend)
    out = tuple(np.full((40, 50), np.nan) for _ in range(3))
    got = model.evaluate(vx, vy, wz, backend=backend, out=out)
    assert all(g is o for g, o in zip(got, out, strict=True))
    for a, b in zip(got, ref, strict=True):
        np.testing.assert_array_equal(a, b)
    same = (vx.copy(), vy.copy(), wz.copy())
    got = model.evaluate(*same, backend=backend, out=same)
    for a, b in zip(got, ref, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    ("out", "message"),
    [
        ((np.empty(5),) * 2, "out must be three arrays (F_x, F_y, M_z)"),
        (
            (np.empty(5), np.empty(4), np.empty(5)),
            "out[1] must be a writeable C-contiguous float64 array of shape (5,), got float64 (4,)",
        ),
        (
            (np.empty(5), np.empty(5), np.empty(5, np.float32)),
            "out[2] must be a writeable C-contiguous float64 array of shape (5,), got float32 (5,)",
        ),
        (
            (np.empty(10)[::2], np.empty(5), np.empty(5)),
            "out[0] must be a writeable C-contiguous float64 array of shape (5,), got float64 (5,)",
        ),
        (
            (np.empty(5), [0.0] * 5, np.empty(5)),
            "out[1] must be a writeable C-contiguous float64 array of shape (5,), got list",
        ),
        ((lambda a: (a, a, np.empty(5)))(np.empty(5)), "out: the three arrays must not overlap"),
    ],
)
def test_bad_out_arrays_are_named(models, out, message):
    for backend in ("numba", "numpy"):
        with pytest.raises(ArgumentError, match=re.escape(message)):
            models["hertz 72"].evaluate(np.ones(5), 0.0, 1.0, backend=backend, out=out)


def test_blocks_take_the_unrolled_sums_up_to_their_limit(models):
    """The type token that makes numba compile the sums unrolled for a shape, and the
    general loops beyond `UNROLL_MAX` numbers (whose numbers the parametrised test
    above compares with the numpy path)."""
    assert models["hertz 72"].kernel_coefficients.shape == ((0,) * 9, (0,) * 8)
    assert models["odd order (3, 5)"].kernel_coefficients.shape == ((0,) * 7, (0,) * 8)  # columns padded
    assert 17 * 12 > kernelpack.UNROLL_MAX >= 72
    assert models["tire-like 204"].kernel_coefficients.shape == ((), ())


@pytest.mark.parametrize("name", ["hertz 72", "odd order (3, 5)", "anisotropic"])
def test_general_and_unrolled_sums_give_the_same_numbers(models, name, monkeypatch):
    """Every block forced through the general loops and through the unrolled sums: the
    numpy path's numbers both ways, and each other's to round-off (the same terms,
    summed in another order)."""
    model = models[name]
    vx, vy, wz = random_kinematics(5000, seed=9)
    monkeypatch.setattr(kernelpack, "UNROLL_MAX", 1000)
    assert model.kernel_coefficients.shape[0]
    unrolled = model.evaluate(vx, vy, wz, backend="numba")
    assert_same(model, unrolled, model.evaluate(vx, vy, wz, backend="numpy"))
    monkeypatch.setattr(kernelpack, "UNROLL_MAX", 0)
    assert model.kernel_coefficients.shape == ((), ())
    general = model.evaluate(vx, vy, wz, backend="numba")
    assert_same(model, general, model.evaluate(vx, vy, wz, backend="numpy"))
    assert_same(model, general, unrolled)


@pytest.mark.parametrize(("rows", "cols"), [(1, 4), (3, 4), (9, 8), (7, 8), (17, 12)])
def test_unrolled_source_sums_as_the_basis_does(rows, cols):
    """The generated sums run as plain Python (no numba) against the basis's own einsum
    sums (`fepost.friction.basis.sums`, C's t-derivative taken there by the basis)."""
    rng = np.random.default_rng(rows * cols)
    C = rng.normal(size=(rows, cols))
    Cd = np.zeros_like(C)
    Cd[:, : cols - 1] = chebyshev.chebder(C, scl=2.0, axis=1)
    n = 64
    t = np.concatenate([[0.0, 1.0], rng.uniform(size=n - 2)])
    theta = rng.uniform(0.0, 2.0 * np.pi, n)
    c1, s1 = np.cos(theta), np.sin(theta)
    namespace: dict = {}
    exec(kernel._unrolled_source(rows, cols), namespace)  # noqa: S102 - the kernel's own source
    acc = np.full((3, n), np.nan)
    namespace["_sums_unrolled"](None, C, Cd, t, c1, s1, n, None, acc, None, None, None, None)
    for got, want in zip(acc, basis.sums(C, c1, s1, t), strict=True):  # measured ≤ 1e-15 of the largest
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-14 * max(float(np.abs(want).max()), 1.0))
