"""The fitter and the model-choice rule, certified on toy models with known answers.

Toy candidates share the structure of the real ones (``none`` ⊂ ``friction_level``
⊂ extensions) but predict from fixed patterns, so thousands of fits take seconds.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from fepost.diagnose.causes import Candidate, Parameter
from fepost.diagnose.fitting import fit, log_likelihood
from fepost.diagnose.selection import (
    ALPHA,
    crossvalidate,
    design_notes,
    folds,
    indistinguishable,
    score_candidates,
)

N = 150
X = np.linspace(-1.0, 1.0, N)
BASE = np.column_stack([np.sign(X) * 0.9 + 0.1 * X, np.cos(3 * X), 0.5 * X])
PATTERN = np.column_stack([X**2 - 1 / 3, np.sin(2 * X), np.abs(X) - 0.5])
SIGMA = np.array([0.02, 0.05, 0.01])  # a different noise level per channel

F = Parameter("f", "1", 1.0, 0.01, 10.0, 1.0)
C = Parameter("c", "1", 0.0, -5.0, 5.0, 0.1, 0.0)


def toy_candidates(second=None) -> dict[str, Candidate]:
    cands = {
        "none": Candidate("none", (), lambda p: BASE, (), "toy"),
        "friction_level": Candidate("friction_level", (F,), lambda p: p[0] * BASE, ("none",), "toy"),
        "ext": Candidate(
            "ext",
            (F, C),
            lambda p: p[0] * (BASE + p[1] * PATTERN),
            ("none", "friction_level"),
            "toy",
        ),
    }
    if second is not None:
        cands["ext2"] = Candidate(
            "ext2",
            (F, C),
            lambda p: p[0] * (BASE + p[1] * second),
            ("none", "friction_level"),
            "toy",
        )
    return cands


def data(seed, f=1.0, c=0.0):
    rng = np.random.default_rng(seed)
    return f * (BASE + c * PATTERN) + rng.normal(size=BASE.shape) * SIGMA


def choose(Y, cands, seed=0):
    fits = {k: fit(c, Y) for k, c in cands.items()}
    parts = folds(N, 5, seed)
    cvs = {k: crossvalidate(c, Y, parts, fits[k]) for k, c in cands.items()}
    return score_candidates(cands, fits, cvs)


def test_fit_matches_weighted_least_squares_and_its_interval():
    """At the profiled optimum the fit is the weighted LS solution with σ_c² = RSS_c/n."""
    Y = data(1, f=1.2, c=0.3)
    ft = fit(toy_candidates()["ext"], Y)
    # The model is linear in (f, f·c): solve it directly at the fitted σ.
    A = np.stack([BASE, PATTERN], axis=-1)  # (n, 3, 2)
    w = 1.0 / ft.sigma
    M = (A * w[None, :, None]).reshape(-1, 2)
    y = (Y * w).ravel()
    theta, *_ = np.linalg.lstsq(M, y, rcond=None)
    np.testing.assert_allclose([ft.values[0], ft.values[0] * ft.values[1]], theta, rtol=1e-6)
    rss = np.sum((Y - ft.values[0] * (BASE + ft.values[1] * PATTERN)) ** 2, axis=0)
    np.testing.assert_allclose(ft.sigma, np.sqrt(rss / N), rtol=1e-6)
    assert ft.log_likelihood == pytest.approx(log_likelihood(rss, N), rel=1e-12)
    assert ft.k == 5 and ft.n_obs == 3 * N
    assert ft.bic == pytest.approx(-2 * ft.log_likelihood + 5 * np.log(3 * N), rel=1e-12)


def test_interval_coverage_is_95_percent():
    """Over 300 noise draws the 95 % intervals of f and c hold the truth 95 % of the time.

    Binomial SD at p = 0.95, n = 300 is 1.26 %: accept 0.91 .. 0.99 (> 3 SD).
    """
    cand = toy_candidates()["ext"]
    hits = np.zeros(2)
    runs = 300
    for seed in range(runs):
        ft = fit(cand, data(seed, f=0.8, c=0.4))
        hits += (ft.ci95[:, 0] <= [0.8, 0.4]) & ([0.8, 0.4] <= ft.ci95[:, 1])
    assert np.all((0.91 <= hits / runs) & (hits / runs <= 0.99)), hits / runs


def test_null_data_rarely_name_a_cause_while_plain_aic_would():
    """On 200 null data sets the nested rule names a cause < 5 %; AIC picks 'ext' over
    'friction_level' far more often (≈ P(χ²₁ > 2) = 16 %)."""
    cands = toy_candidates()
    named = aic_richer = 0
    runs = 200
    for seed in range(runs):
        Y = data(1000 + seed)
        scores = choose(Y, cands, seed)
        named += scores[0].name != "none"
        by = {s.name: s for s in scores}
        aic_richer += by["ext"].fit.aic < by["friction_level"].fit.aic
    assert named / runs < 0.05
    assert aic_richer / runs > 0.08


def test_effect_is_found_with_its_interval():
    scores = choose(data(5, f=1.1, c=0.05), toy_candidates())
    best = scores[0]
    assert best.name == "ext" and best.admissible
    lo, hi = best.fit.ci95[1]
    assert lo <= 0.05 <= hi
    assert best.lrt_p["friction_level"] < ALPHA
    assert best.cv.log_score > next(s for s in scores if s.name == "friction_level").cv.log_score


def test_friction_level_alone():
    scores = choose(data(6, f=1.05), toy_candidates())
    assert scores[0].name == "friction_level"
    ext = next(s for s in scores if s.name == "ext")
    assert not ext.admissible


def test_indistinguishable_siblings_are_listed():
    twin = PATTERN + 1e-4 * np.column_stack([X, X, X])  # the data cannot tell the two patterns apart
    cands = toy_candidates(second=twin)
    scores = choose(data(7, c=0.08), cands)
    assert scores[0].name in ("ext", "ext2")
    assert sorted(indistinguishable(scores, cands)) == ["ext", "ext2"]


def test_distinct_siblings_are_not_listed():
    other = np.column_stack([X**3, X * 0.0 + 0.2, np.cos(5 * X)])
    cands = toy_candidates(second=other)
    scores = choose(data(8, c=0.08), cands)
    assert scores[0].name == "ext"
    assert indistinguishable(scores, cands) == []


def test_ranking_puts_admissible_first():
    scores = choose(data(9, f=1.1, c=0.05), toy_candidates())
    adm = [s.admissible for s in scores]
    assert adm == sorted(adm, reverse=True)
    for a, b in zip(scores, scores[1:], strict=False):
        if a.admissible == b.admissible:
            assert a.bic <= b.bic


def test_chi2_level_is_bonferroni_over_ten_extensions():
    assert ALPHA == pytest.approx(0.05 / 10)
    assert stats.chi2.isf(ALPHA, 1) > 2.0  # far stricter than AIC's 2 per parameter


def test_design_notes():
    R = 0.1
    # one absolute speed per ratio, one load, one spin sign, no pure spin/sliding, two directions
    vx = np.array([0.1, 0.2, 0.0, 0.0])
    vy = np.array([0.0, 0.0, 0.1, 0.2])
    wz = np.array([2.0, 2.0, 1.0, 4.0])
    notes = " | ".join(design_notes(vx, vy, wz, R))
    assert "speed_dependent_friction cannot be told from shape effects" in notes
    assert "all points at one load" in notes
    assert "no pure-spin points" in notes and "no pure-sliding points" in notes
    assert "one spin sign only" in notes
    assert "only 2 sliding direction(s)" in notes
    from fepost.diagnose.synthetic import rig_programme

    kin = rig_programme(R, 400, seed=0, loads=(0.8, 1.0, 1.2))
    assert design_notes(kin.vx, kin.vy, kin.wz, R, kin.load_factor * 3000.0) == []
