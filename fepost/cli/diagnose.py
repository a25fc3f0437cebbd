"""``fepost diagnose --simulation SIM [--rolling ROLLING] --measured CSV [--friction F] --out DIR``.

Compares rig data with the simulation's exact friction integrals, names the most
likely cause of the misfit, fits it and writes ``DIR/diagnosis.json``,
``DIR/summary.txt`` and PNG figures (atomically; ``--force`` replaces a
non-empty DIR). The summary is also printed.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ArgumentError, OutputError
from . import _validate as v
from ._common import add_friction_option, add_input_options, analysis_kwargs


def add_parser(sub) -> None:
    p = sub.add_parser(
        "diagnose",
        help="what the simulation gets wrong against measured friction data, and why",
        description=(
            "Fit every candidate cause (friction level, pressure- or speed-dependent friction, "
            "elliptic patch, anisotropic friction, pressure shift, sensor offsets) through the exact "
            "friction integrals, choose by BIC with nesting tests and a held-out check, and report the gain."
        ),
    )
    p.add_argument(
        "--simulation",
        required=True,
        metavar="SIM",
        help="static FE contact map (.vtu .vtk .vtp .e .exo)",
    )
    p.add_argument(
        "--rolling",
        metavar="ROLLING",
        help="rolling FE contact map (needed for rows with roll = +-1)",
    )
    p.add_argument(
        "--measured", required=True, metavar="CSV", help="measured friction data (INTERFACE.md CSV)"
    )
    add_friction_option(p, "nominal friction coefficient")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--force", action="store_true", help="replace a non-empty output folder")
    p.add_argument(
        "--seed",
        type=v.seed,
        default=0,
        metavar="S",
        help="seed of the cross-validation folds (default 0)",
    )
    p.add_argument(
        "--folds",
        type=v.integer_in(2),
        default=v.LibraryDefault("fepost.diagnose.selection", "FOLDS"),
        metavar="K",
        help="cross-validation folds (default %(default)s)",
    )
    add_input_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..diagnose import diagnose
    from ..diagnose.writer import write_diagnosis

    if not args.friction > 0:
        raise ArgumentError(f"--friction must be positive, got {args.friction!r}")
    if args.folds < 2:
        raise ArgumentError(f"--folds must be at least 2, got {args.folds!r}")
    out = Path(args.out)
    if out.is_dir() and any(out.iterdir()) and not args.force:  # refuse before the work, not after
        raise OutputError(f"{out}: folder exists and is not empty (use --force to replace it)")
    if out.exists() and not out.is_dir():
        raise OutputError(f"{out}: exists and is not a folder")
    result = diagnose(
        args.simulation,
        args.measured,
        rolling=args.rolling,
        friction=args.friction,
        seed=args.seed,
        n_folds=args.folds,
        analyse_kwargs=analysis_kwargs(args),
    )
    out = write_diagnosis(result, args.out, force=args.force)
    print(result.summary(), end="")
    print(f"written: {out}/diagnosis.json, summary.txt, figures")
    return 0
