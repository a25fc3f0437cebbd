"""Equations of motion of the landing gear with dry-friction contact (docs/shimmy.md).

Frame: the ground, X along the aircraft's forward speed V, Y lateral, Z up. The
strut's lower end moves at (V, ẏ): y is the lateral bending deflection of the
strut at the axle (modal mass m_y, stiffness k_y, damping c_y). The wheel
assembly turns about the (vertical) strut axis by ψ (inertia I_ψ, torque-link
stiffness k_ψ, damping c_ψ). Wheel j's contact centre sits at r_j = (−e, d_j) in
the gear frame (trail e behind the axis, lateral offset d_j). The wheel rolls
at Ω with Ω r = (1 − κ) V: the longitudinal slip κ is held (the touchdown
spin-up frozen on the time scale of shimmy, or a brake holding a slip).

Sliding velocity and spin of contact j in its patch frame (x along the wheel):

    vx_j = V cos ψ + ẏ sin ψ − ψ̇ d_j − (1 − κ) V
    vy_j = −V sin ψ + ẏ cos ψ − ψ̇ e
    wz_j = ψ̇

and the friction model gives (Fx_j, Fy_j, Mz_j) on tire j. The motion:

    I_ψ ψ̈ = −k_ψ ψ − c_ψ ψ̇ + Σ_j (−e Fy_j − d_j Fx_j + Mz_j)
    m_y ÿ = −k_y y − c_y ẏ + Σ_j (Fx_j sin ψ + Fy_j cos ψ)

No tire elasticity and no non-holonomic rolling constraint: the tire slides
(Klimov and Zhuravlev's rigid wheel with multi-component dry friction). State
x = (ψ, ψ̇, y, ẏ). The steady motion is straight rolling with longitudinal
sliding κV: ψ̇ = ẏ = 0 and (ψ, y) at the equilibrium `equilibrium` finds
(zero for a map symmetric about x; a rolling map's small asymmetry moves it).
Since the friction forces depend only on the direction of (v, R wz), the
equilibrium does not depend on V.

Optional gear terms (`fepost.shimmy.gear`; absent, the equations above hold to
the last bit):

* strut rake γ: the wheels steer by δ = ψ cos γ about the vertical (δ and δ̇
  replace ψ and ψ̇ in the kinematics and in the lateral force's projection), and the ground's
  moment about the tilted strut axis is cos γ times its vertical moment. The
  camber ψ sin γ and the vertical load's moment on a raked caster are left out.
* wheel spin: each wheel (spin inertia I_w) turns at Ω = (1 − κ) V / R_e; the
  lateral bending rolls the axle by φ = s y. The angular momentum I_w Ω along the
  axle then couples the two degrees of freedom gyroscopically, with
  G = s Σ_j I_w Ω:  I_ψ ψ̈ = … + G ẏ,  m_y ÿ = … − G ψ̇ (skew: no work).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ArgumentError
from .gear import Gear

#: State components, in order.
STATE = ("psi", "psi_dot", "y", "y_dot")


def kinematics(x, V: float, gear: Gear):
    """(vx, vy, wz) of each wheel's contact (arrays over the wheels; complex x allowed)."""
    psi, dpsi, _, dy = x
    if gear.rake:
        psi, dpsi = psi * math.cos(gear.rake), dpsi * math.cos(gear.rake)
    c, s = np.cos(psi), np.sin(psi)
    d = np.asarray(gear.offsets)
    vx = V * c + dy * s - dpsi * d - (1.0 - gear.slip_ratio) * V
    vy = (-V * s + dy * c - dpsi * gear.trail) * np.ones_like(d)
    wz = dpsi * np.ones_like(d)
    return vx, vy, wz


def loads(x, forces, gear: Gear):
    """(yaw moment about the strut axis, lateral force on the strut) from the wheels' forces."""
    psi = x[0] * math.cos(gear.rake) if gear.rake else x[0]
    fx, fy, mz = (np.asarray(f) for f in forces)
    d = np.asarray(gear.offsets)
    moment = np.sum(-gear.trail * fy - d * fx + mz)
    if gear.rake:
        moment = moment * math.cos(gear.rake)
    lateral = np.sum(fx * np.sin(psi) + fy * np.cos(psi))
    return moment, lateral


def gyroscopic(gear: Gear, V: float) -> float:
    """G (N m s/m): the wheels' gyroscopic coupling of yaw and lateral bending at speed V."""
    return gear.gyroscopic * (1.0 - gear.slip_ratio) * V


def rhs(x, V: float, gear: Gear, contact):
    """dx/dt for the state ``x`` at speed ``V`` with ``contact(vx, vy, wz) -> (Fx, Fy, Mz)``."""
    psi, dpsi, y, dy = x
    moment, lateral = loads(x, contact(*kinematics(x, V, gear)), gear)
    g = gyroscopic(gear, V)
    if g:
        moment = moment + g * dy
        lateral = lateral - g * dpsi
    ddpsi = (-gear.torsional_stiffness * psi - gear.torsional_damping * dpsi + moment) / gear.yaw_inertia
    ddy = (-gear.lateral_stiffness * y - gear.lateral_damping * dy + lateral) / gear.lateral_mass
    return np.array([dpsi, ddpsi, dy, ddy])


def equilibrium(gear: Gear, contact, V: float = 1.0) -> np.ndarray:
    """The steady motion's state (ψ, 0, y, 0) (independent of V, module docstring)."""
    from scipy.optimize import root

    def residual(q):
        return rhs(np.array([q[0], 0.0, q[1], 0.0]), V, gear, contact)[[1, 3]]

    sol = root(residual, np.zeros(2), method="hybr", options={"xtol": 1e-13})
    converged = sol.success or _balanced_to_round_off(
        np.array([sol.x[0], 0.0, sol.x[1], 0.0]), V, gear, contact
    )
    if not converged or np.max(np.abs(sol.x)) > 0.2:
        raise ArgumentError(
            f"no steady rolling state found for this gear and contact ({sol.message}; "
            f"psi = {sol.x[0]:.3g} rad, y = {sol.x[1]:.3g} m): the torsional or lateral stiffness "
            "is too small to hold the contact's asymmetry"
        )
    return np.array([sol.x[0], 0.0, sol.x[1], 0.0])


#: Relative residual of the steady state's moment and force balance read as zero (round-off).
BALANCE_RTOL = 1e-10


def _balanced_to_round_off(x: np.ndarray, V: float, gear: Gear, contact) -> bool:
    """Whether the yaw moment and the lateral force balance at ``x`` to `BALANCE_RTOL` of their
    terms' sizes: a steady state the root finder stopped at without "converging" because the
    residual is round-off (a symmetric map's steady state is zero to about 1e-18)."""
    fx, fy, mz = (np.abs(np.asarray(f, float)) for f in contact(*kinematics(x, V, gear)))
    lever = gear.trail + np.abs(np.asarray(gear.offsets)) + float(getattr(contact, "R", 0.0))
    moment_scale = float(np.sum((fx + fy) * lever + mz)) + gear.torsional_stiffness * abs(x[0])
    force_scale = float(np.sum(fx + fy)) + gear.lateral_stiffness * abs(x[2])
    res = rhs(x, V, gear, contact)
    return bool(
        abs(res[1]) * gear.yaw_inertia <= BALANCE_RTOL * moment_scale
        and abs(res[3]) * gear.lateral_mass <= BALANCE_RTOL * force_scale
    )


def scalar_rhs(gear: Gear, V: float, one):
    """`rhs` as a function ``f(t, x)`` of plain Python floats for the time integration.

    ``one(vx, vy, wz) -> (Fx, Fy, Mz)`` is a contact's one-point evaluation
    (`fepost.shimmy.contact.Contact.scalar`); the result equals `rhs` (tested).
    """
    e, kap = gear.trail, gear.slip_ratio
    i_psi, k_psi, c_psi = gear.yaw_inertia, gear.torsional_stiffness, gear.torsional_damping
    m_y, k_y, c_y = gear.lateral_mass, gear.lateral_stiffness, gear.lateral_damping
    offsets = gear.offsets
    slip = (1.0 - kap) * V
    cos, sin = math.cos, math.sin
    cos_rake, gyro = math.cos(gear.rake), gyroscopic(gear, V)

    def f(t, x):
        psi, dpsi, y, dy = x
        steer, rate = psi * cos_rake, dpsi * cos_rake
        c, s = cos(steer), sin(steer)
        bx = V * c + dy * s - slip
        by = -V * s + dy * c - rate * e
        moment = lateral = 0.0
        for d in offsets:
            fx, fy, mz = one(bx - rate * d, by, rate)
            moment += -e * fy - d * fx + mz
            lateral += fx * s + fy * c
        moment = moment * cos_rake + gyro * dy
        lateral -= gyro * dpsi
        return [
            dpsi,
            (-k_psi * psi - c_psi * dpsi + moment) / i_psi,
            dy,
            (-k_y * y - c_y * dy + lateral) / m_y,
        ]

    return f
