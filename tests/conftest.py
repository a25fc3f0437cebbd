"""Shared test set-up: headless rendering, and analytic maps written as FE meshes."""

from __future__ import annotations

import os

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


@pytest.fixture
def analytic_mesh(tmp_path):
    """Factory: ``analytic_mesh(name, profile, **kw)`` writes an analytic map into tmp_path."""

    def make(name: str = "map.vtu", profile: str = "hertz", **kw):
        return write_map(tmp_path / name, profile, **kw)

    return make


@pytest.fixture(scope="session")
def aircraft():
    """The demo's case: the aircraft tire at its rated load, static and rolling, analysed."""
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
        argv = ["build", "--case", "static", "--coarse", "--out", str(folder / "out")]
        rc = main([*argv, "--keep", str(folder / "keep")])
        if rc != 0:
            raise RuntimeError(f"scripts.tiremodel {' '.join(argv)} exited with {rc}")
        (folder / "seconds").write_text(repr(time.perf_counter() - t0))

    folder = made_once("coarse-static-tire", build)
    return folder / "out", folder / "keep", float((folder / "seconds").read_text())
