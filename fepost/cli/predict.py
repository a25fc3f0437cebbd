"""``fepost predict STATIC [--rolling R] --kinematics CSV [--friction F] --out CSV [--model-json PATH]``.

For each row (vx, vy, wz) of the kinematics CSV, writes the friction force and
torque of the exact Coulomb integrals over the FE map, of the paper's closed
forms and of the generalised model (columns in `fepost.friction.predict`),
same rows in the same order, atomically. ``--model-json`` also writes the
generalised model's coefficients (the export documented in ``docs/model.md``).
Module-level imports stay light: the work is imported inside `run`.
"""

from __future__ import annotations

import argparse


def add_parser(sub) -> None:
    from ._common import add_friction_option, add_input_options

    p = sub.add_parser(
        "predict",
        help="friction force and torque for given kinematics: exact integrals, paper, generalised model",
        description=(
            "Read vx, vy (m/s) and wz (rad/s) from a CSV and write, row by row, Fx, Fy (N) and Mz (N m, "
            "about the patch origin) of the exact friction integrals over the FE map, of the paper's "
            "closed forms and of the generalised model for non-circular patches. With --rolling the "
            "rolling map is used (the tire rolls); without, the static map."
        ),
    )
    p.add_argument(
        "static",
        metavar="STATIC",
        help="static contact map (.vtu .vtk .vtp .pvtu .vts .e .xdmf .frd ...: see docs/formats.md)",
    )
    p.add_argument("--rolling", metavar="ROLLING", help="rolling contact map at the same deflection")
    p.add_argument(
        "--kinematics",
        required=True,
        metavar="CSV",
        help="CSV with columns vx, vy (m/s) and wz (rad/s); other columns are ignored",
    )
    add_friction_option(p)
    p.add_argument(
        "--out", required=True, metavar="CSV", help="output CSV (written atomically; - for standard output)"
    )
    p.add_argument(
        "--model-json",
        metavar="PATH",
        help="also write the generalised model's coefficients (- for standard output)",
    )
    add_input_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..analysis import analyse
    from ..errors import ArgumentError
    from ..friction.law import FrictionLaw
    from ..friction.predict import predict, read_kinematics
    from ..output import write_text_atomic
    from ._common import analysis_options, output_name, summary_stream

    if args.out == "-" and args.model_json == "-":
        raise ArgumentError("--out - and --model-json -: only one of them can be standard output")
    kin = read_kinematics(args.kinematics)  # bad CSV: fail before the FE work
    result = analyse(args.static, args.rolling, friction=args.friction, options=analysis_options(args))
    rolling = result.rolling_map is not None
    pmap = result.rolling_map if result.rolling_map is not None else result.static_map
    law = FrictionLaw(f=result.coefficients.f)
    c = result.coefficients
    summary = result.model_summary
    model = summary.rolling if rolling else summary.static
    pred = predict(kin.vx, kin.vy, kin.wz, pmap=pmap, coefficients=c, law=law, rolling=rolling, model=model)
    write_text_atomic(args.out, pred.to_csv())
    if args.model_json:
        write_text_atomic(args.model_json, pred.model.to_json() + "\n")
    acc = summary.map_accuracy(rolling)  # the figure fepost coefficients and the report state
    print(
        f"{len(kin)} rows -> {output_name(args.out)} ({pred.map} map, R = {result.coefficients.R:.6g} m); "
        f"generalised model {acc.sentence()}",
        file=summary_stream(args.out, args.model_json),
    )
    return 0
