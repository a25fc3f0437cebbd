"""Write a diagnosis folder atomically: diagnosis.json, summary.txt and PNG figures.

Everything is written into a temporary folder beside ``out`` and moved into
place only when all of it succeeded (`fepost.output.staged_folder`); an
existing non-empty ``out`` is replaced only with ``force``.
"""

from __future__ import annotations

from pathlib import Path

from ..output import staged_folder, to_json
from .figures import save_figures
from .result import Diagnosis


def write_diagnosis(diag: Diagnosis, out, *, force: bool = False) -> Path:
    """Write ``diag`` into the folder ``out``; returns its path."""
    out = Path(out)
    with staged_folder(out, force=force) as tmp:
        figures = save_figures(diag, tmp)
        data = diag.to_dict()
        data["figures"] = figures
        (tmp / "diagnosis.json").write_text(to_json(data) + "\n", encoding="utf-8")
        (tmp / "summary.txt").write_text(diag.summary(), encoding="utf-8")
    return out
