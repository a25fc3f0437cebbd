"""The outlier rule on toy models with known answers: glitches found, real effects kept."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from fepost.diagnose.fitting import fit
from fepost.diagnose.models import Candidate, Parameter
from fepost.diagnose.noise import Noise
from fepost.diagnose.robust import MAX_OUTLIER_FRACTION, outlier_threshold, robust_pass

N = 200
X = np.linspace(-1.0, 1.0, N)
BASE = np.column_stack([np.sign(X) * 0.9 + 0.1 * X, np.cos(3 * X), 0.5 * X])
PATTERN = np.column_stack([X**2 - 1 / 3, np.sin(2 * X), np.abs(X) - 0.5])
SIGMA = np.array([0.02, 0.05, 0.01])
F = Parameter("f", "1", 1.0, 0.01, 10.0, 1.0)
C = Parameter("c", "1", 0.0, -5.0, 5.0, 0.1, 0.0)
CANDS = {
    "none": Candidate("none", (), lambda p: BASE, (), "toy"),
    "friction_level": Candidate("friction_level", (F,), lambda p: p[0] * BASE, ("none",), "toy"),
    "ext": Candidate(
        "ext", (F, C), lambda p: p[0] * (BASE + p[1] * PATTERN), ("none", "friction_level"), "toy"
    ),
}
G = np.abs(BASE)


def _data(seed, c=0.0, glitches=()):
    rng = np.random.default_rng(seed)
    y = BASE + c * PATTERN + rng.normal(size=BASE.shape) * SIGMA
    for i, factor in glitches:
        y[i] *= factor
    return y


def test_threshold_is_the_bonferroni_normal_quantile():
    assert outlier_threshold(400) == pytest.approx(stats.norm.isf(0.05 / (2 * 1200)), rel=1e-12)
    assert outlier_threshold(400) == pytest.approx(4.10, abs=0.01)
    assert outlier_threshold(20) < outlier_threshold(400) < outlier_threshold(5000)


def test_glitches_are_flagged_exactly_and_a_real_effect_is_not():
    glitches = [(17, -1.0), (60, 2.5), (133, -1.0), (170, 2.5)]
    y = _data(1, c=0.3, glitches=glitches)  # a strong effect that 'none' cannot explain
    rob = robust_pass(CANDS, y, G)
    assert rob.outliers.tolist() == [17, 60, 133, 170]
    assert rob.reference == "ext"
    # even the candidates without the effect do not take its smooth misfit for glitches
    rob2 = robust_pass({k: CANDS[k] for k in ("none", "friction_level")}, y, G)
    assert rob2.outliers.tolist() == [17, 60, 133, 170]


def test_too_many_bad_rows_are_structure_not_glitches():
    y = _data(2, glitches=[(i, 2.5) for i in range(0, N, 7)])  # 15 % of the rows
    rob = robust_pass(CANDS, y, G)
    assert rob.beyond.size > MAX_OUTLIER_FRACTION * N
    assert rob.outliers.size == 0 and rob.widespread
    assert rob.to_dict()["widespread"] is True


def test_clean_data_rarely_lose_a_row():
    """The rule's family-wise level is 5 %: over 40 clean data sets at most a few flag any row."""
    flagged = sum(robust_pass(CANDS, _data(100 + s, c=0.1), G).outliers.size > 0 for s in range(40))
    assert flagged <= 5


def test_robust_fit_is_not_pulled_by_glitches_while_least_squares_is():
    glitches = [(i, 2.5) for i in range(0, N, 25)]  # 8 rows, 4 %
    y = _data(3, c=0.2, glitches=glitches)
    clean = fit(CANDS["ext"], _data(3, c=0.2), noise=Noise.start("combined", G))
    huber = fit(CANDS["ext"], y, noise=Noise.start("combined", G), loss="huber", intervals=False)
    plain = fit(CANDS["ext"], y, noise=Noise.start("combined", G))
    err_h = np.abs(huber.values - clean.values) / clean.stderr
    err_p = np.abs(plain.values - clean.values) / clean.stderr
    # bounded influence: each spike pulls by at most k noise SDs (the final fit then drops them)
    assert np.all(err_h < 2.0) and np.max(err_p) > 10.0 * np.max(err_h), (err_h, err_p)


def test_an_unidentifiable_joint_model_is_refused_quietly():
    """A parameter the data do not see: the pair search records why, no warning escapes."""
    import warnings

    from fepost.diagnose.pairs import _quiet_fit

    twin = Candidate(
        "twin", (F, C, Parameter("c2", "1", 0.0, -5.0, 5.0, 0.1, 0.0)),
        lambda p: p[0] * (BASE + p[1] * PATTERN) + 0.0 * p[2], ("none",), "toy",
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ft, trouble = _quiet_fit(twin, _data(4, c=0.1))
    assert trouble and "not identifiable" in trouble[0]
    assert np.all(np.isinf(ft.stderr))
