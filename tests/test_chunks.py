"""Chunked passes on two threads (fepost._chunks): results in chunk order, two threads only
from `SPLIT` chunks on and with more than one CPU, errors raised in the caller."""

from __future__ import annotations

import threading

import pytest

from fepost import _chunks


def test_slices_cover_the_range_in_order():
    assert _chunks.slices(10, 4) == [slice(0, 4), slice(4, 8), slice(8, 10)]
    assert _chunks.slices(0, 4) == []


@pytest.mark.parametrize(("n", "cpus", "threads"), [(40, 2, 2), (15, 2, 1), (40, 1, 1)])
def test_results_in_chunk_order(monkeypatch, n, cpus, threads):
    monkeypatch.setattr(_chunks.os, "cpu_count", lambda: cpus)
    seen = set()

    def work(sl):
        seen.add(threading.get_ident())
        return sl.start * 10

    assert _chunks.map_chunks(work, _chunks.slices(n, 1)) == [10 * i for i in range(n)]
    assert len(seen) == threads


def test_an_error_on_the_second_thread_reaches_the_caller(monkeypatch):
    monkeypatch.setattr(_chunks.os, "cpu_count", lambda: 2)

    def work(sl):
        if sl.start == 30:
            raise ValueError("chunk 30")
        return sl.start

    with pytest.raises(ValueError, match="^chunk 30$"):
        _chunks.map_chunks(work, _chunks.slices(40, 1))
