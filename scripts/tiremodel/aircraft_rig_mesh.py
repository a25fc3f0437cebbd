"""The aircraft tire as a slide/spin rig mesh: full section, a sector with cut faces.

The aircraft tire of ``aircraft_geometry`` (46x17R20 class, carcass and belt
layers; the same profile, layer thicknesses and material regions) is meshed
for the rig:

- the full section (no symmetry plane): lateral sliding and spin are not
  symmetric about y = 0. The half section that ``build_aircraft_mesh`` makes
  is mirrored about y = 0 and the two halves merged on the plane;
- a sector of +-``sector_deg`` about the bottom instead of the whole
  circumference, with cut faces that the rig deck ties to the rigidly moving
  rim (the cyclic/rigid-rim condition of the small tire's rig);
- even circumferential layers of ``first_deg`` in the fine region (growth 1)
  so that the loaded nodes are spread over the whole static patch, and a few
  coarse layers to the cut faces.

``build_rig_mesh(kind)`` is the stable entry point (``kind``: ``rig`` for the
programme, ``fine`` for the convergence check, ``test`` for quick checks).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from . import meshing as mg
from .aircraft_geometry import AircraftParams, build_aircraft_mesh


@dataclass(frozen=True)
class AircraftRigParams(AircraftParams):
    """The aircraft tire's dimensions with the rig's mesh counts and its sector."""

    sector_deg: float = 70.0  # half-angle of the modelled sector (cut faces at +-sector_deg)
    # the whole tire's element in the rubber band under the patch's lateral edges
    # (``aircraft_rig_deck.incompatible_mask``): C3D8 (the programme's), or C3D8R, which locks far
    # less at the model's K/G = 100 (``check-elements``: 0.87 of the beam, C3D8 0.56): what the
    # band's locking does to the runs
    band_element: str = "C3D8"
    # m or None: the whole tire's band also takes the fine region's rubber whose centroid lies
    # farther than this fore or aft of the bottom, under the patch's leading and trailing edges
    # (``aircraft_rig_deck.incompatible_mask``); None: the band under the lateral edges only
    band_edge_x: float | None = None
    # False: no band under the patch's lateral edges (``aircraft_rig_deck.PLAIN_EDGE_Y``), C3D8I in
    # all the whole tire's rubber
    lateral_band: bool = True

    def coarse_layers(self) -> list[float]:
        """Angular sizes (deg) from ``fine_deg`` to ``sector_deg``, growing geometrically."""
        h0 = self.fine_layers()[-1]
        span = self.sector_deg - self.fine_deg
        if span <= 0.0:
            raise ValueError(f"sector_deg {self.sector_deg} must exceed fine_deg {self.fine_deg}")
        lo, hi = 1.0 + 1e-9, 3.0
        if h0 * self.n_coarse >= span:  # even layers are already large enough
            return [span / self.n_coarse] * self.n_coarse
        for _ in range(200):
            q = 0.5 * (lo + hi)
            s = h0 * sum(q**i for i in range(1, self.n_coarse + 1))
            lo, hi = (q, hi) if s < span else (lo, q)
        return [h0 * q**i for i in range(1, self.n_coarse + 1)]


def _whole(**counts) -> AircraftRigParams:
    """A whole-tire mesh: 360 degrees, two elements through the rubber, incompatible modes."""
    return AircraftRigParams(n_rubber=2, incompatible_all=True, growth=1.0, sector_deg=180.0, **counts)


MESHES = {
    # the programme: 4 + 2 + 3 elements per half section, 2 through the wall, 2.2 degree layers
    "rig": AircraftRigParams(
        n_crown=4, n_shoulder=2, n_side=3, first_deg=2.2, growth=1.0, fine_deg=33.0, n_coarse=3
    ),
    # the convergence check: 1.5 x the rig's counts along the section and around
    "fine": AircraftRigParams(
        n_crown=6, n_shoulder=3, n_side=4, first_deg=1.5, growth=1.0, fine_deg=33.0, n_coarse=4
    ),
    # quick checks of the builder (no solve)
    "test": AircraftRigParams(
        n_crown=2, n_shoulder=1, n_side=2, first_deg=6.0, growth=1.0, fine_deg=30.0, n_coarse=2
    ),
    # the whole tire (issue 39): 360 degrees, no cut faces, two elements through the rubber
    # layer; 1.8 degree layers within +-33 degrees, 12 geometrically growing layers per side
    # from there up to the top. (With the sector's counts, 4 + 2 + 3 and 2.2 degrees, the base
    # stalled at 77 mm of deflection: a crown node row 71 mm off the centre line flipped in and
    # out of contact, the residual 8 to 39 N, the increments cut below 1e-5 of the travel.)
    "whole": _whole(
        n_crown=5,
        n_shoulder=3,
        n_side=4,
        first_deg=1.8,
        fine_deg=33.0,
        n_coarse=12,
    ),
    # the finer partner (the programme's mesh): 6 + 3 + 4 elements per half section, 1.5 degrees
    "whole-fine": _whole(
        n_crown=6,
        n_shoulder=3,
        n_side=4,
        first_deg=1.5,
        fine_deg=33.0,
        n_coarse=12,
    ),
    # the programme's mesh with a reduced-integration band (C3D8R): the band's locking measured
    "whole-fine-r": replace(
        _whole(n_crown=6, n_shoulder=3, n_side=4, first_deg=1.5, fine_deg=33.0, n_coarse=12),
        band_element="C3D8R",
    ),
    # the programme's mesh with the band closed into a ring: plain C3D8 also under the patch's
    # leading and trailing edges (|x| > 0.20 m; the patch reaches 0.254 m fore and aft)
    "whole-fine-ring": replace(
        _whole(n_crown=6, n_shoulder=3, n_side=4, first_deg=1.5, fine_deg=33.0, n_coarse=12),
        band_edge_x=0.20,
    ),
    # the convergence check's finest partner (static map only): about 1.25 x whole-fine's counts
    # along the section (8 + 4 + 5) and around (1.2 degree layers)
    "whole-xfine": _whole(
        n_crown=8,
        n_shoulder=4,
        n_side=5,
        first_deg=1.2,
        fine_deg=33.0,
        n_coarse=12,
    ),
    # one step finer again (static map only): is R, one element's edge, settling? 10 + 5 + 6
    # per half section, 1.0 degree layers (about 1.25 x whole-xfine's counts both ways)
    "whole-xxfine": _whole(n_crown=10, n_shoulder=5, n_side=6, first_deg=1.0, fine_deg=33.0, n_coarse=12),
    # the finest mesh with no band: C3D8I in all the rubber (does the finer mesh still need it?)
    "whole-xfine-i": replace(
        _whole(n_crown=8, n_shoulder=4, n_side=5, first_deg=1.2, fine_deg=33.0, n_coarse=12),
        lateral_band=False,
    ),
    # the whole tire at a few hundred elements: the mu = 0 pure-spin check of the boundary
    # conditions, solved in a few minutes (one element along the sidewall)
    "whole-tiny": _whole(
        n_crown=2,
        n_shoulder=1,
        n_side=1,
        first_deg=8.0,
        fine_deg=32.0,
        n_coarse=4,
    ),
    # the whole tire at the test's size (deck checks and the tiny CalculiX case)
    "whole-test": _whole(
        n_crown=2,
        n_shoulder=1,
        n_side=2,
        first_deg=8.0,
        fine_deg=32.0,
        n_coarse=3,
    ),
}


@dataclass(frozen=True)
class AircraftRigMesh:
    """Full-section sector mesh of the aircraft tire (the fields the rig and aircraft decks use)."""

    kind: str
    params: AircraftRigParams
    nodes: np.ndarray  # (n, 3) m
    hexes: np.ndarray  # (e, 8) 0-based, positive volume
    region: np.ndarray  # (e,) 0 crown, 1 shoulder, 2 side
    layer: np.ndarray  # (e,) 0 rubber, 1 carcass
    fine: np.ndarray  # (e,) bool, in the refined region around the bottom
    meridian: np.ndarray  # (e, 3) unit meridional direction (carcass material axis 1)
    circumferential: np.ndarray  # (e, 3) unit circumferential direction (axis 2)
    outer_quads: np.ndarray  # (f, 4) outward normals
    contact_quads: np.ndarray  # crown and shoulder outer faces in the fine region
    inner_quads: np.ndarray  # cavity faces
    bead_nodes: np.ndarray
    cut_nodes: np.ndarray  # nodes on the two sector cut faces
    symmetry_nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # none
    info: dict = field(default_factory=dict)


def _angle_deg(p: AircraftParams, nodes: np.ndarray) -> np.ndarray:
    """Angle of each node about the axle from the bottom, towards +x (deg)."""
    return np.degrees(np.arctan2(nodes[:, 0], p.axle_z - nodes[:, 2]))


def _mirror(half, tol: float = 1e-7):
    """(nodes, index of each half node, index of each mirrored node) of the merged full section."""
    flip = np.array([1.0, -1.0, 1.0])
    both = np.vstack([half.nodes, half.nodes * flip])
    key = np.round(both / tol).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    n = half.nodes.shape[0]
    return both[first], inv[:n], inv[n:]


def build_rig_mesh(kind: str = "rig") -> AircraftRigMesh:
    """Mesh the aircraft tire for the rig (``kind``: rig, fine or test); see the module docstring."""
    if kind not in MESHES:
        raise ValueError(f"unknown aircraft rig mesh {kind!r} ({', '.join(MESHES)})")
    p = MESHES[kind]
    half = build_aircraft_mesh(p)
    nodes, a, b = _mirror(half)
    # the mirror image of a positive hexahedron is negative: swap nodes 1 <-> 3 and 5 <-> 7
    hexes = np.vstack([a[half.hexes], b[half.hexes][:, [0, 3, 2, 1, 4, 7, 6, 5]]])
    table = mg.face_lookup(hexes)

    def quads(q):
        return mg.orient_outward(hexes, np.vstack([a[q], b[q]]), table)

    flip = np.array([1.0, -1.0, 1.0])
    ang = _angle_deg(p, nodes)
    sector = max(abs(ang.min()), ang.max())
    whole = p.sector_deg >= 180.0
    # the whole tire has no cut faces: its two revolutions were merged at +-180 degrees
    cut = np.zeros(0, dtype=np.int64) if whole else np.flatnonzero(np.abs(np.abs(ang) - sector) < 1e-6)
    mesh = AircraftRigMesh(
        kind=kind,
        params=p,
        nodes=nodes,
        hexes=hexes,
        region=np.concatenate([half.region, half.region]),
        layer=np.concatenate([half.layer, half.layer]),
        fine=np.concatenate([half.fine, half.fine]),
        meridian=np.vstack([half.meridian, half.meridian * flip]),
        circumferential=np.vstack([half.circumferential, half.circumferential]),
        outer_quads=quads(half.outer_quads),
        contact_quads=quads(half.contact_quads),
        inner_quads=quads(half.inner_quads),
        bead_nodes=np.unique(np.concatenate([a[half.bead_nodes], b[half.bead_nodes]])),
        cut_nodes=cut,
        info={
            "nodes": int(nodes.shape[0]),
            "hexahedra": int(hexes.shape[0]),
            "contact_faces": int(2 * half.contact_quads.shape[0]),
            "sector_deg": 180.0 if whole else float(sector),
            "whole_tire": whole,
            "fine_layers_per_side": len(p.fine_layers()),
            "coarse_layers_per_side": p.n_coarse,
            "section_width_m": p.section_width(),
        },
    )
    return mesh
