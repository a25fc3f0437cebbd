"""``fepost pushes LOG... --body BODY.json --out CSV``: a robot rig's push logs -> the measured-data CSV.

Each LOG is a planar-push log (``fepost.pushes.log``) of the block that BODY.json
describes (``fepost.body``). Writes one row per push: vx, vy, wz (the block's
displacement over the push in its frame at the push's start), Fx, Fy, Mz (the
support's friction wrench on the block, torque about the body's reference point), N,
time, push, source; prints the rig checks of each log. Module-level imports stay light.
"""

from __future__ import annotations

import argparse


def add_parser(sub) -> None:
    p = sub.add_parser(
        "pushes",
        help="a robot rig's push logs (planar sliding) -> measured-data CSV for diagnose",
        description=(
            "Read planar-push logs (a finger with a force sensor pushes a block; motion capture gives the "
            "block's pose before and after each push) and write the measured-data CSV, one row per push: "
            "vx, vy, wz (the block's displacement over the push, m and rad, in its frame at the start of "
            "the push: the direction of its twist), Fx, Fy, Mz (the support's friction wrench on the block, "
            "N and N m, torque about the body's reference_point), N (mass x gravity), time and push (the "
            "push's number in its log), source (the log). Prints the rig checks of each log: the sensor's "
            "zero, the finger's impact, pushes left out and why, outliers."
        ),
    )
    p.add_argument("logs", nargs="+", metavar="LOG", help="planar-push logs (text)")
    p.add_argument(
        "--body", required=True, metavar="BODY.json", help="the pushed block (body JSON with a 'log' block)"
    )
    p.add_argument(
        "--out", required=True, metavar="CSV", help="output CSV (written atomically; - for standard output)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..body import load_body
    from ..output import write_text_atomic
    from ..pushes import read_pushes
    from ._common import output_name, summary_stream

    body = load_body(args.body)
    table = read_pushes(args.logs, body)
    write_text_atomic(args.out, table.to_csv())
    say = summary_stream(args.out)
    for line in table.lines():
        print(line, file=say)
    print(
        f"{len(table.pushes)} pushes -> {output_name(args.out)} ({len(table.left_out)} left out) "
        f"from {len(args.logs)} log{'s' if len(args.logs) != 1 else ''}",
        file=say,
    )
    return 0
