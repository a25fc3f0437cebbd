"""Gmsh model of an aircraft-main-gear-like tire sector.

Frame: x = rolling direction, y = axle (lateral), z = road normal (up).
The road is the plane z = 0; the axle is the line x = 0, z = ``axle_z``.

The tire cross-section (in the (y, r) plane, r = distance from the axle) is a
thick shell whose outer profile is three tangent-continuous circular arcs per
half: a flat-ish crown (lateral radius ``crown_radius``), a shoulder and a
sidewall ending at the bead. The inner profile is the concentric offset by the
wall thickness, so every sub-region of the section is an annular sector that
gmsh meshes as a structured (transfinite, recombined) quad grid. The section
is revolved about the axle by +/- ``sector_deg`` (finer layers within
+/- ``fine_deg`` of the bottom) into 8-node hexahedra.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class TireParams:
    outer_radius: float = 0.50  # m, crown radius about the axle (D = 1.0 m)
    crown_radius: float = 0.50  # m, lateral radius of the crown arc
    tread_half_width: float = 0.11  # m, lateral extent of the crown arc
    shoulder_radius: float = 0.08  # m
    sidewall_radius: float = 0.13  # m
    sidewall_end_deg: float = 140.0  # deg, profile angle where the sidewall meets the bead
    wall: float = 0.020  # m, rubber-equivalent wall thickness
    gap0: float = 0.020  # m, clearance between the uninflated crown and the road
    sector_deg: float = 60.0  # half-angle of the modelled sector
    fine_deg: float = 35.0  # half-angle of the refined region around the bottom
    # mesh counts: elements along crown / shoulder / sidewall arcs (per half),
    # through the wall, and circumferential layers (fine region, coarse region, per side)
    n_crown: int = 11
    n_shoulder: int = 7
    n_side: int = 5
    n_wall: int = 1
    n_fine: int = 26
    n_coarse: int = 5

    @property
    def axle_z(self) -> float:
        return self.outer_radius + self.gap0

    def arcs(self) -> list[tuple[float, float, float, float, float]]:
        """Outer-profile arcs (y_c, r_c, R, beta0, beta1) for the y >= 0 half.

        A point of an arc is (y_c + R sin b, r_c + R cos b); b is also the angle
        of the outward normal from the +r direction, so offsetting inward by the
        wall thickness just shrinks R.
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
        y, _, r, _, _ = self.arcs()[1]
        return 2 * (y + r)

    def bead_radius(self) -> float:
        yc, rc, r, _, b = self.arcs()[2]
        return rc + r * math.cos(b)


def coarse_params() -> TireParams:
    """A cheap version of the same tire (for the end-to-end test)."""
    return TireParams(n_crown=7, n_shoulder=4, n_side=3, n_wall=1, n_fine=14, n_coarse=3)


@dataclass
class TireMesh:
    params: TireParams
    nodes: np.ndarray  # (n, 3) float, m
    hexes: np.ndarray  # (e, 8) int, 0-based, Abaqus/CalculiX C3D8 ordering, positive volume
    outer_quads: np.ndarray  # (f, 4) int, the whole outer surface, outward normals
    contact_quads: np.ndarray  # (g, 4) int, outer faces of crown+shoulder in the fine region
    inner_quads: np.ndarray  # (h, 4) int, cavity side (inflation pressure)
    bead_nodes: np.ndarray  # node indices clamped to the rim
    cut_nodes: np.ndarray  # node indices on the two sector cut faces
    info: dict = field(default_factory=dict)


def _point(geo, y: float, r: float, p: TireParams) -> int:
    return geo.addPoint(0.0, y, p.axle_z - r)


def build_mesh(p: TireParams, verbose: bool = False) -> TireMesh:
    """Build and mesh the sector with gmsh; return numpy arrays."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 1 if verbose else 0)
        gmsh.model.add("tire")
        geo = gmsh.model.geo
        counts = [p.n_crown, p.n_shoulder, p.n_side]
        kinds: dict[int, str] = {}  # 2D section surface tag -> region name
        section_surfs: list[tuple[int, int, bool]] = []  # (surface, outer curve, is_bead)
        surf_curves: dict[int, dict[str, int]] = {}
        for side in (1.0, -1.0):
            # arc end points, outer and inner
            prev_o = prev_i = None
            prev_line = None
            for k, (yc, rc, rr, b0, b1) in enumerate(p.arcs()):
                cen = _point(geo, side * yc, rc, p)
                ri = rr - p.wall
                if prev_o is None:
                    if side > 0:
                        o0 = _point(geo, side * (yc + rr * math.sin(b0)), rc + rr * math.cos(b0), p)
                        i0 = _point(geo, side * (yc + ri * math.sin(b0)), rc + ri * math.cos(b0), p)
                        first_line = geo.addLine(o0, i0)
                        shared = (o0, i0, first_line)
                    else:
                        o0, i0, first_line = shared
                    line0 = first_line
                else:
                    o0, i0, line0 = prev_o, prev_i, prev_line
                o1 = _point(geo, side * (yc + rr * math.sin(b1)), rc + rr * math.cos(b1), p)
                i1 = _point(geo, side * (yc + ri * math.sin(b1)), rc + ri * math.cos(b1), p)
                arc_o = geo.addCircleArc(o0, cen, o1)
                arc_i = geo.addCircleArc(i0, cen, i1)
                line1 = geo.addLine(o1, i1)
                loop = geo.addCurveLoop([arc_o, line1, -arc_i, -line0])
                s = geo.addPlaneSurface([loop])
                for c in (arc_o, arc_i):
                    geo.mesh.setTransfiniteCurve(c, counts[k] + 1)
                for c in (line0, line1):
                    geo.mesh.setTransfiniteCurve(c, p.n_wall + 1)
                geo.mesh.setTransfiniteSurface(s, cornerTags=[o0, o1, i1, i0])
                geo.mesh.setRecombine(2, s)
                kinds[s] = ("crown", "shoulder", "side")[k]
                surf_curves[s] = {"outer": arc_o, "end": line1, "inner": arc_i, "start": line0}
                section_surfs.append((s, arc_o, k == 2))
                prev_o, prev_i, prev_line = o1, i1, line1
        zc = p.axle_z
        fine = math.radians(p.fine_deg)
        coarse = math.radians(p.sector_deg - p.fine_deg)
        base = [(2, s) for s, _, _ in section_surfs]
        groups: dict[str, list[int]] = {
            "outer": [],
            "contact": [],
            "inner": [],
            "bead": [],
            "cut": [],
        }
        vols: list[int] = []
        for sign in (1.0, -1.0):
            out1 = geo.revolve(base, 0, 0, zc, 0, 1, 0, sign * fine, [p.n_fine], recombine=True)
            tops = []
            for j, (s, _, is_bead) in enumerate(section_surfs):
                blk = out1[6 * j : 6 * j + 6]
                top, vol, lat = blk[0], blk[1], blk[2:]
                vols.append(vol[1])
                tops.append(top)
                groups["outer"].append(lat[0][1])
                if kinds[s] in ("crown", "shoulder"):
                    groups["contact"].append(lat[0][1])
                groups["inner"].append(lat[2][1])
                if is_bead:
                    groups["bead"].append(lat[1][1])
            out2 = geo.revolve(tops, 0, 0, zc, 0, 1, 0, sign * coarse, [p.n_coarse], recombine=True)
            for j, (_, _, is_bead) in enumerate(section_surfs):
                blk = out2[6 * j : 6 * j + 6]
                top, vol, lat = blk[0], blk[1], blk[2:]
                vols.append(vol[1])
                groups["cut"].append(top[1])
                groups["outer"].append(lat[0][1])
                groups["inner"].append(lat[2][1])
                if is_bead:
                    groups["bead"].append(lat[1][1])
        geo.synchronize()
        gmsh.model.mesh.generate(3)

        tags, coords, _ = gmsh.model.mesh.getNodes()
        coords = coords.reshape(-1, 3)
        etypes, _, enodes = gmsh.model.mesh.getElements(3)
        hex_tags = []
        for et, en in zip(etypes, enodes, strict=True):
            if et != 5:
                raise RuntimeError(f"gmsh produced non-hex 3D elements (type {et})")
            hex_tags.append(en.reshape(-1, 8))
        hexes_t = np.vstack(hex_tags)

        def quads_of(surfs: list[int]) -> np.ndarray:
            out = []
            for s in surfs:
                et, _, en = gmsh.model.mesh.getElements(2, s)
                for t, nn in zip(et, en, strict=True):
                    if t != 3:
                        raise RuntimeError(f"non-quad face on surface {s}")
                    out.append(nn.reshape(-1, 4))
            return np.vstack(out)

        def nodes_of(surfs: list[int]) -> np.ndarray:
            return np.unique(quads_of(surfs))

        q_outer = quads_of(groups["outer"])
        q_contact = quads_of(groups["contact"])
        q_inner = quads_of(groups["inner"])
        n_bead = nodes_of(groups["bead"])
        n_cut = nodes_of(groups["cut"])
    finally:
        gmsh.finalize()

    # renumber: keep nodes used by hexes, 0-based
    used = np.unique(hexes_t)
    tag2idx = -np.ones(int(tags.max()) + 1, dtype=np.int64)
    tag_order = np.argsort(tags)
    tags_sorted = tags[tag_order]
    pos = np.searchsorted(tags_sorted, used)
    nodes = coords[tag_order][pos]
    tag2idx[used] = np.arange(used.size)

    def remap(a):
        r = tag2idx[a]
        if (r < 0).any():
            raise RuntimeError("surface node not in volume mesh")
        return r

    hexes = remap(hexes_t)
    # positive orientation (Abaqus C3D8 ordering, same as gmsh)
    x = nodes[hexes]
    jac = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 3] - x[:, 0]), x[:, 4] - x[:, 0])
    neg = jac < 0
    hexes[neg] = hexes[neg][:, [4, 5, 6, 7, 0, 1, 2, 3]]
    mesh = TireMesh(
        params=p,
        nodes=nodes,
        hexes=hexes,
        outer_quads=remap(q_outer),
        contact_quads=remap(q_contact),
        inner_quads=remap(q_inner),
        bead_nodes=remap(n_bead),
        cut_nodes=remap(n_cut),
    )
    mesh.outer_quads = orient_outward(mesh, mesh.outer_quads)
    mesh.contact_quads = orient_outward(mesh, mesh.contact_quads)
    mesh.inner_quads = orient_outward(mesh, mesh.inner_quads)
    mesh.info = {
        "nodes": int(nodes.shape[0]),
        "hexahedra": int(hexes.shape[0]),
        "outer_faces": int(mesh.outer_quads.shape[0]),
        "contact_faces": int(mesh.contact_quads.shape[0]),
        "section_width_m": p.section_width(),
        "bead_radius_m": p.bead_radius(),
    }
    return mesh


# CalculiX C3D8 faces (0-based local nodes); with positive-volume elements the
# listed order gives an inward normal (right-hand rule).
C3D8_FACES = ((0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0))


def face_lookup(hexes: np.ndarray) -> dict[frozenset, tuple[int, int]]:
    """Map each hex face (as a node set) to (element index, CalculiX face number 1..6)."""
    table: dict[frozenset, tuple[int, int]] = {}
    for e, h in enumerate(hexes):
        for k, f in enumerate(C3D8_FACES):
            table[frozenset(int(h[i]) for i in f)] = (e, k + 1)
    return table


def quads_to_faces(mesh: TireMesh, quads: np.ndarray, table=None) -> list[tuple[int, int]]:
    table = table or face_lookup(mesh.hexes)
    out = []
    for q in quads:
        key = frozenset(int(i) for i in q)
        if key not in table:
            raise RuntimeError("boundary quad is not a hex face")
        out.append(table[key])
    return out


def orient_outward(mesh: TireMesh, quads: np.ndarray) -> np.ndarray:
    """Reorder quads so their right-hand normal points out of the solid."""
    table = face_lookup(mesh.hexes)
    out = quads.copy()
    for n, q in enumerate(quads):
        e, k = table[frozenset(int(i) for i in q)]
        inward = mesh.hexes[e][list(C3D8_FACES[k - 1])]
        out[n] = inward[::-1]
    return out
