"""Diagnose figures say what they claim: the tested group means, the outliers, legible layout."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from fepost.diagnose import diagnose
from fepost.diagnose.figures import along_sliding, plot_predicted_vs_measured, plot_residuals, run_order
from fepost.diagnose.measured import CHANNELS
from fepost.diagnose.residuals import binned_means
from fepost.diagnose.synthetic import analytic_map, synthesize


@pytest.fixture(scope="module")
def diag():
    pmap = analytic_map("hertz", 0.1, 3e5)
    syn = synthesize(pmap, "none", {}, n=160, seed=5)
    return diagnose(pmap, syn.data, friction=0.3)


@pytest.fixture(scope="module")
def diag_outliers():
    """A heavy patch (N ≈ 170 kN) at three loads, a time column (7 panel columns), three gross
    errors and a pressure effect: long tick labels in narrow panels."""
    pmap = analytic_map("hertz", 0.2, 2e6)
    syn = synthesize(
        pmap, "pressure_dependent_friction", {"c_p": 0.3}, n=200, seed=8, outliers=3,
        loads=(0.7, 1.0, 1.3), time_column=True,
    )  # fmt: skip
    d = diagnose(pmap, syn.data, friction=0.3)
    assert list(d.outliers) == list(syn.outliers)
    return d


def _drawn_figure(fig):
    FigureCanvasAgg(fig).draw()
    return fig.canvas.get_renderer()


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


@pytest.mark.parametrize("which", ["diag", "diag_outliers"])
def test_residual_figure_draws_the_tested_group_means(which, request):
    """Every panel's black line is the group means of the kept rows (outliers left out)."""
    d = request.getfixturevalue(which)
    fig = plot_residuals(d)
    meas = d.data.forces
    rb = 100 * (meas - d.predictions["before"]) / d.scales
    keep = np.ones(len(d.data), bool)
    keep[list(d.outliers)] = False
    drawn = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == "group-means"]
    label, order = run_order(d)
    columns = {**{k: np.asarray(v, float) for k, v in d.variables.items()}, "run order": order}
    expected = []
    for r in [rb[:, c] for c in range(len(CHANNELS))] + [along_sliding(d.data, rb)]:
        ok = np.isfinite(r) & keep
        for name, x in columns.items():
            g = binned_means(r[ok], name, x[ok])
            if g is not None:
                scale = 1e-3 if name.startswith("load N") else 1.0  # drawn in kN
                expected.append((g[0] * scale, g[1]))
    assert len(drawn) == len(expected) > 0
    got = {(tuple(np.round(ln.get_xdata(), 9)), tuple(np.round(ln.get_ydata(), 9))) for ln in drawn}
    want = {(tuple(np.round(x, 9)), tuple(np.round(y, 9))) for x, y in expected}
    assert got == want
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any(t.startswith("ANOVA p = ") for t in texts)
    drift = [t for t in texts if t.startswith("drift test p = ")]
    assert drift
    # the figure shows the Holm-adjusted p-value, as the summary and the JSON do
    key = "trend_time" if d.data.time is not None else "trend_file"
    shown = float(drift[0].split("=")[1].split()[0])
    assert shown == pytest.approx(d.lack_of_fit["tests"][key]["p_holm"], rel=0.06)  # shown with 2 digits


def test_large_forces_are_drawn_in_kilonewtons():
    from fepost.diagnose.figures import display_units

    assert display_units(np.array([-60000.0, 40000.0]), "N") == (1e3, "kN")
    assert display_units(np.array([-4999.0, 30.0]), "N·m") == (1.0, "N·m")


def test_outliers_are_drawn_in_every_panel(diag_outliers):
    d = diag_outliers
    fig = plot_residuals(d)
    rb = 100 * (d.data.forces - d.predictions["before"]) / d.scales
    along = along_sliding(d.data, rb)[list(d.outliers)]
    ncol = len(fig.axes) // 4
    for k, ax in enumerate(fig.axes):
        marks = [c for c in ax.collections if (c.get_gid() or "").startswith("outliers")]
        count = sum(len(c.get_offsets()) for c in marks)
        # the along-sliding row (the last) has no value at pure spin
        assert count == (np.isfinite(along).sum() if k >= 3 * ncol else len(d.outliers)), count
    axes = plot_predicted_vs_measured(d)
    for ax in axes:
        marks = [c for c in ax.collections if c.get_gid() == "outliers"]
        assert sum(len(c.get_offsets()) for c in marks) == len(d.outliers)


def _overlap(a, b, pad=0.5) -> bool:
    return a.x0 < b.x1 - pad and b.x0 < a.x1 - pad and a.y0 < b.y1 - pad and b.y0 < a.y1 - pad


@pytest.mark.parametrize("which", ["diag", "diag_outliers"])
def test_tick_labels_never_collide(which, request):
    fig = plot_residuals(request.getfixturevalue(which))
    renderer = _drawn_figure(fig)
    checked = 0
    for ax in fig.axes:
        for ticks in (ax.get_xticklabels(), ax.get_yticklabels()):
            boxes = [t.get_window_extent(renderer) for t in ticks if t.get_visible() and t.get_text()]
            checked += len(boxes)
            for a, b in itertools.combinations(boxes, 2):
                assert not _overlap(a, b), f"{ax.get_xlabel()!r}: tick labels overlap"
    assert checked > 50


@pytest.mark.parametrize("which", ["diag", "diag_outliers"])
def test_legend_covers_no_text_and_no_panel(which, request):
    fig = plot_residuals(request.getfixturevalue(which))
    renderer = _drawn_figure(fig)
    legend = fig.legends[0].get_window_extent(renderer)
    texts = [t for ax in fig.axes for t in ax.texts] + [ax.title for ax in fig.axes]
    texts += [ax.xaxis.label for ax in fig.axes] + [ax.yaxis.label for ax in fig.axes]
    texts += [t for ax in fig.axes for t in ax.get_xticklabels() + ax.get_yticklabels()]
    texts = [t for t in texts if t.get_visible() and t.get_text()]
    assert any(t.get_text().startswith("ANOVA p") for t in texts)
    for t in texts:
        assert not _overlap(legend, t.get_window_extent(renderer)), f"legend over {t.get_text()!r}"
    for ax in fig.axes:
        assert not _overlap(legend, ax.get_window_extent(renderer)), "legend over a panel"
    # and the p-value boxes stay inside their own panel
    for ax in fig.axes:
        for t in ax.texts:
            box = t.get_window_extent(renderer)
            frame = ax.get_window_extent(renderer)
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1


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
