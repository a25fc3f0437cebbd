"""The aircraft tire on the slide/spin rig: its deck lines and settings (``rig_deck.RigTire``).

The rig itself (rigid road held at its reference and rotation nodes, the rim
moved rigidly, restart from a shared base of inflation and vertical load, the
cut faces tied to the rim) is ``rig_deck``'s; what is the aircraft tire's
own comes from ``aircraft_deck``: the two-layer wall (Neo-Hooke tread and
sidewall rubber, the oriented carcass and belt layer), C3D8I/C3D8 by region,
1.38 MPa, the contact pair and the relaxed convergence criteria of the
aircraft sweep (force residual 0.02 of the average nodal force, displacement
correction 0.5 of the increment; see ``aircraft_deck.write_aircraft_deck``).

The deflection is chosen for about the rated load on the rig mesh: at the
aircraft sweep's rated-load deflection (102.3 mm) the coarser rig mesh carried
242.8 kN (1.22 x the sweep mesh's 198.6 kN), and the sweep's load-deflection
curve reaches 200 / 1.22 kN at 87.7 mm; the load at 88 mm is in ``static.json``.
Base and slide each run as one CalculiX step driven by amplitudes
(``one_step``; ``rig_deck._one_step_base`` says why).
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from . import aircraft_deck as ad
from . import ccxdeck as cx
from . import deck as dk
from . import rig_deck as rd
from .meshing import face_lookup

DEFLECTION = 0.088  # m: about the rated load on the rig mesh (see the module docstring)
WHOLE_DEFLECTION = 0.1023  # m: the whole tire at the static sweep's rated-load deflection
SLIDE_PATH = 0.30  # m, reference path of a run: the lateral force needs about 0.15 m to build up
R_REF = 0.30  # m, reference radius that scales the spin (pure spin turns the tire by 1 rad)
CONTROLS = (
    "*CONTROLS, PARAMETERS=FIELD",
    "0.02, 0.5",
    "*CONTROLS, PARAMETERS=TIME INCREMENTATION",
    "4, 8, 9, 16, 10, 4, 0, 10",
)
#: m, the whole tire's rubber elements of the fine region with the centroid farther than this from
#: the mid-plane are plain C3D8 (the sweep's tire has C3D8 in its shoulder rubber for the same
#: reason): at the rated-load deflection the patch's lateral edge lies at |y| = 0.117 m, between
#: the fifth and sixth of the whole-fine mesh's six crown columns (0.093-0.14 m). With C3D8I there,
#: every frictional slide of the whole tire stopped within 1.5-3.4 % of its path: the tread-edge
#: nodes at the patch's side flipped in and out of contact and the incompatible modes of the
#: elements on both sides of that edge diverged (residuals to 1e20 N within 3 iterations, from
#: increments of 3e-6 of the path), with 50 iterations allowed, with an exponential
#: pressure-overclosure law (c0 1 mm, p0 0.1 MPa) and with a stick slope of 1e8 Pa/m; the last two
#: also stalled the base (at 97 and 92 % of its deflection), as did frictionless contact (82 %)
PLAIN_EDGE_Y = 0.09


def road() -> cx.Road:
    """Road block |x|, |y| <= 0.6 m, 50 mm faces: room for the slide and the turn of the patch."""
    return cx.build_road(half_x=0.60, half_y=0.60, thick=0.02, size=0.05)


def whole_road() -> cx.Road:
    """The whole tire's road block, |x|, |y| <= 0.8 m, 50 mm faces: its patch reaches 0.23 m ahead of
    its centre and 0.18 m to the side (``whole-fine``, 102.3 mm), so a slide of up to 0.55 m keeps
    it on the road (on ``road``'s 0.6 m the 0.45 m programme's slides would leave it at 83 %)."""
    return cx.build_road(half_x=0.80, half_y=0.80, thick=0.02, size=0.05)


def incompatible_mask(mesh) -> np.ndarray:
    """(e,) bool: the rig mesh's C3D8I elements (the others are C3D8).

    The sector: the sweep's split (``aircraft_deck.incompatible_mask``). The whole tire: C3D8I
    except the rubber of the fine region whose centroid lies more than ``PLAIN_EDGE_Y`` from the
    mid-plane, the band under the patch's lateral edges (see ``PLAIN_EDGE_Y``; none on
    meshes whose ``lateral_band`` is False), and on meshes with a ``band_edge_x`` also the fine rubber
    farther than that fore or aft (a ring round the patch).
    """
    mask = ad.incompatible_mask(mesh)
    if mesh.info.get("whole_tire"):
        centroid = mesh.nodes[mesh.hexes].mean(axis=1)
        band = (np.abs(centroid[:, 1]) > PLAIN_EDGE_Y) & getattr(mesh.params, "lateral_band", True)
        edge_x = getattr(mesh.params, "band_edge_x", None)
        if edge_x is not None:
            band |= np.abs(centroid[:, 0]) > edge_x
        mask = mask & ~(mesh.fine & (mesh.layer == 0) & band)
    return mask


def plain_element(mesh) -> str:
    """The element type of the elements ``incompatible_mask`` leaves out: C3D8, or the whole tire's
    ``band_element`` (C3D8R on ``whole-fine-r``)."""
    return getattr(mesh.params, "band_element", "C3D8") if mesh.info.get("whole_tire") else "C3D8"


def tire_elements(mesh) -> list[str]:
    """The tire's ``*ELEMENT`` cards (set TIRE), C3D8I or ``plain_element`` by ``incompatible_mask``."""
    incompatible = incompatible_mask(mesh)
    out: list[str] = []
    for etype, sel in (("C3D8I", incompatible), (plain_element(mesh), ~incompatible)):
        if sel.any():  # no empty card (``whole-xfine-i`` has no plain element)
            out += cx.element_block(etype, "TIRE", np.flatnonzero(sel) + 1, mesh.hexes[sel])
    return out


def model_lines(mesh, title: str, road: cx.Road, cut_refs: int | None = None) -> list[str]:
    """Deck lines of the aircraft tire sector on the road, before boundary conditions and steps."""
    return model_lines_with(ad.FRICTION, mesh, title, road, cut_refs)


def model_lines_with(
    friction: float, mesh, title: str, road: cx.Road, cut_refs: int | None = None
) -> list[str]:
    """``model_lines`` with the Coulomb coefficient ``friction``; 0: frictionless contact (no
    ``*FRICTION`` card: CalculiX takes only a coefficient > 0 there)."""
    nt, et = mesh.nodes.shape[0], mesh.hexes.shape[0]
    out = ["*HEADING", title]
    out += cx.node_block(mesh.nodes, road)
    out += tire_elements(mesh)
    out += cx.road_elements(road, nt, et)
    out += ad.rubber_sets(mesh)
    out += cx.node_sets({"BEAD": (int(n) + 1 for n in mesh.bead_nodes), **cx.tire_road_sets(nt, road)})
    out += cx.contact_surfaces(mesh.hexes, mesh.contact_quads, road, face_lookup(mesh.hexes))
    out += ad.material_lines(mesh)
    if dk.cut_nodes(mesh):  # a sector: its cut faces follow the rim (the whole tire has none)
        out += dk.cut_equations(mesh, cut_refs)
    pair = cx.contact_pair(ad.CONTACT_SLOPE, ad.CONTACT_TENSION, friction, ad.STICK_SLOPE)
    if friction == 0.0:
        k = pair.index("*FRICTION")
        del pair[k : k + 2]
    return out + pair


AIRCRAFT = rd.RigTire(
    name="aircraft",
    model_lines=model_lines,
    road=road,
    pressure=ad.PRESSURE,
    deflection=DEFLECTION,
    slide_path=SLIDE_PATH,
    r_ref=R_REF,
    vertical_inc="0.02, 1.0, 1e-7, 0.05",
    controls=CONTROLS,
    friction=ad.FRICTION,
    one_step=True,
    # on a shared, loaded machine the base took 20 min and the fine mesh's base over 30
    timeout=6 * 3600.0,
)

#: the whole 360-degree tire (issue 39; mesh kinds ``whole*``): no cut faces, two elements
#: through the rubber, pressed by the static sweep's rated-load deflection
#: (``meshes/aircraft/static_100``: 102.3 mm, 198.6 kN) so that the loads compare directly,
#: and the sector's relaxed convergence criteria (force residual 0.02 of the average nodal force,
#: displacement correction 0.5): under CalculiX's defaults (0.005, 0.01) the base stalled at 77 mm of
#: its 102.3 mm deflection, the largest residual flipping between 2.6 and 7.8 N (average nodal
#: force 381 N) as a patch-edge node went in and out of contact, the incompatible-mode unknowns of
#: the edge elements moving by 0.8 of their increment, with increments cut to 0.001 of the travel
#: (C3D8I everywhere then). Its rubber beyond |y| = ``PLAIN_EDGE_Y`` is plain C3D8 (see there) and
#: its road is larger (``whole_road``). Its slides converge under CalculiX's default criteria
#: (0.005, 0.01; the pure spin on whole-fine: 2-3 iterations an increment) and may take up to 50
#: iterations an increment (the divergence check after 12 iterations instead of 4).
WHOLE = dataclasses.replace(
    AIRCRAFT,
    name="aircraft-whole",
    deflection=WHOLE_DEFLECTION,
    road=whole_road,
    slide_controls=(
        "*CONTROLS, PARAMETERS=FIELD",
        "0.005, 0.01",
        "*CONTROLS, PARAMETERS=TIME INCREMENTATION",
        "12, 24, 24, 50, 30, 4, 0, 20",
    ),
)


def tire_for(mesh_kind: str, friction: float | None = None) -> rd.RigTire:
    """The rig tire of a mesh kind: the whole tire for ``whole*``, else the +-70 degree sector;
    ``friction``: another Coulomb coefficient for base and runs alike (0: frictionless; the mu = 0
    check runs, which need a base of their own: give them their own work folder)."""
    tire = WHOLE if mesh_kind.startswith("whole") else AIRCRAFT
    if friction is None:
        return tire
    if not 0.0 <= friction <= 10.0:
        raise ValueError(f"friction {friction} outside [0, 10]")
    return dataclasses.replace(
        tire,
        name=f"{tire.name}-mu{friction:g}",
        friction=friction,
        model_lines=functools.partial(model_lines_with, friction),
    )
