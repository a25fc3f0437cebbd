"""Shared test set-up: headless rendering, and analytic maps written as FE meshes."""

from __future__ import annotations

import os
import signal

import matplotlib

matplotlib.use("Agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")

import pytest  # noqa: E402
import pyvista  # noqa: E402

pyvista.OFF_SCREEN = True

from pathlib import Path  # noqa: E402

from fepost.synthetic import write_map  # noqa: E402

#: The aircraft tire's sample maps (`meshes/aircraft`).
AIRCRAFT = Path(__file__).resolve().parents[1] / "meshes" / "aircraft"


@pytest.fixture(autouse=True)
def _fresh_cli_parser():
    """Each test starts with the CLI's parser built anew (`fepost.cli` keeps one per process):
    a test that replaces a command's function sees its replacement."""
    from fepost import cli

    cli._parser.cache_clear()


_STOP_SIGNALS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n))


@pytest.fixture(autouse=True)
def _stop_signals_left_as_found():
    """A test leaves Ctrl-C, SIGTERM and SIGHUP as it found them: no more ignored or blocked.

    A process started later by the same worker inherits both (a `fepost sweep` run as a
    subprocess would then ignore the Ctrl-C its test sends, finish, and exit with 0). What the
    worker started with is kept: a suite started as a background job of a shell (``make test &``)
    starts with SIGINT ignored.
    """
    blockable = hasattr(signal, "pthread_sigmask")
    before = {s: signal.getsignal(s) for s in _STOP_SIGNALS}
    blocked = set(signal.pthread_sigmask(signal.SIG_BLOCK, [])) if blockable else set()
    yield
    leaks = []
    for s, handler in before.items():
        if handler is not signal.SIG_IGN and signal.getsignal(s) is signal.SIG_IGN:
            leaks.append(f"{signal.Signals(s).name} ignored")
            if handler is not None:
                signal.signal(s, handler)
    if blockable:
        now = set(signal.pthread_sigmask(signal.SIG_SETMASK, blocked))
        leaks += [f"{signal.Signals(s).name} blocked" for s in _STOP_SIGNALS if s in now - blocked]
    assert not leaks, f"the test left {', '.join(leaks)} in its process"


@pytest.fixture
def analytic_mesh(tmp_path):
    """Factory: ``analytic_mesh(name, profile, **kw)`` writes an analytic map into tmp_path."""

    def make(name: str = "map.vtu", profile: str = "hertz", **kw):
        return write_map(tmp_path / name, profile, **kw)

    return make


@pytest.fixture(scope="session")
def aircraft():
    """The aircraft tire at its rated load, analysed: ``static_100`` with the sliding stand-in
    ``rolling_100`` as its rolling partner (k_x 0.24; the demo pairs it with the rolled map
    ``meshes/rig-aircraft/roll_free`` instead): the figures, shimmy and continuity tests and the
    shimmy speeds the docs quote stand on this pair."""
    from fepost import analyse

    static, rolling = AIRCRAFT / "static_100.vtu", AIRCRAFT / "rolling_100.vtu"
    if not (static.is_file() and rolling.is_file()):
        pytest.skip(f"{AIRCRAFT} not shipped")
    return analyse(static, rolling)


@pytest.fixture
def small_accuracy_grid(monkeypatch):
    """The generalised model's stated accuracy (`fepost.friction.summary.ACCURACY_GRID`: exact
    integrals at 33 directions x 2 spin signs x 33 ratios, most of a ``fepost coefficients`` run
    on a small map) measured on 5 x 2 x 5 points, by the same code: for the tests of reading and
    refusing files, whose checks (N_fe, the one-line errors) do not depend on that grid."""
    from fepost.friction import summary

    monkeypatch.setitem(summary.ACCURACY_GRID, "n_beta", 5)
    monkeypatch.setitem(summary.ACCURACY_GRID, "n_t", 5)


# ----------------------------------------------------------------------------- work done once
# `make test` runs the suite in several pytest-xdist worker processes (docs/testing.md). A costly
# result that several test files need (a CalculiX solve) is made once per test session in a folder
# every worker sees, under a file lock: the first worker to ask builds it, the others wait and reuse.


def _shared_root(factory: pytest.TempPathFactory) -> Path:
    """This session's folder for results shared by the workers: beside the workers' own temporary
    folders under xdist (their common parent is this session's), else in this process's."""
    base = factory.getbasetemp()
    return (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "shared"


@pytest.fixture(scope="session")
def made_once(tmp_path_factory):
    """Factory: ``made_once(key, build)`` returns the folder ``build(folder)`` filled, built once
    per test session whichever worker asks first. A build that raised is tried again by the next
    caller (its folder is emptied first); tests must only read what they are given."""
    import shutil

    from filelock import FileLock

    root = _shared_root(tmp_path_factory)
    root.mkdir(parents=True, exist_ok=True)

    def get(key: str, build) -> Path:
        folder, done = root / key, root / f"{key}.done"
        with FileLock(str(root / f"{key}.lock")):
            if not done.is_file():
                shutil.rmtree(folder, ignore_errors=True)
                folder.mkdir()
                build(folder)
                done.touch()
        return folder

    return get


REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def documented_page(made_once):
    """Factory: ``documented_page(page)`` runs the marked blocks of a README/docs page once per
    test session (`tests.docexamples.saved_page_run`, whichever worker asks first) and returns
    its `PageRun` (the scratch folder the commands ran in, and what each printed): the
    tutorial's run serves both its checked outputs (test_doc_examples.py) and the files it
    writes (test_docs.py)."""
    import docexamples as dx

    def get(page: str):
        key = "page-" + page.replace("/", "_").replace(".", "_")
        return dx.load_page_run(made_once(key, lambda folder: dx.saved_page_run(page, folder)))

    return get


@pytest.fixture(scope="session")
def analytic_report(made_once):
    """A report of two analytic tire maps (``tire`` profile, 12 rings; the rolling one shifted,
    k_x 0.13) that lie outside the folder the report ran in, with the default seed; made once
    per session: ``(static, rolling, report folder)``."""
    import contextlib
    import io

    from fepost.cli import main

    def build(folder: Path) -> None:
        maps, work = folder / "maps", folder / "work"
        maps.mkdir()
        work.mkdir()
        s = write_map(maps / "static.vtu", "tire", radius=0.15, peak=6e5, n_rings=12)
        r = write_map(maps / "rolling.vtu", "tire", radius=0.15, peak=6e5, k_x=0.13, n_rings=12)
        with (
            contextlib.chdir(work),
            contextlib.redirect_stdout(io.StringIO()),
            contextlib.redirect_stderr(io.StringIO()),
        ):
            code = main(["report", str(s), str(r), "--out", "rep"])
        if code != 0:
            raise RuntimeError(f"fepost report of the analytic maps exited with {code}")

    folder = made_once("analytic-report", build)
    return folder / "maps" / "static.vtu", folder / "maps" / "rolling.vtu", folder / "work" / "rep"


@pytest.fixture(scope="session")
def coarse_static_tire(made_once):
    """The coarse sample tire's static case (scripts/tiremodel ``build --case static --coarse``)
    solved by CalculiX once per session: ``(out, keep, seconds)`` with ``out`` the exported
    ``static.vtu``/``.json``/``.e``, ``keep`` CalculiX's work files (``keep/static/static.frd``)
    and ``seconds`` the build's wall time. Skipped without ``ccx`` on PATH."""
    import shutil
    import sys
    import time

    if shutil.which("ccx") is None:
        pytest.skip("CalculiX 'ccx' is not on PATH")
    if str(REPO) not in sys.path:  # scripts/ is a plain folder (namespace package) at the repo root
        sys.path.insert(0, str(REPO))

    def build(folder: Path) -> None:
        from scripts.tiremodel.__main__ import main

        t0 = time.perf_counter()
        # one CalculiX thread: the other workers have the other cores
        argv = ["build", "--case", "static", "--coarse", "--threads", "1", "--out", str(folder / "out")]
        rc = main([*argv, "--keep", str(folder / "keep")])
        if rc != 0:
            raise RuntimeError(f"scripts.tiremodel {' '.join(argv)} exited with {rc}")
        (folder / "seconds").write_text(repr(time.perf_counter() - t0))

    folder = made_once("coarse-static-tire", build)
    return folder / "out", folder / "keep", float((folder / "seconds").read_text())


# ----------------------------------------------------------------------------- the files' order
# Under xdist (--dist loadfile --no-loadscope-reorder, pyproject.toml) a worker that runs out of
# work takes the next file in collection order. The longest files go first, so that no worker
# starts a long file when the other is nearly done: by their seconds in the last run recorded in
# pytest's cache (.pytest_cache), else by SECONDS, measured on a quiet 2-core machine.

_ORDER = pytest.StashKey[dict]()
#: The longest files' seconds (their tests' durations summed), for a fresh clone: measured in one
#: whole run of `make test` on the 2-core machine; only their order matters.
SECONDS = {
    "test_doc_examples.py": 31,
    "test_diagnose_detect.py": 26,
    "test_reader_frd.py": 22,
    "test_diagnose_rig.py": 19,
    "test_sweep.py": 19,
    "test_diagnose_cli.py": 18,
    "test_report.py": 16,
    "test_rig_ccx.py": 15,
    "test_rolling.py": 14,
    "test_diagnose_recording.py": 14,
    "test_fuzz_files.py": 11,
    "test_fuzz_cli.py": 11,
    "test_diagnose_rates.py": 10,
    "test_reader_frd_fuzz.py": 9,
    "test_rig_extension.py": 9,
    "test_diagnose_figures.py": 9,
    "test_diagnose_selection.py": 9,
    "test_read_direct_vtk.py": 8,
    "test_identify_generalised.py": 7,
    "test_table1_cli.py": 6,
    "test_fuzz_formats.py": 6,
    "test_external.py": 6,
    "test_figures.py": 5,
    "test_cli_output.py": 5,
    "test_friction_exact.py": 5,
    "test_reader_writers.py": 5,
}
_CACHE_KEY = "fepost/seconds-per-file"
_seconds: dict[str, float] = {}


def _file_of(nodeid: str) -> str:
    return nodeid.split("::", 1)[0].rsplit("/", 1)[-1]


def pytest_configure(config):
    """Read once, in the controller: every worker must collect the tests in the same order.
    And, before the workers start, one thread in each (`_one_thread_per_worker`)."""
    if not hasattr(config, "workerinput"):
        cache = getattr(config, "cache", None)
        config.stash[_ORDER] = (cache.get(_CACHE_KEY, None) if cache is not None else None) or SECONDS
        _one_thread_per_worker(config)


def _one_thread_per_worker(config) -> None:
    """With a worker on every core (`make test`), one thread in each worker and in the
    processes the tests start, set in the environment the workers inherit.

    A worker's own threads would only compete with the other workers for the same cores:
    fepost's (the exact friction integrals, the passes over large meshes; `FEPOST_THREADS`,
    fepost._threads; the numbers are the same on any count) and OpenBLAS's. OpenBLAS's idle
    threads spin after each call until a timeout: 100 products of 200 x 200 matrices, 20 ms
    apart, cost 2.1 s of CPU in 2.1 s (a core busy between the calls). Beside a worker on
    every core that spinning takes the other worker's CPU and that of the forked child a
    worker waits for while it reads a file: test_reader_frd_fuzz.py alone under -n 2 took
    18.3 s of user CPU, 8.8 s with one BLAS thread. Its count must be set before the library
    loads (a plugin imports numpy before any conftest code runs in a worker): threadpoolctl's
    limit at run time left the spinning as it was (18.1 s)."""
    workers = getattr(config.option, "numprocesses", None)
    if isinstance(workers, int) and workers >= (os.cpu_count() or 1):
        os.environ.setdefault("FEPOST_THREADS", "1")
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):  # pytest-xdist's controller, for each worker
    node.workerinput[_CACHE_KEY] = node.config.stash[_ORDER]


def pytest_collection_modifyitems(config, items):
    seconds = config.workerinput[_CACHE_KEY] if hasattr(config, "workerinput") else config.stash[_ORDER]
    first: dict[str, int] = {}
    for k, item in enumerate(items):
        first.setdefault(_file_of(item.nodeid), k)
    items.sort(key=lambda it: (-seconds.get(_file_of(it.nodeid), 0.0), first[_file_of(it.nodeid)]))


def pytest_runtest_logreport(report):
    name = _file_of(report.nodeid)
    _seconds[name] = _seconds.get(name, 0.0) + report.duration


def pytest_sessionfinish(session):
    """Record the files' seconds after a whole run (no file, -k or -m chosen), in the controller."""
    config = session.config
    cache = getattr(config, "cache", None)
    whole = config.args_source == pytest.Config.ArgsSource.TESTPATHS
    whole = whole and not config.option.keyword and not config.option.markexpr
    if cache is None or hasattr(config, "workerinput") or not whole or not _seconds:
        return
    recorded = dict(cache.get(_CACHE_KEY, None) or {})
    recorded.update({name: round(s, 1) for name, s in _seconds.items()})
    cache.set(_CACHE_KEY, recorded)
