"""``fepost sweep INPUT... --out DIR [--workers N] [--scheduler ADDRESS] [--steps last|all]``.

Nothing heavy is imported at module level: the parser is built for every
command, the sweep machinery (Dask, pyarrow) only when ``sweep`` runs.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

#: Error rows listed on stderr at the end of a sweep (all are in the table).
SHOWN_ERRORS = 10


def add_parser(sub) -> None:
    from . import _validate as v
    from ._common import add_friction_option, add_input_options

    p = sub.add_parser(
        "sweep",
        help="coefficients of many FE exports and time steps in one table, on Dask",
        description=(
            "Run the analysis of `fepost coefficients` on every input (files, folders, glob patterns) "
            "and, with --steps all, on every Exodus time step, as tasks on a Dask cluster. Writes "
            "DIR/coefficients.parquet and DIR/coefficients.csv (one row per file and step), and "
            "DIR/trends.html (coefficients against load, power-law fits with 95 % intervals). "
            "Re-running the same command computes only the rows not finished yet. Exit status 1 "
            "when some rows failed (the table is still complete and marks them)."
        ),
    )
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="FE export, folder of exports, or glob pattern")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created; re-use it to resume)")
    p.add_argument(
        "--workers",
        type=v.integer_in(1, what="a whole number of processes"),
        metavar="N",
        help="worker processes of the embedded local Dask cluster (default: the CPU cores)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on an existing Dask cluster, e.g. tcp://HOST:8786 "
        "(its workers must see the inputs at the same paths)",
    )
    p.add_argument(
        "--steps",
        choices=("last", "all"),
        default=None,
        help="'last' (default): one row per file; 'all': one row per Exodus time step",
    )
    p.add_argument(
        "--rolling-pairs",
        metavar="SPEC",
        help="pair rolling maps with static ones: a naming rule STATIC=ROLLING (e.g. static=rolling) "
        "or a CSV file with columns static,rolling",
    )
    p.add_argument("--fresh", action="store_true", help="recompute every row (forget earlier runs in DIR)")
    p.add_argument("--force", action="store_true", help="write into a folder that holds other files")
    p.add_argument("--no-trends", action="store_true", help="write the table only, no trends page")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_friction_option(p)
    add_input_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..errors import ArgumentError
    from ..output import is_stdout
    from ..report.sweeppage import write_trends
    from ..sweep import run_sweep
    from ..sweep.trends import load_trends, trend_lines
    from . import FAILED_INPUTS, OK, Terminated
    from ._common import analysis_options

    options = analysis_options(args)
    if is_stdout(args.out):
        raise ArgumentError("--out -: the sweep writes a folder, which cannot be standard output")
    if args.step is not None and args.steps == "all":
        raise ArgumentError("--step N picks one time step of every file; it cannot go with --steps all")
    steps = args.step if args.step is not None else (args.steps or "last")
    try:
        result = run_sweep(
            args.inputs,
            args.out,
            steps=steps,
            rolling_pairs=args.rolling_pairs,
            options=replace(options, step=None),  # the sweep's steps are its own business
            friction=args.friction,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=False if args.no_progress else None,
            fresh=args.fresh,
            force=args.force,
            trends=None if args.no_trends else write_trends,
        )
    except (KeyboardInterrupt, Terminated):
        print(
            f"fepost: the rows finished so far are kept in {args.out}: run the same command again to resume",
            file=sys.stderr,
        )
        raise
    print(
        f"{len(result.rows)} rows ({result.reused} from an earlier run, {result.computed} computed), "
        f"{result.errors} failed"
    )
    for r in result.rows:
        if r["also_as"]:
            print(f"note: {r['source']} read; the same case also as {r['also_as']} (not read)")
        if r.get("rolling_also_as"):
            print(
                f"note: {r['rolling']} read as the rolling map of {r['source']}; the same rolling case "
                f"also as {r['rolling_also_as']} (not read)"
            )
        if r["role"] == "rolling" and r["step"] in (None, 0):
            print(
                f"note: {r['source']} is a rolling map without its static map among the inputs: "
                "listed apart (role rolling), not a load point of the trends"
            )
    for line in trend_lines(load_trends(result.rows)):  # the fits the trends page draws
        print(line)
    print(f"table: {result.csv}  {result.parquet}")
    if result.trends is not None:
        print(f"trends: {result.trends}")
    failed = [r for r in result.rows if r["status"] != "ok"]
    for r in failed[:SHOWN_ERRORS]:
        print(f"fepost: error: {r['error']}", file=sys.stderr)
    if len(failed) > SHOWN_ERRORS:
        more = len(failed) - SHOWN_ERRORS
        print(f"fepost: ... and {more} more failed rows (see the table)", file=sys.stderr)
    return OK if result.ok else FAILED_INPUTS
