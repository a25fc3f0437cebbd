"""CLI: python -m scripts.tiremodel build|aircraft ...

- ``build --case static|rolling|heavy|all [--coarse] [--out DIR]``: the small
  sample tire (meshes/*.vtu, the test data);
- ``aircraft [--coarse] [--out DIR] [--jobs N]``: the aircraft main-gear tire
  (meshes/aircraft/: load sweep 25-150 % of the rated load and the rolling
  stand-in at the rated load);
- ``rig [--mesh coarse|tiny|full] [--only RUN ...] [--out DIR] [--work DIR]``:
  the slide/spin programme on the small tire (meshes/rig/: the road moves
  rigidly with a sliding velocity and a spin, Coulomb friction 0.3);
- ``rig-aircraft [--mesh rig|fine|whole|whole-fine|whole-fine-r|whole-xfine|whole-xfine-i|whole-xxfine]
  [--inc F] [--path S] [--friction MU] [--only RUN ...] [--out DIR] --work DIR
  [--workers N | --scheduler ADDRESS]``:
  the slide/spin programme on the aircraft tire (the +-70 degree sector: meshes/rig-aircraft/; the whole tire:
  meshes/rig-tire360/), resumable, its runs as Dask tasks;
- ``roll --work DIR [--only RUN ...] [--out DIR] [--scheduler ADDRESS]``: the
  aircraft tire rolling quasi-statically (free, braking, driving; meshes/rig-aircraft/roll_*);
- ``check-elements``: tip deflection of a rubber cantilever (C3D8I / C3D8,
  K/G = 100 / 1000) against Timoshenko's beam, the locking check behind the
  element choice.

Outputs go to ``--out DIR`` if given, else to ``out/tiremodel/<folder>`` (ignored by git);
only ``--update`` rewrites the tracked folder under ``meshes/`` named above.
Every case is solved in a temporary folder; the exported files are moved into
``--out`` only when all requested cases have succeeded, so a failed or
interrupted run leaves existing results untouched. Problems (no ``ccx``, no
convergence) are reported in one line on stderr with a non-zero exit status.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

from . import deck as dk
from .solve import ModelError, find_ccx

REPO = Path(__file__).resolve().parents[2]


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m scripts.tiremodel", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build", help="mesh, solve with CalculiX and export sample results")
    b.add_argument("--case", choices=[*dk.CASES, "all"], default="all")
    b.add_argument("--coarse", action="store_true", help="cheap mesh (tests, quick looks)")
    _out_options(b, "meshes")
    b.add_argument("--keep", type=Path, default=None, help="also copy the CalculiX work files here")
    b.add_argument("--threads", type=int, default=2)
    b.add_argument("--debug", action="store_true", help="show tracebacks")
    a = sub.add_parser(
        "aircraft", help="aircraft main-gear tire: load sweep + rolling stand-in (meshes/aircraft/)"
    )
    a.add_argument("--coarse", action="store_true", help="solve the sweep on the coarse mesh (quick look)")
    _out_options(a, "meshes/aircraft")
    a.add_argument("--jobs", type=int, default=2, help="CalculiX runs at a time (one thread each)")
    a.add_argument(
        "--work",
        type=Path,
        default=None,
        help="keep the CalculiX files here; runs already completed there with the same deck are reused",
    )
    a.add_argument("--debug", action="store_true", help="show tracebacks")
    r = sub.add_parser("rig", help="slide/spin programme on the small tire (meshes/rig/)")
    r.add_argument("--mesh", choices=["tiny", "coarse", "full"], default="tiny")
    r.add_argument("--inc", type=float, default=0.1, help="largest increment of the slide step")
    r.add_argument("--only", nargs="+", default=None, help="solve only these runs (names)")
    _out_options(r, "meshes/rig")
    r.add_argument(
        "--work", type=Path, required=True, help="CalculiX work folder; finished runs there are reused"
    )
    r.add_argument("--debug", action="store_true", help="show tracebacks")
    ra = sub.add_parser(
        "rig-aircraft", help="slide/spin programme on the aircraft tire (meshes/rig-aircraft/)"
    )
    ra.add_argument(
        "--mesh",
        choices=[
            "rig",
            "fine",
            "whole",
            "whole-fine",
            "whole-fine-r",
            "whole-fine-ring",
            "whole-xfine",
            "whole-xfine-i",
            "whole-xxfine",
            "whole-tiny",
            "whole-test",
        ],
        default="rig",
        help="rig, fine: the +-70 degree sector (meshes/rig-aircraft/); whole, whole-fine: the whole "
        "360-degree tire (meshes/rig-tire360/; whole-xfine: its finer partner, "
        "meshes/rig-tire360/xfine/; whole-fine-r: whole-fine with C3D8R in its plain band; "
        "whole-fine-ring: its band closed round the patch; whole-xfine-i: whole-xfine with no band, C3D8I "
        "in all the rubber; whole-xxfine: one step finer again, static map only); whole-tiny, whole-test: "
        "tiny versions",
    )
    ra.add_argument("--inc", type=float, default=0.1, help="largest increment of the slide step")
    ra.add_argument(
        "--only",
        nargs="+",
        default=None,
        help="solve only these runs, in this order (names; static: the base alone)",
    )
    ra.add_argument(
        "--path", type=float, default=None, help="reference path S of every slide, m (default: 0.30)"
    )
    ra.add_argument(
        "--friction",
        type=float,
        default=None,
        help="Coulomb coefficient of base and runs (default 0.3; 0: frictionless, the mu = 0 "
        "check); the base differs: give it a --work of its own",
    )
    _out_options(ra, "meshes/rig-aircraft (meshes/rig-tire360 for the whole tire)")
    ra.add_argument(
        "--work", type=Path, required=True, help="CalculiX work folder; finished solves there are reused"
    )
    ra.add_argument("--workers", type=int, default=2, help="local Dask workers (one thread each)")
    ra.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler")
    ra.add_argument("--debug", action="store_true", help="show tracebacks")
    ro = sub.add_parser("roll", help="aircraft tire rolling: free, braking, driving (rig-aircraft/roll_*)")
    _out_options(ro, "meshes/rig-aircraft")
    ro.add_argument("--work", type=Path, required=True, help="CalculiX work folder; finished solves reused")
    ro.add_argument("--only", nargs="+", default=None, help="solve only these runs (names, e.g. roll_free)")
    ro.add_argument("--scheduler", default=None, help="Dask scheduler ADDRESS (default: one local worker)")
    ro.add_argument("--debug", action="store_true", help="show tracebacks")
    c = sub.add_parser("check-elements", help="cantilever check of the rubber elements against Timoshenko")
    c.add_argument("--debug", action="store_true", help="show tracebacks")
    return ap


def _out_options(p: argparse.ArgumentParser, tracked: str) -> None:
    """``--out DIR`` and ``--update``: outputs go to out/tiremodel/... unless the user names a
    folder or asks, with ``--update``, to rewrite the tracked files under meshes/."""
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default: out/tiremodel/..., beside the tracked folder's name)",
    )
    p.add_argument(
        "--update",
        action="store_true",
        help=f"write into the tracked folder {tracked} (rewrites committed files)",
    )


def out_folder(args: argparse.Namespace) -> Path:
    """Where a command writes: ``--out``, else with ``--update`` the tracked folder under meshes/,
    else the same name under out/tiremodel/ (ignored by git): a clean clone's tracked files stay."""
    if args.out is not None:
        if args.update:
            raise ValueError("--out and --update: give one (--update writes the tracked folder)")
        return args.out
    if args.command == "build":
        sub = ""
    elif args.command == "aircraft":
        sub = "aircraft"
    elif args.command == "rig":
        sub = "rig"
    elif args.command == "rig-aircraft" and args.mesh.startswith("whole"):
        sub = "rig-tire360"
    else:  # rig-aircraft on the sector, roll
        sub = "rig-aircraft"
    return (REPO / "meshes" / sub) if args.update else (REPO / "out" / "tiremodel" / (sub or "meshes"))


def build(
    cases: list[str], coarse: bool, out: Path, keep: Path | None = None, threads: int = 2
) -> list[dict]:
    from .export import write_case
    from .geometry import TireParams, build_mesh, coarse_params
    from .solve import solve_case

    find_ccx()  # fail fast, before meshing
    params = coarse_params() if coarse else TireParams()
    mesh = build_mesh(params)
    sides = []
    with tempfile.TemporaryDirectory(prefix="tiremodel-") as tmp:
        tmp = Path(tmp)
        stage = tmp / "export"
        for name in cases:
            print(
                f"tiremodel: solving {name} ({'coarse' if coarse else 'full'} mesh) ...",
                file=sys.stderr,
            )
            try:
                steps = dk.COARSE_INC if coarse else dk.FINE_INC
                res = solve_case(mesh, dk.CASES[name], tmp / name, threads=threads, increments=steps)
            finally:
                if keep is not None and (tmp / name).exists():
                    shutil.copytree(tmp / name, keep / name, dirs_exist_ok=True)
            side = write_case(res, stage)
            print(
                f"tiremodel: {name}: reaction_z = {side['reaction_z']:.1f} N, "
                f"CPRESS integral = {side['cpress_integral']:.1f} N, {side['runtime_s']:.0f} s",
                file=sys.stderr,
            )
            sides.append(side)
        out.mkdir(parents=True, exist_ok=True)
        for f in sorted(stage.iterdir()):
            tmp_target = out / (f.name + ".part")
            shutil.copy2(f, tmp_target)
            os.replace(tmp_target, out / f.name)
    return sides


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.command == "check-elements":
            from .element_check import main as check_main

            return check_main()
        if args.command == "rig":
            from .rig_programme import run_programme

            run_programme(out_folder(args), args.work, mesh_kind=args.mesh, inc=args.inc, only=args.only)
            return 0
        if args.command == "rig-aircraft":
            from .aircraft_rig_deck import AIRCRAFT
            from .aircraft_rig_programme import run_programme as run_aircraft_programme

            run_aircraft_programme(
                out_folder(args),
                args.work,
                mesh_kind=args.mesh,
                inc=args.inc,
                path=AIRCRAFT.slide_path if args.path is None else args.path,
                friction=args.friction,
                only=args.only,
                workers=None if args.scheduler else args.workers,
                scheduler=args.scheduler,
            )
            return 0
        if args.command == "roll":
            from .aircraft_roll_programme import programme, run_programme

            names = [s.name for s in programme()]
            unknown = sorted(set(args.only or ()) - set(names))
            if unknown:
                msg = f"--only: no run {unknown[0]!r} (runs: {', '.join(names)})"
                print(f"tiremodel: error: {msg}", file=sys.stderr)
                return 2
            specs = [s for s in programme() if args.only is None or s.name in args.only]
            run_programme(out_folder(args), args.work, specs, scheduler=args.scheduler)
            return 0
        if args.command == "aircraft":
            from .aircraft_build import build_aircraft

            build_aircraft(out_folder(args), coarse=args.coarse, jobs=args.jobs, work=args.work)
        else:
            cases = list(dk.CASES) if args.case == "all" else [args.case]
            build(cases, args.coarse, out_folder(args), args.keep, args.threads)
    except ModelError as exc:
        if args.debug:
            raise
        print(f"tiremodel: error: {exc}", file=sys.stderr)
        return 1
    except ModuleNotFoundError as exc:  # gmsh, ccx2paraview: the 'model' extra
        if args.debug:
            raise
        hint = "install the model extra: pip install -e '.[model]'"
        print(f"tiremodel: error: no Python module {exc.name!r}: {hint}", file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - one-line report for the CLI
        if args.debug:
            raise
        print(f"tiremodel: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
