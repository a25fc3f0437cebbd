"""PolarGrid / PolarMap: weights, validation, interpolation between nodes and rim."""

import numpy as np
import pytest

from fepost import analytic
from fepost.errors import ArgumentError
from fepost.polar import PolarGrid, PolarMap


@pytest.mark.parametrize("rule", ["gauss", "trapezoid"])
def test_area_weights_sum_to_disc_area(rule):
    g = PolarGrid.make(33, 16, rule)
    assert g.area_weights(0.2).sum() == pytest.approx(np.pi * 0.04, rel=1e-12)


@pytest.mark.parametrize(
    "kw,msg",
    [
        ({"nr": 1}, "nr must be an integer >= 2, got 1"),
        ({"nphi": 2}, "nphi must be an integer >= 4, got 2"),
        ({"rule": "simpson"}, "rule must be 'gauss' or 'trapezoid', got 'simpson'"),
    ],
)
def test_grid_arguments_are_named(kw, msg):
    with pytest.raises(ArgumentError, match=msg):
        PolarGrid.make(**kw)


def test_map_rejects_wrong_shape_and_radius():
    g = PolarGrid.make(4, 8)
    with pytest.raises(ArgumentError, match=r"sigma must have shape \(4, 8\), got \(3, 8\)"):
        PolarMap(g, 1.0, np.zeros((3, 8)))
    with pytest.raises(ArgumentError, match="radius must be a positive finite length in m, got -1"):
        PolarMap(g, -1.0, np.zeros((4, 8)))


def test_map_arrays_are_read_only():
    pm = PolarMap.from_function(analytic.pressure_function("hertz", 1.0), 1.0, PolarGrid.make(8, 16))
    with pytest.raises(ValueError):
        pm.sigma[0, 0] = 1.0


def test_interpolation_inside_the_grid():
    """Bilinear in (ρ, φ): O(h²) on a smooth region; zero outside the disc."""
    f = analytic.pressure_function("hertz", 0.1, peak=1e6)
    pm = PolarMap.from_function(f, 0.1, PolarGrid.make(24, 48))
    r = np.linspace(0.01, 0.08, 8)
    assert np.allclose(pm.interpolate(r, 0 * r), f(r, 0 * r), rtol=5e-3)
    assert pm.interpolate(0.2, 0.0) == 0.0


def test_interpolation_holds_the_last_ring_up_to_the_rim():
    g = PolarGrid.make(6, 8)
    pm = PolarMap(g, 1.0, np.ones((6, 8)))
    assert pm.interpolate(0.9999, 0.0) == pytest.approx(1.0)


def test_a_grid_beyond_memory_is_refused_with_an_estimate():
    import re

    from fepost.polar import BYTES_PER_NODE

    with pytest.raises(ArgumentError) as err:
        PolarGrid.make(100_000, 100_000)
    msg = str(err.value)
    assert re.match(r"polar grid nr x nphi = 100000 x 100000 = 1e\+10 nodes would need about 4 TB", msg)
    assert 1e10 * BYTES_PER_NODE == pytest.approx(4e12)
