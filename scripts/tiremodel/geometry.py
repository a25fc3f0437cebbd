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

from . import meshing as mg


@dataclass(frozen=True)
class TireParams(mg.TireProfile):
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

    def bead_radius(self) -> float:
        return self.bead()[1]


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
    with mg.gmsh_model("tire", verbose) as gmsh:
        geo = gmsh.model.geo
        counts = [p.n_crown, p.n_shoulder, p.n_side]
        kinds: dict[int, str] = {}  # 2D section surface tag -> region name
        section_surfs: list[tuple[int, int, bool]] = []  # (surface, outer curve, is_bead)
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
                corners = [o0, o1, i1, i0]
                s = mg.structured_patch(geo, arc_o, line1, arc_i, line0, corners, counts[k], p.n_wall)
                kinds[s] = ("crown", "shoulder", "side")[k]
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
        for sign in (1.0, -1.0):
            out1 = geo.revolve(base, 0, 0, zc, 0, 1, 0, sign * fine, [p.n_fine], recombine=True)
            tops = []
            for (s, _, is_bead), (top, _, lat) in zip(section_surfs, mg.revolved_blocks(out1), strict=True):
                tops.append(top)
                groups["outer"].append(lat[0][1])
                if kinds[s] in ("crown", "shoulder"):
                    groups["contact"].append(lat[0][1])
                groups["inner"].append(lat[2][1])
                if is_bead:
                    groups["bead"].append(lat[1][1])
            out2 = geo.revolve(tops, 0, 0, zc, 0, 1, 0, sign * coarse, [p.n_coarse], recombine=True)
            for (_, _, is_bead), (top, _, lat) in zip(section_surfs, mg.revolved_blocks(out2), strict=True):
                groups["cut"].append(top[1])
                groups["outer"].append(lat[0][1])
                groups["inner"].append(lat[2][1])
                if is_bead:
                    groups["bead"].append(lat[1][1])
        geo.synchronize()
        gmsh.model.mesh.generate(3)

        tags, coords, _ = gmsh.model.mesh.getNodes()
        coords = coords.reshape(-1, 3)
        hexes_t = mg.gmsh_hexes(gmsh)
        q = {name: mg.gmsh_quads(gmsh, groups[name]) for name in groups}

    nodes, hexes, remap = mg.volume_mesh(tags, coords, hexes_t)
    table = mg.face_lookup(hexes)
    mesh = TireMesh(
        params=p,
        nodes=nodes,
        hexes=hexes,
        outer_quads=mg.orient_outward(hexes, remap(q["outer"]), table),
        contact_quads=mg.orient_outward(hexes, remap(q["contact"]), table),
        inner_quads=mg.orient_outward(hexes, remap(q["inner"]), table),
        bead_nodes=remap(np.unique(q["bead"])),
        cut_nodes=remap(np.unique(q["cut"])),
    )
    mesh.info = {
        "nodes": int(nodes.shape[0]),
        "hexahedra": int(hexes.shape[0]),
        "outer_faces": int(mesh.outer_quads.shape[0]),
        "contact_faces": int(mesh.contact_quads.shape[0]),
        "section_width_m": p.section_width(),
        "bead_radius_m": p.bead_radius(),
    }
    return mesh
