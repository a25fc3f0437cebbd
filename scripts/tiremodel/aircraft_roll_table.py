"""The rolling runs side by side: slip, longitudinal force, torque and fepost's k_x.

``python -m scripts.tiremodel.aircraft_roll_table [DIR]`` reads every
``roll_*.json`` in DIR (default meshes/rig-aircraft), analyses each rolled map
with fepost as the rolling partner of ``roll_static.vtu`` and prints a
Markdown table, with the sliding stand-in (meshes/aircraft: static_100 /
rolling_100) and the paper's k_x = 0.13 as the last rows.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PAPER_KX = 0.13


@dataclass(frozen=True)
class Row:
    name: str
    slip: float | None
    fx_over_n: float
    torque: float | None
    k_x: float
    x_c: float
    x_c_own: float | None  # the sidecar's exact face integral of the centre shift
    x_c_moment: float | None  # the shift from the solver's reactions: (T - h Fx) / Fz - static centre
    x_c_steady: tuple[float, ...]  # the own shift at the last three written times
    load_ratio: float  # N_rolling / N (fepost)


def analyse_run(static: Path, run_json: Path) -> Row:
    from fepost import analyse

    side = json.loads(run_json.read_text())
    res = analyse(static, run_json.with_suffix(".vtu"))
    c = res.coefficients
    force = side["reaction"]["force"]
    shifts = tuple(s["centre_of_pressure_shift_m"] for s in side["samples"][-3:])
    return Row(
        name=run_json.stem,
        slip=side["longitudinal_slip"],
        fx_over_n=force[0] / force[2],
        torque=side["axle_torque_Nm"],
        k_x=float(c.k_x),
        x_c=float(c.x_c),
        x_c_own=shifts[-1],
        x_c_moment=moment_shift(side),
        x_c_steady=shifts,
        load_ratio=float(c.N_rolling / c.N),
    )


def moment_shift(side: dict) -> float:
    """Centre-of-pressure shift (m) from the moment balance of the tire about the axle.

    The road's force acts at the road plane, h = axle height above it below the axle:
    the axle torque T balances h Fx + x_p Fz, so the pressure centre is at
    x_p = (T - h Fx) / Fz (axle frame); minus the static map's centre.
    """
    from .aircraft_geometry import AircraftParams

    h = AircraftParams().axle_z - side["rim_travel_z"]
    fx, _, fz = side["reaction"]["force"]
    return (side["axle_torque_Nm"] - h * fx) / fz - side["static_centre_of_pressure_x_m"]


def exact_centre(vtu: Path) -> float:
    """x (m) of the centre of pressure of a rolled map: the exact integral of p(xi) x(xi) over its
    deformed faces projected on the road, over that of p (``projected_integral`` with a weight)."""
    import meshio

    from .aircraft_roll_export import projected_integral

    m = meshio.read(vtu)
    quads = m.cells_dict["quad"]
    x = m.points + m.point_data["displacement"]
    cp = m.point_data["CPRESS"]
    return projected_integral(x, quads, cp, x[:, 0]) / projected_integral(x, quads, cp)


def rows(folder: Path) -> list[Row]:
    static = folder / "roll_static.vtu"
    runs = sorted(p for p in folder.glob("roll_*.json") if p.stem != "roll_static")
    out = [analyse_run(static, p) for p in runs]
    return sorted(out, key=lambda r: (r.slip is None, r.slip or 0.0))


def standin_row() -> Row:
    from fepost import analyse

    air = REPO / "meshes" / "aircraft"
    side = json.loads((air / "rolling_100.json").read_text())
    res = analyse(air / "static_100.vtu", air / "rolling_100.vtu")
    force = side["reaction_force_road"]
    c = res.coefficients
    return Row(
        name="aircraft/rolling_100 (slide)",
        slip=None,
        fx_over_n=force[0] / force[2],
        torque=None,
        k_x=float(c.k_x),
        x_c=float(c.x_c),
        x_c_own=None,
        x_c_moment=None,
        x_c_steady=(),
        load_ratio=float(c.N_rolling / c.N),
    )


def markdown(table: list[Row]) -> str:
    head = (
        "| run | slip κ | Fx/N | axle torque (kN m) | x_c fepost (mm) | x_c faces (mm) | x_c moments (mm) "
        "| k_x | N_roll/N |"
    )
    lines = [head, "|---|---|---|---|---|---|---|---|---|"]
    for r in table:
        slip = "–" if r.slip is None else f"{r.slip:+.3f}"
        torque = "–" if r.torque is None else f"{r.torque / 1e3:+.2f}"
        own = "–" if r.x_c_own is None else f"{1e3 * r.x_c_own:+.2f}"
        mom = "–" if r.x_c_moment is None else f"{1e3 * r.x_c_moment:+.2f}"
        lines.append(
            f"| `{r.name}` | {slip} | {r.fx_over_n:+.3f} | {torque} | {1e3 * r.x_c:+.2f} | {own} | {mom} "
            f"| {r.k_x:+.3f} | {r.load_ratio:.3f} |"
        )
    lines.append(f"| paper (steady rolling, its tire) | – | – | – | – | – | – | {PAPER_KX:+.3f} | – |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    folder = Path(args[0]) if args else REPO / "meshes" / "rig-aircraft"
    table = [*rows(folder), standin_row()]
    print(markdown(table))
    print()
    print("centre shift at the last three written times (mm, faces):")
    for r in table:
        if r.x_c_steady:
            print(f"  {r.name}: " + ", ".join(f"{1e3 * v:+.2f}" for v in r.x_c_steady))
    print()
    print("centre shift from the maps themselves, exact face integral of p(xi) x(xi) (mm):")
    x0 = exact_centre(folder / "roll_static.vtu")
    for r in table:
        if r.x_c_steady:
            shift = exact_centre(folder / f"{r.name}.vtu") - x0
            print(f"  {r.name}: {1e3 * shift:+.2f} (fepost {1e3 * r.x_c:+.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
