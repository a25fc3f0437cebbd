"""``fepost report [STATIC [ROLLING]] --out DIR [--force]``, plus friction, P* and seed options.

``--force`` replaces a non-empty DIR, but never one that holds the inputs, the
sample meshes, the current folder, the home folder or the root
(`fepost.output.check_replaceable`).
"""

from __future__ import annotations

import argparse

from . import _validate as v
from ._common import add_friction_option, add_input_options, analysis_options, progress_line


def add_parser(sub) -> None:
    p = sub.add_parser(
        "report",
        help="HTML report with Figures 1-6, the coefficients and Table 1",
        description=(
            "Write DIR/report.html (self-contained, figures embedded) with the figures beside it (PNG, "
            "and SVG/PDF for the plots), coefficients.json, table1.json, curves.csv and VTK files of the "
            "polar maps and patches, and the error maps of the closed forms and the generalised model. "
            "With no inputs, uses the sample aircraft tire at its rated load: the static map "
            "meshes/aircraft/static_100.vtu and the rolled map meshes/rig-aircraft/roll_free.vtu (free "
            "rolling); the report also shows the tire's load sweep. The report says what the rolling map "
            "is, from its sidecar (a rolled map, a sliding stand-in, or not stated). "
            "File formats: docs/formats.md."
        ),
    )
    p.add_argument(
        "static", metavar="STATIC", nargs="?", help="static contact map (default: the sample aircraft tire)"
    )
    p.add_argument(
        "rolling",
        metavar="ROLLING",
        nargs="?",
        help="rolling contact map at the same load (default with no inputs: the sample rolled map)",
    )
    p.add_argument("--out", metavar="DIR", required=True, help="output folder (created; must be empty)")
    p.add_argument(
        "--force",
        action="store_true",
        help="replace a non-empty output folder (never one holding the inputs or the current folder)",
    )
    add_friction_option(p)
    p.add_argument("--gear", metavar="GEAR.json", help="add the landing-gear shimmy section (docs/shimmy.md)")
    p.add_argument(
        "--inflation-pressure",
        type=v.pressure,
        metavar="P",
        help="inflation pressure P* for sigma/P* of Figures 1-3, a number in Pa or with a unit "
        "(1380kPa, 1.38MPa, 13.8bar, 200psi); default: the sidecar's inflation_pressure (or "
        "model.inflation_pressure), else the paper's 200 kPa, with a warning",
    )
    p.add_argument(
        "--seed",
        type=v.seed,
        default=v.LibraryDefault("fepost.table1", "DEFAULT_SEED"),
        metavar="S",
        help="seed of the Table 1 noise (default %(default)s, as fepost table1)",
    )
    add_input_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..output import check_replaceable
    from ..report import build_report
    from ..report.samples import meshes_folder, sample_inputs

    if args.gear:
        from ..shimmy import load_gear

        load_gear(args.gear)  # a bad gear file fails before the report's work
    inputs = [args.static, args.rolling] if args.static is not None else [*sample_inputs()]
    check_replaceable(args.out, [*inputs, meshes_folder()])
    result = build_report(
        args.static,  # None: the sample meshes (fepost.report.samples)
        args.rolling,
        args.out,
        force=args.force,
        friction=args.friction,
        seed=args.seed,
        options=analysis_options(args),
        progress=progress_line,
        gear=args.gear,
    )
    total = sum(t for _, t in result.timings)
    print(f"{result.out / 'report.html'}  ({len(result.files)} files, {total:.1f} s)")
    return 0
