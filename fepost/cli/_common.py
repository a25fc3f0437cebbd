"""Options and helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TextIO

from ..errors import ArgumentError
from ..options import DEFAULT_FRICTION, FRICTION_RANGE, AnalysisOptions
from ..reader.units import SYSTEMS  # a light module: no numpy
from . import _validate as v


def summary_stream(*outputs: str | None) -> TextIO:
    """Where a command's human summary goes: standard error when one of its data ``outputs``
    is standard output (``-``, `fepost.output.STDOUT`), so that stdout holds the data alone."""
    return sys.stderr if any(o == "-" for o in outputs) else sys.stdout


def progress_line(k: int, n: int, step: str, seconds: float) -> None:
    """A long command's stage done, one line on standard error: ``[k/n] step ... done in 1.2 s``.

    The line and its newline go in one write: ``print`` writes them apart, and a signal
    handled in between (``fepost: terminated by SIGTERM``) would land on the same line."""
    sys.stderr.write(f"[{k}/{n}] {step} ... done in {seconds:.1f} s\n")
    sys.stderr.flush()


def output_name(path: str) -> str:
    """``path`` as a summary names it: ``standard output`` for ``-``."""
    return "standard output" if path == "-" else path


def repo_meshes() -> Path:
    """The sample meshes folder shipped beside the package (``<repo>/meshes``)."""
    return Path(__file__).resolve().parents[2] / "meshes"


def sample_mesh(name: str) -> Path:
    """Path of a shipped sample mesh; a one-line error if it is missing."""
    p = repo_meshes() / name
    if not p.is_file():
        raise ArgumentError(f"{p}: sample mesh not found (give the FE exports explicitly)")
    return p


def add_friction_option(p: argparse.ArgumentParser, what: str = "friction coefficient f") -> None:
    """``--friction F`` (default `fepost.options.DEFAULT_FRICTION`), for every command that needs f."""
    p.add_argument(
        "--friction",
        type=v.friction,
        default=DEFAULT_FRICTION,
        metavar="F",
        help=f"{what} in [{FRICTION_RANGE[0]:g}, {FRICTION_RANGE[1]:g}] (default {DEFAULT_FRICTION:g})",
    )


def add_input_options(p: argparse.ArgumentParser) -> None:
    """Reading, patch and grid options common to commands that read FE exports."""
    g = p.add_argument_group("reading and resampling")
    g.add_argument("--field", metavar="NAME", help="contact-pressure array (NAME:K for component K)")
    g.add_argument("--step", type=int, metavar="N", help="Exodus time step (default: last)")
    g.add_argument(
        "--displacement",
        default="auto",
        metavar="NAME",
        help="nodal displacement array added to the coordinates ('auto' default, 'none' to skip)",
    )
    g.add_argument(
        "--units",
        metavar="SYSTEM",
        help="the model's consistent unit system, converted to SI on reading: "
        + ", ".join(s.name for s in SYSTEMS)
        + " (aliases mm-t-s, mm-kg-ms, ...); default: SI, with implausible scales refused",
    )
    g.add_argument(
        "--surface",
        metavar="NAME",
        help="take the contact faces from this Exodus side set or element block (name or id)",
    )
    g.add_argument("--rolling-axis", metavar="X,Y,Z", help="global rolling direction (default 1,0,0)")
    g.add_argument(
        "--allow-load-mismatch",
        action="store_true",
        help="accept a rolling map whose load differs from the static map's by more than 3 %% "
        "(recorded in the outputs; k_x then mixes two loads)",
    )
    g.add_argument(
        "--threshold",
        type=v.fraction,
        default=v.LibraryDefault("fepost.patch", "DEFAULT_THRESHOLD"),
        help="loaded if pressure > THRESHOLD x peak (default %(default)s)",
    )
    g.add_argument(
        "--nr",
        type=v.radial_nodes,
        default=v.LibraryDefault("fepost.polar", "DEFAULT_NR"),
        help="radial grid nodes (default %(default)s)",
    )
    g.add_argument(
        "--nphi",
        type=v.angular_nodes,
        default=v.LibraryDefault("fepost.polar", "DEFAULT_NPHI"),
        help="angular grid nodes (default %(default)s)",
    )
    g.add_argument("--rule", choices=("gauss", "trapezoid"), default="gauss", help="radial quadrature rule")


def analysis_options(args: argparse.Namespace) -> AnalysisOptions:
    """The `AnalysisOptions` of a command's reading, grid and pairing options (validated:
    an unknown unit system or a bad rolling axis fails here, before any file is read)."""
    axis = None
    if args.rolling_axis:
        try:
            axis = tuple(float(v) for v in args.rolling_axis.split(","))
        except ValueError:
            raise ArgumentError(
                f"--rolling-axis must be three numbers X,Y,Z, got {args.rolling_axis!r}"
            ) from None
        if len(axis) != 3:
            raise ArgumentError(f"--rolling-axis must be three numbers X,Y,Z, got {args.rolling_axis!r}")
    disp = None if str(args.displacement).lower() == "none" else args.displacement
    return AnalysisOptions(
        field=args.field,
        step=args.step,
        displacement=disp,
        units=args.units,
        surface=args.surface,
        nr=args.nr,
        nphi=args.nphi,
        rule=args.rule,
        threshold=args.threshold,
        rolling_axis=axis,  # type: ignore[arg-type]
        allow_load_mismatch=bool(args.allow_load_mismatch),
        inflation_pressure=getattr(args, "inflation_pressure", None),
    )
