"""``fepost map BODY.json --out MAP [--fe] [--profile hertz|uniform]``: a body's contact-pressure map.

Writes the support's contact pressure as an FE-style ``MAP.vtu`` with its
sidecar ``MAP.json`` (`fepost.bodymap`), in the body frame moved to the body's
``reference_point``: point supports as small loaded discs with the statics
loads, a flat base as a uniform pressure, or, with ``--fe``, the flat base's
pressure on an elastic board solved by CalculiX. Prints the map's load, its
centre of pressure and the polar grid (``--nr``/``--nphi``) that carries its
load. Module-level imports stay light: the work is imported inside `run`.
"""

from __future__ import annotations

import argparse
import os


def add_parser(sub) -> None:
    p = sub.add_parser(
        "map",
        help="a body's contact-pressure map (point supports, flat base, or --fe: on an elastic board)",
        description=(
            "Write the contact-pressure map of a rigid body on its supports (body JSON) as an FE-style "
            ".vtu, with its sidecar .json beside it, that every fepost command reads: point supports as "
            "small loaded discs with the statics loads, a flat base as a uniform pressure (m g / area), "
            "or with --fe the base pressed by its weight on an elastic board, solved by CalculiX (ccx). "
            "Frame: the body frame moved to reference_point (x, y in m, z up)."
        ),
    )
    p.add_argument(
        "body", metavar="BODY.json", help="body file (mass, gravity, centre of mass, supports or base)"
    )
    p.add_argument(
        "--out",
        required=True,
        metavar="MAP",
        help="output map (.vtu; its sidecar MAP.json is written beside it)",
    )
    p.add_argument(
        "--fe",
        action="store_true",
        help="a flat base's pressure from a CalculiX model of the block on an elastic board",
    )
    p.add_argument(
        "--profile",
        choices=("hertz", "uniform"),
        default="hertz",
        help="pressure profile of each point support's disc (default hertz)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..body import load_body
    from ..bodymap import body_map, write_map
    from ..bodymap.grid import recommended_grid
    from ..bodymap.write import check_map_path, sidecar_path
    from ..errors import OutputError
    from ..output import check_replaceable

    out = check_map_path(args.out)  # before any work
    side = sidecar_path(out)  # MAP.json beside MAP.vtu: never the body file
    if os.path.exists(args.body) and os.path.exists(side) and os.path.samefile(side, args.body):
        raise OutputError(
            f"{args.out}: its sidecar {side} would overwrite the body file; name the map otherwise"
        )
    check_replaceable(side, [args.body])
    body = load_body(args.body)
    if args.fe:
        from ..bodymap.board import board_map  # refuses a body on point supports

        bmap = board_map(body)
    else:
        bmap = body_map(body, profile=args.profile)
    grid = recommended_grid(bmap)
    bmap.info["grid"] = grid
    write_map(bmap, out)
    cx, cy = bmap.centre_of_pressure
    print(
        f"{bmap.info['contact']} -> {out} (+ sidecar {side.name}): N = {bmap.load:.6g} N "
        f"(m g = {body.weight:.6g} N), centre of pressure ({cx:.4g}, {cy:.4g}) m from reference_point, "
        f"peak/mean pressure {bmap.peak() / bmap.mean_pressure():.3g}"
    )
    print(
        f"polar grid: the default carries {grid['default_load_carried']:.2%} of the load; "
        f"--nr {grid['nr']} --nphi {grid['nphi']} carries {grid['load_carried']:.2%} (pure-spin moment "
        f"{grid['moment_carried']:.2%})"
    )
    if "uniform_pressure" in bmap.info:
        print(
            f"board model: solver's reaction {bmap.info['reaction_z']:.6g} N, peak pressure "
            f"{bmap.peak() / bmap.info['uniform_pressure']:.3g} x the uniform m g / area "
            f"(CPRESS scaled by {bmap.info['cpress_scale']:.5f} to carry the reaction)"
        )
    for note in bmap.info.get("notes", []):
        print(f"note: {note}")
    return 0
