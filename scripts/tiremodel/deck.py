"""CalculiX input deck for the tire sector pressed onto a rigid road.

Node/element numbers in the deck are 1-based: tire nodes 1..n_tire, then the
road block's nodes; tire elements 1..e_tire, then the road's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import ccxdeck as cx
from .geometry import TireMesh
from .meshing import face_lookup

PRESSURE = 2.0e5  # Pa, inflation pressure (the paper's P*)
FRICTION = 0.3
E_RUBBER = 100.0e6  # Pa, linear-elastic cord-rubber equivalent
NU_RUBBER = 0.45
CONTACT_SLOPE = 5.0e9  # Pa/m, penalty stiffness (pressure per overclosure)
CONTACT_TENSION = 1.0  # Pa, node-to-surface tension limit at large clearance (sigma_inf)
CONTACT_TYPE = "NODE TO SURFACE"
STICK_SLOPE = 5.0e8  # Pa/m, tangential penalty (stick) stiffness


@dataclass(frozen=True)
class LoadCase:
    name: str
    deflection: float  # m, rim travel beyond first contact of the inflated tire
    roll_dx: float = 0.0  # m, longitudinal rim displacement after the vertical step (+x)
    description: str = ""


CASES = {
    "static": LoadCase("static", 0.029, 0.0, "inflation, then vertical rim travel of 29 mm"),
    "rolling": LoadCase(
        "rolling",
        0.029,
        0.010,
        "quasi-static stand-in for rolling: the static case, then a +x rim displacement "
        "with friction active (no inertia, no rotation, no hysteresis)",
    ),
    "heavy": LoadCase("heavy", 0.060, 0.0, "inflation, then vertical rim travel of 60 mm"),
}


#: CalculiX's ``*STATIC`` line of the load steps after inflation (vertical travel, roll):
#: first increment, step length, smallest and largest increment. The full mesh's: at least
#: ten increments.
FINE_INC = "0.05, 1.0, 1e-6, 0.1"
#: The coarse mesh's (tests, quick looks): increments of a quarter of the step. On the coarse
#: static case the road's reaction is that of `FINE_INC` within 0.02 % (13 034 N against
#: 13 031 N) in 4 increments instead of 12: 17 s of CalculiX instead of 32.
COARSE_INC = "0.25, 1.0, 1e-6, 0.5"


def cut_nodes(mesh: TireMesh) -> list[int]:
    """0-based indices of the sector cut-face nodes that carry an equation (bead nodes excluded)."""
    bead = set(int(n) for n in mesh.bead_nodes)
    return [int(n) for n in mesh.cut_nodes if int(n) not in bead]


def model_lines(mesh: TireMesh, title: str, road=None, cut_refs: int | None = None) -> list[str]:
    """Deck lines of the model (nodes, elements, sets, surfaces, materials, cyclic
    equations, contact pair), everything before the boundary conditions and steps.

    ``road``: the road block (default ``ccxdeck.build_road()``). ``cut_refs``:
    if given, each cut-face node gets its own reference node (numbers from
    ``cut_refs`` on, in the order of ``cut_nodes``, at the cut node's position,
    set CUTREF) instead of the one bead node, so that a rigid motion of the rim
    that is not a rotation about the axle can be prescribed at the cut faces too.
    """
    road = cx.build_road() if road is None else road
    nt, et = mesh.nodes.shape[0], mesh.hexes.shape[0]
    out = []
    w = out.append
    w("*HEADING")
    w(title)
    out += cx.node_block(mesh.nodes, road)
    out += cx.element_block("C3D8I", "TIRE", range(1, et + 1), mesh.hexes)
    out += cx.road_elements(road, nt, et)
    out += cx.node_sets({"BEAD": (int(n) + 1 for n in mesh.bead_nodes), **cx.tire_road_sets(nt, road)})
    table = face_lookup(mesh.hexes)
    out += cx.contact_surfaces(mesh.hexes, mesh.contact_quads, road, table)
    w("*MATERIAL, NAME=CORDRUBBER")
    w("*ELASTIC")
    w(f"{E_RUBBER:.6e}, {NU_RUBBER}")
    out += cx.ROAD_MATERIAL
    w("*SOLID SECTION, ELSET=TIRE, MATERIAL=CORDRUBBER")
    w(cx.ROAD_SECTION)
    out += cut_equations(mesh, cut_refs)
    out += cx.contact_pair(CONTACT_SLOPE, CONTACT_TENSION, FRICTION, STICK_SLOPE, CONTACT_TYPE)
    return out


def cut_equations(mesh, cut_refs: int | None = None) -> list[str]:
    """Sector cut faces: tangential displacement equals the rim's (rigid-rim cyclic condition).

    t . u_node - t . u_ref = 0, t = circumferential direction; the reference is
    the first bead node, or with ``cut_refs`` each cut node's own reference node
    (see ``model_lines``).
    """
    p = mesh.params
    out: list[str] = []
    w = out.append
    ref = int(mesh.bead_nodes[0]) + 1
    if cut_refs is not None:
        w("*NODE, NSET=CUTREF")
        for i, n in enumerate(cut_nodes(mesh)):
            x, y, z = mesh.nodes[n]
            w(f"{cut_refs + i}, {x:.9e}, {y:.9e}, {z:.9e}")
    w("*EQUATION")
    for i, n in enumerate(cut_nodes(mesh)):
        if cut_refs is not None:
            ref = cut_refs + i
        x, _, z = mesh.nodes[n]
        rx, rz = x, z - p.axle_z
        rr = math.hypot(rx, rz)
        tx, tz = rz / rr, -rx / rr
        terms = [(1, tx), (3, tz)]
        if abs(tz) > abs(tx):
            terms.reverse()
        w("4")
        (d1, c1), (d2, c2) = terms
        w(f"{n + 1}, {d1}, {c1:.9f}, {n + 1}, {d2}, {c2:.9f}, ")
        out[-1] += f"{ref}, {d1}, {-c1:.9f}, {ref}, {d2}, {-c2:.9f}"
    return out


def write_deck(
    path,
    mesh: TireMesh,
    case: LoadCase,
    rim_travel: float,
    inflation_only: bool = False,
    increments: str = FINE_INC,
) -> dict:
    """Write the deck; ``rim_travel`` is the total downward rim displacement (m);
    ``increments``: the ``*STATIC`` line of the load steps after inflation."""
    road = cx.build_road()
    nt, et = mesh.nodes.shape[0], mesh.hexes.shape[0]
    out = model_lines(mesh, f"fepost tire sector, case {case.name}", road)
    w = out.append
    n_eq = len(cut_nodes(mesh))
    table = face_lookup(mesh.hexes)
    w("*BOUNDARY")
    w("ROADN, 1, 3")
    w("BEAD, 1, 3")

    def outputs():
        w("*NODE FILE, NSET=TIREN")
        w("U")
        w("*CONTACT FILE")
        w("CDIS, CSTR")
        w("*NODE PRINT, NSET=ROADN, TOTALS=ONLY")
        w("RF")
        w("*NODE PRINT, NSET=BEAD, TOTALS=ONLY")
        w("RF")

    # step 1: inflation
    w("*STEP, NLGEOM, INC=400")
    w("*STATIC")
    w("0.25, 1.0, 1e-5, 0.5")
    w("*DLOAD")
    out += cx.pressure_load(mesh.hexes, mesh.inner_quads, PRESSURE, table)
    outputs()
    w("*END STEP")
    if not inflation_only:
        # step 2: vertical rim travel (pressure kept)
        w("*STEP, NLGEOM, INC=400")
        w("*STATIC")
        w(increments)
        w("*BOUNDARY")
        w(f"BEAD, 3, 3, {-rim_travel:.9e}")
        outputs()
        w("*END STEP")
        if case.roll_dx:
            w("*STEP, NLGEOM, INC=400")
            w("*STATIC")
            w(increments)
            w("*BOUNDARY")
            w(f"BEAD, 1, 1, {case.roll_dx:.9e}")
            w(f"BEAD, 3, 3, {-rim_travel:.9e}")
            outputs()
            w("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return {
        "tire_nodes": nt,
        "tire_elements": et,
        "road_nodes": int(road.nodes.shape[0]),
        "road_elements": int(road.hexes.shape[0]),
        "equations": n_eq,
    }
