"""``fepost rig RUN... --out CSV``: slide/spin rig runs -> the measured-data CSV.

Each RUN is an FE export with a sidecar ``<run>.json`` (kinematics and the
solver's reactions on the road, see ``fepost.rig``). Writes one row per run:
vx, vy, wz, Fx, Fy, Mz (about the static patch origin), N, source, plus the
shear-traction integrals as a check. Module-level imports stay light.
"""

from __future__ import annotations

import argparse


def add_parser(sub) -> None:
    p = sub.add_parser(
        "rig",
        help="slide/spin rig runs (FE with friction) -> measured-data CSV for diagnose",
        description=(
            "Read FE slide/spin runs (each with a <run>.json sidecar holding the kinematics and the "
            "solver's reactions on the road) and write the measured-data CSV: vx, vy (m/s), wz (rad/s), "
            "Fx, Fy (N, road on tire), Mz (N m, about the static patch origin), N, source; the integrals "
            "of the exported shear traction are added as Fx_shear, Fy_shear, Mz_shear, N_shear."
        ),
    )
    p.add_argument("runs", nargs="+", metavar="RUN", help="FE exports of rig runs (.vtu with <run>.json)")
    p.add_argument(
        "--out", required=True, metavar="CSV", help="output CSV (written atomically; - for standard output)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..output import write_text_atomic
    from ..rig import rig_table
    from ._common import output_name, summary_stream

    table = rig_table(args.runs)
    write_text_atomic(args.out, table.to_csv())
    d = table.max_shear_difference()
    say = summary_stream(args.out)
    for path, why in table.skipped:
        print(f"note: {path} skipped: {why}", file=say)
    print(
        f"{len(table.runs)} runs -> {output_name(args.out)}; reactions vs shear-traction integrals: "
        f"max |dF| = {d['F']:.3g} N, max |dMz| = {d['Mz']:.3g} N m",
        file=say,
    )
    return 0
