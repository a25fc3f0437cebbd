"""Power-law trends of a sweep: the fit, its 95 % intervals, the figures and the HTML section.

The fit on FE maps through the whole sweep is in ``test_sweep.py``
(``test_trends_on_hertz_maps``); here the fit itself is checked against closed
forms, a second computation (numpy's ``polyfit`` covariance) and its coverage.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fepost import analytic
from fepost.report.sweeppage import sweep_section
from fepost.sweep import fit_power_law, load_trends
from fepost.sweep.trends import MIN_POINTS, groups


def hertz_rows(loads, pressure=None, friction=0.3):
    """Table rows of ideal Hertz contacts (closed forms): radius ∝ N^(1/3)."""
    rows = []
    for load in loads:
        R = 0.05 * (load / 1e4) ** (1 / 3)
        peak = 3 * load / (2 * math.pi * R**2)
        c = analytic.coefficients("hertz", R, peak, friction)
        rows.append(
            {
                "status": "ok",
                "source": f"{load:g}.vtu",
                "N": analytic.load("hertz", R, peak),
                "R": R,
                "M0": c["M0"],
                "aR2": c["a"] * R**2,
                "m_over_R2": c["m"] / R**2,
                "a": c["a"],
                "m": c["m"],
                "k_x": None,
                "inflation_pressure": pressure,
                "step": None,
            }
        )
    return rows


def test_hertz_exponents_from_closed_forms():
    fits = {f.quantity: f for f in load_trends(hertz_rows([5e3, 1e4, 3e4, 1e5, 2e5]))}
    assert set(fits) == {"R", "M0", "aR2", "m_over_R2"}  # no k_x without rolling maps
    for q, alpha in (("R", 1 / 3), ("M0", 4 / 3), ("aR2", 2 / 3), ("m_over_R2", -2 / 3)):
        assert fits[q].exponent == pytest.approx(alpha, abs=1e-12), q
        assert fits[q].hertz == pytest.approx(alpha)
        lo, hi = fits[q].ci95
        assert lo <= alpha <= hi and hi - lo < 1e-9  # exact data: a vanishing interval
    # M0 = (3π/16) f N R and R = 0.05 (N/1e4)^(1/3): the prefactor in closed form
    assert fits["M0"].prefactor == pytest.approx(3 * math.pi / 16 * 0.3 * 0.05 / 1e4 ** (1 / 3), rel=1e-10)


def test_interval_matches_polyfit_covariance():
    """A second computation of the same interval: numpy's polyfit covariance (scaled by n − 2)."""
    from scipy import stats

    rng = np.random.default_rng(3)
    N = np.geomspace(1e4, 2e5, 7)
    y = 2.0 * N**0.41 * np.exp(rng.normal(0, 0.05, N.size))
    fit = fit_power_law(N, y)
    coef, cov = np.polyfit(np.log(N), np.log(y), 1, cov=True)
    half = stats.t.ppf(0.975, N.size - 2) * math.sqrt(cov[0, 0])
    assert fit.exponent == pytest.approx(coef[0], rel=1e-12)
    assert fit.ci95 == pytest.approx((coef[0] - half, coef[0] + half), rel=1e-10)
    assert fit.prefactor == pytest.approx(math.exp(coef[1]), rel=1e-10)
    # the band holds the fitted line; at the mean log load its half-width is t·s/√n
    grid = np.geomspace(N.min(), N.max(), 50)
    lo, hi = fit.band(grid)
    assert np.all(lo < fit.predict(grid)) and np.all(fit.predict(grid) < hi)
    resid = np.log(y) - np.polyval(coef, np.log(N))
    s = math.sqrt(np.sum(resid**2) / (N.size - 2))
    centre = math.exp(np.log(N).mean())
    lo_c, hi_c = fit.band([centre])
    assert math.log(hi_c[0] / fit.predict([centre])[0]) == pytest.approx(
        stats.t.ppf(0.975, N.size - 2) * s / math.sqrt(N.size), rel=1e-10
    )


def test_interval_coverage():
    """Over 2000 noisy data sets the 95 % interval holds the true exponent 95 % of the time.

    Binomial spread at p = 0.95, n = 2000: sd 0.49 %; the bounds are ±3.5 sd.
    """
    rng = np.random.default_rng(11)
    N = np.geomspace(2e4, 2e5, 6)
    hits = 0
    for _ in range(2000):
        y = 0.7 * N ** (1 / 3) * np.exp(rng.normal(0, 0.03, N.size))
        lo, hi = fit_power_law(N, y).ci95
        hits += lo <= 1 / 3 <= hi
    assert 0.933 <= hits / 2000 <= 0.967


def test_unfittable_cases_say_why():
    assert fit_power_law([1e4, 2e4], [1, 2]).note == f"2 loads: a fit needs {MIN_POINTS}"
    kx = fit_power_law([1e4, 2e4, 4e4], [0.1, -0.02, 0.3], quantity="k_x")
    assert not kx.fitted and kx.note == "k_x or N is zero or negative: no power law"
    flat = fit_power_law([1e4, 1.01e4, 1.02e4], [1.0, 1.1, 1.2])
    assert flat.note == "the loads span less than 5%: no load trend"
    nan = fit_power_law([1e4, math.nan, 4e4, 8e4], [1.0, 2.0, math.inf, 3.0])
    assert nan.n == 2 and not nan.fitted  # non-finite points are dropped, then too few remain
    assert fit_power_law([1e4, 2e4, 4e4], [1, 2, 4]).to_dict()["exponent"] == pytest.approx(1.0)


def test_groups_by_inflation_pressure():
    rows = hertz_rows([1e4, 2e4, 4e4], pressure=1.0e6) + hertz_rows([1e4, 2e4, 4e4, 8e4], pressure=1.4e6)
    rows.append({"status": "error", "source": "bad.vtu", "N": None, "inflation_pressure": 1.0e6})
    g = groups(rows)
    assert list(g) == ["inflation_pressure = 1e+06 Pa", "inflation_pressure = 1.4e+06 Pa"]
    assert [len(v) for v in g.values()] == [3, 4]
    fits = [f for f in load_trends(rows) if f.quantity == "R"]
    assert [f.n for f in fits] == [3, 4] and all(f.exponent == pytest.approx(1 / 3) for f in fits)
    assert list(groups(hertz_rows([1e4, 2e4]))) == ["all"]


def test_section_renders_figures_fits_and_escaped_table(tmp_path):
    rows = hertz_rows([1e4, 2e4, 4e4, 8e4])
    rows[0]["source"] = "<b>odd name</b>.vtu"
    series = [{**r, "source": "ramp.e", "step": k, "time": 0.1 * k} for k, r in enumerate(rows)]
    html = sweep_section(rows + series, tmp_path / "figs", href="sweep", heading_level=3)
    assert html.lstrip().startswith('<section class="fepost-sweep">') and "<h3>" in html and "<h4>" in html
    assert 'src="sweep/load_trends.png"' in html and 'src="sweep/time_trends.png"' in html
    for name in ("load_trends.png", "load_trends.svg", "time_trends.png", "time_trends.svg"):
        assert (tmp_path / "figs" / name).stat().st_size > 1000
    assert "&lt;b&gt;odd name&lt;/b&gt;.vtu" in html and "<b>odd name" not in html
    assert "0.3333" in html  # the R exponent in the fits table
    # one load, one row: no load figure, no fit, the section still renders; no heading on request
    one = sweep_section(rows[:1], tmp_path / "one", title=None)
    assert "load_trends" not in one and "1 row " in one and "<h2>" not in one and "<h3>" in one


def test_figures_and_page_write_symbols_and_units_in_the_reports_style(tmp_path):
    """Subscripts rendered (M₀, k_x as mathtext / <sub>), torques in N·m, areas in m⁻²,
    no unit for dimensionless quantities: never the literal column names."""
    import matplotlib.pyplot as plt

    from fepost.figures.sweep import plot_load_trends, plot_time_trends

    rows = hertz_rows([1e4, 2e4, 4e4, 8e4])
    for k, r in enumerate(rows):
        r["k_x"] = 0.1 + 0.01 * k
    fig = plot_load_trends(rows, load_trends(rows))
    labels = {ax.get_ylabel() for ax in fig.axes if ax.get_visible()}
    titles = {ax.get_title() for ax in fig.axes if ax.get_visible()}
    plt.close(fig)
    assert labels == {"$R$ (m)", "$M_0$ (N·m)", r"$a\,R^2$ (m²)", "$m/R^2$ (m⁻²)", "$k_x$"}
    assert not any("k_x " in t or t.startswith("M0") for t in titles)
    series = {"ramp.e": [{**r, "step": k, "time": 0.1 * k} for k, r in enumerate(rows)]}
    fig = plot_time_trends(series)
    labels = [ax.get_ylabel() for ax in fig.axes]
    plt.close(fig)
    assert "$M_0$ (N·m)" in labels and "aspect" in labels and "$m/R^2$ (m⁻²)" in labels
    html = sweep_section(rows, tmp_path / "figs")
    assert "<th>M<sub>0</sub> (N·m)</th>" in html and "<th>k<sub>x</sub></th>" in html
    assert "<td>M<sub>0</sub> (N·m)</td>" in html and "<td>k<sub>x</sub></td>" in html
    assert "<td>m / R² (m⁻²)</td>" in html
    assert "N m" not in html and "k_x" not in html and "(1)" not in html
