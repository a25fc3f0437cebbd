"""Small helpers for immutable array fields of frozen dataclasses."""

from __future__ import annotations

import numpy as np


def frozen(a, dtype=float) -> np.ndarray:
    """Return a read-only float (or given dtype) copy-or-view of ``a``."""
    arr = np.array(a, dtype=dtype, copy=True)
    arr.setflags(write=False)
    return arr
