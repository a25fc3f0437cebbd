"""Write a shimmy study's folder atomically: shimmy.json, the time histories (CSV) and figures.

Everything is written into a temporary folder beside ``out`` and moved into place
only when all of it succeeded (`fepost.output.staged_folder`); an existing
non-empty ``out`` is replaced only with ``force``.
"""

from __future__ import annotations

from pathlib import Path

from ..output import staged_folder, to_json
from .figures import save_figures
from .result import ShimmyResult


def write_shimmy(result: ShimmyResult, out, *, force: bool = False, protect=()) -> Path:
    """Write ``result`` into the folder ``out``; returns its path."""
    out = Path(out)
    with staged_folder(out, force=force, protect=protect) as tmp:
        for sim in result.simulations:
            (tmp / sim.csv).write_text(sim.history.to_csv(), encoding="utf-8")
        data = result.to_dict()
        data["figures"] = save_figures(result, tmp)
        (tmp / "shimmy.json").write_text(to_json(data) + "\n", encoding="utf-8")
    return out
