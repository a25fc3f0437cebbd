"""Immutable array fields for the frozen result objects."""

from __future__ import annotations

import weakref

import numpy as np

#: Read-only views whose writable bases no one else holds, by id (see `adopted`).
_ADOPTED: weakref.WeakValueDictionary = weakref.WeakValueDictionary()


def _immutable(a) -> bool:
    """True when neither ``a`` nor any array it views can be written."""
    while a is not None:
        if not isinstance(a, np.ndarray) or a.flags.writeable:
            return False
        if _ADOPTED.get(id(a)) is a:
            return True
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

    Only for arrays no caller holds: it lets `frozen` share them. The
    arrays it views (numpy's fancy indexing may return a view of a transposed
    temporary) are sealed too.
    """
    b: object = a
    while isinstance(b, np.ndarray):
        b.setflags(write=False)
        b = b.base
    return a


def adopted(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` that `frozen` shares instead of copying.

    For arrays whose memory belongs to an object that the library itself has
    just created and drops (a VTK data set a reader built from a file):
    nothing else can reach that memory, so the view is as good as immutable.
    """
    v = a.view(np.ndarray)
    v.setflags(write=False)
    _ADOPTED[id(v)] = v
    return v
