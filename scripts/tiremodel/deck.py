"""CalculiX input deck for the tire sector pressed onto a rigid road.

Node/element numbers in the deck are 1-based: tire nodes 1..n_tire, then the
road block's nodes; tire elements 1..e_tire, then the road's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .geometry import TireMesh, quads_to_faces

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


@dataclass
class Road:
    nodes: np.ndarray
    hexes: np.ndarray  # 0-based in road-local numbering
    top_faces: list[tuple[int, int]]  # (road element index, face number)


def build_road(half_x=0.40, half_y=0.26, thick=0.02, size=0.025) -> Road:
    nx, ny = int(round(2 * half_x / size)), int(round(2 * half_y / size))
    xs = np.linspace(-half_x, half_x, nx + 1)
    ys = np.linspace(-half_y, half_y, ny + 1)
    zs = np.array([-thick, 0.0])
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    nodes = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])

    def nid(i, j, k):
        return (i * (ny + 1) + j) * 2 + k

    hexes = []
    for i in range(nx):
        for j in range(ny):
            b = [nid(i, j, 0), nid(i + 1, j, 0), nid(i + 1, j + 1, 0), nid(i, j + 1, 0)]
            t = [nid(i, j, 1), nid(i + 1, j, 1), nid(i + 1, j + 1, 1), nid(i, j + 1, 1)]
            hexes.append(b + t)
    hexes = np.array(hexes)
    # face 2 (nodes 5-8) is the top face z = 0
    return Road(nodes, hexes, [(e, 2) for e in range(len(hexes))])


def _lines(vals, per=8):
    vals = list(vals)
    return "\n".join(", ".join(str(v) for v in vals[i : i + per]) for i in range(0, len(vals), per))


def write_deck(
    path,
    mesh: TireMesh,
    case: LoadCase,
    rim_travel: float,
    inflation_only: bool = False,
) -> dict:
    """Write the deck; ``rim_travel`` is the total downward rim displacement (m)."""
    p = mesh.params
    road = build_road()
    nt, et = mesh.nodes.shape[0], mesh.hexes.shape[0]
    out = []
    w = out.append
    w("*HEADING")
    w(f"fepost tire sector, case {case.name}")
    w("*NODE, NSET=NALL")
    for i, (x, y, z) in enumerate(mesh.nodes):
        w(f"{i + 1}, {x:.9e}, {y:.9e}, {z:.9e}")
    for i, (x, y, z) in enumerate(road.nodes):
        w(f"{nt + i + 1}, {x:.9e}, {y:.9e}, {z:.9e}")
    w("*ELEMENT, TYPE=C3D8I, ELSET=TIRE")
    for e, h in enumerate(mesh.hexes):
        w(f"{e + 1}, " + ", ".join(str(int(n) + 1) for n in h))
    w("*ELEMENT, TYPE=C3D8, ELSET=ROAD")
    for e, h in enumerate(road.hexes):
        w(f"{et + e + 1}, " + ", ".join(str(int(n) + nt + 1) for n in h))
    w("*NSET, NSET=BEAD")
    w(_lines(int(n) + 1 for n in mesh.bead_nodes))
    w("*NSET, NSET=ROADN")
    w(_lines(range(nt + 1, nt + road.nodes.shape[0] + 1)))
    w("*NSET, NSET=TIREN")
    w(_lines(range(1, nt + 1)))
    w("*SURFACE, NAME=STIRE, TYPE=ELEMENT")
    for e, k in quads_to_faces(mesh, mesh.contact_quads):
        w(f"{e + 1}, S{k}")
    w("*SURFACE, NAME=SROAD, TYPE=ELEMENT")
    for e, k in road.top_faces:
        w(f"{et + e + 1}, S{k}")
    w("*MATERIAL, NAME=CORDRUBBER")
    w("*ELASTIC")
    w(f"{E_RUBBER:.6e}, {NU_RUBBER}")
    w("*MATERIAL, NAME=ROADMAT")
    w("*ELASTIC")
    w("2.1e11, 0.3")
    w("*SOLID SECTION, ELSET=TIRE, MATERIAL=CORDRUBBER")
    w("*SOLID SECTION, ELSET=ROAD, MATERIAL=ROADMAT")
    # sector cut faces: tangential displacement equals the rim's (rigid-rim
    # cyclic condition): t . u_node - t . u_ref = 0, t = circumferential direction
    bead = set(int(n) for n in mesh.bead_nodes)
    ref = int(mesh.bead_nodes[0]) + 1
    w("*EQUATION")
    n_eq = 0
    for n in mesh.cut_nodes:
        n = int(n)
        if n in bead:
            continue
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
        n_eq += 1
    w("*SURFACE INTERACTION, NAME=SI")
    w("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR")
    w(f"{CONTACT_SLOPE:.6e}, {CONTACT_TENSION:.6e}")
    w("*FRICTION")
    w(f"{FRICTION}, {STICK_SLOPE:.6e}")
    w(f"*CONTACT PAIR, INTERACTION=SI, TYPE={CONTACT_TYPE}")
    w("STIRE, SROAD")
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
    for e, k in quads_to_faces(mesh, mesh.inner_quads):
        w(f"{e + 1}, P{k}, {PRESSURE:.6e}")
    outputs()
    w("*END STEP")
    if not inflation_only:
        # step 2: vertical rim travel (pressure kept)
        w("*STEP, NLGEOM, INC=400")
        w("*STATIC")
        w("0.05, 1.0, 1e-6, 0.1")
        w("*BOUNDARY")
        w(f"BEAD, 3, 3, {-rim_travel:.9e}")
        outputs()
        w("*END STEP")
        if case.roll_dx:
            w("*STEP, NLGEOM, INC=400")
            w("*STATIC")
            w("0.05, 1.0, 1e-6, 0.1")
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
