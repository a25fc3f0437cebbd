"""Contact-patch rules: what counts as one patch, fragments, circularity tolerances."""

import meshio
import numpy as np
import pytest

from fepost import analyse, analytic
from fepost.errors import PatchWarning
from fepost.patch import GAP_FRACTION
from fepost.synthetic import disc_mesh

R = 0.1
PEAK = 4.0e5


def _write(path, p2, tri, val):
    meshio.write(
        path, meshio.Mesh(np.column_stack([p2, 0 * val]), [("triangle", tri)], point_data={"CPRESS": val})
    )
    return path


def test_grooved_patch_is_one_patch(tmp_path):
    """Two circumferential grooves (unloaded bands of 4 mm, < 5 % of √area) split the
    loaded faces into three mesh components, which are still one contact patch."""
    p2, tri = disc_mesh(60)
    p2 = R * p2
    val = analytic.pressure_function("hertz", R, PEAK)(p2[:, 0], p2[:, 1])
    groove = np.abs(np.abs(p2[:, 1]) - 0.03) < 0.002
    val[groove] = 0.0
    gap = 0.004 - 2 * R / 60  # band width less one element on each side, still < GAP_FRACTION·√area
    assert gap < GAP_FRACTION * np.sqrt(np.pi) * R
    a = analyse(_write(tmp_path / "ribs.vtu", p2, tri, val))
    assert a.static_patch.dropped_fragments == 0
    assert a.coefficients.N == pytest.approx(a.static_patch.N_fe, rel=2e-3)


def test_small_fragment_is_dropped_with_a_warning(tmp_path):
    p2, tri = disc_mesh(30)
    main_pts = R * p2
    frag = 0.01 * p2 + [0.5, 0.0]  # a 1 cm spot 0.4 m away carrying ~0.1 % of the load
    val = np.r_[
        analytic.pressure_function("hertz", R, PEAK)(main_pts[:, 0], main_pts[:, 1]),
        analytic.pressure_function("hertz", 0.01, 0.1 * PEAK, centre=(0.5, 0.0))(frag[:, 0], frag[:, 1]),
    ]
    path = _write(tmp_path / "frag.vtu", np.vstack([main_pts, frag]), np.vstack([tri, tri + len(p2)]), val)
    with pytest.warns(PatchWarning, match=r"frag\.vtu: dropped 1 small loaded fragment\(s\) carrying 0\.10%"):
        a = analyse(path)
    assert a.static_patch.dropped_fragments == 1
    assert a.coefficients.N == pytest.approx(analytic.load("hertz", R, PEAK), rel=2e-3)
    assert a.coefficients.R == pytest.approx(R, rel=1e-3)


@pytest.mark.parametrize("aspect,circular", [(1.0, True), (1.08, True), (1.12, False), (1.3, False)])
def test_circularity_verdict_follows_the_documented_tolerance(analytic_mesh, aspect, circular):
    p = analyse(analytic_mesh("e.vtu", "hertz", radius=R, aspect=aspect, n_rings=30)).static_patch
    assert p.aspect == pytest.approx(aspect, rel=5e-3)
    assert p.circular is circular


def test_too_coarse_a_grid_is_reported(analytic_mesh):
    path = analytic_mesh("h.vtu", "uniform", radius=R, n_rings=30)
    from fepost.polar import PolarGrid

    with pytest.warns(PatchWarning, match=r"h\.vtu: the polar grid carries -\d+\.\d% of the FE load"):
        analyse(path, grid=PolarGrid.make(4, 4, "trapezoid"))


@pytest.mark.parametrize("location", ["point", "cell"])
def test_load_outside_the_equivalent_circle_of_an_ellipse(analytic_mesh, location):
    """Uniform pressure on an ellipse of aspect 1.3: the share outside the circle of equal
    area is the ellipse's area outside that circle over its whole area (an independent
    1-D integral over the polar angle)."""
    from scipy.integrate import quad

    aspect = 1.3
    p = analyse(
        analytic_mesh("u.vtu", "uniform", radius=R, aspect=aspect, n_rings=60, location=location)
    ).static_patch
    a, b = R * np.sqrt(aspect), R / np.sqrt(aspect)
    r = p.r_equiv

    def inside(phi):
        rho = a * b / np.hypot(b * np.cos(phi), a * np.sin(phi))
        return 0.5 * min(rho, r) ** 2

    kink = np.arccos(np.sqrt((r**-2 - a**-2) / (b**-2 - a**-2)))  # where the ellipse crosses the circle
    area_in = 4 * quad(inside, 0, np.pi / 2, points=[kink], epsabs=0, epsrel=1e-12)[0]
    expected = 1.0 - area_in / (np.pi * a * b)
    assert 0.03 < expected < 0.2
    assert p.load_outside == pytest.approx(expected, rel=2e-3)
    assert p.r_equiv == pytest.approx(R, rel=2e-3)
