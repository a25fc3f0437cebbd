"""CalculiX deck of the slide/spin rig: the small tire sector on a rigidly moving road.

Steps (all quasi-static, NLGEOM):

1. inflation (as the static case);
2. vertical rim travel (as the static case); the rim (bead nodes) then stays put;
3. the road moves as one rigid body (``*RIGID BODY``) so that, seen from the
   tire, every road point has the constant velocity field of a sliding
   velocity (vx, vy) of the static patch origin c plus a spin wz about the
   road normal.

Kinematics. The relative sliding velocity of the tire point x against the road
is (THEORY section 3) ``w(x) = (vx - wz (y - cy), vy + wz (x - cx))``. With the
rim held, the road moves with the opposite field ``-w(x)``. For wz != 0 that
field is a rotation about the fixed point P = c + (-vy/wz, vx/wz) (where
w = 0, the instantaneous centre of rotation) at the rate -wz, so the rigid
body's reference node sits at P, is held fixed, and the rotation node turns by
-wz T about z; both grow linearly with the step time, which makes the motion
exactly the constant-rate one (CalculiX's rigid-body MPC is a finite
rotation). For wz = 0 the reference node sits at c and translates by -(vx, vy) T.

Quasi-static. There is no inertia and no rate in the material or the friction
law, so the "velocities" are displacements per unit of the step's pseudo-time
T = 1: only the direction of the sliding velocity and the ratio of spin to
sliding (wz R / |v|) matter for rigid-slip Coulomb friction, not their size.

Road reactions. The reference node's RF is the total force of the road on the
tire (the constraint holds the road against the tire's push), the rotation
node's RF the moment about the reference node; both are printed per increment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import ccxdeck as cx
from . import deck as dk
from .geometry import TireMesh
from .meshing import face_lookup

SLIDE_PATH = 0.03  # m, reference sliding path of a run: |v| T + |wz| R_REF T combined in quadrature
R_REF = 0.10  # m, reference patch radius used to scale the spin


@dataclass(frozen=True)
class Kinematics:
    """Sliding velocity (vx, vy) of the static patch origin relative to the road and spin wz.

    Units: m and rad per unit pseudo-time (the slide step lasts T = 1).
    """

    vx: float
    vy: float
    wz: float

    def pivot(self, origin: tuple[float, float]) -> tuple[float, float] | None:
        """The instantaneous centre of rotation P (m), None for pure sliding."""
        if self.wz == 0.0:
            return None
        return origin[0] - self.vy / self.wz, origin[1] + self.vx / self.wz


def kinematics(direction_deg: float, spin_angle_deg: float, spin_sign: int) -> Kinematics:
    """Kinematics of one run with the reference path ``SLIDE_PATH``.

    ``spin_angle_deg``: 0 = pure sliding, 90 = pure spin; |v| = S cos(a),
    |wz| R_REF = S sin(a). ``direction_deg``: direction of the sliding velocity
    from +x towards +y. ``spin_sign``: sign of wz.
    """
    a = math.radians(spin_angle_deg)
    d = math.radians(direction_deg)
    v = SLIDE_PATH * math.cos(a)
    wz = spin_sign * SLIDE_PATH * math.sin(a) / R_REF
    vx, vy = v * math.cos(d), v * math.sin(d)
    # exact zeros where they belong (pure spin, axis directions): the deck stays clean
    r = 12
    return Kinematics(round(vx, r) + 0.0, round(vy, r) + 0.0, round(wz, r) + 0.0)


@dataclass(frozen=True)
class RigNodes:
    ref: int  # 1-based CalculiX node number of the rigid body's reference node
    rot: int  # ... of its rotation node
    ref_xy: tuple[float, float]  # m, reference position of the reference node (z = 0)


def write_rig_deck(
    path, mesh: TireMesh, kin: Kinematics, rim_travel: float, origin: tuple[float, float], inc: float
) -> RigNodes:
    """Write the three-step rig deck; ``inc``: largest increment of the slide step (pseudo-time)."""
    road = cx.build_road()
    nt, nr = mesh.nodes.shape[0], road.nodes.shape[0]
    out = dk.model_lines(mesh, "fepost tire sector, slide/spin rig", road)
    w = out.append
    pivot = kin.pivot(origin)
    ref_xy = origin if pivot is None else pivot
    nodes = RigNodes(ref=nt + nr + 1, rot=nt + nr + 2, ref_xy=(float(ref_xy[0]), float(ref_xy[1])))
    w("*NODE, NSET=NALL")
    w(f"{nodes.ref}, {ref_xy[0]:.9e}, {ref_xy[1]:.9e}, 0.0")
    w(f"{nodes.rot}, {ref_xy[0]:.9e}, {ref_xy[1]:.9e}, 0.0")
    w("*NSET, NSET=REFN")
    w(str(nodes.ref))
    w("*NSET, NSET=ROTN")
    w(str(nodes.rot))
    w(f"*RIGID BODY, NSET=ROADN, REF NODE={nodes.ref}, ROT NODE={nodes.rot}")
    w("*BOUNDARY")
    w("REFN, 1, 3")
    w("ROTN, 1, 3")
    w("BEAD, 1, 3")
    table = face_lookup(mesh.hexes)

    def prints(frequency: int) -> None:
        # CalculiX 2.20 uses one output frequency for the .frd and the .dat requests: the
        # last increment of each step is always written; the slide step writes every one
        w(f"*NODE FILE, NSET=TIREN, FREQUENCY={frequency}")
        w("U")
        w(f"*CONTACT FILE, FREQUENCY={frequency}")
        w("CDIS, CSTR")
        w(f"*NODE PRINT, NSET=REFN, FREQUENCY={frequency}")
        w("U, RF")
        w(f"*NODE PRINT, NSET=ROTN, FREQUENCY={frequency}")
        w("U, RF")
        w(f"*NODE PRINT, NSET=BEAD, TOTALS=ONLY, FREQUENCY={frequency}")
        w("RF")

    w("*STEP, NLGEOM, INC=400")
    w("*STATIC")
    w("0.25, 1.0, 1e-5, 0.5")
    w("*DLOAD")
    out += cx.pressure_load(mesh.hexes, mesh.inner_quads, dk.PRESSURE, table)
    prints(1000)
    w("*END STEP")
    w("*STEP, NLGEOM, INC=400")
    w("*STATIC")
    w("0.05, 1.0, 1e-6, 0.1")
    w("*BOUNDARY")
    w(f"BEAD, 3, 3, {-rim_travel:.9e}")
    prints(1000)
    w("*END STEP")
    w("*STEP, NLGEOM, INC=2000")
    w("*STATIC")
    w(f"{inc / 2:.6g}, 1.0, 1e-7, {inc:.6g}")
    w("*BOUNDARY")
    if pivot is None:
        w(f"REFN, 1, 1, {-kin.vx:.12e}")
        w(f"REFN, 2, 2, {-kin.vy:.12e}")
    else:
        w(f"ROTN, 3, 3, {-kin.wz:.12e}")
    w(f"BEAD, 3, 3, {-rim_travel:.9e}")
    prints(1)
    w("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")
    return nodes
