"""Figures: image regression for the pyvista renders, data-level checks for matplotlib.

The baselines live in ``tests/image_cache/`` (pytest-pyvista's ``image_cache_dir``
in pyproject.toml; regenerate with
``pytest tests/test_figures.py --reset_image_cache`` after a deliberate change
and look at the new images before committing them).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import pyvista  # noqa: E402

from fepost.analysis import analyse  # noqa: E402
from fepost.errors import ArgumentError  # noqa: E402
from fepost.field import ContactField  # noqa: E402
from fepost.figures import (  # noqa: E402
    CurveData,
    curve_table,
    diameter_sections,
    plot_curve,
    plot_patch_plan,
    plot_sections,
    pressure_surface,
)
from fepost.figures.render import default_height_scale, patch_mesh  # noqa: E402
from fepost.figures.section import fe_pressure_at  # noqa: E402
from fepost.patch import build_patch  # noqa: E402
from fepost.synthetic import disc_mesh, write_map  # noqa: E402

pyvista.OFF_SCREEN = True
RADIUS = 0.15  # m
PEAK = 6e5  # Pa


@pytest.fixture(scope="module")
def maps(tmp_path_factory):
    d = tmp_path_factory.mktemp("maps")
    s = write_map(d / "static.vtu", "tire", radius=RADIUS, peak=PEAK, n_rings=24)
    r = write_map(d / "rolling.vtu", "tire", radius=RADIUS, peak=PEAK, k_x=0.13, n_rings=24)
    return analyse(s, r)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


# ---------------------------------------------------------------- Figures 1 and 2
def test_figure1_static(maps, verify_image_cache):
    hs = default_height_scale(maps.static_patch, maps.rolling_patch)
    pl = pressure_surface(maps.static_patch, title="Figure 1: static contact pressure", height_scale=hs)
    assert tuple(pl.window_size) == (1200, 900)
    pl.show()


def test_figure2_rolling(maps, verify_image_cache):
    hs = default_height_scale(maps.static_patch, maps.rolling_patch)
    pl = pressure_surface(maps.rolling_patch, title="Figure 2: rolling contact pressure", height_scale=hs)
    pl.show()


def test_figure_elliptic_patch(tmp_path, verify_image_cache):
    """A visibly elongated patch: the orange ellipse departs from the r_max circle."""
    a = analyse(write_map(tmp_path / "e.vtu", "hertz", radius=0.1, aspect=2.0, n_rings=20))
    pl = pressure_surface(a.static_patch, title="elliptic patch")
    pl.show()


def test_figure1_calculix_sample(verify_image_cache):
    """Figure 1 from real solver output (the committed CalculiX static case)."""
    from pathlib import Path

    mesh = Path(__file__).resolve().parents[1] / "meshes" / "static.vtu"
    a = analyse(mesh)
    pl = pressure_surface(a.static_patch, title="Figure 1: CalculiX static sample")
    pl.show()


def test_patch_mesh_carries_the_fe_values_exactly(maps):
    p = maps.static_patch
    mesh = patch_mesh(p, inflation_pressure=2e5, height_scale=10.0)
    np.testing.assert_array_equal(mesh.point_data["pressure_kPa"], p.values / 1e3)
    np.testing.assert_array_equal(mesh.point_data["sigma_over_P"], p.values / 2e5)
    np.testing.assert_allclose(mesh.points[:, :2], p.xy, rtol=0, atol=1e-12)
    np.testing.assert_allclose(mesh.points[:, 2], 10.0 * p.node_values() / 2e5, rtol=1e-12)
    assert mesh.n_cells == len(p.triangles)


def test_render_rejects_bad_pressure(maps):
    with pytest.raises(
        ArgumentError, match=r"^inflation_pressure must be a positive pressure in Pa, got -1$"
    ):
        pressure_surface(maps.static_patch, inflation_pressure=-1)


# ---------------------------------------------------------------- Figure 3
def _linear_patch():
    """σ = p0 (2 + x/R) on a triangulated unit disc scaled to R: linear, so the FE
    interpolation along any line is exact."""
    pts, tri = disc_mesh(n_rings=16)
    xyz = np.column_stack([pts * RADIUS, np.zeros(len(pts))])
    values = 1e5 * (2.0 + xyz[:, 0] / RADIUS)
    fld = ContactField("linear", xyz, tri, values, "point", "CPRESS")
    return build_patch(fld)


def test_sections_interpolate_the_fe_field_exactly_for_a_linear_field():
    p = _linear_patch()
    ox = p.frame.origin[0]  # patch x = global x − ox
    sec = diameter_sections(p, inflation_pressure=1e5, n=201, half_length=1.2 * RADIUS)
    s = sec.s
    inside = np.abs(s + ox) < 0.95 * RADIUS
    np.testing.assert_allclose(sec.static_x[inside], 2.0 + (s[inside] + ox) / RADIUS, rtol=1e-9)
    inside_y = np.hypot(ox, s) < 0.95 * RADIUS
    np.testing.assert_allclose(sec.static_y[inside_y], np.full(inside_y.sum(), 2.0 + ox / RADIUS), rtol=1e-9)
    outside = np.hypot(s, 0) > 1.01 * RADIUS + abs(ox)
    assert np.all(sec.static_x[outside] == 0.0)
    assert sec.rolling_x is None


def test_fe_pressure_at_nodes_equals_nodal_values(maps):
    p = maps.static_patch
    idx = np.arange(0, len(p.xy), 37)
    np.testing.assert_allclose(
        fe_pressure_at(p, p.xy[idx, 0], p.xy[idx, 1]), p.values[idx], rtol=1e-9, atol=1e-6
    )


def test_figure3_plots_the_computed_sections(maps):
    sec = diameter_sections(maps.static_patch, maps.rolling_patch)
    fig = plot_sections(sec)
    lines = {ln.get_gid(): ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid()}
    for key in ("static_x", "static_y", "rolling_x", "rolling_y"):
        np.testing.assert_array_equal(lines[key].get_xdata(), sec.s)
        np.testing.assert_array_equal(lines[key].get_ydata(), getattr(sec, key))
    # The rolling map is shifted forward: more pressure ahead (x > 0) than behind.
    front = sec.s > 0
    assert sec.rolling_x[front].sum() > sec.rolling_x[~front].sum()
    np.testing.assert_allclose(sec.rolling_y, sec.static_y, atol=1e-9 + 0.02 * sec.static_y.max())


# ---------------------------------------------------------------- patch plan
def test_patch_plan_draws_patch_circles_and_verdict(maps):
    p = maps.static_patch
    fig = plot_patch_plan(p)
    ax = fig.axes[0]
    tpc = [c for c in ax.collections if c.get_gid() == "pressure"][0]
    np.testing.assert_array_equal(np.asarray(tpc.get_array()), p.values / 1e3)
    lines = {ln.get_gid(): ln for ln in ax.get_lines() if ln.get_gid()}
    r = np.hypot(lines["r_max"].get_xdata(), lines["r_max"].get_ydata())
    np.testing.assert_allclose(r, p.r_max, rtol=1e-12)
    ce = np.array(p.ellipse_centre)
    r = np.hypot(lines["r_equiv"].get_xdata() - ce[0], lines["r_equiv"].get_ydata() - ce[1])
    np.testing.assert_allclose(r, p.r_equiv, rtol=1e-12)
    assert ax.get_title() == (
        f"Loaded region — circular: aspect {p.aspect:.3f}, "
        rf"$r_{{\max}}/r_{{\mathrm{{equiv}}}}$ {p.r_max / p.r_equiv:.3f}"
    )


def test_patch_plan_title_says_not_circular(tmp_path):
    a = analyse(write_map(tmp_path / "e.vtu", "hertz", radius=0.1, aspect=2.0, n_rings=16))
    fig = plot_patch_plan(a.static_patch)
    assert fig.axes[0].get_title().startswith("Loaded region — NOT circular: aspect 2.0")
    e = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "ellipse"][0]
    assert np.ptp(e.get_xdata()) == pytest.approx(2 * a.static_patch.ellipse_axes[0], rel=1e-3)


# ---------------------------------------------------------------- Figures 4-6
def _curve(**kw):
    x = np.linspace(0, 5, 11)
    base = dict(
        name="M_C",
        title="t",
        x_name="upsilon",
        x_label="υ",
        y_label="M_C (N·m)",
        unit="N m",
        x=x,
        closed_form=1 / np.sqrt(1 + 8 * x**2),
        exact=1 / np.sqrt(1 + 9 * x**2),
        fit=1 / np.sqrt(1 + 8.2 * x**2),
        band_lo=np.full(11, -0.1),
        band_hi=np.full(11, 1.1),
        test_x=np.linspace(0, 5, 7),
        test_y=np.arange(7.0),
    )
    base.update(kw)
    return CurveData(**base)


def test_plot_curve_plots_the_given_arrays():
    c = _curve()
    fig = plot_curve(c)
    ax = fig.axes[0]
    lines = {ln.get_gid(): ln for ln in ax.get_lines() if ln.get_gid()}
    for key in ("exact", "closed_form", "fit"):
        np.testing.assert_array_equal(lines[key].get_xdata(), c.x)
        np.testing.assert_array_equal(lines[key].get_ydata(), getattr(c, key))
    np.testing.assert_array_equal(lines["test"].get_xdata(), c.test_x)
    np.testing.assert_array_equal(lines["test"].get_ydata(), c.test_y)
    band = [col for col in ax.collections if col.get_gid() == "band"][0]
    verts = band.get_paths()[0].vertices
    assert verts[:, 1].min() == pytest.approx(-0.1) and verts[:, 1].max() == pytest.approx(1.1)


def test_plot_curve_without_optional_series():
    c = _curve(exact=None, fit=None, band_lo=None, band_hi=None, test_x=None, test_y=None)
    fig = plot_curve(c)
    assert [ln.get_gid() for ln in fig.axes[0].get_lines() if ln.get_gid()] == ["closed_form"]


def test_curve_data_checks_lengths_and_is_read_only():
    with pytest.raises(ArgumentError, match=r"^M_C: exact has 3 values, x has 11$"):
        _curve(exact=np.ones(3))
    with pytest.raises(ArgumentError, match=r"^M_C: give both test_x and test_y or neither$"):
        _curve(test_y=None)
    c = _curve()
    with pytest.raises(ValueError):
        c.x[0] = 1.0


def test_curve_table_long_form():
    c = _curve()
    header, rows = curve_table([c])
    assert header == ["figure", "x_name", "series", "x", "value", "unit"]
    assert len(rows) == 5 * 11 + 7
    fit = [r for r in rows if r[2] == "fit"]
    np.testing.assert_array_equal([r[4] for r in fit], c.fit)


# ---------------------------------------------------------------- what the figures claim
HEAVY = Path(__file__).resolve().parents[1] / "meshes" / "heavy.e"


@pytest.fixture(scope="module")
def heavy():
    """The heavy CalculiX sample: lateral peaks at 13 × P* (the case that clipped Figure 3)."""
    if not HEAVY.is_file():
        pytest.skip(f"{HEAVY} not shipped")
    return analyse(HEAVY)


def _projected(points, renderer):
    out = []
    for p in points:
        renderer.SetWorldPoint(*map(float, p), 1.0)
        renderer.WorldToDisplay()
        out.append(renderer.GetDisplayPoint()[:2])
    return np.array(out)


def _inside(pts, box):
    return (pts[:, 0] > box[0]) & (pts[:, 0] < box[1]) & (pts[:, 1] > box[2]) & (pts[:, 1] < box[3])


@pytest.mark.parametrize("case", ["heavy", "maps", "aircraft"])
def test_figure1_texts_legend_and_colour_bar_are_legible(case, request):
    """No two labels overlap, the legend and colour bar hold no data and touch no label,
    tick labels are not tiny, the height axis has a title, the colour bar ticks are round."""
    from fepost.figures.render import TICK_FONT, boxes_overlap, layout, text_box, viewport_box

    a = request.getfixturevalue(case)
    patch = a.static_patch
    pl = pressure_surface(patch, title="Figure 1: static contact pressure")
    try:
        ren = pl.renderer
        lay = layout(pl)
        texts = {f"{t.GetInput()}#{i}": text_box(t, ren) for i, t in enumerate(lay.texts)}
        assert {"x (m)", "y (m)", "σ/P*"} <= {k.split("#")[0] for k in texts}
        assert min(t.GetTextProperty().GetFontSize() for t in lay.texts) >= TICK_FONT >= 18
        names = list(texts)
        for i, p in enumerate(names):
            for q in names[i + 1 :]:
                assert not boxes_overlap(texts[p], texts[q]), (p, q)
        # the axes carry at least three labels each way (x, y in m; height in σ/P*)
        assert (
            sum(k.split("#")[0].replace("−", "-").replace(".", "").lstrip("-").isdigit() for k in names) >= 8
        )
        legend = viewport_box(lay.legend, ren)
        bar = viewport_box(pl.scalar_bar, ren)
        head = text_box(lay.heading, ren)
        data = _projected(lay.surface.points, ren)
        for name, box in (("legend", legend), ("colour bar", bar)):
            assert not _inside(data, box).any(), f"{name} covers data"
            for p, tb in texts.items():
                assert not boxes_overlap(box, tb), (name, p)
        assert not boxes_overlap(legend, head) and not boxes_overlap(legend, bar)
        # colour bar: 0 … a round top above the peak, every label a multiple of one round step
        lo, hi = pl.scalar_bar.GetLookupTable().GetRange()
        n = pl.scalar_bar.GetNumberOfLabels()
        step = (hi - lo) / (n - 1)
        assert lo == 0 and hi >= patch.values.max() / 1e3
        mantissa = step / 10 ** np.floor(np.log10(step))
        assert any(np.isclose(mantissa, m) for m in (1, 2, 2.5, 5)), step
    finally:
        pl.close()


def test_figures_1_and_2_share_one_frame_and_label_every_axis_at_zero(aircraft):
    """As the report draws them: the same framed square for the static and the rolling map
    (their r_max differ), and the height axis keeps its 0 (no y tick at the corner it
    stands on, where the two labels collided and the height's 0 was dropped)."""
    from fepost.figures.render import EXTENT_FACTOR, boxes_overlap, layout, text_box

    patches = (aircraft.static_patch, aircraft.rolling_patch)
    assert patches[0].r_max != patches[1].r_max
    extent = max(p.r_max for p in patches) * EXTENT_FACTOR
    frames = []
    for patch in patches:
        pl = pressure_surface(patch, inflation_pressure=1.38e6, extent=extent)
        try:
            texts = [(t.GetInput(), text_box(t, pl.renderer)) for t in layout(pl).texts]
            assert [t for t, _ in texts].count("0") == 3, [t for t, _ in texts]  # x, y and height
            for i, (a, ba) in enumerate(texts):
                for b, bb in texts[i + 1 :]:
                    assert not boxes_overlap(ba, bb), (a, b)
            frames.append(pl.bounds)
        finally:
            pl.close()
    np.testing.assert_allclose(frames[0][:4], frames[1][:4])


def test_figure1_surface_ends_at_the_contact_edge(heavy):
    """The surface is cut where p = EDGE_FRACTION × peak and that edge is drawn: every
    edge point interpolates the FE field to the level, and the faces left out carry
    almost no load."""
    from fepost.figures.render import EDGE_FRACTION, contact_edge, layout

    p = heavy.static_patch
    seg = contact_edge(p).reshape(-1, 2)
    level = EDGE_FRACTION * p.node_values().max()
    np.testing.assert_allclose(fe_pressure_at(p, seg[:, 0], seg[:, 1]), level, rtol=1e-6)
    pl = pressure_surface(p)
    try:
        surf = layout(pl).surface
        # VTK interpolates the clipped scalars in single precision
        assert surf.point_data["sigma_over_P_nodes"].min() * 2e5 >= level * (1 - 1e-6)
        kept = surf.copy()  # its area in plan: flatten it
        flat_pts = np.array(kept.points)
        flat_pts[:, 2] = 0.0
        kept.points = flat_pts
        kept_area = kept.compute_cell_sizes()["Area"].sum()
        fe_area = patch_mesh(p, 1.0, 0.0).compute_cell_sizes()["Area"].sum()
        assert 0.85 * fe_area < kept_area < fe_area
    finally:
        pl.close()


def test_level_segments_of_a_linear_field_lie_on_its_level_line():
    from fepost.figures.outline import level_segments

    pts, tri = disc_mesh(n_rings=10)
    values = 2.0 * pts[:, 0] - pts[:, 1]
    seg = level_segments(pts, tri, values, 0.3).reshape(-1, 2)
    assert len(seg) > 10
    np.testing.assert_allclose(2.0 * seg[:, 0] - seg[:, 1], 0.3, atol=1e-12)


def _mpl_texts(fig):
    """The drawn, non-empty texts of a figure with their window boxes: tick labels inside
    the axis limits, axis labels, titles, free texts, legend entries."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    texts = []
    for ax in fig.axes:
        for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            lo, hi = min(lo, hi), max(lo, hi)
            for loc, label in zip(axis.get_majorticklocs(), axis.get_ticklabels(), strict=False):
                if lo - 1e-9 * (hi - lo) <= loc <= hi + 1e-9 * (hi - lo) and label.get_visible():
                    texts.append(label)
            texts.append(axis.label)
        texts += [ax.title, *ax.texts]
        if ax.get_legend() is not None:
            texts += ax.get_legend().get_texts()
    for leg in fig.legends:
        texts += leg.get_texts()
    return [(t.get_text(), t.get_window_extent(r)) for t in texts if t.get_text().strip() and t.get_visible()]


def _no_text_overlaps(fig):
    texts = _mpl_texts(fig)
    for i, (a, ba) in enumerate(texts):
        for b, bb in texts[i + 1 :]:
            assert not ba.overlaps(bb), (a, b)


def test_figure3_y_limits_hold_every_peak(heavy):
    """The heavy case's lateral peaks (13 × P*) were cut at 3.5 × P*: both panels' y-limits
    now hold every plotted value."""
    from fepost.figures.section import plotted_values

    sec = diameter_sections(heavy.static_patch, inflation_pressure=2e5)
    assert plotted_values(sec).max() > 10  # the peaks this test is about
    fig = plot_sections(sec)
    fig.canvas.draw()
    for ax in fig.axes:
        lo, hi = ax.get_ylim()
        for ln in ax.get_lines():
            y = np.asarray(ln.get_ydata(), float)
            if ln.get_gid() and not ln.get_gid().startswith("rmax"):
                assert lo <= y.min() and y.max() <= hi, (ln.get_gid(), y.max(), hi)
        assert hi <= 1.1 * plotted_values(sec).max()


@pytest.mark.parametrize("case", ["heavy", "maps", "aircraft"])
def test_figure3_legend_and_labels_clear_of_data(case, request):
    a = request.getfixturevalue(case)
    sec = diameter_sections(a.static_patch, a.rolling_patch)
    fig = plot_sections(sec)
    _no_text_overlaps(fig)
    legend = fig.legends[0].get_window_extent()
    for ax in fig.axes:
        assert not legend.overlaps(ax.get_window_extent()), "legend inside a panel"
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels[:1] == ["static"] and ("rolling" in labels) == (a.rolling_patch is not None)


@pytest.mark.parametrize("case", ["heavy", "maps", "aircraft"])
def test_patch_plan_labels_and_legend_clear(case, request):
    a = request.getfixturevalue(case)
    fig = plot_patch_plan(a.static_patch)
    _no_text_overlaps(fig)
    ax = fig.axes[0]
    legend = ax.get_legend().get_window_extent()
    assert not legend.overlaps(ax.get_window_extent()), "legend over the plan"
    edge = [c for c in ax.collections if c.get_gid() == "edge"][0]
    assert len(edge.get_segments()) > 0
