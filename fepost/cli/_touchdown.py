"""``fepost shimmy ... --touchdown SPEEDS``: the touchdown runs of the shimmy command.

The options, the gear's check before any FE work, the runs on the brush tire of the
static map (`fepost.shimmy.touchdown`), and their lines on the console. Light at
import, as every command module: the work is imported inside the functions.
"""

from __future__ import annotations

import argparse
import math
import sys

from ._validate import number_in


def _numbers(lo: float, hi: float, unit: str):
    def parse(text: str) -> tuple[float, ...]:
        out = []
        for part in str(text).split(","):
            part = part.strip()
            try:
                value = float(part)
            except ValueError:
                raise argparse.ArgumentTypeError(
                    f"must be a comma-separated list of numbers, got {part!r}"
                ) from None
            if not (math.isfinite(value) and lo <= value <= hi):
                raise argparse.ArgumentTypeError(
                    f"each value must be in [{lo:g}, {hi:g}] {unit}, got {part!r}"
                )
            out.append(value)
        return tuple(dict.fromkeys(out))

    return parse


def add_touchdown_options(p: argparse.ArgumentParser) -> None:
    """The touchdown's options of ``fepost shimmy``."""
    g = p.add_argument_group("touchdown (docs/touchdown.md; the gear file needs the touchdown's parameters)")
    g.add_argument(
        "--touchdown",
        type=_numbers(1.0, 200.0, "m/s"),
        metavar="SPEEDS",
        help="simulate the touchdown at these landing speeds (m/s, comma-separated): wheels at rest, "
        "load building up at the sink rate, spin-up on the brush tire of the static map",
    )
    g.add_argument(
        "--sink-rates",
        type=_numbers(0.05, 10.0, "m/s"),
        default=(1.5,),
        metavar="LIST",
        help="sink rates (m/s, comma-separated; default 1.5)",
    )
    g.add_argument(
        "--touchdown-yaw",
        type=_numbers(-20.0, 20.0, "degrees"),
        default=(0.5,),
        metavar="LIST",
        help="initial strut torsion (degrees, comma-separated; default 0.5)",
    )
    g.add_argument(
        "--crab",
        type=_numbers(-20.0, 20.0, "degrees"),
        default=(0.0,),
        metavar="LIST",
        help="crab angles (degrees, comma-separated; default 0)",
    )
    g.add_argument(
        "--touchdown-duration",
        type=number_in(0.05, 60.0),
        default=2.0,
        metavar="T",
        help="simulated seconds per touchdown (default 2)",
    )


def check_touchdown(args: argparse.Namespace, gear) -> None:
    """Refuse a touchdown the gear file cannot give, before the FE work (one line, exit 2)."""
    from ..shimmy.touchdown import check_gear

    if getattr(args, "touchdown", None):
        check_gear(gear, str(args.gear))


def run_touchdowns(args: argparse.Namespace, gear, analysis) -> list:
    """[(Touchdown, csv name)] over speeds x sink rates x yaws x crabs; a line per run on stderr."""
    import time

    from ..friction.quadrature import PressureQuadrature
    from ..shimmy.touchdown import GRID, simulate_touchdown, touchdown_tire

    if not getattr(args, "touchdown", None):
        return []
    tire = touchdown_tire(
        gear,
        PressureQuadrature.from_polar(analysis.static_map),
        analysis.coefficients.f,
        nx=GRID[0],
        ny=GRID[1],
    )
    cases = [
        (v, s, y, c)
        for v in args.touchdown
        for s in args.sink_rates
        for y in args.touchdown_yaw
        for c in args.crab
    ]
    out = []
    for k, (v, s, y, c) in enumerate(cases, 1):
        t0 = time.perf_counter()
        run = simulate_touchdown(
            gear,
            tire,
            v,
            sink_rate=s,
            yaw=math.radians(y),
            crab=math.radians(c),
            duration=args.touchdown_duration,
        )
        out.append((run, f"touchdown_{k:02d}.csv"))
        if not args.no_progress:
            print(
                f"[touchdown {k}/{len(cases)}] {v:g} m/s ... done in {time.perf_counter() - t0:.1f} s",
                file=sys.stderr,
                flush=True,
            )
    return out


def touchdown_line(run) -> str:
    """One run's line on stdout."""
    head = (
        f"touchdown {run.speed:g} m/s, sink {run.sink_rate:g} m/s, yaw {math.degrees(run.yaw):g} deg, "
        f"crab {math.degrees(run.crab):g} deg: "
    )
    if run.spin_up_time is None:
        return head + "still spinning up at the end of the run"
    return (
        head + f"spun up in {run.spin_up_time:.3f} s, {run.verdict} (largest torsion {run.amplitude:.3g} rad)"
    )
