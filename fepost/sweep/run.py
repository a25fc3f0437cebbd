"""``run_sweep``: many FE exports and time steps → one coefficients table.

The steps of a sweep:

1. expand the inputs (files, folders, globs) and pair rolling maps
   (`.inputs`, `.pairs`);
2. with ``steps="all"``, list the time steps of every Exodus file, as tasks
   on the cluster (a hostile file may crash a reader: it then fails its own
   row, not the sweep);
3. one `Job` per (file, step); rows finished by an earlier run
   with the same inputs and options are taken from the work folder;
4. the other rows run on Dask (`run_job`, one
   `fepost.analysis.analyse` call each); each row is saved the moment it
   arrives;
5. the table is written whole (``coefficients.parquet``, ``coefficients.csv``),
   then, when the caller gives a page writer (``trends``, e.g.
   ``fepost.report.sweeppage.write_trends``), the trends page. The sweep
   computes; how a sweep is presented lives in the report and figure packages.

The cluster is started only when something is left to compute.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from types import MappingProxyType

from ..errors import ArgumentError
from ..options import DEFAULT_FRICTION, AnalysisOptions, check_friction
from ..output import umask_mode
from .engine import Cluster, WorkerDied
from .inputs import expand_inputs
from .jobs import Job, run_job
from .pairs import Pairing, RollingPairs, pair_sources, parse_rolling_pairs
from .progress import ProgressBar
from .steps import SERIES_SUFFIXES, time_steps
from .store import WorkFolder
from .table import normalise, one_line, write_table

#: A page writer: ``writer(rows, out) -> path of the page`` (``fepost.report.sweeppage.write_trends``).
TrendsWriter = Callable[[Sequence[Mapping], Path], Path]


@dataclass(frozen=True)
class SweepResult:
    """What a sweep wrote.

    Attributes
    ----------
    out : Path
        The output folder.
    rows : tuple of mappings
        The table, one read-only row per (file, step), columns of
        `fepost.sweep.table.COLUMNS`.
    reused, computed : int
        Rows taken from an earlier run / computed by this one.
    parquet, csv : Path
        The table files.
    trends : Path or None
        The trends page (None when not written).
    """

    out: Path
    rows: tuple
    reused: int
    computed: int
    parquet: Path
    csv: Path
    trends: Path | None = None

    def __repr__(self) -> str:
        return (
            f"SweepResult(out={str(self.out)!r}, rows={len(self.rows)}, errors={self.errors}, "
            f"reused={self.reused}, computed={self.computed})"
        )

    @property
    def errors(self) -> int:
        return sum(r["status"] != "ok" for r in self.rows)

    @property
    def ok(self) -> bool:
        return self.errors == 0

    def to_dict(self) -> dict:
        return {
            "out": str(self.out),
            "rows": len(self.rows),
            "errors": self.errors,
            "reused": self.reused,
            "computed": self.computed,
            "parquet": str(self.parquet),
            "csv": str(self.csv),
            "trends": None if self.trends is None else str(self.trends),
        }


def list_steps_task(path: str, units=None) -> dict:
    """Worker task: the time values of ``path`` (``{"times": ...}``) or ``{"error": message}``."""
    from ..errors import FepostError

    try:
        return {"times": time_steps(path, units)}
    except FepostError as exc:
        return {"error": one_line(str(exc))}


def _check_steps(steps) -> str | int:
    if steps in ("last", "all"):
        return steps
    if isinstance(steps, int) and not isinstance(steps, bool):
        return steps
    raise ArgumentError(f"--steps must be 'last' or 'all', got {steps!r}")


def _listed_steps(pairings: Sequence[Pairing], work: WorkFolder, cluster: Cluster, units) -> dict:
    """{path: times | None | error message} for the Exodus files among ``pairings``."""
    listed: dict[str, object] = {}
    todo = []
    for pr in pairings:
        path = pr.static.path
        if path is None or path in listed or Path(path).suffix.lower() not in SERIES_SUFFIXES:
            continue
        if not os.path.isfile(path):
            listed[path] = None  # the row's analysis names the missing file
            continue
        cached = work.load_steps(path)
        if cached is False:
            todo.append(path)
            listed[path] = None
        else:
            listed[path] = cached
    if todo:
        futures = cluster.map(partial(list_steps_task, units=units), todo, "steps")
        where = dict(zip(futures, todo, strict=True))
        try:
            for fut, res in cluster.as_completed(futures):
                path = where[fut]
                if isinstance(res, BaseException):
                    listed[path] = f"{path}: cannot list the time steps ({one_line(str(res))})"
                elif "error" in res:
                    listed[path] = res["error"]
                else:
                    listed[path] = res["times"]
                    work.save_steps(path, res["times"])
        except BaseException:
            cluster.cancel(futures)
            raise
    return listed


def _jobs(
    pairings: Sequence[Pairing], steps, listed: dict, options: AnalysisOptions, friction: float
) -> list[Job]:
    jobs: list[Job] = []
    for pr in pairings:
        src = pr.static
        base = Job(
            src.given,
            src.path,
            None,
            options,
            rolling=pr.rolling,
            rolling_given=pr.rolling_given,
            role=pr.role,
            also=src.also,
            rolling_also=pr.rolling_also,
            friction=friction,
        )
        if src.error is not None or src.path is None:
            jobs.append(replace(base, error=src.error or f"{src.given}: no file"))
        elif steps != "all":
            jobs.append(replace(base, step=None if steps == "last" else steps))
        else:
            times = listed.get(src.path)
            if isinstance(times, str):
                jobs.append(replace(base, error=times))
            elif not times:
                jobs.append(base)
            else:
                jobs += [replace(base, step=k, time=t) for k, t in enumerate(times)]
    return jobs


def run_sweep(
    inputs: Sequence[str | os.PathLike],
    out: str | os.PathLike,
    *,
    steps: str | int = "last",
    rolling_pairs: str | RollingPairs | None = None,
    options: AnalysisOptions | None = None,
    friction: float = DEFAULT_FRICTION,
    workers: int | None = None,
    scheduler: str | None = None,
    client=None,
    processes: bool = True,
    progress: bool | None = None,
    fresh: bool = False,
    force: bool = False,
    trends: TrendsWriter | None = None,
) -> SweepResult:
    """Analyse every input (and, with ``steps="all"``, every time step) on Dask.

    Parameters
    ----------
    inputs : sequence of paths, folders or glob patterns
        FE exports; see `fepost.sweep.inputs`.
    out : path
        Output folder: ``coefficients.parquet``, ``coefficients.csv``,
        ``trends.html``, ``trends.json``, ``trends/`` and the work folder
        ``.fepost-sweep/``. Created when missing; a folder holding other files
        than an earlier sweep is refused unless ``force``.
    steps : ``"last"``, ``"all"`` or int
        ``"last"``: one row per file (its last time step); ``"all"``: one row
        per time step of every Exodus file; an int: that step of every file.
    rolling_pairs : str or RollingPairs, optional
        ``STATIC=ROLLING`` naming rule or a CSV of pairs (`.pairs`).
    options : AnalysisOptions, optional
        Analysis options of every row (default: those of ``fepost coefficients``); its
        ``step`` is replaced by each row's (see ``steps``).
    friction : float
        Friction coefficient f of every row.
    workers : int, optional
        Processes of the embedded local cluster (default: the usable CPU cores).
    scheduler : str, optional
        Address of an existing Dask scheduler instead of the embedded cluster.
    client : distributed.Client, optional
        An open client to compute on (neither started nor closed here).
    processes : bool
        The embedded cluster's workers are processes (default) or threads of
        this process (quicker to start, for a handful of small files).
    progress : bool, optional
        Progress bar on stderr; None (default): when stderr is a terminal.
    fresh : bool
        Forget rows finished by earlier runs.
    force : bool
        Write into a folder that holds other files.
    trends : callable, optional
        Writes the trends page (figures and power-law fits) from the table's
        rows into ``out`` and returns its path: ``fepost.report.sweeppage.write_trends``
        (what ``fepost sweep`` passes). None (default): the table only.

    Returns
    -------
    SweepResult
        Rows in input order (then step order). Rows that failed have
        ``status == "error"``; the sweep itself raises only for bad options,
        an unusable output folder or a lost cluster.
    """
    if not inputs:
        raise ArgumentError("no inputs given (files, folders or glob patterns)")
    steps = _check_steps(steps)
    options = options or AnalysisOptions()
    friction = check_friction(friction)
    pairs = parse_rolling_pairs(rolling_pairs) if isinstance(rolling_pairs, str) else rolling_pairs
    cluster = Cluster(workers, scheduler, client, processes=processes)
    pairings = pair_sources(expand_inputs(inputs), pairs)
    out = Path(out)
    with WorkFolder(out, force=force, fresh=fresh) as work, cluster:
        units = options.unit_system
        listed = _listed_steps(pairings, work, cluster, units) if steps == "all" else {}
        jobs = _jobs(pairings, steps, listed, options, friction)
        keys = [j.key() for j in jobs]
        rows, todo = _saved_rows(jobs, keys, work)
        reused = len(jobs) - len(todo) - sum(j.error is not None for j in jobs)
        bar = ProgressBar(len(todo), done=len(jobs) - len(todo), enabled=progress)
        if todo:
            _compute(cluster, jobs, keys, todo, rows, work, bar)
        bar.close()
        table = [normalise(r) for r in rows if r is not None]
        parquet, csv = write_table(table, out)
        page = None
        if trends is not None:
            page = trends(table, out)
            umask_mode(out / "trends")  # drawn in a tempfile.mkdtemp folder (0700)
    frozen = tuple(MappingProxyType(r) for r in table)
    return SweepResult(out, frozen, reused, len(todo), parquet, csv, page)


def _saved_rows(jobs: Sequence[Job], keys: Sequence[str], work: WorkFolder) -> tuple[list, list[int]]:
    """The rows known without computing (failed jobs, rows finished by an earlier run), and
    the indices of the jobs left to compute."""
    rows: list[dict | None] = [None] * len(jobs)
    todo = []
    for i, (job, key) in enumerate(zip(jobs, keys, strict=True)):
        if job.error is not None:
            rows[i] = run_job(job)
        elif (saved := work.load_row(key)) is not None and saved["status"] == "ok":
            rows[i] = saved
        else:
            todo.append(i)
    return rows, todo


def _compute(cluster: Cluster, jobs, keys, todo, rows, work: WorkFolder, bar: ProgressBar) -> None:
    futures = cluster.map(run_job, [jobs[i] for i in todo], "row")
    where = dict(zip(futures, todo, strict=True))
    try:
        for fut, res in cluster.as_completed(futures):
            i = where[fut]
            if isinstance(res, BaseException):
                job = jobs[i]
                why = str(res) if isinstance(res, WorkerDied) else f"{type(res).__name__}: {res}"
                res = {**job.base_row(), "status": "error", "error": one_line(f"{job.path}: {why}")}
            rows[i] = res
            work.save_row(keys[i], res)
            bar.update(res["status"] == "ok")
    except BaseException:
        cluster.cancel(futures)
        raise
