"""The friction coefficient: its one default and its one rule.

`DEFAULT_FRICTION` is the friction coefficient f when none is given (the
paper's 0.3); `check_friction` is the one validation every entry point applies:
a finite real number in `FRICTION_RANGE`, [0.001, 10]. Below 0.001 there is no
friction to speak of (ice is about 0.05) and Table 1's curves underflow; above
10 they overflow, and no tire reaches it (dry asphalt about 1.2; the command
line warns above 1.5).

A foundation module (the standard library and `fepost.errors` only), so that
every layer, from the analytic reference maps up to the command line, takes
the default and the rule from one place.
"""

from __future__ import annotations

import math

from .errors import ArgumentError

#: The friction coefficient f when none is given (the paper's).
DEFAULT_FRICTION = 0.3
#: Accepted friction coefficients, inclusive (see the module docstring).
FRICTION_RANGE = (0.001, 10.0)


def is_real(value: object) -> bool:
    """A real number (int or float, not bool)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def check_friction(f: object, *, name: str = "friction") -> float:
    """``f`` as a float when it is a friction coefficient in `FRICTION_RANGE`.

    Raises
    ------
    ArgumentError
        Not a real number, not finite, or outside the range (naming ``name``).
    """
    lo, hi = FRICTION_RANGE
    if not is_real(f) and type(f).__module__ != "numpy":
        raise ArgumentError(f"{name} must be a friction coefficient in [{lo:g}, {hi:g}], got {f!r}")
    try:
        value = float(f)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ArgumentError(f"{name} must be a friction coefficient in [{lo:g}, {hi:g}], got {f!r}") from None
    if not (math.isfinite(value) and lo <= value <= hi):
        raise ArgumentError(f"{name} must be a friction coefficient in [{lo:g}, {hi:g}], got {f!r}")
    return value
