"""Element types, their faces, and the boundary surface of a set of elements.

Every reader maps the element types it meets onto the canonical types below,
with the **Exodus II node ordering** (corners first, then one node per edge in
the order of `CellSpec.edges`, then face centres, then the volume
centre). VTK orderings differ for some quadratic types and are permuted on
reading (`VTK_TYPES`); the permutations are checked against VTK's own
cell definitions in the tests.

The faces of an element are written as *face types* ``tri3 tri6 tri7 quad4
quad8 quad9``: corners, then the mid-edge nodes of edges (c0 c1), (c1 c2),
(c2 c3|c0), …, then the face centre. `fepost.reader.quadratic` holds the
shape functions of those face types.

Why hand-written: the boundary of a volume mesh must keep every face node
(VTK's surface filter linearises quadratic faces or subdivides them without
telling which sub-face belongs to which element face), must not merge the
nodes of different bodies, and must never see out-of-range connectivity
(VTK's filters do not check it). The face tables are those of the Exodus II
element documentation (Sandia SEACAS).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputFileError

_HEX_FACES = ((0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (0, 4, 7, 3), (0, 3, 2, 1), (4, 5, 6, 7))
_HEX_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 5), (2, 6), (3, 7), (4, 5), (5, 6), (6, 7), (7, 4))
_TET_FACES = ((0, 1, 3), (1, 2, 3), (0, 3, 2), (0, 2, 1))
_TET_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
_WEDGE_FACES = ((0, 1, 4, 3), (1, 2, 5, 4), (0, 3, 5, 2), (0, 2, 1), (3, 4, 5))
_WEDGE_EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 4), (2, 5), (3, 4), (4, 5), (5, 3))
_PYR_FACES = ((0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4), (0, 3, 2, 1))
_PYR_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 4), (2, 4), (3, 4))
_QUAD_EDGES = ((0, 1), (1, 2), (2, 3), (3, 0))
_TRI_EDGES = ((0, 1), (1, 2), (2, 0))


@dataclass(frozen=True)
class CellSpec:
    """A canonical element type.

    ``faces``: corner indices of each face (outward for volumes); ``edges``:
    corner pairs whose mid-edge nodes follow the corners, in this order, when
    ``quadratic``; ``face_centres``: node index of each face's centre node
    (same order as ``faces``) for the types that have them.
    """

    name: str
    dim: int  # 3: volume, 2: surface (shell / 2-D), 1: line, 0: point
    n_nodes: int
    faces: tuple[tuple[int, ...], ...] = ()
    edges: tuple[tuple[int, int], ...] = ()
    quadratic: bool = False
    face_centres: tuple[int, ...] = ()

    @property
    def n_corners(self) -> int:
        return len({c for f in self.faces for c in f}) if self.faces else self.n_nodes

    def face_nodes(self) -> list[tuple[str, tuple[int, ...]]]:
        """Each face as (face type, local node indices in face-type order)."""
        out = []
        mid = {frozenset(e): self.n_corners + k for k, e in enumerate(self.edges)} if self.quadratic else {}
        for k, f in enumerate(self.faces):
            nodes = list(f)
            if self.quadratic:
                nodes += [mid[frozenset((f[i], f[(i + 1) % len(f)]))] for i in range(len(f))]
            if self.face_centres:
                nodes.append(self.face_centres[k])
            base = "tri" if len(f) == 3 else "quad"
            out.append((f"{base}{len(nodes)}", tuple(nodes)))
        return out


def _surface(name: str, n: int, corners: int, edges, centre: bool = False) -> CellSpec:
    face = tuple(range(corners))
    return CellSpec(
        name,
        2,
        n,
        faces=(face,),
        edges=edges,
        quadratic=n > corners,
        face_centres=(n - 1,) if centre else (),
    )


#: The canonical element types (Exodus II node ordering).
SPECS: dict[str, CellSpec] = {
    "point": CellSpec("point", 0, 1),
    "line2": CellSpec("line2", 1, 2),
    "line3": CellSpec("line3", 1, 3),
    "tri3": _surface("tri3", 3, 3, _TRI_EDGES),
    "tri6": _surface("tri6", 6, 3, _TRI_EDGES),
    "tri7": _surface("tri7", 7, 3, _TRI_EDGES, centre=True),
    "quad4": _surface("quad4", 4, 4, _QUAD_EDGES),
    "quad8": _surface("quad8", 8, 4, _QUAD_EDGES),
    "quad9": _surface("quad9", 9, 4, _QUAD_EDGES, centre=True),
    "tet4": CellSpec("tet4", 3, 4, _TET_FACES, _TET_EDGES),
    "tet10": CellSpec("tet10", 3, 10, _TET_FACES, _TET_EDGES, quadratic=True),
    "wedge6": CellSpec("wedge6", 3, 6, _WEDGE_FACES, _WEDGE_EDGES),
    "wedge15": CellSpec("wedge15", 3, 15, _WEDGE_FACES, _WEDGE_EDGES, quadratic=True),
    "pyramid5": CellSpec("pyramid5", 3, 5, _PYR_FACES, _PYR_EDGES),
    "pyramid13": CellSpec("pyramid13", 3, 13, _PYR_FACES, _PYR_EDGES, quadratic=True),
    "hex8": CellSpec("hex8", 3, 8, _HEX_FACES, _HEX_EDGES),
    "hex20": CellSpec("hex20", 3, 20, _HEX_FACES, _HEX_EDGES, quadratic=True),
    # Exodus HEX27: node 21 (index 20) is the volume centre, 22–27 the face centres
    "hex27": CellSpec(
        "hex27", 3, 27, _HEX_FACES, _HEX_EDGES, quadratic=True, face_centres=(25, 24, 26, 23, 21, 22)
    ),
}

#: Face types and their node counts.
FACE_TYPES = ("tri3", "tri6", "tri7", "quad4", "quad8", "quad9")

# VTK cell type → (canonical type, permutation: canonical node k = VTK node perm[k])
_ID = None
VTK_TYPES: dict[int, tuple[str, tuple[int, ...] | None]] = {
    1: ("point", _ID),  # VTK_VERTEX
    3: ("line2", _ID),  # VTK_LINE
    21: ("line3", _ID),  # VTK_QUADRATIC_EDGE
    5: ("tri3", _ID),  # VTK_TRIANGLE
    9: ("quad4", _ID),  # VTK_QUAD
    22: ("tri6", _ID),  # VTK_QUADRATIC_TRIANGLE
    34: ("tri7", _ID),  # VTK_BIQUADRATIC_TRIANGLE
    23: ("quad8", _ID),  # VTK_QUADRATIC_QUAD
    28: ("quad9", _ID),  # VTK_BIQUADRATIC_QUAD
    10: ("tet4", _ID),  # VTK_TETRA
    24: ("tet10", _ID),  # VTK_QUADRATIC_TETRA (same edge order as Exodus)
    13: ("wedge6", _ID),  # VTK_WEDGE
    # VTK_QUADRATIC_WEDGE: mid-edges top triangle (9-11) before the verticals (12-14)
    26: ("wedge15", (0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11)),
    14: ("pyramid5", _ID),  # VTK_PYRAMID
    27: ("pyramid13", _ID),  # VTK_QUADRATIC_PYRAMID (same order as Exodus)
    12: ("hex8", _ID),  # VTK_HEXAHEDRON
    # VTK_QUADRATIC_HEXAHEDRON: top edges (12-15) before the verticals (16-19)
    25: ("hex20", (*range(12), 16, 17, 18, 19, 12, 13, 14, 15)),
    # VTK_TRIQUADRATIC_HEXAHEDRON: as 25, then faces x-, x+, y-, y+, z-, z+ (20-25), centre 26
    29: ("hex27", (*range(12), 16, 17, 18, 19, 12, 13, 14, 15, 26, 24, 25, 20, 21, 22, 23)),
}

# VTK_PIXEL (8) and VTK_VOXEL (11) are axis-aligned cells with a z-order node numbering
VTK_REORDERED = {8: ("quad4", (0, 1, 3, 2)), 11: ("hex8", (0, 1, 3, 2, 4, 5, 7, 6))}
VTK_TYPES.update(VTK_REORDERED)

#: Exodus element type names (upper-cased, digits stripped to the family) → canonical type by node count.
_EXODUS_FAMILY = {
    "HEX": "hex",
    "HEXAHEDRON": "hex",
    "TETRA": "tet",
    "TET": "tet",
    "WEDGE": "wedge",
    "PYRAMID": "pyramid",
    "PYRA": "pyramid",
    "QUAD": "quad",
    "QUADRILATERAL": "quad",
    "SHELL": "quad",
    "TRI": "tri",
    "TRIANGLE": "tri",
    "TRISHELL": "tri",
    "TRIANGLESHELL": "tri",
    "BEAM": "line",
    "BAR": "line",
    "TRUSS": "line",
    "EDGE": "line",
    "SPHERE": "point",
    "CIRCLE": "point",
    "NSIDED": "nsided",
    "NFACED": "nfaced",
}


def exodus_type(elem_type: str, nodes_per_element: int) -> str | None:
    """The canonical type of an Exodus block (``elem_type`` attribute and node count), or None."""
    letters = "".join(ch for ch in elem_type.upper() if ch.isalpha())
    family = _EXODUS_FAMILY.get(letters)
    if family is None:
        return None
    if family == "point":
        return "point" if nodes_per_element == 1 else None
    if family == "line":
        return {2: "line2", 3: "line3"}.get(nodes_per_element)
    name = f"{family}{nodes_per_element}"
    return name if name in SPECS else None


def check_connectivity(conn: np.ndarray, n_points: int, what: str) -> None:
    """Raise unless every index of ``conn`` is a node (0 ≤ i < ``n_points``)."""
    if conn.size == 0:
        return
    lo, hi = int(conn.min()), int(conn.max())
    if lo < 0 or hi >= n_points:
        raise InputFileError(
            f"{what}: connectivity refers to node {lo if lo < 0 else hi} but the file has {n_points} nodes "
            "(corrupt or inconsistent file)"
        )


@dataclass
class Faces:
    """Element faces grouped by face type.

    ``conn[t]`` (m, k) node indices of the faces of type ``t``; ``cell[t]`` (m,)
    the index of the element each face belongs to, within the list of
    elements handed to `boundary_faces` (for cell data).
    """

    conn: dict[str, np.ndarray]
    cell: dict[str, np.ndarray]

    def count(self) -> int:
        return sum(len(c) for c in self.conn.values())


def pack_key(corners: np.ndarray) -> np.ndarray:
    """One sortable row per face from its sorted corner nodes (padded with -1)."""
    s = np.sort(corners, axis=1)
    if s.shape[1] < 4:
        s = np.concatenate([np.full((len(s), 4 - s.shape[1]), -1, s.dtype), s], axis=1)
    return np.ascontiguousarray(s.astype(np.int64))


def boundary_faces(blocks: list[tuple[str, np.ndarray]]) -> Faces:
    """The faces of the given elements that belong to exactly one of them.

    ``blocks``: (canonical type, (m, k) connectivity) pairs. Surface elements
    are faces themselves; the faces of volume elements shared by two elements
    (interior faces, block interfaces) are dropped. Lines and points are
    ignored. Element indices in `Faces.cell` run over the blocks in
    order.
    """
    chunks: list[tuple[str, np.ndarray, np.ndarray, np.ndarray]] = []  # face type, nodes, corner key, cell
    offset = 0
    for name, conn in blocks:
        spec = SPECS[name]
        m = len(conn)
        cells = np.arange(offset, offset + m, dtype=np.int64)
        offset += m
        if spec.dim < 2 or m == 0:
            continue
        for ftype, local in spec.face_nodes():
            # a surface element is its own face: its connectivity is used as it is (no copy)
            nodes = conn if list(local) == list(range(conn.shape[1])) else conn[:, list(local)]
            ncorner = 3 if ftype.startswith("tri") else 4
            chunks.append((ftype, nodes, nodes[:, :ncorner], cells))
    if not chunks:
        return Faces({}, {})
    volume = any(SPECS[name].dim == 3 and len(conn) for name, conn in blocks)
    keep: list[np.ndarray]
    if volume:
        keys = np.concatenate([pack_key(c[2]) for c in chunks])
        void = keys.view(np.dtype((np.void, keys.dtype.itemsize * 4))).ravel()
        _, inverse, counts = np.unique(void, return_inverse=True, return_counts=True)
        once = counts[inverse.ravel()] == 1
        keep = []
        pos = 0
        for c in chunks:
            keep.append(once[pos : pos + len(c[1])])
            pos += len(c[1])
    else:
        keep = [np.ones(len(c[1]), bool) for c in chunks]
    conn_out: dict[str, list[np.ndarray]] = {}
    cell_out: dict[str, list[np.ndarray]] = {}
    for (ftype, nodes, _, cells), k in zip(chunks, keep, strict=True):
        if k.all():
            conn_out.setdefault(ftype, []).append(nodes)
            cell_out.setdefault(ftype, []).append(cells)
        elif k.any():
            conn_out.setdefault(ftype, []).append(nodes[k])
            cell_out.setdefault(ftype, []).append(cells[k])
    return Faces(
        {t: v[0] if len(v) == 1 else np.concatenate(v) for t, v in conn_out.items()},
        {t: v[0] if len(v) == 1 else np.concatenate(v) for t, v in cell_out.items()},
    )


def side_faces(name: str, conn: np.ndarray, sides: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The faces named by an Exodus side set: element connectivity rows and 0-based side numbers.

    Returns (face type, (m, k) nodes, indices into ``conn``/``sides``) groups.
    Surface elements (shells) have side 0 = the element itself (front) and
    1 = it reversed (back); their edge sides name no face.
    """
    spec = SPECS[name]
    faces = spec.face_nodes()
    out = []
    if spec.dim == 2:
        ftype, local = faces[0]
        hit = np.flatnonzero(np.isin(sides, (0, 1)))
        if hit.size:
            out.append((ftype, conn[hit][:, list(local)], hit))
        return out
    for k, (ftype, local) in enumerate(faces):
        hit = np.flatnonzero(sides == k)
        if hit.size:
            out.append((ftype, conn[hit][:, list(local)], hit))
    return out
