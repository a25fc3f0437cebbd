"""Meshing pieces shared by the small sample tire and the aircraft tire.

Both models have the same section profile (three tangent circular arcs per
half), mesh it as structured quad patches with gmsh, revolve it about the axle
into 8-node hexahedra and hand numpy arrays to the deck writers. What differs
(one wall layer or two, a sector or the full circumference, the whole section
or the half y >= 0) stays in ``geometry`` and ``aircraft_geometry``.

Frame: x = rolling direction, y = axle (lateral), z = road normal (up); the
road is the plane z = 0 and the axle the line x = 0, z = ``axle_z``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numpy as np

# CalculiX C3D8 faces (0-based local nodes); with positive-volume elements the
# listed order gives an inward normal (right-hand rule).
C3D8_FACES = ((0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0))

GMSH_HEX = 5  # gmsh element type of the 8-node hexahedron
GMSH_QUAD = 3  # gmsh element type of the 4-node quadrangle


class TireProfile:
    """Outer section profile of a tire: crown, shoulder and sidewall arcs (m, deg).

    A mixin for the frozen parameter dataclasses of both models, which declare
    these fields with their own defaults.
    """

    outer_radius: float  # crown radius about the axle
    crown_radius: float  # lateral radius of the crown arc
    tread_half_width: float  # lateral extent of the crown arc
    shoulder_radius: float
    sidewall_radius: float
    sidewall_end_deg: float  # profile angle where the sidewall meets the bead
    gap0: float  # clearance between the uninflated crown and the road

    @property
    def axle_z(self) -> float:
        return self.outer_radius + self.gap0

    def arcs(self) -> list[tuple[float, float, float, float, float]]:
        """Outer-profile arcs (y_c, r_c, R, beta0, beta1) of the y >= 0 half.

        A point of an arc is (y_c + R sin b, r_c + R cos b), r = distance from
        the axle; b is also the angle of the outward normal from the +r
        direction, so a curve at depth d below the outer profile has radius R - d.
        """
        rc, rs, rw = self.crown_radius, self.shoulder_radius, self.sidewall_radius
        b1 = math.asin(self.tread_half_width / rc)
        c0 = (0.0, self.outer_radius - rc)
        c1 = (c0[0] + (rc - rs) * math.sin(b1), c0[1] + (rc - rs) * math.cos(b1))
        b2 = math.pi / 2
        c2 = (c1[0] + (rs - rw) * math.sin(b2), c1[1] + (rs - rw) * math.cos(b2))
        b3 = math.radians(self.sidewall_end_deg)
        return [
            (c0[0], c0[1], rc, 0.0, b1),
            (c1[0], c1[1], rs, b1, b2),
            (c2[0], c2[1], rw, b2, b3),
        ]

    def section_width(self) -> float:
        """Largest width of the outer profile (m), at the shoulder-sidewall junction."""
        y, _, r, _, _ = self.arcs()[1]
        return 2 * (y + r)

    def bead(self) -> tuple[float, float]:
        """(y, r) of the outer bead point (m)."""
        yc, rc, r, _, b = self.arcs()[2]
        return yc + r * math.sin(b), rc + r * math.cos(b)


@contextmanager
def gmsh_model(name: str, verbose: bool = False) -> Iterator:
    """An initialised gmsh with one empty model ``name``; finalised on exit."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 1 if verbose else 0)
        gmsh.model.add(name)
        yield gmsh
    finally:
        gmsh.finalize()


def structured_patch(
    geo, top: int, end: int, bottom: int, start: int, corners: list[int], n_along: int, n_through: int
) -> int:
    """Plane surface bounded by four curves, meshed as a transfinite, recombined quad grid.

    ``top`` and ``bottom`` run along the profile (``n_along`` elements), ``start``
    and ``end`` through the wall (``n_through`` elements); ``corners`` are the
    four corner points, counter-clockwise from the start of ``top``.
    """
    loop = geo.addCurveLoop([top, end, -bottom, -start])
    s = geo.addPlaneSurface([loop])
    for c in (top, bottom):
        geo.mesh.setTransfiniteCurve(c, n_along + 1)
    for c in (start, end):
        geo.mesh.setTransfiniteCurve(c, n_through + 1)
    geo.mesh.setTransfiniteSurface(s, cornerTags=corners)
    geo.mesh.setRecombine(2, s)
    return s


def revolved_blocks(out: list[tuple[int, int]]) -> list[tuple[tuple[int, int], int, list[tuple[int, int]]]]:
    """Split the result of ``geo.revolve`` of n quad surfaces into n (top, volume tag, laterals).

    gmsh returns, per revolved surface, the swept copy (``top``), the volume and
    the four lateral surfaces, in the order of the surface's boundary curves.
    """
    return [(out[i], out[i + 1][1], out[i + 2 : i + 6]) for i in range(0, len(out), 6)]


def gmsh_hexes(gmsh, tag: int = -1) -> np.ndarray:
    """(e, 8) node tags of the hexahedra of volume ``tag`` (-1: all volumes)."""
    etypes, _, enodes = gmsh.model.mesh.getElements(3, tag)
    blocks = []
    for t, nn in zip(etypes, enodes, strict=True):
        if t != GMSH_HEX:
            raise RuntimeError(f"gmsh produced non-hex 3D elements (type {t})")
        blocks.append(nn.reshape(-1, 8))
    return np.vstack(blocks)


def gmsh_quads(gmsh, surfaces: list[int]) -> np.ndarray:
    """(f, 4) node tags of the quadrangles of the given surfaces."""
    blocks = []
    for s in surfaces:
        et, _, en = gmsh.model.mesh.getElements(2, s)
        for t, nn in zip(et, en, strict=True):
            if t != GMSH_QUAD:
                raise RuntimeError(f"non-quad face on surface {s}")
            blocks.append(nn.reshape(-1, 4))
    return np.vstack(blocks)


def volume_mesh(
    tags: np.ndarray, coords: np.ndarray, hex_tags: np.ndarray, merge_tol: float | None = None
) -> tuple[np.ndarray, np.ndarray, Callable[[np.ndarray], np.ndarray]]:
    """Compact gmsh's nodes to those of the hexahedra, 0-based; orient every hexahedron positively.

    Parameters
    ----------
    tags, coords : gmsh node tags (n,) and coordinates (n, 3), m
    hex_tags : (e, 8) hexahedra as gmsh node tags
    merge_tol : m; if given, nodes closer than about this (same rounded
        coordinates) are merged into one (where two revolutions meet), and
        the nodes come out sorted by their rounded coordinates; otherwise in
        the order of their gmsh tags.

    Returns
    -------
    nodes : (n', 3) float, m
    hexes : (e, 8) int, CalculiX C3D8 ordering (the same as gmsh's), positive volume
    remap : maps arrays of gmsh node tags to the new 0-based indices; raises
        RuntimeError for a node that no hexahedron uses.
    """
    order = np.argsort(tags)
    used = np.unique(hex_tags)
    nodes = coords[order][np.searchsorted(tags[order], used)]
    if merge_tol is None:
        index = np.arange(used.size)
    else:
        key = np.round(nodes / merge_tol).astype(np.int64)
        _, first, index = np.unique(key, axis=0, return_index=True, return_inverse=True)
        index = index.ravel()
        nodes = nodes[first]
    tag2idx = -np.ones(int(tags.max()) + 1, dtype=np.int64)
    tag2idx[used] = index

    def remap(a: np.ndarray) -> np.ndarray:
        r = tag2idx[a]
        if (r < 0).any():
            raise RuntimeError("surface node not in volume mesh")
        return r

    hexes = remap(hex_tags)
    x = nodes[hexes]
    jac = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 3] - x[:, 0]), x[:, 4] - x[:, 0])
    neg = jac < 0
    hexes[neg] = hexes[neg][:, [4, 5, 6, 7, 0, 1, 2, 3]]
    return nodes, hexes, remap


def face_lookup(hexes: np.ndarray) -> dict[frozenset, tuple[int, int]]:
    """Map each hex face (as a node set) to (element index, CalculiX face number 1..6)."""
    table: dict[frozenset, tuple[int, int]] = {}
    for e, h in enumerate(hexes):
        for k, f in enumerate(C3D8_FACES):
            table[frozenset(int(h[i]) for i in f)] = (e, k + 1)
    return table


def quads_to_faces(hexes: np.ndarray, quads: np.ndarray, table=None) -> list[tuple[int, int]]:
    """(element index, CalculiX face number) of each boundary quad."""
    table = table or face_lookup(hexes)
    out = []
    for q in quads:
        key = frozenset(int(i) for i in q)
        if key not in table:
            raise RuntimeError("boundary quad is not a hex face")
        out.append(table[key])
    return out


def orient_outward(hexes: np.ndarray, quads: np.ndarray, table=None) -> np.ndarray:
    """Reorder quads so their right-hand normal points out of the solid."""
    out = quads.copy()
    for n, (e, k) in enumerate(quads_to_faces(hexes, quads, table)):
        out[n] = hexes[e][list(C3D8_FACES[k - 1])][::-1]
    return out
