"""Write a shimmy study's folder atomically: shimmy.json, the time histories (CSV) and figures.

Everything is written into a temporary folder beside ``out`` and moved into place
only when all of it succeeded (`fepost.output.staged_folder`); an existing
non-empty ``out`` is replaced only with ``force``. `CSV_FILES` lists what writes
the CSV files of a result (one function per kind of record; a new kind of record
adds its own), `JSON_KEYS` what adds keys to shimmy.json beyond `ShimmyResult.to_dict`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from ..output import staged_folder, to_json
from .figures import save_figures
from .result import ShimmyResult


def _simulation_csvs(result: ShimmyResult, folder: Path) -> None:
    for sim in result.simulations:
        (folder / sim.csv).write_text(sim.history.to_csv(), encoding="utf-8")


#: Writers of a result's CSV files: ``write(result, folder)``.
CSV_FILES: list[Callable[[ShimmyResult, Path], None]] = [_simulation_csvs]
#: Extra keys of shimmy.json: ``key -> (result -> value or None)`` (None: key left out).
JSON_KEYS: dict[str, Callable[[ShimmyResult], object]] = {}


def write_shimmy(
    result: ShimmyResult, out, *, force: bool = False, protect=(), progress=None, touchdown=()
) -> Path:
    """Write ``result`` into the folder ``out``; returns its path. ``progress(k, n, step, s)``
    is called once the figures are drawn (the writing's one long stage). ``touchdown``:
    [(`fepost.shimmy.touchdown.Touchdown`, csv name)], written as CSV files and the
    ``touchdown`` rows of shimmy.json."""
    out = Path(out)
    with staged_folder(out, force=force, protect=protect) as tmp:
        for write in CSV_FILES:
            write(result, tmp)
        data = result.to_dict()
        for key, value in JSON_KEYS.items():
            v = value(result)
            if v is not None:
                data[key] = v
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
