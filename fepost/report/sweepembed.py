"""A sweep as a section of another page (the report): run it, draw it, return the HTML.

`sweep_report_section` is the one call a report needs: it runs the sweep
of ``inputs`` into ``folder/<href>/`` (table files and figures, no work
folder left behind) on a small in-process Dask cluster and returns the HTML
section with the files it wrote.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Sequence
from pathlib import Path

from ..sweep.run import run_sweep
from ..sweep.store import WORK
from .sweeppage import sweep_section


def sweep_report_section(
    inputs: Sequence[str | os.PathLike],
    folder: str | os.PathLike,
    *,
    href: str = "sweep",
    rolling_pairs: str | None = None,
    heading_level: int = 2,
    title: str | None = "Load sweep: coefficients against load",
    workers: int = 1,
    processes: bool = False,
    client=None,
) -> tuple[str, tuple[str, ...]]:
    """Run a sweep for a page in ``folder`` and return (HTML section, files written).

    Parameters
    ----------
    inputs : sequence of paths, folders or glob patterns
        The sweep's FE exports (see `fepost.sweep.run_sweep`).
    folder : path
        The page's folder; the sweep writes ``folder/href/coefficients.csv``,
        ``coefficients.parquet`` and its figures there.
    href : str
        Sub-folder name, also the relative URL prefix of the figures.
    rolling_pairs, heading_level, title
        As in `run_sweep` and `sweep_section`.
    workers, processes, client
        Where the rows run: by default one worker thread in this process
        (starts in well under a second; right for the few small sample files).

    Returns
    -------
    (str, tuple of str)
        The ``<section>`` HTML and the written files relative to ``folder``.
    """
    out = Path(folder) / href
    result = run_sweep(
        inputs,
        out,
        rolling_pairs=rolling_pairs,
        workers=None if client is not None else workers,
        client=client,
        processes=processes,
        progress=False,
        force=True,
    )
    shutil.rmtree(out / WORK, ignore_errors=True)
    html = sweep_section(result.rows, out, href, heading_level=heading_level, title=title)
    files = sorted(str(p.relative_to(folder)) for p in out.rglob("*") if p.is_file())
    return html, tuple(files)
