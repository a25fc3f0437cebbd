"""The heap `fepost coefficients` faults in while its files are read (``warm_heap``)."""

from __future__ import annotations

import ctypes
import subprocess
import sys

import pytest

_PROBE = """
import resource, sys
import numpy as np
from fepost.cli.coefficients import warm_heap
if sys.argv[1] == "warm":
    warm_heap(16 << 20)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
kept = [np.ones(1 << 17) for _ in range(12)]  # 12 arrays of 1 MB, each written
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> int:
    p = subprocess.run([sys.executable, "-c", _PROBE, mode], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    return int(p.stdout)


def test_arrays_allocated_after_the_warm_up_reuse_its_pages():
    """12 MB of fresh arrays fault page by page (about 3000 faults of 4 kB) without the warm-up;
    after it they take pages already mapped."""
    try:
        ctypes.CDLL(None).mallopt  # noqa: B018
    except (AttributeError, OSError):
        pytest.skip("no glibc mallopt: warm_heap does nothing here")
    cold, warm = _faults("cold"), _faults("warm")
    assert cold > 1500, cold  # the arrays do fault when nothing is warmed
    assert warm < 0.1 * cold, (warm, cold)


def test_warm_up_only_in_the_command_and_bounded_by_the_map_size(tmp_path, monkeypatch):
    """The ``fepost`` command warms no more than its map's file size (a small map: a few kB); a
    program calling `fepost.cli.main` keeps its malloc as it is."""
    import fepost.cli as cli
    from fepost.cli import coefficients
    from fepost.synthetic import write_map

    got: list[int] = []
    monkeypatch.setattr(coefficients, "warm_heap", got.append)
    m = write_map(tmp_path / "s.vtu", "hertz", radius=0.1, peak=3e5, n_rings=8)
    monkeypatch.setattr(cli, "WHOLE_PROCESS", False)
    assert cli.main(["coefficients", str(m)]) == 0
    assert got == []
    monkeypatch.setattr(cli, "WHOLE_PROCESS", True)
    assert cli.main(["coefficients", str(m)]) == 0
    assert got == [m.stat().st_size] and got[0] < coefficients.WARM_HEAP
    assert cli.main(["coefficients", str(tmp_path / "absent.vtu")]) == 2
    assert got[1:] in ([], [0])  # refused before or after the warm-up: nothing warmed for it
