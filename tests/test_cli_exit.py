"""How the ``fepost`` entry point ends its process (``fepost.cli.console_main``)."""

from __future__ import annotations

import json
import subprocess
import sys
import threading

import pytest

import fepost.cli as cli
from fepost.synthetic import write_map


class _Exited(Exception):
    def __init__(self, how: str, status: int) -> None:
        super().__init__(how, status)
        self.how, self.status = how, status


@pytest.fixture
def ends(monkeypatch):
    """Run console_main with a stub command; record how the process would end and whether
    the exit functions ran first."""
    events: list[str] = []

    def quick(status):
        raise _Exited("os._exit", status)

    monkeypatch.setattr(cli.os, "_exit", quick)
    # the threads a test session already runs (other tests' pools) are not the command's: count
    # only those started during this test, as a fresh ``fepost`` process would see them
    before = set(threading.enumerate())
    monkeypatch.setattr(
        cli.threading, "active_count", lambda: 1 + sum(t not in before for t in threading.enumerate())
    )
    monkeypatch.setattr(cli, "WHOLE_PROCESS", False)  # console_main sets it: restored afterwards
    monkeypatch.setattr("atexit._run_exitfuncs", lambda: events.append("atexit"))

    def run(argv, status=0):
        monkeypatch.setattr(sys, "argv", ["fepost", *argv])
        monkeypatch.setattr(cli, "main", lambda: status)
        try:
            cli.console_main()
        except SystemExit as exc:
            return "sys.exit", exc.code, events
        except _Exited as exc:
            return exc.how, exc.status, events
        raise AssertionError("console_main returned")

    return run


@pytest.mark.parametrize("status", [0, 1, 2])
def test_coefficients_ends_without_teardown_after_the_exit_functions(ends, status):
    assert ends(["coefficients", "map.vtu"], status) == ("os._exit", status, ["atexit"])
    assert ends(["--debug", "coefficients", "map.vtu"], status)[:2] == ("os._exit", status)


@pytest.mark.parametrize("argv", [["report", "map.vtu"], ["sweep", "x"], [], ["--version"]])
def test_other_commands_end_with_the_interpreter_teardown(ends, argv):
    assert ends(argv, 0) == ("sys.exit", 0, [])


def test_a_running_thread_keeps_the_teardown(ends):
    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    try:
        assert ends(["coefficients", "map.vtu"], 0)[0] == "sys.exit"
    finally:
        stop.set()
        t.join()


_PROBE = """
import atexit, sys
import fepost.cli as cli
atexit.register(lambda: print("exit function ran", file=sys.stderr))
sys.argv = ["fepost", "coefficients", sys.argv[1], "--json", sys.argv[2]]
cli.console_main()
"""


def test_a_whole_process_keeps_its_output_and_exit_functions(tmp_path):
    """End to end: the summary and the JSON file are complete, the exit functions ran, and the
    status is the command's."""
    m = write_map(tmp_path / "s.vtu", "hertz", radius=0.1, peak=3e5, n_rings=8)
    out = tmp_path / "c.json"
    p = subprocess.run(
        [sys.executable, "-c", _PROBE, str(m), str(out)], capture_output=True, text=True, timeout=120
    )
    assert p.returncode == 0, p.stderr
    assert p.stderr == "exit function ran\n"
    assert "normal load N (polar)" in p.stdout and p.stdout.endswith("\n")
    assert json.loads(out.read_text())["N"] > 0
    missing = subprocess.run(
        [sys.executable, "-c", _PROBE, str(tmp_path / "absent.vtu"), str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert missing.returncode == 2
    assert missing.stderr.endswith("exit function ran\n")
