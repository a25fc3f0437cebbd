"""The noise model: maximum likelihood checked against a direct optimiser, robust scale, selection."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize, stats

from fepost.diagnose.noise import (
    HUBER_BETA,
    HUBER_K,
    NOISE_FLOOR,
    Noise,
    fit_channel,
    select_structure,
)

N = 400


def _residuals(seed, s0, s1, n=N):
    rng = np.random.default_rng(seed)
    g = rng.uniform(0.0, 1.2, n)  # reference magnitudes, scaled units
    sd = np.sqrt(s0**2 + (s1 * g) ** 2)
    return rng.normal(size=n) * sd, g


def _nll(a, b, r, g):
    s2 = a + b * g**2
    return 0.5 * np.sum(np.log(2 * np.pi * s2) + r**2 / s2)


@pytest.mark.parametrize(
    ("structure", "s0", "s1"),
    [("constant", 0.03, 0.0), ("proportional", NOISE_FLOOR, 0.04), ("combined", 0.01, 0.03)],
)
def test_maximum_likelihood_matches_a_direct_optimiser(structure, s0, s1):
    """Fisher scoring lands where scipy's bounded minimiser of −ℓ lands."""
    r, g = _residuals(1, s0, s1)
    a, b = fit_channel(r, g, structure)
    floor2 = NOISE_FLOOR**2
    if structure == "constant":
        assert b == 0.0
        assert a == pytest.approx(np.mean(r**2), rel=1e-12)
        return
    if structure == "proportional":
        assert a == floor2
        res = optimize.minimize_scalar(lambda bb: _nll(floor2, bb, r, g), bounds=(0, 1), method="bounded",
                                       options={"xatol": 1e-14})  # fmt: skip
        assert b == pytest.approx(res.x, rel=1e-5)
        return
    res = optimize.minimize(
        lambda p: _nll(p[0], p[1], r, g), x0=[0.5 * np.mean(r**2), 0.5 * np.mean(r**2)],
        bounds=[(floor2, None), (0, None)], method="L-BFGS-B", options={"ftol": 1e-15, "gtol": 1e-12},
    )  # fmt: skip
    assert _nll(a, b, r, g) <= res.fun + 1e-9
    np.testing.assert_allclose([a, b], res.x, rtol=1e-3)
    # and the truth is recovered within sampling error
    assert np.sqrt(a) == pytest.approx(s0, rel=0.3) and np.sqrt(b) == pytest.approx(s1, rel=0.15)


def test_bounds_hold():
    r, g = _residuals(2, 0.0, 0.05)  # truly proportional: a sits on the floor
    a, b = fit_channel(r, g, "combined")
    assert a == pytest.approx(NOISE_FLOOR**2) and b > 0
    r, g = _residuals(3, 0.03, 0.0)  # truly constant: b sits on zero
    a, b = fit_channel(r, g, "combined")
    assert b == pytest.approx(0.0, abs=1e-12) and a == pytest.approx(np.mean(r**2), rel=1e-6)
    a, _ = fit_channel(np.full(10, 1e-9), np.ones(10), "constant")
    assert a == NOISE_FLOOR**2  # no channel is trusted beyond the floor


def test_huber_consistency_constant():
    """β = E[min(Z², k²)] in closed form: check it by quadrature."""
    from scipy import integrate

    psi2 = integrate.quad(lambda z: min(z * z, HUBER_K**2) * stats.norm.pdf(z), -np.inf, np.inf)[0]
    assert psi2 == pytest.approx(HUBER_BETA, rel=1e-8)
    assert HUBER_BETA == pytest.approx(0.7102, abs=1e-4)


@pytest.mark.parametrize("structure", ["constant", "proportional", "combined"])
def test_robust_scale_is_unbiased_at_the_normal_and_ignores_gross_errors(structure):
    s0, s1 = {"constant": (0.03, 0.0), "proportional": (NOISE_FLOOR, 0.04), "combined": (0.01, 0.03)}[
        structure
    ]
    a_clean, b_clean = [], []
    for seed in range(40):
        r, g = _residuals(100 + seed, s0, s1)
        a, b = fit_channel(r, g, structure, robust=True)
        a_clean.append(a)
        b_clean.append(b)
    # averaged over 40 data sets the robust variance matches the true one at the mean g² (within 3 %)
    g2 = np.mean(_residuals(0, s0, s1)[1] ** 2)
    true = s0**2 + s1**2 * g2
    got = np.mean(a_clean) + np.mean(b_clean) * g2
    assert got == pytest.approx(true, rel=0.03)
    r, g = _residuals(7, s0, s1)
    bad = r.copy()
    bad[:20] = 50.0 * np.sqrt(true)  # 5 % gross errors of 50 SDs
    a_r, b_r = fit_channel(bad, g, structure, robust=True)
    a_g, b_g = fit_channel(bad, g, structure)
    robust_var = a_r + b_r * g2
    plain_var = a_g + b_g * g2
    assert robust_var < 1.5 * true < plain_var / 10


@pytest.mark.parametrize(
    ("truth", "s0", "s1"),
    [("constant", 0.03, 0.0), ("proportional", 0.0, 0.04), ("combined", 0.015, 0.03)],
)
def test_selection_finds_the_structure(truth, s0, s1):
    picks = [select_structure(*_residuals(200 + seed, s0, s1))[0] for seed in range(10)]
    assert picks.count(truth) >= 9, picks


def test_noise_object():
    g = np.array([[0.0, 1.0, 2.0], [1.0, 1.0, 1.0]])
    nz = Noise(
        ("constant", "proportional", "combined"), np.array([0.01, 1e-6, 0.02]), np.array([0, 0.04, 0.5]), g
    )
    np.testing.assert_allclose(nz.variance(), [[0.01, 1e-6 + 0.04, 0.02 + 2.0], [0.01, 1e-6 + 0.04, 0.52]])
    assert nz.n_params == 4 and nz.fitted
    assert not Noise.start("combined", g).fitted
    with pytest.raises(ValueError):
        nz.g[0, 0] = 1.0
    d = nz.to_dict()
    assert d["Fy"]["model"] == "proportional" and d["Mz"]["s1"] == pytest.approx(np.sqrt(0.5))
