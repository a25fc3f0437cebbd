"""``fepost table1 [--static S] [--rolling R] [--seed N] [--json PATH] [--source SRC] ...``.

Without ``--static`` and ``--rolling`` the report's sample pair is used: the
aircraft tire at its rated load, ``meshes/aircraft/static_100.vtu`` and the rolled
map ``meshes/rig-aircraft/roll_free.vtu`` (`fepost.report.samples`; a one-line
error names a missing file), so that ``fepost table1`` and ``fepost report`` show
the same table. With ``--static`` alone no rolling map is used (the sample rolled
map belongs to the sample tire only): k_x is then assumed (``--k-x``, default the
paper's 0.130) and the table says so. The rolling map is printed with what its
sidecar says it is (`fepost.report.rollinglabel.rolling_label`): a rolled map, a
sliding stand-in, or not stated.
"""

from __future__ import annotations

import argparse

from . import _validate as v
from ._common import add_friction_option, add_input_options, analysis_options, summary_stream

#: The committed seed of ``fepost table1`` (`fepost.table1.DEFAULT_SEED`).
SEED = v.LibraryDefault("fepost.table1", "DEFAULT_SEED")


def add_parser(sub) -> None:
    p = sub.add_parser(
        "table1",
        help="the paper's identification experiment (Table 1) on FE maps, with 95 %% bounds",
        description=(
            "Make the paper's friction curves (1.8) from the coefficients of the FE maps, "
            "add the paper's 20 % noise, fit them back and print theory | fitted | "
            "95 % bounds | the paper's values."
        ),
    )
    p.add_argument(
        "--static",
        metavar="STATIC",
        help="static contact map (default: the sample aircraft tire, meshes/aircraft/static_100.vtu)",
    )
    p.add_argument(
        "--rolling",
        metavar="ROLLING",
        help="rolling contact map (default: the rolled map meshes/rig-aircraft/roll_free.vtu "
        "when --static is not given)",
    )
    p.add_argument("--seed", type=v.seed, default=SEED, metavar="S", help="noise seed (default %(default)s)")
    p.add_argument("--json", metavar="PATH", help="write the table as JSON (- for standard output)")
    p.add_argument(
        "--source",
        choices=("closed_form", "exact"),
        default="closed_form",
        help="test curves from the paper's closed forms (default) or the exact friction integrals",
    )
    add_friction_option(p)
    p.add_argument("--noise", choices=("uniform", "gaussian"), default="uniform", help="noise distribution")
    p.add_argument(
        "--amplitude",
        type=v.number_in(0.0, 2.0),
        default=v.LibraryDefault("fepost.identify.curves", "DEFAULT_AMPLITUDE"),
        metavar="A",
        help="noise amplitude as a fraction of each curve's maximum (default %(default)s)",
    )
    p.add_argument(
        "--n-points",
        type=v.integer_in(2, 1_000_000),
        default=v.LibraryDefault("fepost.identify.curves", "DEFAULT_N_POINTS"),
        metavar="N",
        help="points per curve (default %(default)s)",
    )
    p.add_argument(
        "--span",
        type=v.span,
        default=v.LibraryDefault("fepost.identify.curves", "DEFAULT_SPAN"),
        metavar="X",
        help="largest psi and upsilon of the curves (default %(default)s)",
    )
    p.add_argument(
        "--k-x",
        type=v.number_in(-10.0, 10.0),
        metavar="K",
        help="assumed k_x when no rolling map is used (default 0.130)",
    )
    add_input_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..analysis import analyse
    from ..output import write_json_atomic
    from ..report.rollinglabel import rolling_label
    from ..report.samples import sample_inputs
    from ..table1 import format_table, table1

    if args.static is None:
        static, sample_rolling = sample_inputs()
        rolling = args.rolling if args.rolling is not None else sample_rolling
    else:
        static, rolling = args.static, args.rolling
    result = analyse(static, rolling, friction=args.friction, options=analysis_options(args))
    t = table1(
        result,
        seed=args.seed,
        source=args.source,
        noise=args.noise,
        amplitude=args.amplitude,
        n_points=args.n_points,
        span=args.span,
        k_x=args.k_x,
    )
    say = summary_stream(args.json)
    print(f"static map: {result.static_field.source}", file=say)
    if result.rolling_field is not None:
        rf = result.rolling_field
        print(f"rolling map: {rf.source}: {rolling_label(rf.sidecar).text}", file=say)
    print(format_table(t), file=say)
    if args.json:
        d = t.to_dict()
        d["inputs"] = {
            "static": str(result.static_field.source),
            "rolling": str(result.rolling_field.source) if result.rolling_field is not None else None,
        }
        write_json_atomic(args.json, d)
    return 0
