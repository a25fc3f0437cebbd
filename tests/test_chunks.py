"""Chunked passes on two threads (fepost._chunks): results in chunk order, two threads only
from `SPLIT` chunks on and with more than one thread allowed (the CPU count or FEPOST_THREADS),
errors raised in the caller."""

from __future__ import annotations

import threading

import pytest

from fepost import _chunks


def test_slices_cover_the_range_in_order():
    assert _chunks.slices(10, 4) == [slice(0, 4), slice(4, 8), slice(8, 10)]
    assert _chunks.slices(0, 4) == []


@pytest.mark.parametrize(("n", "cpus", "threads"), [(40, 2, 2), (15, 2, 1), (40, 1, 1)])
def test_results_in_chunk_order(monkeypatch, n, cpus, threads):
    monkeypatch.setattr(_chunks, "default_threads", lambda: cpus)
    seen = set()

    def work(sl):
        seen.add(threading.get_ident())
        return sl.start * 10

    assert _chunks.map_chunks(work, _chunks.slices(n, 1)) == [10 * i for i in range(n)]
    assert len(seen) == threads


def test_an_error_on_the_second_thread_reaches_the_caller(monkeypatch):
    monkeypatch.setattr(_chunks, "default_threads", lambda: 2)

    def work(sl):
        if sl.start == 30:
            raise ValueError("chunk 30")
        return sl.start

    with pytest.raises(ValueError, match="^chunk 30$"):
        _chunks.map_chunks(work, _chunks.slices(40, 1))


# ----------------------------------------------------------------------------- map_gathered
@pytest.mark.parametrize(("chunks", "cpus", "threads"), [(40, 2, 2), (15, 2, 1), (40, 1, 1)])
def test_gathered_blocks_are_worked_in_order(monkeypatch, chunks, cpus, threads):
    """The gathers on a second thread (from `SPLIT` chunks on, with more than one thread
    allowed), the work on the caller's, the results in block order."""
    monkeypatch.setattr(_chunks, "default_threads", lambda: cpus)
    gathered, worked = set(), set()

    def gather(sl):
        gathered.add(threading.get_ident())
        return sl.start * 10

    def work(got, sl):
        worked.add(threading.get_ident())
        assert got == sl.start * 10
        return sl.start

    blocks = _chunks.slices(100, 10)
    assert _chunks.map_gathered(gather, work, blocks, chunks=chunks) == list(range(0, 100, 10))
    assert worked == {threading.get_ident()}
    assert len(gathered | worked) == threads


@pytest.mark.parametrize("where", ["gather", "work"])
def test_an_error_while_gathering_or_working_reaches_the_caller(monkeypatch, where):
    """Either side's error is raised in the caller, and the gathering thread has ended."""
    monkeypatch.setattr(_chunks, "default_threads", lambda: 2)
    started = threading.active_count()

    def gather(sl):
        if where == "gather" and sl.start == 50:
            raise ValueError("block 50")
        return sl.start

    def work(got, sl):
        if where == "work" and sl.start == 20:
            raise ValueError("block 20")
        return got

    with pytest.raises(ValueError, match="^block (50|20)$"):
        _chunks.map_gathered(gather, work, _chunks.slices(100, 10), chunks=100)
    assert threading.active_count() == started


# ----------------------------------------------------------------------------- FEPOST_THREADS
def test_threads_default_to_the_cpu_count(monkeypatch):
    import os

    from fepost import _threads

    monkeypatch.delenv(_threads.THREADS_ENV, raising=False)
    assert _threads.default_threads() == (os.cpu_count() or 1)
    monkeypatch.setenv(_threads.THREADS_ENV, " 3 ")
    assert _threads.default_threads() == 3


@pytest.mark.parametrize("bad", ["0", "-2", "two", "1.5"])
def test_threads_env_must_be_a_positive_integer(monkeypatch, bad):
    from fepost import _threads
    from fepost.errors import ArgumentError

    monkeypatch.setenv(_threads.THREADS_ENV, bad)
    with pytest.raises(ArgumentError, match=rf"^FEPOST_THREADS='{bad}': must be a positive integer"):
        _threads.default_threads()


def test_one_thread_from_the_environment_keeps_chunks_on_the_caller(monkeypatch):
    monkeypatch.setenv("FEPOST_THREADS", "1")
    seen = set()

    def work(sl):
        seen.add(threading.get_ident())
        return sl.start

    assert _chunks.map_chunks(work, _chunks.slices(40, 1)) == list(range(40))
    assert seen == {threading.get_ident()}
