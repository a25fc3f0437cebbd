"""``fepost shimmy STATIC [--rolling ROLLING] --gear GEAR.json --out DIR``: does the gear shimmy?

Builds the tire's friction models from the FE maps (the paper's closed forms, the
generalised model, the exact integrals), puts them under the landing gear of the
gear file, and writes DIR/shimmy.json (stability over speed, critical speeds with
their 95 % intervals, time histories and their verdicts, the published anchor),
the time histories as CSV and the figures (docs/shimmy.md). Module-level imports
stay light: the work is imported inside `run`.
"""

from __future__ import annotations

import argparse

from . import _validate as v
from ._common import progress_line

#: The friction models the command knows, in the order of shimmy.json.
MODELS = ("closed_forms", "generalised", "exact")


def _models(text: str) -> tuple[str, ...]:
    names = tuple(t.strip() for t in str(text).split(",") if t.strip())
    bad = [n for n in names if n not in MODELS]
    if not names or bad:
        got = bad[0] if bad else text
        raise argparse.ArgumentTypeError(
            f"must be a comma-separated list of {', '.join(MODELS)}, got {got!r}"
        )
    return tuple(dict.fromkeys(names))


def add_parser(sub) -> None:
    from ._common import add_friction_option, add_input_options
    from ._touchdown import add_touchdown_options

    p = sub.add_parser(
        "shimmy",
        help="landing-gear shimmy with the tire's dry-friction contact: critical speed per friction model",
        description=(
            "Put the tire of the FE maps under the landing gear of GEAR.json (strut torsion with trail, "
            "lateral bending, wheels sliding with multi-component dry friction) and find where straight "
            "rolling with longitudinal sliding turns unstable: eigenvalues over a speed sweep and time "
            "simulations, for the paper's closed forms, the generalised model and the exact integrals, "
            "with the coefficients' 95 % intervals carried to the critical speed. Writes DIR/shimmy.json, "
            "time histories (CSV) and figures. Model and gear file: docs/shimmy.md."
        ),
    )
    p.add_argument("static", metavar="STATIC", help="static contact map (see docs/formats.md)")
    p.add_argument(
        "--rolling", metavar="ROLLING", help="rolling contact map at the same deflection (gives k_x)"
    )
    p.add_argument("--gear", required=True, metavar="GEAR.json", help="gear parameters (docs/shimmy.md)")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created; must be empty)")
    p.add_argument("--force", action="store_true", help="replace a non-empty output folder")
    p.add_argument(
        "--models",
        type=_models,
        default=MODELS,
        metavar="LIST",
        help="friction models, comma-separated: closed_forms,generalised,exact (default all three)",
    )
    p.add_argument(
        "--speed-min", type=v.number_in(1e-3, 1e4), default=1.0, metavar="V", help="m/s (default 1)"
    )
    p.add_argument(
        "--speed-max", type=v.number_in(1e-3, 1e4), default=150.0, metavar="V", help="m/s (default 150)"
    )
    p.add_argument(
        "--speeds",
        type=v.integer_in(2, 100000),
        default=200,
        metavar="N",
        help="speeds in the sweep (default 200)",
    )
    p.add_argument(
        "--duration",
        type=v.number_in(0.01, 1000.0),
        default=10.0,
        metavar="T",
        help="simulated seconds (default 10)",
    )
    p.add_argument(
        "--trails",
        type=v.integer_in(0, 1000),
        default=16,
        metavar="N",
        help="boundary over speed x trail at N trails from 0 to 3 x the gear's (default 16; 0: none)",
    )
    p.add_argument(
        "--branch-speeds",
        type=v.integer_in(0, 1000),
        default=8,
        metavar="N",
        help="limit-cycle amplitude over speed: N simulations from 0.8 x the critical speed up "
        "(default 8; 0: none)",
    )
    p.add_argument("--no-simulation", action="store_true", help="linear stability only (no time histories)")
    p.add_argument("--no-intervals", action="store_true", help="skip the coefficients' intervals (Table 1)")
    p.add_argument("--no-progress", action="store_true", help="no progress lines on stderr")
    add_friction_option(p)
    add_input_options(p)
    add_touchdown_options(p)
    p.set_defaults(func=run)


class _Progress:
    """One line per stage on stderr, as ``fepost report`` prints them: the study's stages, then
    the writing of the folder (its figures) as the last one."""

    def __init__(self) -> None:
        self.total = 0

    def study(self, k: int, n: int, step: str, seconds: float) -> None:
        self.total = n + 1
        self._line(k, step, seconds)

    def writing(self, k: int, n: int, step: str, seconds: float) -> None:
        self._line(self.total, step, seconds)

    def _line(self, k: int, step: str, seconds: float) -> None:
        progress_line(k, self.total, step, seconds)


def summary(m) -> str:
    """One model's line on stdout: the verdict over the sweep, the critical speed (the first
    onset of instability) with its interval, and where an unstable range ends."""
    s = m.stability
    if s.critical_speed is None:
        return f"{m.name}: {s.summary()}"
    text = f"{m.name}: critical speed {s.critical_speed:.2f} m/s"
    ci = m.critical_speed_ci95
    if ci is not None:
        text += f" (95 % {ci[0]:.2f} to {ci[1]:.2f})"
    if len(s.boundaries) > 1 or s.unstable[0]:
        text += f"; {s.summary()}"
    return text


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..analysis import analyse
    from ..errors import ArgumentError
    from ..output import check_replaceable
    from ..shimmy import load_gear
    from ..shimmy.study import shimmy_study
    from ..shimmy.writer import write_shimmy
    from ._common import analysis_options
    from ._touchdown import check_touchdown, run_touchdowns, touchdown_line

    if args.speed_max <= args.speed_min:
        raise ArgumentError(
            f"argument --speed-max: must be above --speed-min ({args.speed_min:g}), got {args.speed_max:g}"
        )
    gear = load_gear(args.gear)  # a bad gear file fails before the FE work
    check_touchdown(args, gear)
    inputs = [args.static, args.rolling, args.gear]
    check_replaceable(args.out, inputs)
    result = analyse(args.static, args.rolling, friction=args.friction, options=analysis_options(args))
    progress = _Progress()
    study = shimmy_study(
        result,
        gear,
        speeds=np.linspace(args.speed_min, args.speed_max, args.speeds),
        models=args.models,
        intervals=not args.no_intervals,
        simulate_motion=not args.no_simulation,
        duration=args.duration,
        trails=args.trails,
        branch_speeds=args.branch_speeds,
        progress=None if args.no_progress else progress.study,
    )
    touchdowns = run_touchdowns(args, gear, result)
    write_shimmy(
        study,
        args.out,
        force=args.force,
        protect=inputs,
        progress=None if args.no_progress else progress.writing,
        touchdown=touchdowns,
    )
    for m in study.models:
        print(summary(m))
    for run_, _ in touchdowns:
        print(touchdown_line(run_))
    print(f"-> {args.out}/shimmy.json")
    return 0
