"""Sweeps: many FE exports and time steps in one table, computed on Dask.

::

    from fepost.sweep import run_sweep
    res = run_sweep(["runs/*.e"], "sweep_out", steps="all", workers=2)
    res.rows[0]["M0"], res.ok, res.parquet

Every row is one `fepost.analysis.analyse` call (the call behind
``fepost coefficients``), run as a task on a ``dask.distributed`` cluster.
Modules, one job each:

* `.inputs` – files, folders and globs → sources
* `.pairs` – ``--rolling-pairs``: naming rule or CSV of static/rolling pairs
* `.steps` – which time steps an export holds
* `.metadata` – case metadata from a sidecar ``<case>.json``
* `.jobs` – one row: its identity and the function a worker runs
* `.store` – the work folder that makes a sweep resumable
* `.engine` – the Dask client (embedded local cluster or an existing one)
* `.progress` – the progress bar
* `.table` – columns, units, Parquet and CSV
* `.run` – `run_sweep`, the steps above in order
* `.trends` – power-law fits of the coefficients against the load

The sweep computes; its presentation lives above it: the figures in
``fepost.figures.sweep``, the trends page and the embeddable section in
``fepost.report.sweeppage`` (``write_trends``, ``sweep_section``),
``fepost.report.sweepembed`` (``sweep_report_section``: run a sweep and return
its HTML section) and ``fepost.report.sweepsection`` (the sweep as an optional
section of ``fepost report``).
"""

from .run import SweepResult, run_sweep
from .table import COLUMNS, read_table
from .trends import PowerLaw, fit_power_law, load_trends

__all__ = [
    "COLUMNS",
    "PowerLaw",
    "SweepResult",
    "fit_power_law",
    "load_trends",
    "read_table",
    "run_sweep",
]
