"""CalculiX deck for the aircraft tire (half model) on a rigid flat road.

Materials (SI units; where the numbers come from is in meshes/README.md):

- tread and sidewall rubber: nearly incompressible Neo-Hooke solids
  (``*HYPERELASTIC, NEO HOOKE``, bulk modulus K = 100 G);
- carcass (and, under the crown, the belt package): one orthotropic cord-rubber
  layer, ``*ELASTIC, TYPE=ENGINEERING CONSTANTS`` in per-element
  ``*ORIENTATION`` frames: local 1 = meridional (along the section profile,
  the direction of the radial carcass cords), 2 = circumferential (the belts),
  3 = normal to the wall.

The rim is rigid and held (bead nodes fixed); the road block moves instead (up
by the rim travel, and for the rolling stand-in along -x), and results are
expressed in the road's frame, where the rim moves down and along +x. Node-to-
surface penalty contact with Coulomb friction between the tread/shoulder nodes
and the top of the road block, as for the small sample tire.

Node numbers: tire nodes 1..n_tire, then the road block's nodes. Elements: tire 1..e_tire, then the road's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import ccxdeck as cx
from .aircraft_geometry import AircraftMesh
from .meshing import face_lookup

PRESSURE = 1.38e6  # Pa, rated inflation (200 psi)
RATED_LOAD = 200.0e3  # N, rated load of the modelled tire (45,000 lbf)
FRICTION = 0.3
CONTACT_SLOPE = 5.0e9  # Pa/m, pressure per overclosure
CONTACT_TENSION = 1.0  # Pa
STICK_SLOPE = 5.0e8  # Pa/m
INFLATION_TIME = 0.2  # analysis time of the inflation ramp (each road stage takes 1.0)

# rubber: Neo-Hooke C10 = G/2, D1 = 2/K with K = 100 G (initial Poisson ratio 0.495)
RUBBER = {
    "TREAD": {"shear_modulus": 1.5e6, "bulk_modulus": 150.0e6},
    "SIDEWALL": {"shear_modulus": 1.0e6, "bulk_modulus": 100.0e6},
}
# carcass layers: E1 meridional, E2 circumferential, E3 normal; nu12, nu13, nu23; G12, G13, G23
CARCASS = {
    # radial nylon carcass plies + circumferential (aramid/nylon) belt package under the crown
    "BELTED": (0.6e9, 2.0e9, 30.0e6, 0.10, 0.45, 0.45, 20.0e6, 10.0e6, 10.0e6),
    # radial nylon carcass plies only (shoulder, sidewall)
    "CARCASS": (1.0e9, 30.0e6, 30.0e6, 0.45, 0.45, 0.45, 10.0e6, 10.0e6, 10.0e6),
}


def orthotropic_ok(c) -> bool:
    """Positive definite compliance (Lempriere's conditions) for engineering constants."""
    e1, e2, e3, n12, n13, n23, g12, g13, g23 = c
    s = np.array(
        [
            [1 / e1, -n12 / e1, -n13 / e1],
            [-n12 / e1, 1 / e2, -n23 / e2],
            [-n13 / e1, -n23 / e2, 1 / e3],
        ]
    )
    return bool(np.all(np.linalg.eigvalsh(s) > 0) and min(g12, g13, g23) > 0)


@dataclass(frozen=True)
class Stage:
    """One unit of analysis time after inflation: the road moves linearly to this travel.

    ``travel_z`` is the total upward road travel (= downward rim travel relative
    to the road, m); ``travel_x`` the total road travel along -x (= rim travel
    along +x relative to the road, m). ``outputs`` maps a case name to the
    fraction of the stage (0 < f <= 1) at which its results are written.
    """

    travel_z: float
    travel_x: float = 0.0
    outputs: tuple[tuple[str, float], ...] = ()
    max_inc: float = 0.1  # largest increment, in units of stage time
    samples: int = 0  # extra evenly spaced output times (load-deflection curve points)


@dataclass
class DeckInfo:
    tire_nodes: int
    tire_elements: int
    road_nodes: int
    road_elements: int
    output_times: dict = field(default_factory=dict)  # case name -> analysis time
    step_names: list = field(default_factory=list)


def write_aircraft_deck(
    path,
    mesh: AircraftMesh,
    stages: list[Stage],
    residual_tolerance: float | None = None,
    correction_tolerance: float | None = None,
) -> DeckInfo:
    """Write the deck: one static step, inflation over [0, INFLATION_TIME], then the stages.

    Everything happens in a single CalculiX step driven by amplitudes (pressure,
    road travel z and x), with results written at the requested times only
    (``*TIME POINTS``): CalculiX 2.20 did not converge the first increment of a
    new step whose prescribed displacements change after a pressure step, while
    the same path inside one step converges without cut-backs.

    ``residual_tolerance`` (CalculiX's R_n, default 0.005 of the average nodal
    force) relaxes the force criterion; with it, up to 10 cut-backs per
    increment are allowed instead of 5. The fine runs use 0.02: when the lateral
    patch edge crosses from the crown onto the shoulder (and when the patch
    starts sliding), a node pair flips in and out of contact with a residual of
    about 1 N that never drops below the default criterion.
    ``correction_tolerance`` (CalculiX's C_n, default 0.01) relaxes the
    displacement-correction criterion: after cut-backs to increments of a few
    tenths of a millimetre, the incompatible-mode unknowns of the elements at
    the patch edge oscillate by about 0.1 mm from one iteration to the next
    while the force residual already meets its criterion.
    """
    for name, c in CARCASS.items():
        if not orthotropic_ok(c):
            raise ValueError(f"carcass constants {name} are not positive definite")
    road = _half_road()
    nt, et = mesh.nodes.shape[0], mesh.hexes.shape[0]
    out: list[str] = []
    w = out.append
    w("*HEADING")
    w("fepost aircraft tire (46x17R20 class), half model y >= 0")
    out += cx.node_block(mesh.nodes, road)
    out += tire_elements(mesh)
    out += cx.road_elements(road, nt, et)
    out += rubber_sets(mesh)
    sets = {
        "BEAD": (int(n) + 1 for n in mesh.bead_nodes),
        "SYMN": (int(n) + 1 for n in mesh.symmetry_nodes),
        **cx.tire_road_sets(nt, road),
        "ROADREF": [nt + 1],
    }
    out += cx.node_sets(sets)
    table = face_lookup(mesh.hexes)
    out += cx.contact_surfaces(mesh.hexes, mesh.contact_quads, road, table)
    out += material_lines(mesh)
    out += cx.contact_pair(CONTACT_SLOPE, CONTACT_TENSION, FRICTION, STICK_SLOPE)
    # time schedule: inflation over [0, t0], then stage k over [t0 + k - 1, t0 + k]
    t0 = INFLATION_TIME
    times, zs, xs = [0.0, t0], [0.0, 0.0], [0.0, 0.0]
    output_times: dict[str, float] = {"inflation": t0}
    for k, st in enumerate(stages, start=1):
        samples = tuple((f"sample{k}_{i:03d}", i / st.samples) for i in range(1, st.samples + 1))
        for name, frac in (*st.outputs, *samples):
            if not 0.0 < frac <= 1.0:
                raise ValueError(f"output {name}: stage fraction {frac} outside (0, 1]")
            output_times[name] = t0 + k - 1 + frac
        times.append(t0 + k)
        zs.append(st.travel_z)
        xs.append(st.travel_x)
    total = times[-1]
    w("*AMPLITUDE, NAME=APRESS")
    w(f"0.0, 0.0, {t0:.6f}, 1.0, {total:.6f}, 1.0")
    for name, vals in (("AROADZ", zs), ("AROADX", xs)):
        w(f"*AMPLITUDE, NAME={name}")
        w(cx.data_lines((f"{t:.6f}, {v:.9e}" for t, v in zip(times, vals, strict=True)), per=4))
    w("*TIME POINTS, NAME=TOUT")
    # results (.frd and .dat alike: CalculiX writes both at these times only)
    w(cx.data_lines(f"{t:.9f}" for t in sorted(set(round(t, 9) for t in output_times.values()))))
    w("*BOUNDARY")
    w("SYMN, 2, 2")
    w("BEAD, 1, 3")
    w("ROADN, 2, 2")
    w("*STEP, NLGEOM, INC=5000")
    w("*STATIC")
    max_inc = min([t0, *[st.max_inc for st in stages]])
    w(f"{max_inc}, {total:.6f}, 1e-8, {max_inc}")
    if residual_tolerance is not None:
        w("*CONTROLS, PARAMETERS=FIELD")
        w(f"{residual_tolerance}" + ("" if correction_tolerance is None else f", {correction_tolerance}"))
        w("*CONTROLS, PARAMETERS=TIME INCREMENTATION")
        w("4, 8, 9, 16, 10, 4, 0, 10")
    # the road block moves (all nodes prescribed) and the rim stays; the export
    # expresses everything in the road's frame, where the rim moves
    w("*BOUNDARY, AMPLITUDE=AROADZ")
    w("ROADN, 3, 3, 1.0")
    w("*BOUNDARY, AMPLITUDE=AROADX")
    w("ROADN, 1, 1, -1.0")
    w("*DLOAD, AMPLITUDE=APRESS")
    out += cx.pressure_load(mesh.hexes, mesh.inner_quads, PRESSURE, table)
    w("*NODE FILE, NSET=TIREN, TIME POINTS=TOUT")
    w("U")
    w("*CONTACT FILE, TIME POINTS=TOUT")
    w("CDIS, CSTR")
    w("*NODE PRINT, NSET=ROADN, TOTALS=ONLY, TIME POINTS=TOUT")
    w("RF")
    w("*NODE PRINT, NSET=ROADREF, TIME POINTS=TOUT")
    w("U")
    w("*NODE PRINT, NSET=BEAD, TOTALS=ONLY, TIME POINTS=TOUT")
    w("RF")
    w("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return DeckInfo(
        tire_nodes=nt,
        tire_elements=et,
        road_nodes=int(road.nodes.shape[0]),
        road_elements=int(road.hexes.shape[0]),
        output_times=output_times,
        step_names=list(output_times),
    )


def incompatible_mask(mesh: AircraftMesh) -> np.ndarray:
    """(e,) bool: the elements that are C3D8I (the others are C3D8).

    The sweep's tire: incompatible-mode hexahedra (good in bending) in the refined
    region around the patch; plain C3D8 in the coarse upper part, which only
    carries the inflation, and in the shoulder rubber: there the incompatible
    modes of the elements under the lateral patch edge oscillated without
    converging once the edge reached them (one element through the rubber). A
    mesh whose parameters set ``incompatible_all`` (the whole rig tire, two
    elements through the rubber) is C3D8I everywhere: plain C3D8 lock in bending.
    """
    if getattr(mesh.params, "incompatible_all", False):
        return np.ones(mesh.hexes.shape[0], dtype=bool)
    return mesh.fine & ~((mesh.region == 1) & (mesh.layer == 0))


def tire_elements(mesh: AircraftMesh) -> list[str]:
    """The tire's ``*ELEMENT`` cards (set TIRE), C3D8I or C3D8 by region (``incompatible_mask``)."""
    incompatible = incompatible_mask(mesh)
    out: list[str] = []
    for etype, sel in (("C3D8I", incompatible), ("C3D8", ~incompatible)):
        out += cx.element_block(etype, "TIRE", np.flatnonzero(sel) + 1, mesh.hexes[sel])
    return out


def rubber_sets(mesh: AircraftMesh) -> list[str]:
    """Element sets ETREAD (crown rubber) and ESIDEWALL (shoulder and sidewall rubber)."""
    rubber = mesh.layer == 0
    tread = rubber & (mesh.region == 0)
    out: list[str] = []
    for name, sel in (("ETREAD", tread), ("ESIDEWALL", rubber & ~tread)):
        out.append(f"*ELSET, ELSET={name}")
        out.append(cx.data_lines(int(e) + 1 for e in np.flatnonzero(sel)))
    return out


def material_lines(mesh: AircraftMesh) -> list[str]:
    """Materials and sections of the tire (rubber, oriented carcass) and of the road."""
    out: list[str] = []
    w = out.append
    for name, r in RUBBER.items():
        w(f"*MATERIAL, NAME={name}")
        w("*HYPERELASTIC, NEO HOOKE")
        w(f"{r['shear_modulus'] / 2:.6e}, {2.0 / r['bulk_modulus']:.6e}")
    for name, c in CARCASS.items():
        w(f"*MATERIAL, NAME={name}")
        w("*ELASTIC, TYPE=ENGINEERING CONSTANTS")
        w(", ".join(f"{v:.6e}" for v in c[:8]))
        w(f"{c[8]:.6e}")
    out += cx.ROAD_MATERIAL
    w("*SOLID SECTION, ELSET=ETREAD, MATERIAL=TREAD")
    w("*SOLID SECTION, ELSET=ESIDEWALL, MATERIAL=SIDEWALL")
    w(cx.ROAD_SECTION)
    # carcass: one orientation per element (local 1 meridional, 2 circumferential)
    for e in np.flatnonzero(mesh.layer == 1):
        a, b = mesh.meridian[e], mesh.circumferential[e]
        mat = "BELTED" if mesh.region[e] == 0 else "CARCASS"
        w(f"*ORIENTATION, NAME=OR{e + 1}")
        w(", ".join(f"{v:.8f}" for v in (*a, *b)))
        w(f"*ELSET, ELSET=EC{e + 1}")
        w(str(e + 1))
        w(f"*SOLID SECTION, ELSET=EC{e + 1}, MATERIAL={mat}, ORIENTATION=OR{e + 1}")
    return out


def _half_road():
    """Road block on x in [-0.6, 0.6], y in [0, 0.3], top face z = 0, 25 mm faces."""
    road = cx.build_road(half_x=0.60, half_y=0.15, thick=0.02, size=0.025)
    road.nodes[:, 1] += 0.15
    return road
