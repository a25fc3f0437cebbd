"""A clean clone stays clean: documented commands write under out/ (or where the user says),
and tracked files are rewritten only on an explicit --update.

A representative, cheap subset of the commands README.md and docs/ show is run in a fresh
``git clone`` of this repository (its committed state), from the clone's root as a new user
runs them; afterwards ``git status --porcelain`` must be empty: nothing modified, nothing
untracked outside the ignored out/. The expensive ones (``fepost report``,
``scripts/rig_study.py``) are checked for where they write without running them whole.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

#: Documented commands (README.md, docs/tutorial.md, docs/cli.md, docs/rig.md, docs/diagnose.md),
#: in the form the pages give them: each writes only under out/.
COMMANDS = (
    "mkdir -p out",
    "fepost coefficients meshes/static.vtu --json out/coefficients.json",
    "fepost diagnose --make-example out/my_rig.csv --simulation meshes/static.vtu --cause elliptic_patch "
    "--seed 4",
    "fepost rig meshes/rig/d000_slide.vtu meshes/rig/spin_p.vtu --out out/rig.csv",
)


def _git(*args: str, cwd: Path) -> str:
    return subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True, check=True).stdout


@pytest.fixture(scope="module")
def clone(tmp_path_factory):
    if shutil.which("git") is None or not (REPO / ".git").exists():
        pytest.skip("not a git checkout (or no git): nothing to clone")
    where = tmp_path_factory.mktemp("clone") / "fepost"
    subprocess.run(["git", "clone", "-q", "--shared", str(REPO), str(where)], check=True, timeout=120)
    assert _git("status", "--porcelain", cwd=where) == ""
    return where


@pytest.mark.slow
def test_documented_commands_leave_a_clean_clone_clean(clone):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    for line in COMMANDS:
        argv = line.split()
        argv = [sys.executable, "-m", "fepost", *argv[1:]] if argv[0] == "fepost" else argv
        proc = subprocess.run(argv, cwd=clone, env=env, capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, f"{line}: {proc.stderr[-1500:]}"
    written = sorted(p.relative_to(clone).as_posix() for p in (clone / "out").rglob("*") if p.is_file())
    assert written == ["out/coefficients.json", "out/my_rig.csv", "out/rig.csv"]
    assert _git("status", "--porcelain", "--untracked-files=all", cwd=clone) == ""


def _rig_study():
    spec = importlib.util.spec_from_file_location("rig_study_paths", REPO / "scripts" / "rig_study.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_rig_study_writes_out_unless_told_to_update(tmp_path):
    """``python scripts/rig_study.py`` writes out/<rig folder>; only --update writes the tracked
    docs/rig/ (and only for the rig folders whose study the documentation shows)."""
    study = _rig_study()
    rig, aircraft = REPO / "meshes" / "rig", REPO / "meshes" / "rig-aircraft"
    assert study.output_folder(rig, None, False) == Path("out") / "rig"
    assert study.output_folder(aircraft, None, False) == Path("out") / "rig-aircraft"
    assert study.output_folder(rig, tmp_path, False) == tmp_path
    assert study.output_folder(rig, None, True) == REPO / "docs" / "rig"
    assert study.output_folder(aircraft, None, True) == REPO / "docs" / "rig" / "aircraft"
    with pytest.raises(SystemExit, match="either --out or --update"):
        study.output_folder(rig, tmp_path, True)
    other = tmp_path / "rig"
    other.mkdir()
    with pytest.raises(SystemExit, match="has no tracked study"):
        study.output_folder(other, None, True)
    tracked = set(_git("ls-files", "docs/rig", cwd=REPO).split())
    assert {"docs/rig/table.txt", "docs/rig/misfit.csv"} <= tracked  # what --update rewrites
