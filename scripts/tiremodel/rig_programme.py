"""The slide/spin programme on the small stand-in tire: which runs, in which order, and the driver.

Runs (names ``d<direction>_a<spin angle><sign>``): the sliding direction
0, 45 and 90 degrees from +x, the spin angle a with |v| = S cos a and
|wz| R_REF = S sin a (a = 0 pure sliding, 90 pure spin) and both spin signs.
The order puts the runs that differ physically first: at 0 and 90 degrees
the negative spin is the mirror image of the positive one (the tire is
symmetric about x = 0 and y = 0), so those runs come last, as a symmetry
check. A finished run in the work folder is reused.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from pathlib import Path

from . import deck as dk
from . import rig_deck as rd
from .geometry import TireParams, build_mesh, coarse_params
from .rig_export import write_run, write_static
from .rig_run import check_on_road, inflation_rim_travel, solve_base, solve_run
from .solve import ccx_version, find_ccx

SPIN_ANGLES = (40.0, 60.0, 20.0, 75.0)  # combined runs, degrees
DIRECTIONS = (0.0, 45.0, 90.0)


def run_name(direction: float, angle: float, sign: int) -> str:
    if angle == 90.0:
        return f"spin_{'p' if sign > 0 else 'n'}"
    if angle == 0.0:
        return f"d{direction:03.0f}_slide"
    return f"d{direction:03.0f}_a{angle:02.0f}{'p' if sign > 0 else 'n'}"


def programme() -> list[tuple[str, float, float, int]]:
    """(name, direction, spin angle, spin sign) of every run, in solving order."""
    runs = [(0.0, 0.0, 1), (0.0, 90.0, 1), (45.0, 0.0, 1), (90.0, 0.0, 1)]
    for a in SPIN_ANGLES:
        runs += [(0.0, a, 1), (45.0, a, 1), (45.0, a, -1), (90.0, a, 1)]
    # the tire is symmetric about the planes x = 0 and y = 0: at 0 and 90 degrees the
    # negative spin is the mirror image of the positive one (a symmetry check, solved last)
    for a in SPIN_ANGLES:
        runs += [(0.0, a, -1), (90.0, a, -1)]
    runs.append((0.0, 90.0, -1))
    return [(run_name(d, a, s), d, a, s) for d, a, s in runs]


def mesh_params(kind: str) -> TireParams:
    """``tiny`` (the programme and the tests), ``coarse`` (the convergence check) or ``full``."""
    if kind == "tiny":
        return TireParams(n_crown=4, n_shoulder=2, n_side=2, n_wall=1, n_fine=8, n_coarse=2)
    if kind == "coarse":
        return coarse_params()
    if kind == "full":
        return TireParams()
    raise ValueError(f"unknown mesh {kind!r} (tiny, coarse, full)")


def run_programme(
    out: Path,
    work: Path,
    *,
    mesh_kind: str = "tiny",
    inc: float = 0.1,
    base_inc: str | None = None,
    only: list[str] | None = None,
    log: Callable[[str], None] = lambda s: print(s, file=sys.stderr, flush=True),
) -> list[dict]:
    """Solve (or reuse) and export the runs ``only`` (default: the whole programme).

    ``inc``: the slides' largest increment; ``base_inc``: the ``*STATIC`` line of the base's
    vertical travel (default the small tire's, `rig_deck.SMALL`), recorded in the sidecars
    when given."""
    exe = find_ccx()
    params = mesh_params(mesh_kind)
    mesh = build_mesh(params)
    rim_travel, clearance, t_infl = inflation_rim_travel(mesh, work, exe)
    log(f"rig: inflation pre-run {t_infl:.0f} s, clearance {clearance * 1e3:.2f} mm")
    base = solve_base(mesh, rim_travel, work / "base", exe, vertical_inc=base_inc)
    log(f"rig: base run (inflation + vertical load) {base.runtime_s:.0f} s")
    info = {
        "solver": ccx_version(exe),
        "mesh": {
            "name": mesh_kind,
            "tire_nodes": int(mesh.nodes.shape[0]),
            "tire_elements": int(mesh.hexes.shape[0]),
            "element_type": "C3D8I",
            "contact_faces": int(mesh.contact_quads.shape[0]),
            "n_crown": params.n_crown,
            "n_shoulder": params.n_shoulder,
            "n_fine": params.n_fine,
        },
        "model": {
            "deflection": 0.029,
            "rim_travel_z": round(rim_travel, 9),
            "inflation_pressure": dk.PRESSURE,
            "youngs_modulus": dk.E_RUBBER,
            "poisson_ratio": dk.NU_RUBBER,
            "contact": f"node-to-surface penalty, {dk.CONTACT_SLOPE:.3g} Pa/m; Coulomb friction "
            f"{dk.FRICTION}, stick slope {dk.STICK_SLOPE:.3g} Pa/m",
            "road": "rigid body (*RIGID BODY), held at its reference and rotation nodes; the rim moves",
            "slide_path": rd.SLIDE_PATH,
            "r_ref": rd.R_REF,
            "max_increment": inc,
            "slide_steps": rd.substeps(inc),
        },
    }
    if base_inc is not None:
        info["model"]["base_vertical_increments"] = base_inc
    runs = programme()
    if only:
        runs = [r for r in runs if r[0] in only]
    check_on_road(
        mesh, base, rd.SMALL.road(), {n: rd.kinematics(d, a, s) for n, d, a, s in runs}, rd.SLIDE_PATH, log
    )
    sides = []
    for name, d, a, s in runs:
        kin = rd.kinematics(d, a, s)
        t0 = time.perf_counter()
        res = solve_run(mesh, base, name, kin, rim_travel, work / name, exe, inc)
        if not (out / "static.json").exists():
            write_static(mesh, res, out, info)
        side = write_run(mesh, res, out, {**info, "direction_deg": d, "spin_angle_deg": a, "spin_sign": s})
        f = side["reaction"]["force"]
        log(
            f"rig: {name}: F = ({f[0]:.0f}, {f[1]:.0f}, {f[2]:.0f}) N, Mz = "
            f"{side['history']['Mz'][-1]:.1f} N m, solve {res.runtime_s:.0f} s "
            f"(wall {time.perf_counter() - t0:.0f} s)"
        )
        sides.append(side)
    return sides
