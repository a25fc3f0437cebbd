"""One row of the sweep: a job description and the function a worker runs for it.

`run_job` is exactly one single-file run: it calls
`fepost.analysis.analyse` with the options ``fepost coefficients`` would
use and copies the numbers from `to_dict` (the
``--json`` document). Errors fepost raises on purpose become an error row with
their one-line message; anything else is reported with its exception type,
so a bug in one file's analysis shows in its row instead of stopping the sweep.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
import warnings
from dataclasses import dataclass, replace

from ..errors import ArgumentError, FepostError, FepostWarning
from ..options import DEFAULT_FRICTION, AnalysisOptions
from .metadata import case_metadata, sidecar_path
from .table import coefficient_columns, one_line


def _stamp(path: str | None) -> list | None:
    """(size, mtime in ns) of a file, None when it is absent: a changed file is a new row."""
    if path is None:
        return None
    try:
        st = os.stat(path)
    except OSError:
        return None
    return [st.st_size, st.st_mtime_ns]


@dataclass(frozen=True)
class Job:
    """What one row is computed from.

    Attributes
    ----------
    source, rolling_given : str, str or None
        Paths as given (the table's ``source`` and ``rolling`` columns).
    path, rolling : str or None
        Absolute paths the worker reads (None: nothing to read, see ``error``).
    step : int or None
        Time step to read; None: the file's last step (or a file without steps).
    time : float or None
        Time value of ``step`` when listed.
    options : AnalysisOptions
        How the row is analysed (its ``step`` is replaced by the job's).
    friction : float
        Friction coefficient f.
    error : str or None
        Set when the row fails before any analysis (input names no file, its
        time steps cannot be listed): the row is this error.
    role : str
        ``"static"`` (a load point) or ``"rolling"`` (an unpaired rolling map,
        listed apart and left out of the load trends).
    also : tuple of str
        Other files of the same case (other formats), not read.
    rolling_also : tuple of str
        Other files of the rolling map's case (other formats), not read.
    """

    source: str
    path: str | None
    step: int | None
    options: AnalysisOptions
    rolling: str | None = None
    rolling_given: str | None = None
    time: float | None = None
    error: str | None = None
    role: str = "static"
    also: tuple[str, ...] = ()
    friction: float = DEFAULT_FRICTION
    rolling_also: tuple[str, ...] = ()

    def key(self) -> str:
        """Identity of the row: inputs, their size and modification time, step and options."""
        ident = [
            self.path or self.source,
            self.step,
            self.rolling,
            {**self.options.to_dict(), "step": None, "friction": self.friction},
            _stamp(self.path),
            _stamp(self.rolling),
            _stamp(None if self.path is None else str(sidecar_path(self.path))),
            self.error,
            self.role,
            list(self.also + self.rolling_also),  # as when they were one list: earlier rows keep their keys
        ]
        return hashlib.sha1(json.dumps(ident, sort_keys=True).encode()).hexdigest()

    def base_row(self) -> dict:
        return {
            "source": self.source,
            "rolling": self.rolling_given or "",
            "step": self.step,
            "time": self.time,
            "role": self.role,
            "also_as": " ".join(self.also),
            "rolling_also_as": " ".join(self.rolling_also),
        }


def analysis_row(job: Job, res) -> dict:
    """The ok row of ``job`` from its analysis ``res`` (`fepost.analysis.Analysis`):
    the job's identity columns, the coefficient columns and the sidecar metadata.

    `run_job` makes its rows with it; a caller that already holds the
    analysis of a job (the report, for its own case) makes the same row without
    analysing the file again.

    Raises
    ------
    ArgumentError
        The job names no file.
    """
    path = job.path
    if path is None:
        raise ArgumentError(f"{job.source}: the job names no file")
    row = job.base_row()
    step = res.static_field.step
    meta = case_metadata(res.static_field.sidecar)
    columns = coefficient_columns(res.to_dict(model=False))  # the table has no model block
    row.update(step=step, time=res.static_field.time, **columns, **meta)
    row["status"], row["error"] = "ok", ""
    return row


def run_job(job: Job) -> dict:
    """Analyse one row (on a worker); never raises for a bad input.

    Returns
    -------
    dict
        The row: the job's identity columns, ``status`` and ``error``, the
        coefficient columns, the sidecar metadata, ``warnings`` and ``seconds``.
    """
    from ..analysis import analyse

    row = job.base_row()
    if job.error is not None or job.path is None:
        return {**row, "status": "error", "error": one_line(job.error or f"{job.source}: no file")}
    path = job.path
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FepostWarning)
        try:
            res = analyse(
                path, job.rolling, friction=job.friction, options=replace(job.options, step=job.step)
            )
            row = analysis_row(job, res)
        except FepostError as exc:
            row["status"], row["error"] = "error", one_line(str(exc))
        except MemoryError:
            row["status"], row["error"] = "error", one_line(f"{path}: out of memory")
        except Exception as exc:  # a bug must not stop the other rows; its type is kept
            row["status"], row["error"] = "error", one_line(f"{path}: {type(exc).__name__}: {exc}")
    row["warnings"] = " | ".join(
        one_line(str(w.message)) for w in caught if issubclass(w.category, FepostWarning)
    )
    row["seconds"] = time.perf_counter() - t0
    return row
