"""Immutable array fields for the frozen result objects."""

from __future__ import annotations

import numpy as np


def _immutable(a) -> bool:
    """True when neither ``a`` nor any array it views can be written."""
    while a is not None:
        if not isinstance(a, np.ndarray) or a.flags.writeable:
            return False
        a = a.base
    return True


def frozen(a, dtype=float) -> np.ndarray:
    """A read-only array of ``dtype`` holding ``a``.

    An array that is already immutable all the way down (e.g. another result
    object's field) is shared; anything else is copied, so callers keep their
    own arrays writable and untouched.
    """
    if isinstance(a, np.ndarray) and a.dtype == np.dtype(dtype) and _immutable(a):
        return a
    arr = np.array(a, dtype=dtype, copy=True)
    arr.setflags(write=False)
    return arr


def sealed(a: np.ndarray) -> np.ndarray:
    """Mark an array the library has just created as read-only, without copying.

    Only for arrays no caller holds: it lets :func:`frozen` share them.
    """
    a.setflags(write=False)
    return a
