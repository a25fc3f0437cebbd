"""Mesh of the aircraft tire for quasi-static rolling: fine along the whole rolled arc.

In the rolling runs the axle stays put and the rim turns about it by theta
(rad, about +y) while the road moves along -x under it. Tread material at the
angle phi from the bottom (positive towards +x) turns to phi - theta, so the
material that is in the patch at some time during the roll started on
phi in [-half_patch, theta + half_patch]. The mesh must be fine (and its
nodes contact slaves) on that whole arc, not symmetrically about the bottom.

It is the static sweep's tire (``aircraft_geometry``) meshed with uniform
circumferential layers over +-``fine_deg`` and then turned about the axle by
``centre_deg``, so that the fine arc covers [centre - fine_deg, centre + fine_deg].
The material axes of the carcass turn with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .aircraft_geometry import AircraftMesh, AircraftParams, build_aircraft_mesh


@dataclass(frozen=True)
class RollMeshSpec:
    """Circumferential layout of the rolling mesh (degrees)."""

    layer_deg: float = 2.0  # uniform layer size over the fine arc
    fine_deg: float = 78.0  # half-span of the fine arc
    centre_deg: float = 45.0  # where the fine arc is centred (from the bottom, towards +x)
    n_coarse: int = 8  # layers per side over the rest of the circumference
    n_crown: int = 5
    n_shoulder: int = 3
    n_side: int = 4

    def params(self) -> AircraftParams:
        return AircraftParams(
            first_deg=self.layer_deg,
            growth=1.0,
            fine_deg=self.fine_deg,
            n_coarse=self.n_coarse,
            n_crown=self.n_crown,
            n_shoulder=self.n_shoulder,
            n_side=self.n_side,
        )

    def arc(self) -> tuple[float, float]:
        """The fine arc (deg from the bottom, towards +x)."""
        return self.centre_deg - self.fine_deg, self.centre_deg + self.fine_deg


def turn_about_axle(mesh: AircraftMesh, angle_deg: float) -> AircraftMesh:
    """The mesh turned about the axle (the y axis through (0, 0, axle_z)) by ``angle_deg``.

    A point at phi from the bottom (towards +x) ends at phi + angle.
    """
    b = math.radians(angle_deg)
    c, s = math.cos(b), math.sin(b)
    zc = mesh.params.axle_z

    def turn(v: np.ndarray, shift: float) -> np.ndarray:
        x, z = v[:, 0], v[:, 2] - shift
        out = v.copy()
        out[:, 0] = x * c - z * s
        out[:, 2] = z * c + x * s + shift
        return out

    return replace(
        mesh,
        nodes=turn(mesh.nodes, zc),
        meridian=turn(mesh.meridian, 0.0),
        circumferential=turn(mesh.circumferential, 0.0),
        info={**mesh.info, "turned_deg": angle_deg},
    )


def build_roll_mesh(spec: RollMeshSpec) -> AircraftMesh:
    """The rolling mesh: uniform layers over the fine arc, turned to centre it on ``centre_deg``."""
    mesh = build_aircraft_mesh(spec.params())
    mesh = turn_about_axle(mesh, spec.centre_deg)
    lo, hi = spec.arc()
    mesh.info.update({"fine_arc_deg": [lo, hi], "layer_deg": spec.layer_deg})
    return mesh


def tiny_roll_spec() -> RollMeshSpec:
    """A few hundred elements: the test's rolling deck (coarse section, 6 degree layers)."""
    return RollMeshSpec(
        layer_deg=6.0, fine_deg=36.0, centre_deg=6.0, n_coarse=3, n_crown=2, n_shoulder=1, n_side=1
    )
