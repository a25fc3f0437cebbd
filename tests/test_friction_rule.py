"""One default and one rule for the friction coefficient, wherever it enters."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from fepost.analytic import coefficients as analytic_coefficients
from fepost.coefficients import coefficients_from_moments
from fepost.errors import ArgumentError
from fepost.friction.accuracy import approximation_error
from fepost.friction.closed_form import asymptotic_coefficients
from fepost.friction.law import FrictionLaw
from fepost.friction_coefficient import DEFAULT_FRICTION, FRICTION_RANGE, check_friction
from fepost.identify.curves import exact_curves
from fepost.options import DEFAULT_FRICTION as OPTIONS_DEFAULT
from fepost.options import check_friction as options_check

BAD = [0.0, -0.3, 0.0009, 10.5, float("nan"), float("inf"), "0.3", True, None]


def test_one_default_everywhere():
    assert DEFAULT_FRICTION == 0.3
    assert OPTIONS_DEFAULT is DEFAULT_FRICTION and options_check is check_friction
    assert FrictionLaw().f == DEFAULT_FRICTION
    for func, name in [
        (analytic_coefficients, "friction"),
        (coefficients_from_moments, "friction"),
        (exact_curves, "friction"),
        (asymptotic_coefficients, "f"),
        (approximation_error, "f"),
    ]:
        assert inspect.signature(func).parameters[name].default == DEFAULT_FRICTION, func.__name__


@pytest.mark.parametrize("bad", BAD)
def test_one_rule_everywhere(bad):
    lo, hi = FRICTION_RANGE
    with pytest.raises(
        ArgumentError, match=rf"friction must be a friction coefficient in \[{lo:g}, {hi:g}\]"
    ):
        check_friction(bad)
    with pytest.raises(ArgumentError, match=r"^f must be"):  # the law names its field
        FrictionLaw(f=bad)


@pytest.mark.parametrize("good", [FRICTION_RANGE[0], 0.3, np.float64(1.2), FRICTION_RANGE[1]])
def test_the_range_is_inclusive(good):
    assert check_friction(good) == float(good)
