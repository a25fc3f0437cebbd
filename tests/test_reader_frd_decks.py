"""Tiny CalculiX contact decks for the ``.frd`` reader tests: a soft block pressed on a steel plate.

The block (0.1 × 0.1 × 0.04 m, E = 10 MPa) sits on a plate (0.16 × 0.16 ×
0.02 m, steel) at z = 0; the block's top is pushed down by ``push`` m and its
bottom element faces are the slave surface of a penalty contact pair. The block is
meshed with the element type asked for (hexahedra split into wedges or
tetrahedra, mid-side nodes added for the quadratic types); the plate is C3D8.
The solver's own check of the load: ``*NODE PRINT, TOTALS=ONLY`` of the
reaction forces of the plate's fixed bottom (set ``PBOT``) in the ``.dat`` file.
This module holds no tests: it writes the decks of tests/test_reader_frd.py and
tests/test_reader_frd_fuzz.py.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

#: Hexahedron corner offsets (i, j, k) in CalculiX/Exodus order.
_HEX = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
_HEX20_EDGES = [
    (0, 1),
    (1, 2),
    (2, 3),
    (3, 0),
    (4, 5),
    (5, 6),
    (6, 7),
    (7, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
]
_TET10_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
_WEDGE15_EDGES = [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)]
#: CalculiX face numbers (S1, S2, ...) as corner indices, per base shape.
FACES = {
    "hex": [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)],
    "wedge": [(0, 1, 2), (3, 4, 5), (0, 1, 4, 3), (1, 2, 5, 4), (2, 0, 3, 5)],
    "tet": [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)],
}
#: Element types and (linear base, mid-side edges).
TYPES = {
    "C3D8": ("hex", None),
    "C3D8I": ("hex", None),
    "C3D8R": ("hex", None),
    "C3D20": ("hex", _HEX20_EDGES),
    "C3D20R": ("hex", _HEX20_EDGES),
    "C3D6": ("wedge", None),
    "C3D15": ("wedge", _WEDGE15_EDGES),
    "C3D4": ("tet", None),
    "C3D10": ("tet", _TET10_EDGES),
}


def _grid(lo, hi, n):
    axes = [np.linspace(lo[a], hi[a], n[a] + 1) for a in range(3)]
    index = {}
    pts = []
    for k, j, i in itertools.product(range(n[2] + 1), range(n[1] + 1), range(n[0] + 1)):
        index[i, j, k] = len(pts)
        pts.append((axes[0][i], axes[1][j], axes[2][k]))
    hexes = [
        [index[i + a, j + b, k + c] for a, b, c in _HEX]
        for k, j, i in itertools.product(range(n[2]), range(n[1]), range(n[0]))
    ]
    return np.array(pts), np.array(hexes)


def _split(base: str, hexes: np.ndarray, pts: np.ndarray) -> np.ndarray:
    if base == "hex":
        return hexes
    if base == "wedge":  # two prisms over the bottom diagonal 0-2
        return np.concatenate([hexes[:, [0, 1, 2, 4, 5, 6]], hexes[:, [0, 2, 3, 4, 6, 7]]])
    tets = []
    for perm in itertools.permutations(range(3)):  # Kuhn split: 6 tetrahedra along the diagonal 0-6
        path, v = [(0, 0, 0)], [0, 0, 0]
        for a in perm:
            v[a] = 1
            path.append(tuple(v))
        tets.append(hexes[:, [_HEX.index(p) for p in path]])
    out = np.concatenate(tets)
    a, b, c, d = (pts[out[:, i]] for i in range(4))
    neg = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    out[neg] = out[neg][:, [0, 2, 1, 3]]
    return out


def _quadratic(conn: np.ndarray, pts: np.ndarray, edges) -> tuple[np.ndarray, np.ndarray]:
    mids: dict[tuple[int, int], int] = {}
    extra = []
    cols = []
    for a, b in edges:
        col = []
        for e in conn:
            key = (min(e[a], e[b]), max(e[a], e[b]))
            if key not in mids:
                mids[key] = len(pts) + len(extra)
                extra.append(0.5 * (pts[key[0]] + pts[key[1]]))
            col.append(mids[key])
        cols.append(col)
    return np.column_stack([conn, np.array(cols).T]), np.vstack([pts, extra])


def _lines(ids, per=8) -> list[str]:
    ids = [str(int(i)) for i in ids]
    return [", ".join(ids[i : i + per]) for i in range(0, len(ids), per)]


def write_deck(
    path: Path,
    etype: str = "C3D8",
    *,
    binary: bool = False,
    contact: str = "NODE TO SURFACE",
    push: float = 2e-4,
    increments: int = 1,
    n: int = 4,
) -> Path:
    """Write the deck ``path`` (job = its stem) and return it."""
    base, edges = TYPES[etype]
    pts, hexes = _grid((-0.05, -0.05, 0.0), (0.05, 0.05, 0.04), (n, n, 2))
    conn = _split(base, hexes, pts)
    if edges is not None:
        conn, pts = _quadratic(conn, pts, edges)
    ppts, phex = _grid((-0.08, -0.08, -0.02), (0.08, 0.08, 0.0), (3, 3, 1))
    off = 10000
    bottom = np.flatnonzero(np.abs(pts[:, 2]) < 1e-12) + 1
    top = np.flatnonzero(np.abs(pts[:, 2] - 0.04) < 1e-12) + 1
    pbot = np.flatnonzero(np.abs(ppts[:, 2] + 0.02) < 1e-12) + 1 + off
    w = ["*HEADING", f"fepost frd reader test: {etype} block on a plate", "*NODE"]
    w += [f"{i + 1}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in enumerate(pts)]
    w += [f"{i + 1 + off}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in enumerate(ppts)]
    w += [f"*ELEMENT, TYPE={etype}, ELSET=BLOCK"]
    for e, c in enumerate(conn):
        nodes = [str(k + 1) for k in c]
        w.append(f"{e + 1}, " + ", ".join(nodes[:15]) + ("," if len(nodes) > 15 else ""))
        if len(nodes) > 15:
            w.append(", ".join(nodes[15:]))
    w += ["*ELEMENT, TYPE=C3D8, ELSET=PLATE"]
    w += [f"{off + e + 1}, " + ", ".join(str(k + 1 + off) for k in c) for e, c in enumerate(phex)]
    w += [
        "*NSET, NSET=TOP",
        *_lines(top),
        "*NSET, NSET=PBOT",
        *_lines(pbot),
        "*NSET, NSET=BBOT",
        *_lines(bottom),
    ]
    w += ["*ELSET, ELSET=PTOP", *_lines(off + 1 + np.arange(len(phex)))]
    w += ["*SURFACE, NAME=SLAVE"]  # the element faces in z = 0
    for e, c in enumerate(conn):
        for k, face in enumerate(FACES[base]):
            if np.all(np.abs(pts[c[list(face)], 2]) < 1e-12):
                w.append(f"{e + 1}, S{k + 1}")
    w += ["*SURFACE, NAME=MASTER", "PTOP, S2"]
    w += ["*MATERIAL, NAME=SOFT", "*ELASTIC", "1e7, 0.3", "*MATERIAL, NAME=STEEL", "*ELASTIC", "2e11, 0.3"]
    w += ["*SOLID SECTION, ELSET=BLOCK, MATERIAL=SOFT", "*SOLID SECTION, ELSET=PLATE, MATERIAL=STEEL"]
    w += ["*SURFACE INTERACTION, NAME=SI", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR"]
    w += ["1e11, 1.0" if contact == "NODE TO SURFACE" else "1e11"]
    w += [f"*CONTACT PAIR, INTERACTION=SI, TYPE={contact}", "SLAVE, MASTER"]
    w += ["*BOUNDARY", "PBOT, 1, 3", "TOP, 1, 2"]
    dt = 1.0 / increments
    w += ["*STEP, NLGEOM, INC=100", "*STATIC, DIRECT", f"{dt:.6g}, 1.0"]
    w += ["*BOUNDARY", f"TOP, 3, 3, {-push:.9g}"]
    node, cont = ("*NODE OUTPUT", "*CONTACT OUTPUT") if binary else ("*NODE FILE", "*CONTACT FILE")
    w += [node, "U", cont, "CSTR, CDIS", "*NODE PRINT, NSET=PBOT, TOTALS=ONLY", "RF", "*END STEP"]
    path.write_text("\n".join(w) + "\n")
    return path
