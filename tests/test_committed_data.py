"""Committed sample data that vanish fail the suite instead of turning tests into skips.

Several tests skip where a folder of solver output is absent (a checkout made
before it was solved). Once committed, those files are part of what the suite
checks: this module lists them, so a deletion, a bad merge or an export that
silently stopped writing shows up as a failure naming the files.
"""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

#: Folder -> {suffix: fewest files}: the solved runs and sample maps as committed.
FOLDERS = {
    "meshes": {".vtu": 3, ".e": 3, ".json": 3},
    "meshes/aircraft": {".vtu": 7, ".e": 7, ".json": 7, ".csv": 1},
    "meshes/rig": {".vtu": 30, ".json": 30, ".txt": 29},
    "meshes/rig-aircraft": {".vtu": 38, ".json": 38, ".txt": 36},
    "meshes/rig-aircraft/long": {".vtu": 11, ".json": 11, ".txt": 10},
    "meshes/rig-aircraft/fine": {".vtu": 4, ".json": 4, ".txt": 3},
    "meshes/rig-aircraft/inc05": {".vtu": 4, ".json": 4, ".txt": 3},
}
#: Files the documentation and the demo name.
FILES = (
    "meshes/static.vtu",
    "meshes/rolling.vtu",
    "meshes/heavy.vtu",
    "meshes/aircraft/static_075.vtu",
    "meshes/aircraft/static_100.vtu",
    "meshes/rig-aircraft/static.vtu",
    "meshes/rig-aircraft/roll_free.vtu",
    "meshes/rig-aircraft/roll_brake04.vtu",
    "meshes/rig-aircraft/roll_brake20.vtu",
    "examples/gear_a320_main.json",
    "examples/measured_example.csv",
)


@pytest.mark.parametrize("folder", sorted(FOLDERS))
def test_committed_runs_are_all_there(folder):
    path = REPO / folder
    assert path.is_dir(), f"{folder}/ is committed sample data and is missing"
    for suffix, fewest in FOLDERS[folder].items():
        have = sorted(p.name for p in path.glob(f"*{suffix}"))
        assert len(have) >= fewest, f"{folder}/ holds {len(have)} {suffix} files, {fewest} are committed"


@pytest.mark.parametrize("name", FILES)
def test_documented_sample_files_exist_and_are_not_empty(name):
    path = REPO / name
    assert path.is_file(), f"{name} is committed sample data and is missing"
    assert path.stat().st_size > 0, f"{name} is empty"


def test_every_run_has_its_sidecar():
    """A solved run is its export and its sidecar: one without the other is a broken commit."""
    for folder in FOLDERS:
        for vtu in (REPO / folder).glob("*.vtu"):
            assert vtu.with_suffix(".json").is_file(), f"{vtu.relative_to(REPO)} has no sidecar"
