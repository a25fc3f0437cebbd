"""Write a shimmy study's folder atomically: shimmy.json, the time histories (CSV) and figures.

Everything is written into a temporary folder beside ``out`` and moved into place
only when all of it succeeded (`fepost.output.staged_folder`); an existing
non-empty ``out`` is replaced only with ``force``.
"""

from __future__ import annotations

import time
from pathlib import Path

from ..output import staged_folder, to_json
from .figures import save_figures
from .result import ShimmyResult


def write_shimmy(
    result: ShimmyResult, out, *, force: bool = False, protect=(), progress=None, touchdown=()
) -> Path:
    """Write ``result`` into the folder ``out``; returns its path. ``progress(k, n, step, s)``
    is called once the figures are drawn (the writing's one long stage). ``touchdown``:
    [(`fepost.shimmy.touchdown.Touchdown`, csv name)], written as CSV files and the
    ``touchdown`` rows of shimmy.json."""
    out = Path(out)
    with staged_folder(out, force=force, protect=protect) as tmp:
        for sim in result.simulations:
            (tmp / sim.csv).write_text(sim.history.to_csv(), encoding="utf-8")
        data = result.to_dict()
        for run, csv in touchdown:
            (tmp / csv).write_text(run.to_csv(), encoding="utf-8")
        if touchdown:
            data["touchdown"] = [run.row(csv) for run, csv in touchdown]
        t0 = time.perf_counter()
        data["figures"] = save_figures(result, tmp)
        if progress is not None:
            progress(1, 1, f"figures ({len(data['figures'])})", time.perf_counter() - t0)
        (tmp / "shimmy.json").write_text(to_json(data) + "\n", encoding="utf-8")
    return out
