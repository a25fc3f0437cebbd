"""Immutable array fields: what is shared and what is copied."""

import numpy as np
import pytest

from fepost._arrays import adopted, frozen, sealed


def test_writable_input_is_copied_and_left_writable():
    a = np.arange(5.0)
    f = frozen(a)
    assert f is not a and not np.shares_memory(f, a)
    a[0] = 9.0  # the caller's array stays theirs
    assert f[0] == 0.0
    with pytest.raises(ValueError):
        f[0] = 1.0


def test_read_only_view_of_a_writable_base_is_copied():
    base = np.arange(5.0)
    v = base[1:]
    v.setflags(write=False)
    assert not np.shares_memory(frozen(v), base)


def test_sealed_and_adopted_arrays_are_shared():
    s = sealed(np.arange(4.0))
    assert frozen(s) is s
    owner = np.arange(6.0)  # stands for memory held by a VTK object nobody else reaches
    a = adopted(owner)
    assert frozen(a) is a and np.shares_memory(a, owner)
    assert not a.flags.writeable
    # numpy collapses a view's base to the memory's owner, which is writable: a copy, the safe side
    view = frozen(a[2:])
    np.testing.assert_array_equal(view, owner[2:])
    assert not view.flags.writeable


def test_dtype_change_copies():
    a = adopted(np.arange(3, dtype=np.int32))
    f = frozen(a, dtype=np.int64)
    assert f.dtype == np.int64 and not np.shares_memory(f, a)
