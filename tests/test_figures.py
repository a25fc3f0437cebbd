"""Figures: image regression for the pyvista renders, data-level checks for matplotlib.

The baselines live in ``tests/image_cache/`` (pytest-pyvista's ``image_cache_dir``
in pyproject.toml; regenerate with
``pytest tests/test_figures.py --reset_image_cache`` after a deliberate change
and look at the new images before committing them).
"""

from __future__ import annotations

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
    np.testing.assert_allclose(mesh.points[:, :2], p.xy * 1e3, rtol=0, atol=1e-9)
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
    s = sec.s / 1e3
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
    np.testing.assert_allclose(r, p.r_max * 1e3, rtol=1e-12)
    ce = np.array(p.ellipse_centre) * 1e3
    r = np.hypot(lines["r_equiv"].get_xdata() - ce[0], lines["r_equiv"].get_ydata() - ce[1])
    np.testing.assert_allclose(r, p.r_equiv * 1e3, rtol=1e-12)
    assert ax.get_title() == (
        f"Loaded region — circular: aspect {p.aspect:.3f}, r_max/r_equiv {p.r_max / p.r_equiv:.3f}"
    )


def test_patch_plan_title_says_not_circular(tmp_path):
    a = analyse(write_map(tmp_path / "e.vtu", "hertz", radius=0.1, aspect=2.0, n_rings=16))
    fig = plot_patch_plan(a.static_patch)
    assert fig.axes[0].get_title().startswith("Loaded region — NOT circular: aspect 2.0")
    e = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "ellipse"][0]
    assert np.ptp(e.get_xdata()) == pytest.approx(2 * a.static_patch.ellipse_axes[0] * 1e3, rel=1e-3)


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
