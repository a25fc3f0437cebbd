"""Outputs: permissions that follow the umask, nothing half-written after an error,
Ctrl-C, SIGTERM or SIGKILL, stale temporaries removed, and `--force` that never
deletes a run's own inputs."""

from __future__ import annotations

import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fepost import output
from fepost.cli import main
from fepost.errors import OutputError
from fepost.output import (
    check_replaceable,
    remove_stale_temporaries,
    staged_folder,
    write_json_atomic,
    write_text_atomic,
)
from fepost.synthetic import write_map


@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    return write_map(tmp_path_factory.mktemp("out") / "s.vtu", "hertz", radius=0.1, peak=3e5, n_rings=8)


@pytest.fixture
def umask():
    """Set a umask for the test; restored afterwards."""
    old = os.umask(0o022)
    yield lambda mask: os.umask(mask)
    os.umask(old)


def mode(p: Path) -> int:
    return stat.S_IMODE(p.stat().st_mode)


def temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".fepost-" in p.name)


# --- permissions ---------------------------------------------------------------------------


@pytest.mark.parametrize(("mask", "file_mode", "dir_mode"), [(0o022, 0o644, 0o755), (0o002, 0o664, 0o775),
                                                             (0o077, 0o600, 0o700)])  # fmt: skip
def test_outputs_follow_the_umask(umask, tmp_path, mask, file_mode, dir_mode):
    umask(mask)
    f = write_json_atomic(tmp_path / "a.json", {"x": 1})
    assert mode(f) == file_mode
    with staged_folder(tmp_path / "out") as tmp:
        (tmp / "inner.txt").write_text("x")
    assert mode(tmp_path / "out") == dir_mode
    assert mode(tmp_path / "out" / "inner.txt") == file_mode


def test_cli_json_follows_the_umask(umask, capsys, small_map, tmp_path):
    umask(0o022)
    out = tmp_path / "c.json"
    assert main(["coefficients", str(small_map), "--json", str(out)]) == 0
    assert mode(out) == 0o644 and json.loads(out.read_text())["N"] > 0


def test_json_through_a_symlink_keeps_the_link(tmp_path):
    target = tmp_path / "real.json"
    target.write_text("{}")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    write_json_atomic(link, {"a": 1})
    assert link.is_symlink() and json.loads(target.read_text()) == {"a": 1}


def test_json_to_a_fifo_writes_through_and_never_replaces_it(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE)
    write_json_atomic(fifo, {"a": 1})
    got = reader.communicate(timeout=10)[0]
    assert json.loads(got) == {"a": 1}
    assert stat.S_ISFIFO(fifo.stat().st_mode)


# --- nothing half-written ------------------------------------------------------------------


def test_failed_file_write_leaves_nothing(monkeypatch, tmp_path):
    (tmp_path / "a.json").write_text("old")

    def interrupted(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(output.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_text_atomic(tmp_path / "a.json", "new")
    assert (tmp_path / "a.json").read_text() == "old" and temporaries(tmp_path) == []


@pytest.mark.parametrize("exc", [KeyboardInterrupt, RuntimeError, OutputError])
def test_interrupted_folder_leaves_the_old_one_and_no_temporary(tmp_path, exc):
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.txt").write_text("old")
    with pytest.raises(exc), staged_folder(out, force=True) as tmp:
        (tmp / "new.txt").write_text("half")
        raise exc("stop")
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"]
    assert temporaries(tmp_path) == []


def test_force_replaces_a_folder_whole(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.txt").write_text("old")
    with staged_folder(out, force=True) as tmp:
        (tmp / "new.txt").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == ["new.txt"]
    assert temporaries(tmp_path) == []


def test_unwritable_outputs_are_one_line_errors(capsys, small_map, tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    for target, message in [
        (blocker / "c.json", f"fepost: error: {blocker / 'c.json'}: folder {blocker} does not exist"),
        (tmp_path / "no" / "c.json", f"fepost: error: {tmp_path / 'no' / 'c.json'}: folder"),
        (tmp_path, f"fepost: error: {tmp_path}: is a folder, not a file"),
    ]:
        assert main(["coefficients", str(small_map), "--json", str(target)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(message), err
    with pytest.raises(OutputError, match="exists and is not a folder"), staged_folder(blocker):
        pass


# --- stale temporaries -----------------------------------------------------------------------


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def _stale_name(pid: int, kind: str = "tmp", host: str = output._HOST, token: str = "0123abcd") -> str:
    return f".report.fepost-{host}-{pid}-{token}.{kind}"


def test_stale_temporaries_of_dead_processes_are_removed(tmp_path):
    dead = _dead_pid()
    stale_dir = tmp_path / _stale_name(dead)
    stale_dir.mkdir()
    (stale_dir / "fig.png").write_bytes(b"x")
    stale_file = tmp_path / _stale_name(dead, "old")
    stale_file.write_text("x")
    reused = tmp_path / _stale_name(os.getpid())  # our pid, but older than this process: pid reused
    reused.mkdir()
    os.utime(reused, (time.time() - 10 * 86400,) * 2)
    kept = [
        tmp_path / _stale_name(os.getpid(), token="4567cdef"),  # ours and fresh: a run in progress
        tmp_path / _stale_name(1),  # a live process that started before the entry
        tmp_path / _stale_name(dead, host="abcdef"),  # another host's (a shared file system)
        tmp_path / ".report.old-12345",  # not fepost's pattern
        tmp_path / "notes.fepost-000000-1-0123abcd.tmp",  # not hidden: not ours
    ]
    for k in kept[:1]:
        k.mkdir()
    for k in kept[1:]:
        k.write_text("keep")
    removed = remove_stale_temporaries(tmp_path)
    assert sorted(removed) == sorted([stale_dir, stale_file, reused])
    assert all(k.exists() for k in kept)
    shutil.rmtree(kept[0])


def test_writes_clean_stale_temporaries_first(tmp_path):
    stale = tmp_path / _stale_name(_dead_pid())
    stale.mkdir()
    write_json_atomic(tmp_path / "a.json", {})
    assert not stale.exists()
    stale.mkdir()
    with staged_folder(tmp_path / "out"):
        pass
    assert not stale.exists()


# --- real processes: SIGTERM and SIGKILL -----------------------------------------------------


def _start_report(static: Path, out: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "fepost", "report", str(static), "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )


def _wait_for_temporary(p: subprocess.Popen, folder: Path, timeout: float = 60.0) -> None:
    end = time.monotonic() + timeout
    while not temporaries(folder):
        assert p.poll() is None, p.stderr.read().decode()
        assert time.monotonic() < end, "no temporary folder appeared"
        time.sleep(0.02)


@pytest.mark.parametrize("delay", [0.0, 0.3])
def test_sigterm_during_report_leaves_nothing(small_map, tmp_path, delay):
    out = tmp_path / "rep"
    p = _start_report(small_map, out)
    _wait_for_temporary(p, tmp_path)
    time.sleep(delay)
    p.send_signal(signal.SIGTERM)
    err = p.communicate(timeout=60)[1].decode()
    assert p.returncode == 143, err
    assert err.strip().splitlines()[-1] == "fepost: terminated by SIGTERM"
    assert "Traceback" not in err
    assert not out.exists() and temporaries(tmp_path) == []


class _Writes:
    """A stream that records each write call."""

    def __init__(self) -> None:
        self.calls: list[str] = []

    def write(self, text: str) -> int:
        self.calls.append(text)
        return len(text)

    def flush(self) -> None:
        pass


def test_progress_and_stop_lines_are_written_whole(monkeypatch):
    """A progress line and the stop message each go out in one write, newline included: the
    handler of a signal that arrives between two writes raises there, and the stop message
    then lands on the progress line's end (as the SIGTERM test above once saw)."""
    import fepost.cli as cli
    from fepost.cli._common import progress_line

    stream = _Writes()
    monkeypatch.setattr(sys, "stderr", stream)
    progress_line(1, 12, "read", 0.25)
    cli._say("fepost: terminated by SIGTERM")
    assert stream.calls == ["[1/12] read ... done in 0.2 s\n", "fepost: terminated by SIGTERM\n"]


_HALF_BUILT = """
import os, signal, sys, time
import fepost.cli as cli
import fepost.cli.coefficients as command

class HalfBuilt:  # like a renderer stopped in its constructor: its finaliser then fails
    def __init__(self):
        self.cycle = self
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(10)
        self.actor = None

    def __del__(self):
        self.actor

def run(args):
    HalfBuilt()
    return 0

command.run = run
sys.argv = ["fepost", "coefficients", sys.argv[1]]
cli.console_main()
"""


def test_sigterm_message_is_the_last_line_even_when_finalisers_fail(small_map):
    """A SIGTERM that stops an object half-built: one line, no "Exception ignored" after it."""
    p = subprocess.run(
        [sys.executable, "-c", _HALF_BUILT, str(small_map)], capture_output=True, text=True, timeout=60
    )
    assert p.returncode == 143, p.stderr
    assert p.stderr == "fepost: terminated by SIGTERM\n"


_IN_A_FINALISER = """
import gc, os, signal, sys, time
import fepost.cli as cli
import fepost.cli.coefficients as command

REST = float(sys.argv[2])

class Finaliser:  # the signal lands while a finaliser runs: its exception cannot propagate
    def __del__(self):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.2)

def run(args):
    Finaliser()
    gc.collect()
    time.sleep(REST)  # the command goes on: the stop must still come
    print("finished", flush=True)
    return 0

command.run = run
sys.argv = ["fepost", "coefficients", sys.argv[1]]
cli.console_main()
"""


@pytest.mark.parametrize("rest", [0.0, 1.0])
def test_sigterm_inside_a_finaliser_still_stops(small_map, rest):
    """A stop raised inside a finaliser is not lost: raised again later, or, if the command ends
    first, reported as a stop all the same."""
    p = subprocess.run(
        [sys.executable, "-c", _IN_A_FINALISER, str(small_map), str(rest)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert p.returncode == 143, (p.stdout, p.stderr)
    assert p.stderr == "fepost: terminated by SIGTERM\n"
    if rest:
        assert "finished" not in p.stdout  # stopped in the sleep, not after it


def test_sigkill_litter_is_removed_by_the_next_run(small_map, tmp_path, capsys):
    out = tmp_path / "rep"
    p = _start_report(small_map, out)
    _wait_for_temporary(p, tmp_path)
    p.kill()
    p.wait(timeout=60)
    litter = temporaries(tmp_path)
    assert len(litter) == 1  # SIGKILL cannot be caught: the temporary stays ...
    assert main(["coefficients", str(small_map), "--json", str(tmp_path / "c.json")]) == 0
    assert temporaries(tmp_path) == []  # ... until the next write into the folder


# --- --force never deletes the inputs ----------------------------------------------------------


@pytest.fixture
def project(tmp_path, monkeypatch, small_map):
    """A scratch project: data/ with the input, a fake sample-meshes folder, cwd and home."""
    data = tmp_path / "data"
    data.mkdir()
    static = shutil.copy(small_map, data / "static.vtu")
    meshes = tmp_path / "samples" / "meshes"
    meshes.mkdir(parents=True)
    import fepost.report.samples as samples

    for name in ("static.vtu", "rolling.vtu", samples.SAMPLE_STATIC, samples.SAMPLE_ROLLING):
        (meshes / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(small_map, meshes / name)

    monkeypatch.setattr(samples, "meshes_folder", lambda: meshes)
    home = tmp_path / "home"
    (home / "work").mkdir(parents=True)
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(home / "work")
    return Path(static), meshes, home


@pytest.mark.parametrize(
    ("out", "inputs", "holds"),
    [
        ("{data}", "static", "contains the input"),
        ("{tmp}", "static", "contains the input"),
        ("{meshes}", "static", "is the input"),
        ("{meshes}", "", "contains the input"),
        ("{tmp}/samples", "", "contains the input"),
        (".", "static", "is the current folder"),
        ("..", "static", "contains the current folder"),
        ("{home}", "static", "contains the current folder"),
    ],
)
def test_report_force_never_deletes_its_inputs(capsys, project, tmp_path, out, inputs, holds):
    static, meshes, home = project
    target = out.format(data=static.parent, tmp=tmp_path, meshes=meshes, home=home)
    argv = ["report", *([str(static)] if inputs else []), "--out", target, "--force"]
    before = sorted(str(p) for p in tmp_path.rglob("*"))
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(
        f"fepost: error: {target}: refusing to replace this folder: it "
    )
    assert holds in err[0]
    assert sorted(str(p) for p in tmp_path.rglob("*")) == before
    assert static.is_file() and (meshes / "static.vtu").is_file()


def test_home_and_root_are_never_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.chdir("/")
    with pytest.raises(OutputError, match="it is the current folder"):
        check_replaceable("/")
    monkeypatch.chdir(tmp_path.parent)
    with pytest.raises(OutputError, match=r"^/: refusing to replace this folder: it contains the current"):
        check_replaceable("/")
    with pytest.raises(OutputError, match="it is the home folder"):
        check_replaceable(tmp_path)
    other = tmp_path.parent / f"{tmp_path.name}-other"
    check_replaceable(other, [tmp_path / "x.vtu"])  # a sibling: fine


def test_no_command_writes_over_its_inputs(capsys, small_map, tmp_path):
    """--json or --out naming an input (or a folder holding one) is refused before any work."""
    static = Path(shutil.copy(small_map, tmp_path / "static.vtu"))
    before = static.read_bytes()
    csv = tmp_path / "rig" / "measured.csv"
    csv.parent.mkdir()
    csv.write_text("vx,vy,wz,Fx,Fy,Mz\n")
    for argv, message in [
        (["coefficients", static, "--json", static], f"{static}: refusing to overwrite this file: it is the"),
        (["table1", "--static", static, "--json", static], f"{static}: refusing to overwrite this file"),
        (["diagnose", "--simulation", static, "--measured", csv, "--out", csv.parent, "--force"],
         f"{csv.parent}: refusing to replace this folder: it contains the input {csv}"),
        (["diagnose", "--simulation", static, "--measured", csv, "--out", tmp_path, "--force"],
         f"{tmp_path}: refusing to replace this folder: it contains the input {static}"),
    ]:  # fmt: skip
        assert main([str(a) for a in argv]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1, err
        assert err[0].startswith(f"fepost: error: {message}")
    assert static.read_bytes() == before and csv.is_file()
