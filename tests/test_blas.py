"""`fepost._blas.one_blas_thread`: one BLAS thread inside, the previous count restored after,
and the process's libraries inspected once (not on every use)."""

from __future__ import annotations

import numpy as np  # noqa: F401  (loads the BLAS the limit applies to)
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from fepost import _blas


def _blas_threads() -> list[int]:
    return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]


def test_limits_to_one_thread_and_restores():
    if not _blas_threads():
        pytest.skip("no BLAS library reported by threadpoolctl")
    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        with _blas.one_blas_thread():
            assert _blas_threads() == [1] * len(before)
        assert _blas_threads() == before


def test_libraries_inspected_once(monkeypatch):
    _blas._controller()  # made (the first use in this process may be here)
    calls = []
    monkeypatch.setattr(_blas, "ThreadpoolController", lambda: calls.append(1))
    for _ in range(3):
        with _blas.one_blas_thread():
            pass
    assert calls == []


_CLI_PROBE = """
import fepost.cli as cli
def probe():
    import numpy  # noqa: F401  (loads BLAS after the entry point has set its thread count)
    from threadpoolctl import threadpool_info
    print(sorted({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}))
    return 0
cli.main = probe
cli.console_main()
"""


@pytest.mark.parametrize(("given", "expected"), [(None, "[1]"), ("2", "[2]")])
def test_the_command_runs_blas_on_one_thread_unless_told(given, expected):
    """The ``fepost`` entry point sets OpenBLAS to one thread before numpy loads it; a count
    the user's environment gives is kept."""
    import os
    import subprocess
    import sys

    if not _blas_threads():
        pytest.skip("no BLAS library reported by threadpoolctl")
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    out = subprocess.run(
        [sys.executable, "-c", _CLI_PROBE], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == expected
