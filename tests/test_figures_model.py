"""Figures of the friction models: subscripts in Figures 4–6, the generalised curve, the error map."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib.mathtext import MathTextParser

from fepost.analysis import analyse
from fepost.errors import ArgumentError
from fepost.figures.curves import CurveData, curve_table, mathtext, plot_curve
from fepost.figures.errormap import plot_error_map
from fepost.friction.law import FrictionLaw
from fepost.friction.sphere import ErrorMap
from fepost.friction.summary import model_error_map

matplotlib.use("Agg")
MESHES = Path(__file__).resolve().parents[1] / "meshes"


@pytest.mark.parametrize(
    "text,expected",
    [
        ("M_C (N·m)", "$M_{C}$ (N·m)"),
        ("F_y (N)", "$F_{y}$ (N)"),
        ("ψ = ω_z R / v", r"ψ = $\omega_{z}$ R / v"),
        ("F_{xy} and $a_b$", "$F_{xy}$ and $a_b$"),
        ("no subscript", "no subscript"),
    ],
)
def test_mathtext(text, expected):
    assert mathtext(text) == expected


def _glyphs(math: str):
    """(character, font size, y offset) of each glyph mathtext draws for ``math``."""
    parsed = MathTextParser("path").parse(math, dpi=72)
    return [(chr(g[2]), g[1], g[4]) for g in parsed.glyphs]


def _curve(**kw):
    x = np.linspace(0, 5, 11)
    base = dict(
        name="M_C",
        title="Figure 5: friction torque M_C against υ = v/u",
        x_name="upsilon",
        x_label="υ = v / (ω_z R)",
        y_label="M_C (N·m)",
        unit="N m",
        x=x,
        closed_form=1 / np.sqrt(1 + 8 * x**2),
        exact=1 / np.sqrt(1 + 9 * x**2),
        model=1 / np.sqrt(1 + 9.1 * x**2),
    )
    base.update(kw)
    return CurveData(**base)


def test_labels_render_subscripts_not_underscores():
    fig = plot_curve(_curve())
    ax = fig.axes[0]
    fig.canvas.draw()
    ylabel, xlabel, title = ax.yaxis.label.get_text(), ax.xaxis.label.get_text(), ax.get_title()
    assert ylabel == "$M_{C}$ (N·m)"
    assert "$\\omega_{z}$" in xlabel and "$M_{C}$" in title
    for text in (ylabel, xlabel, title):
        outside = text.split("$")[::2]
        assert not any("_" in part for part in outside), text  # no literal underscore is drawn
    glyphs = _glyphs("$M_{C}$")
    assert "_" not in [g[0] for g in glyphs]
    (m, m_size, m_y), (c, c_size, c_y) = glyphs
    assert (m, c) == ("M", "C") and c_size < m_size and c_y != m_y  # C is a subscript
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "generalised model (FE map)" in legend


def test_curve_legend_lies_outside_the_axes():
    """Figures 4-6: the legend sits below the axes, so it covers no test point and no band,
    and every entry is inside the figure (none cut at the edge)."""
    fig = plot_curve(_curve())
    fig.canvas.draw()
    ax = fig.axes[0]
    assert ax.get_legend() is None and len(fig.legends) == 1
    legend = fig.legends[0].get_window_extent()
    assert not legend.overlaps(ax.get_window_extent())
    assert legend.y1 < ax.get_window_extent().y0
    width = fig.get_window_extent().width
    for t in fig.legends[0].get_texts():
        box = t.get_window_extent()
        assert 0 <= box.x0 and box.x1 <= width, t.get_text()


def test_generalised_curve_is_plotted_and_tabulated():
    c = _curve()
    fig = plot_curve(c)
    lines = {ln.get_gid(): ln for ln in fig.axes[0].get_lines() if ln.get_gid()}
    np.testing.assert_array_equal(lines["model"].get_ydata(), c.model)
    _, rows = curve_table([c])
    np.testing.assert_array_equal([r[4] for r in rows if r[2] == "model"], c.model)
    with pytest.raises(ArgumentError, match="model has 3 values, x has 11"):
        _curve(model=np.ones(3))


def _error_map():
    beta, t = np.linspace(0, 180, 5), np.linspace(0, 1, 7)
    b, tt = np.meshgrid(beta, t, indexing="ij")
    paper = 0.2 * np.sin(np.pi * tt) + 0.01
    model = 0.01 * np.sin(np.pi * tt) * (1 + b / 180)
    return ErrorMap(
        beta,
        t,
        {"paper": paper, "model": model},
        {"paper": 1.2 * paper, "model": 0.5 * model},
        100.0,
        5.0,
        0.1,
    )


def test_error_map_figure_shows_the_data():
    em = _error_map()
    fig = plot_error_map(em)
    axes = {ax.get_gid(): ax for ax in fig.axes if ax.get_gid()}
    assert set(axes) == {"force:paper", "force:model", "torque:paper", "torque:model"}
    for gid, ax in axes.items():
        q, name = gid.split(":")
        mesh = ax.collections[0]
        np.testing.assert_allclose(
            np.asarray(mesh.get_array()).reshape(7, 5), np.clip(getattr(em, q)[name], 1e-3, None).T
        )
        assert f"{em.worst(name)[q]:.3f}" in ax.get_title()
        assert "_" not in "".join(ax.get_title().split("$")[::2])
    assert axes["force:paper"].get_yticklabels()[-1].get_text() == "∞"
    # the 3 % contour is drawn where a panel exceeds it, and only there
    assert len(axes["force:paper"].collections) > 1 and len(axes["force:model"].collections) == 1


def test_error_map_rejects_bad_input():
    with pytest.raises(ArgumentError, match="data must be an ErrorMap"):
        plot_error_map({"force": 1})
    with pytest.raises(ArgumentError, match="names must be models"):
        plot_error_map(_error_map(), names=("base",))
    with pytest.raises(ArgumentError, match="must have shape"):
        ErrorMap(np.zeros(2), np.zeros(3), {"a": np.zeros((3, 2))}, {"a": np.zeros((3, 2))}, 1.0, 1.0, 1.0)


def test_error_map_of_the_calculix_sample():
    an = analyse(MESHES / "static.vtu")
    law = FrictionLaw(f=an.coefficients.f)
    em = model_error_map(an.static_map, an.coefficients, law, model=an.model_summary.static, n_beta=7, n_t=25)
    assert set(em.names) == {"paper", "base", "model"}
    assert em.worst("paper")["force"] > 0.10 and em.worst("paper")["torque"] > 0.15
    assert em.worst("model")["force"] <= 0.03 and em.worst("model")["torque"] <= 0.03
    d = em.to_dict()
    assert d["eps"][-1] is None and d["eps"][0] == 0.0  # ε = ∞ at pure sliding
