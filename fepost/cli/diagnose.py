"""``fepost diagnose --simulation SIM [--rolling ROLLING] --measured CSV [--friction F] --out DIR``.

Compares rig data with the simulation's exact friction integrals, names the most
likely cause(s) of the misfit, fits them and writes ``DIR/diagnosis.json``,
``DIR/summary.txt`` and PNG figures (atomically; ``--force`` replaces a
non-empty DIR). The summary is also printed.

``fepost diagnose --make-example CSV --simulation SIM [--cause NAME] [--seed S]``
writes example measured data instead: the project's generator over SIM with one
documented cause hidden in it (`fepost.diagnose.example`).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from ..diagnose.causenames import CAUSES  # a light module: no numpy
from ..errors import ArgumentError, OutputError
from . import _validate as v
from ._common import add_friction_option, add_input_options, analysis_options


def add_parser(sub) -> None:
    p = sub.add_parser(
        "diagnose",
        help="what the simulation gets wrong against measured friction data, and why",
        description=(
            "Fit every candidate cause (friction level, pressure- or speed-dependent friction, "
            "elliptic patch, anisotropic friction, pressure shift, sensor offsets, sensor crosstalk, "
            "load transfer) through the exact "
            "friction integrals, robustly (gross outliers are flagged and left out) and under a noise "
            "model chosen per channel (constant, proportional to |F|, or both); choose by BIC with "
            "nesting tests and a held-out check, try a second cause on top, test for lack of fit "
            "(per channel against replicates or the scatter within holds, drift along the run order or "
            "a time column) and report the gain. Rig recordings (CSV, Parquet, MATLAB, TYDEX) are "
            "reduced to their steady holds first. "
            "With --make-example CSV, write example measured data over SIM instead. "
            "Formats and every output key: docs/diagnose.md."
        ),
    )
    p.add_argument(
        "--simulation",
        required=True,
        metavar="SIM",
        help="static FE contact map (.vtu .vtk .vtp .pvtu .vts .e .xdmf .frd ...: see docs/formats.md)",
    )
    p.add_argument(
        "--rolling",
        metavar="ROLLING",
        help="rolling FE contact map (needed for rows with roll = +-1)",
    )
    p.add_argument(
        "--measured",
        metavar="CSV",
        help="measured friction data: a CSV of test points (vx, vy, wz, Fx, Fy, Mz [, N, roll, time]) or "
        "a rig recording (.csv, .parquet, .mat, .tdx) whose steady holds are found; docs/diagnose.md",
    )
    p.add_argument(
        "--columns",
        metavar="MAP",
        help="recording channel names, e.g. Fx=FX_N,Mz=MZ_Nm,time=RUNTIME (default: own names, aliases)",
    )
    p.add_argument(
        "--channel-units",
        metavar="MAP",
        help="recording units per channel, e.g. Fx=kN,Fy=kN,Mz=kNm,wz=deg/s,vx=km/h (default SI)",
    )
    p.add_argument(
        "--point-column",
        metavar="NAME",
        help="recording column numbering the test points: holds are its runs (default: steady kinematics)",
    )
    p.add_argument(
        "--steady-window",
        type=_seconds,
        default=v.LibraryDefault("fepost.diagnose.holds", "WINDOW_SECONDS"),
        metavar="SECONDS",
        help="recording: a sample is steady when vx, vy, wz stayed within their tolerance over this "
        "trailing window (default %(default)s s, whatever the logging rate)",
    )
    p.add_argument(
        "--settle",
        type=_seconds,
        default=v.LibraryDefault("fepost.diagnose.holds", "SETTLE_SECONDS"),
        metavar="SECONDS",
        help="recording: settling left out at each end of a hold (default %(default)s s)",
    )
    p.add_argument(
        "--strict-recording",
        action="store_true",
        help="recording: refuse a non-finite sample (a dropout) or a clock that goes back, "
        "instead of leaving them out of the holds and reporting them",
    )
    p.add_argument(
        "--layout",
        choices=("auto", "points", "recording"),
        default="auto",
        help="read --measured as a table of test points or as a recording (default auto: docs/diagnose.md)",
    )
    add_friction_option(p, "nominal friction coefficient")
    p.add_argument("--out", metavar="DIR", help="output folder")
    p.add_argument("--force", action="store_true", help="replace a non-empty output folder")
    p.add_argument(
        "--seed",
        type=v.seed,
        default=None,
        metavar="S",
        help="seed of the cross-validation folds (default 0); "
        "with --make-example, of the generator (default 1)",
    )
    p.add_argument(
        "--folds",
        type=v.integer_in(2),
        default=v.LibraryDefault("fepost.diagnose.selection", "FOLDS"),
        metavar="K",
        help="cross-validation folds (default %(default)s)",
    )
    p.add_argument(
        "--make-example",
        metavar="CSV",
        help="write example measured data over SIM to CSV (a hidden cause, see --cause) and stop",
    )
    p.add_argument(
        "--cause",
        choices=CAUSES,
        default="pressure_dependent_friction",
        metavar="NAME",
        help="with --make-example: the cause hidden in the data (default pressure_dependent_friction; "
        f"one of {', '.join(CAUSES)})",
    )
    add_input_options(p)
    p.set_defaults(func=run)


def _seconds(text: str) -> float:
    """A duration in seconds: a finite number >= 0."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds, got {text!r}") from None
    if not (math.isfinite(x) and x >= 0):
        raise argparse.ArgumentTypeError(f"must be a number of seconds >= 0, got {text!r}")
    return x


def _make_example(args: argparse.Namespace) -> int:
    from ..diagnose.example import EXAMPLE_SEED, make_example
    from ..output import check_replaceable

    if args.measured or args.out:
        raise ArgumentError(
            "--make-example writes data and stops: do not combine it with --measured or --out"
        )
    target = Path(args.make_example)
    check_replaceable(target, [args.simulation, args.rolling])
    if target.is_dir():
        raise OutputError(f"{target}: is a folder; --make-example needs a CSV file name")
    if target.exists() and not args.force:
        raise OutputError(f"{target}: file exists (use --force to replace it)")
    if not target.parent.is_dir():
        raise OutputError(f"{target}: folder {target.parent} does not exist")
    seed = EXAMPLE_SEED if args.seed is None else args.seed
    syn = make_example(
        args.simulation,
        target,
        cause=args.cause,
        seed=seed,
        friction=args.friction,
        rolling=args.rolling,
        analyse_kwargs={"options": analysis_options(args)},
    )
    print(
        f"written: {target} ({len(syn.data)} test points, hidden cause {args.cause}, seed {seed}; "
        f"gross errors in rows {', '.join(map(str, syn.outliers)) or 'none'})"
    )
    return 0


def run(args: argparse.Namespace) -> int:
    if args.seed is not None and args.seed < 0:
        raise ArgumentError(f"--seed must be a non-negative integer, got {args.seed!r}")
    if args.make_example:
        return _make_example(args)
    missing = [name for name, value in (("--measured", args.measured), ("--out", args.out)) if not value]
    if missing:
        raise ArgumentError(f"{' and '.join(missing)} required (or --make-example CSV to write example data)")
    if args.folds < 2:
        raise ArgumentError(f"--folds must be at least 2, got {args.folds!r}")
    out = Path(args.out)
    if out.is_dir() and any(out.iterdir()) and not args.force:  # refuse before the work, not after
        raise OutputError(f"{out}: folder exists and is not empty (use --force to replace it)")
    if out.exists() and not out.is_dir():
        raise OutputError(f"{out}: exists and is not a folder")
    from ..diagnose import diagnose
    from ..diagnose.holds import HoldRule
    from ..diagnose.recording import Columns
    from ..diagnose.writer import write_diagnosis

    if args.steady_window <= 0:
        raise ArgumentError(f"--steady-window must be a number of seconds > 0, got {args.steady_window!r}")
    rule = HoldRule(
        window=args.steady_window,
        settle=args.settle,
        use_point=bool(args.point_column),
        strict=args.strict_recording,
    )
    columns = Columns.parse(args.columns, args.channel_units)
    if args.point_column:
        columns = Columns({**columns.names, "point": args.point_column}, columns.units)
    result = diagnose(
        args.simulation,
        args.measured,
        rolling=args.rolling,
        friction=args.friction,
        seed=0 if args.seed is None else args.seed,
        n_folds=args.folds,
        analyse_kwargs={"options": analysis_options(args)},
        columns=columns,
        hold_rule=rule,
        layout=args.layout,
    )
    out = write_diagnosis(result, args.out, force=args.force)
    print(result.summary(), end="")
    print(f"written: {out}/diagnosis.json, summary.txt, figures")
    return 0
