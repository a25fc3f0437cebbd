"""Gmsh model of an aircraft main-gear radial tire (46x17R20 size class), half section.

Frame as for the small sample tire: x = rolling direction, y = axle (lateral),
z = road normal (up); the road is the plane z = 0 and the axle the line
x = 0, z = ``axle_z``. Only the half y >= 0 is meshed: every load case here
(vertical load, then a longitudinal rim displacement) is symmetric about the
plane y = 0, which becomes a symmetry plane (u_y = 0). The export mirrors the
surface back to the full tire.

Cross-section (in the (y, r) plane, r = distance from the axle): the outer
profile is three tangent-continuous circular arcs (crown, shoulder, sidewall),
as for the small tire. The wall is two layers, each one element thick:

- outer layer: rubber (tread on the crown, sidewall cover on the sidewall);
- inner layer: the cord-rubber carcass (plus the belt package under the crown),
  an orthotropic layer whose material axes follow the profile (meridional,
  circumferential, normal); see ``aircraft_deck``.

Layer thicknesses vary linearly along each arc (thick tread on the crown, thin
cover on the sidewall), so the interface and inner curves are splines through
offset points; every sub-region is a structured (transfinite) quad grid. The
section is revolved about the axle over the full circumference: finely and
with slowly growing layers near the bottom (the contact patch), coarsely above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import meshing as mg

REGIONS = ("crown", "shoulder", "side")
LAYERS = ("rubber", "carcass")


@dataclass(frozen=True)
class AircraftParams(mg.TireProfile):
    """Dimensions (m) and mesh counts of the aircraft tire model."""

    outer_radius: float = 0.584  # D = 46 in = 1.168 m
    crown_radius: float = 0.45  # lateral radius of the crown arc
    tread_half_width: float = 0.14  # lateral extent of the crown arc
    shoulder_radius: float = 0.107  # section width 2 * 0.2137 = 0.427 m (17 in = 0.432 m)
    sidewall_radius: float = 0.3386
    sidewall_end_deg: float = 121.1  # bead at r = 0.285 m, y = 0.165 m (20 in rim + flange)
    # wall thickness (total, rubber layer) at the start and end of each arc
    total_thickness: tuple = ((0.030, 0.030), (0.030, 0.018), (0.018, 0.018))
    rubber_thickness: tuple = ((0.020, 0.020), (0.020, 0.006), (0.006, 0.006))
    gap0: float = 0.030  # clearance between the uninflated crown and the road
    # mesh: elements along crown / shoulder / sidewall arcs (half section)
    n_crown: int = 7
    n_shoulder: int = 4
    n_side: int = 5
    # elements through the outer rubber layer (tread and sidewall cover); the carcass has one
    n_rubber: int = 1
    # incompatible-mode hexahedra (C3D8I) in every element instead of only the fine region
    # outside the shoulder rubber (see ``aircraft_deck.incompatible_mask``)
    incompatible_all: bool = False
    # circumferential layers, per side of the bottom: the first layer spans
    # ``first_deg`` and each next one is ``growth`` times longer up to ``fine_deg``;
    # beyond it ``n_coarse`` layers of geometrically growing size up to 180 deg
    first_deg: float = 0.45
    growth: float = 1.02
    fine_deg: float = 55.0
    n_coarse: int = 22

    def fine_layers(self) -> list[float]:
        """Angular sizes (deg) of the circumferential layers from the bottom up to ``fine_deg``."""
        sizes, total, h = [], 0.0, self.first_deg
        while total + h < self.fine_deg - 0.3 * h:
            sizes.append(h)
            total += h
            h *= self.growth
        sizes.append(self.fine_deg - total)
        return sizes

    def coarse_layers(self) -> list[float]:
        """Angular sizes (deg) from ``fine_deg`` to 180 deg, growing geometrically."""
        h0 = self.fine_layers()[-1]
        span = 180.0 - self.fine_deg
        # solve h0 * sum(q^i, i=1..n) = span for q by bisection
        lo, hi = 1.0 + 1e-9, 3.0
        for _ in range(200):
            q = 0.5 * (lo + hi)
            s = h0 * sum(q**i for i in range(1, self.n_coarse + 1))
            lo, hi = (q, hi) if s < span else (lo, q)
        return [h0 * q**i for i in range(1, self.n_coarse + 1)]


def coarse_aircraft_params() -> AircraftParams:
    """A cheap version of the same tire (debugging, load pre-estimates)."""
    return AircraftParams(n_crown=5, n_shoulder=3, n_side=4, first_deg=1.2, growth=1.06, n_coarse=22)


@dataclass
class AircraftMesh:
    params: AircraftParams
    nodes: np.ndarray  # (n, 3) float, m
    hexes: np.ndarray  # (e, 8) int, 0-based, C3D8 ordering, positive volume
    region: np.ndarray  # (e,) int: 0 crown, 1 shoulder, 2 side
    layer: np.ndarray  # (e,) int: 0 rubber, 1 carcass
    fine: np.ndarray  # (e,) bool: element in the refined region around the bottom
    meridian: np.ndarray  # (e, 3) unit meridional direction at the element centroid
    circumferential: np.ndarray  # (e, 3) unit circumferential direction
    outer_quads: np.ndarray  # (f, 4) outer surface, outward normals
    contact_quads: np.ndarray  # outer faces of crown + shoulder in the fine region
    inner_quads: np.ndarray  # cavity faces (inflation pressure)
    bead_nodes: np.ndarray
    symmetry_nodes: np.ndarray  # nodes on the plane y = 0
    info: dict = field(default_factory=dict)


def _offset_curve(geo, p: AircraftParams, k: int, depth: tuple[float, float], ends: tuple[int, int]) -> int:
    """Curve at ``depth`` (linear from start to end of arc k) below the outer arc."""
    yc, rc, rr, b0, b1 = p.arcs()[k]
    d0, d1 = depth
    if abs(d1 - d0) < 1e-12:
        cen = geo.addPoint(0.0, yc, p.axle_z - rc)
        return geo.addCircleArc(ends[0], cen, ends[1])
    pts = [ends[0]]
    n = 12
    for i in range(1, n):
        s = i / n
        b = b0 + s * (b1 - b0)
        d = d0 + s * (d1 - d0)
        pts.append(geo.addPoint(0.0, yc + (rr - d) * math.sin(b), p.axle_z - (rc + (rr - d) * math.cos(b))))
    pts.append(ends[1])
    return geo.addSpline(pts)


def build_aircraft_mesh(p: AircraftParams, verbose: bool = False) -> AircraftMesh:
    """Mesh the half tire (y >= 0) with gmsh; return numpy arrays."""
    with mg.gmsh_model("aircraft_tire", verbose) as gmsh:
        geo = gmsh.model.geo
        counts = (p.n_crown, p.n_shoulder, p.n_side)
        arcs = p.arcs()

        def pt(y, r):
            return geo.addPoint(0.0, y, p.axle_z - r)

        def profile_points(k: int, b: float, end: int):
            yc, rc, rr, _, _ = arcs[k]
            t = p.total_thickness[k][end]
            tr = p.rubber_thickness[k][end]
            return [pt(yc + (rr - d) * math.sin(b), rc + (rr - d) * math.cos(b)) for d in (0.0, tr, t)]

        surfaces: list[tuple[int, int, int]] = []  # (surface tag, region, layer)
        prev = None  # (points, lines) at the start of the current arc
        for k, (yc, rc, _, b0, b1) in enumerate(arcs):
            if prev is None:
                p0 = profile_points(k, b0, 0)
                l0 = [geo.addLine(p0[0], p0[1]), geo.addLine(p0[1], p0[2])]
            else:
                p0, l0 = prev
            p1 = profile_points(k, b1, 1)
            l1 = [geo.addLine(p1[0], p1[1]), geo.addLine(p1[1], p1[2])]
            cen = geo.addPoint(0.0, yc, p.axle_z - rc)
            outer = geo.addCircleArc(p0[0], cen, p1[0])
            mid = _offset_curve(
                geo, p, k, (p.rubber_thickness[k][0], p.rubber_thickness[k][1]), (p0[1], p1[1])
            )
            inner = _offset_curve(
                geo, p, k, (p.total_thickness[k][0], p.total_thickness[k][1]), (p0[2], p1[2])
            )
            for layer, (top, bot) in enumerate(((outer, mid), (mid, inner))):
                corners = [p0[layer], p1[layer], p1[layer + 1], p0[layer + 1]]
                through = p.n_rubber if layer == 0 else 1
                s = mg.structured_patch(geo, top, l1[layer], bot, l0[layer], corners, counts[k], through)
                surfaces.append((s, k, layer))
            prev = (p1, l1)

        zc = p.axle_z
        fine = p.fine_layers()
        coarse = p.coarse_layers()
        base = [(2, s) for s, _, _ in surfaces]
        groups: dict[str, list[int]] = {"outer": [], "contact": [], "inner": [], "bead": [], "sym": []}
        vol_kind: dict[int, tuple[int, int, bool]] = {}

        def heights(sizes):
            c = np.cumsum(sizes)
            return list(c / c[-1])

        for sign in (1.0, -1.0):
            tops = base
            for part, sizes in (("fine", fine), ("coarse", coarse)):
                out = geo.revolve(
                    tops,
                    0,
                    0,
                    zc,
                    0,
                    1,
                    0,
                    sign * math.radians(sum(sizes)),
                    [1] * len(sizes),
                    heights(sizes),
                    recombine=True,
                )
                tops = []
                for (_, k, layer), (top, vol, lat) in zip(surfaces, mg.revolved_blocks(out), strict=True):
                    tops.append(top)
                    vol_kind[vol] = (k, layer, part == "fine")
                    if layer == 0:
                        groups["outer"].append(lat[0][1])
                        if part == "fine" and k in (0, 1):
                            groups["contact"].append(lat[0][1])
                    else:
                        groups["inner"].append(lat[2][1])
                    if k == 2:
                        groups["bead"].append(lat[1][1])
                    if k == 0:
                        groups["sym"].append(lat[3][1])
        geo.synchronize()
        gmsh.model.mesh.generate(3)

        tags, coords, _ = gmsh.model.mesh.getNodes()
        coords = coords.reshape(-1, 3)
        hex_list, reg_list, lay_list, fine_list = [], [], [], []
        for vtag, (k, layer, is_fine) in vol_kind.items():
            h = mg.gmsh_hexes(gmsh, vtag)
            hex_list.append(h)
            reg_list.append(np.full(h.shape[0], k))
            lay_list.append(np.full(h.shape[0], layer))
            fine_list.append(np.full(h.shape[0], is_fine))
        hexes_t = np.vstack(hex_list)
        q = {name: mg.gmsh_quads(gmsh, groups[name]) for name in groups}

    # the two revolutions meet at +-180 deg: merge their coincident nodes
    nodes, hexes, remap = mg.volume_mesh(tags, coords, hexes_t, merge_tol=1e-7)
    region = np.concatenate(reg_list)
    layer = np.concatenate(lay_list)
    meridian, circ = _material_axes(p, nodes, hexes, region)
    table = mg.face_lookup(hexes)
    mesh = AircraftMesh(
        params=p,
        nodes=nodes,
        hexes=hexes,
        region=region,
        layer=layer,
        fine=np.concatenate(fine_list),
        meridian=meridian,
        circumferential=circ,
        outer_quads=mg.orient_outward(hexes, remap(q["outer"]), table),
        contact_quads=mg.orient_outward(hexes, remap(q["contact"]), table),
        inner_quads=mg.orient_outward(hexes, remap(q["inner"]), table),
        bead_nodes=np.unique(remap(q["bead"])),
        symmetry_nodes=np.unique(remap(q["sym"])),
    )
    if np.abs(nodes[mesh.symmetry_nodes, 1]).max() > 1e-9:
        raise RuntimeError("symmetry-plane nodes off y = 0")
    mesh.info = {
        "nodes": int(nodes.shape[0]),
        "hexahedra": int(hexes.shape[0]),
        "outer_faces": int(mesh.outer_quads.shape[0]),
        "contact_faces": int(mesh.contact_quads.shape[0]),
        "fine_layers_per_side": len(p.fine_layers()),
        "coarse_layers_per_side": p.n_coarse,
        "section_width_m": p.section_width(),
        "bead_radius_m": p.bead()[1],
    }
    return mesh


def _material_axes(p: AircraftParams, nodes, hexes, region):
    """Unit meridional and circumferential directions at the element centroids."""
    c = nodes[hexes].mean(axis=1)
    d = np.column_stack([c[:, 0], np.zeros(len(c)), c[:, 2] - p.axle_z])
    r = np.linalg.norm(d, axis=1)
    e_r = d / r[:, None]
    e_y = np.array([0.0, 1.0, 0.0])
    e_c = np.cross(e_y, e_r)
    arcs = p.arcs()
    yc = np.array([arcs[k][0] for k in region])
    rc = np.array([arcs[k][1] for k in region])
    b = np.arctan2(c[:, 1] - yc, r - rc)
    meridian = np.cos(b)[:, None] * e_y[None, :] - np.sin(b)[:, None] * e_r
    return meridian, e_c
