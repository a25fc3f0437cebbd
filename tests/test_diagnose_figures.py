"""Diagnose figures at the data level: the plotted group means are the tested ones."""

from __future__ import annotations

import numpy as np
import pytest

from fepost.diagnose import diagnose
from fepost.diagnose.figures import along_sliding, plot_residuals
from fepost.diagnose.measured import CHANNELS
from fepost.diagnose.residuals import binned_means
from fepost.diagnose.synthetic import analytic_map, synthesize


@pytest.fixture(scope="module")
def diag():
    pmap = analytic_map("hertz", 0.1, 3e5)
    syn = synthesize(pmap, "none", {}, n=160, seed=5)
    return diagnose(pmap, syn.data, friction=0.3)


def test_group_means_are_the_means_per_spin_sign(diag):
    """Spin sign has two values: the groups are exactly the points of each sign."""
    x = np.asarray(diag.variables["spin sign"], float)
    r = np.random.default_rng(1).normal(size=x.size)
    xs, ms, hw = binned_means(r, "spin sign", x)
    signs = np.unique(x)
    np.testing.assert_allclose(xs, signs)
    np.testing.assert_allclose(ms, [r[x == s].mean() for s in signs])
    n = np.array([(x == s).sum() for s in signs])
    assert np.all(hw > 0) and np.all(hw < 3 * np.array([r[x == s].std() for s in signs]) / np.sqrt(n))
    assert binned_means(r, "roll", np.zeros(x.size)) is None  # a variable that does not vary


def test_residual_figure_draws_the_tested_group_means(diag):
    fig = plot_residuals(diag)
    meas = diag.data.forces
    rb = 100 * (meas - diag.predictions["before"]) / diag.scales
    drawn = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == "group-means"]
    expected = []
    rows = [rb[:, c] for c in range(len(CHANNELS))] + [along_sliding(diag.data, rb)]
    for r in rows:
        ok = np.isfinite(r)
        for name, x in diag.variables.items():
            g = binned_means(r[ok], name, np.asarray(x, float)[ok])
            if g is not None:
                expected.append(g)
    assert len(drawn) == len(expected) > 0
    got = {(tuple(np.round(ln.get_xdata(), 12)), tuple(np.round(ln.get_ydata(), 12))) for ln in drawn}
    want = {(tuple(np.round(g[0], 12)), tuple(np.round(g[1], 12))) for g in expected}
    assert got == want
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any(t.startswith("ANOVA p = ") for t in texts)


def test_direction_groups_sit_at_their_sector_centres():
    deg = np.array([-179.0, 179.0, -170.0, 1.0, -2.0, 44.0, 46.0, 91.0, 89.0])
    r = np.array([1.0, 3.0, 2.0, 0.0, 2.0, 5.0, 7.0, 1.0, 1.0])
    xs, ms, _ = binned_means(r, "sliding direction (deg)", deg)
    np.testing.assert_allclose(xs, [0.0, 45.0, 90.0, 180.0])  # sectors of 45°, ±180° wraps to 180
    np.testing.assert_allclose(ms, [1.0, 6.0, 1.0, 2.0])


def test_along_sliding_residual_is_positive_for_too_little_friction(diag):
    """Measured forces 20 % below the simulation's: the residual along v is +0.2 |F_sim|."""
    pred = diag.predictions["before"]
    res = 0.8 * pred - pred
    along = along_sliding(diag.data, res)
    v = np.hypot(diag.data.vx, diag.data.vy)
    sliding = v > 0
    opposing = -(pred[:, 0] * diag.data.vx + pred[:, 1] * diag.data.vy)[sliding] / v[sliding]
    assert np.all(opposing > 0)  # friction opposes sliding
    np.testing.assert_allclose(along[sliding], 0.2 * opposing, rtol=1e-12)
    assert np.all(np.isnan(along[~sliding]))
