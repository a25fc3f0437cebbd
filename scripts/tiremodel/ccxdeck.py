"""CalculiX input-deck pieces shared by the small sample tire and the aircraft tire.

Both decks press a tire mesh onto a rigid steel road block with node-to-surface
penalty contact and Coulomb friction. Numbering is the same in both: tire
nodes 1..n_tire, then the road's nodes; tire elements 1..e_tire, then the
road's. Every function here returns the deck lines (without newlines); the
load steps and the tire's materials are each model's own.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from .meshing import quads_to_faces

# the road block: steel, far stiffer than any tire
ROAD_MATERIAL = ("*MATERIAL, NAME=ROADMAT", "*ELASTIC", "2.1e11, 0.3")
ROAD_SECTION = "*SOLID SECTION, ELSET=ROAD, MATERIAL=ROADMAT"


@dataclass
class Road:
    nodes: np.ndarray  # (n, 3) float, m
    hexes: np.ndarray  # (e, 8) int, 0-based in road-local numbering
    top_faces: list[tuple[int, int]]  # (road element index, face number)


def build_road(half_x=0.40, half_y=0.26, thick=0.02, size=0.025) -> Road:
    """One layer of hexahedra on |x| <= half_x, |y| <= half_y, -thick <= z <= 0 (m), faces ~ ``size``."""
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


def data_lines(vals: Iterable, per: int = 8) -> str:
    """Comma-separated values, ``per`` to a line."""
    vals = list(vals)
    return "\n".join(", ".join(str(v) for v in vals[i : i + per]) for i in range(0, len(vals), per))


def node_block(tire_nodes: np.ndarray, road: Road) -> list[str]:
    """``*NODE`` card (set NALL) with the tire's nodes, then the road's."""
    nt = tire_nodes.shape[0]
    out = ["*NODE, NSET=NALL"]
    for i, (x, y, z) in enumerate(tire_nodes):
        out.append(f"{i + 1}, {x:.9e}, {y:.9e}, {z:.9e}")
    for i, (x, y, z) in enumerate(road.nodes):
        out.append(f"{nt + i + 1}, {x:.9e}, {y:.9e}, {z:.9e}")
    return out


def element_block(
    etype: str, elset: str, numbers: Iterable[int], hexes: np.ndarray, first_node: int = 1
) -> list[str]:
    """``*ELEMENT`` card: element ``numbers`` (1-based) with the 0-based ``hexes`` rows,
    whose node indices are shifted to start at ``first_node``."""
    out = [f"*ELEMENT, TYPE={etype}, ELSET={elset}"]
    for e, h in zip(numbers, hexes, strict=True):
        out.append(f"{e}, " + ", ".join(str(int(n) + first_node) for n in h))
    return out


def road_elements(road: Road, n_tire_nodes: int, n_tire_elements: int) -> list[str]:
    """The road block's C3D8 elements (set ROAD), numbered after the tire's."""
    numbers = range(n_tire_elements + 1, n_tire_elements + road.hexes.shape[0] + 1)
    return element_block("C3D8", "ROAD", numbers, road.hexes, n_tire_nodes + 1)


def node_sets(sets: dict[str, Iterable[int]]) -> list[str]:
    """``*NSET`` cards, in the given order, of 1-based node numbers."""
    out = []
    for name, numbers in sets.items():
        out.append(f"*NSET, NSET={name}")
        out.append(data_lines(numbers))
    return out


def tire_road_sets(n_tire_nodes: int, road: Road) -> dict[str, range]:
    """Node sets ROADN (the road block's nodes) and TIREN (the tire's)."""
    nt = n_tire_nodes
    return {"ROADN": range(nt + 1, nt + road.nodes.shape[0] + 1), "TIREN": range(1, nt + 1)}


def contact_surfaces(hexes: np.ndarray, contact_quads: np.ndarray, road: Road, table=None) -> list[str]:
    """Element-face surfaces STIRE (the tire's ``contact_quads``) and SROAD (the road's top)."""
    et = hexes.shape[0]
    out = ["*SURFACE, NAME=STIRE, TYPE=ELEMENT"]
    for e, k in quads_to_faces(hexes, contact_quads, table):
        out.append(f"{e + 1}, S{k}")
    out.append("*SURFACE, NAME=SROAD, TYPE=ELEMENT")
    for e, k in road.top_faces:
        out.append(f"{et + e + 1}, S{k}")
    return out


def contact_pair(
    slope: float, tension: float, friction: float, stick_slope: float, kind: str = "NODE TO SURFACE"
) -> list[str]:
    """Penalty contact between STIRE (slave) and SROAD with Coulomb friction.

    ``slope``: Pa/m, contact pressure per overclosure; ``tension``: Pa, the
    tension limit at large clearance; ``friction``: Coulomb coefficient;
    ``stick_slope``: Pa/m, tangential (stick) penalty stiffness.
    """
    return [
        "*SURFACE INTERACTION, NAME=SI",
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
        f"{slope:.6e}, {tension:.6e}",
        "*FRICTION",
        f"{friction}, {stick_slope:.6e}",
        f"*CONTACT PAIR, INTERACTION=SI, TYPE={kind}",
        "STIRE, SROAD",
    ]


def pressure_load(hexes: np.ndarray, quads: np.ndarray, pressure: float, table=None) -> list[str]:
    """``*DLOAD`` data lines: ``pressure`` (Pa) on the element faces of ``quads``."""
    return [f"{e + 1}, P{k}, {pressure:.6e}" for e, k in quads_to_faces(hexes, quads, table)]
