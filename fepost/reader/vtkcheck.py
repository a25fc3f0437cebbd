"""Checks of VTK files before VTK reads them (filled in below)."""

from pathlib import Path


def check_file(path: Path) -> None:
    return None
