"""The gear of `fepost.shimmy.equations` on brush tires (`fepost.shimmy.brush`): grip and partial sliding.

``crab`` (rad): the direction of travel turned by that angle from the gear's x (an
aircraft landing crabbed); the kinematics then use cos(δ − crab), sin(δ − crab)
where the rigid wheel's use cos δ, sin δ.

State: the gear's (ψ, ψ̇, y, ẏ), then with ``spin`` each wheel's spin ω_j (rad/s,
rolling speed V_r = ω_j R_e), then each wheel's element deflections (e_x, e_y),
and with ``energy`` five work integrals (J): the contact force's work on the
forward motion, the dampers', the sliding elements', the tread's released at
the trailing edge, and the tread's given up to the fresh tread entering a growing
patch at touchdown ((ṡ/s) times the tread's energy). Each wheel's patch origin moves over the road as in
`fepost.shimmy.equations.kinematics` (the rigid wheel's slip, V_r in place of
(1 − κ) V), its elements deflect as the brush says, and their resultants enter
the yaw and lateral equations as the rigid wheel's contact forces do:

    I_ψ ψ̈ = −k_ψ ψ − c_ψ ψ̇ + cos γ Σ_j (−e Fy_j − d_j Fx_j + Mz_j) + G ẏ
    m_y ÿ = −k_y y − c_y ẏ + Σ_j (Fx_j sin δ + Fy_j cos δ) − G ψ̇
    I_w ω̇_j = −R_e Fx_j            (with ``spin``; else V_r = (1 − κ) V, held)

with G = s Σ_j I_w ω_j (the gear's ``bending_slope`` s, 0 without it). Energy
(tested): d/dt (kinetic + elastic + tread) = −P_forward − P_dampers − P_sliding + P_released − P_entering,
where P_forward = V Σ_j (Fx_j cos δ − Fy_j sin δ), so the integrals close the balance
to the integrator's tolerance.

`steady_state` and `jacobian` give the straight rolling at a held slip and its
linearisation (central differences on the equations; the element states are
smooth there away from the stick-slip boundary), `growth_rate` the largest real
part of its eigenvalues.

The tire may be the brush on a carcass (`fepost.shimmy.carcass.CarcassTire`): its
element states are then the total deflections (tread and carcass), its elastic
energy includes the carcass's, and its linearisation holds the steady state's
sliding elements on their sliding branch (a step on one element moves the carcass
and every element with it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ArgumentError
from .brush import BrushTire
from .carcass import CarcassTire
from .gear import Gear

#: Work integrals appended with ``energy`` (J).
WORKS = ("forward", "dampers", "sliding", "released", "entering")


@dataclass(frozen=True)
class GripModel:
    """The gear on brush tires (module docstring)."""

    gear: Gear
    tire: BrushTire | CarcassTire
    spin: bool = False
    energy: bool = False
    crab: float = 0.0

    @property
    def wheels(self) -> int:
        return self.gear.wheels

    @property
    def n_state(self) -> int:
        return (
            4
            + (self.wheels if self.spin else 0)
            + 2 * self.wheels * self.tire.n
            + (len(WORKS) if self.energy else 0)
        )

    def blocks(self, X):
        """(gear state, spins or None, [(ex, ey) per wheel], works or None) views of a state."""
        n, w = self.tire.n, self.wheels
        i = 4 + (w if self.spin else 0)
        elems = [
            (X[i + 2 * j * n : i + (2 * j + 1) * n], X[i + (2 * j + 1) * n : i + (2 * j + 2) * n])
            for j in range(w)
        ]
        works = X[i + 2 * w * n :] if self.energy else None
        return X[:4], (X[4 : 4 + w] if self.spin else None), elems, works

    def rhs(self, V: float, load=None):
        """f(t, X) at forward speed V (m/s); ``load(t) -> (s, ṡ/s)``: the share of the full load
        and its relative rate (default (1, 0); `fepost.shimmy.brush.BrushTire.resultants`)."""
        g, tire = self.gear, self.tire
        cr = math.cos(g.rake)
        e_tr, offsets, kap = g.trail, g.offsets, g.slip_ratio
        re, iw = g.rolling_radius, g.wheel_spin_inertia
        crab = self.crab
        if self.spin and not (re > 0 and iw > 0):
            raise ArgumentError("wheel spin needs the gear's rolling_radius and wheel_spin_inertia")

        def f(t, X):
            (psi, dpsi, y, dy), spins, elems, _ = self.blocks(X)
            scale, growth = (1.0, 0.0) if load is None else load(t)
            steer, rate = psi * cr, dpsi * cr
            c, s = math.cos(steer - crab), math.sin(steer - crab)
            cs, ss = math.cos(steer), math.sin(steer)
            out = np.empty_like(X)
            moment = lateral = forward = sliding = released = entering = 0.0
            spin_sum = 0.0
            parts = []
            for j, d in enumerate(offsets):
                vr = spins[j] * re if self.spin else (1.0 - kap) * V
                vx = V * c + dy * s - rate * d - vr
                vy = -V * s + dy * c - rate * e_tr
                ex, ey = elems[j]
                dex, dey, lam = tire.rates(ex, ey, vx, vy, rate, vr, growth)
                fx, fy, mz = tire.resultants(ex, ey, scale)
                moment += -e_tr * fy - d * fx + mz
                lateral += fx * ss + fy * cs
                forward += V * (fx * c - fy * s)
                if self.energy:
                    sliding += tire.dissipation(ex, ey, lam, scale)
                    released += scale * tire.released(ex, ey, vr)
                    entering += growth * tire.energy(ex, ey, scale)
                if self.spin:
                    spin_sum += spins[j]
                parts.append((dex, dey, fx))
            gyro = (
                g.bending_slope * iw * (spin_sum if self.spin else self.wheels * (1 - kap) * V / re)
                if iw
                else 0.0
            )
            moment = moment * cr + gyro * dy
            lateral -= gyro * dpsi
            out[0] = dpsi
            out[1] = (-g.torsional_stiffness * psi - g.torsional_damping * dpsi + moment) / g.yaw_inertia
            out[2] = dy
            out[3] = (-g.lateral_stiffness * y - g.lateral_damping * dy + lateral) / g.lateral_mass
            _, out_spins, out_elems, _ = self.blocks(out)
            for j, ((out_x, out_y), (dex, dey, fx)) in enumerate(zip(out_elems, parts, strict=True)):
                out_x[:], out_y[:] = dex, dey
                if self.spin:
                    out_spins[j] = -re * fx / iw
            if self.energy:
                damp = g.torsional_damping * dpsi * dpsi + g.lateral_damping * dy * dy
                out[-5:] = (forward, damp, sliding, released, entering)
            return out

        return f

    def mechanical_energy(self, X, scale: float = 1.0) -> float:
        """Kinetic and elastic energy of gear, wheels and tread (J) at the load share ``scale``."""
        g = self.gear
        (psi, dpsi, y, dy), spins, elems, _ = self.blocks(X)
        e = 0.5 * (g.yaw_inertia * dpsi**2 + g.torsional_stiffness * psi**2)
        e += 0.5 * (g.lateral_mass * dy**2 + g.lateral_stiffness * y**2)
        if self.spin:
            e += 0.5 * g.wheel_spin_inertia * float(np.sum(np.asarray(spins) ** 2))
        return e + sum(self.tire.energy(ex, ey, scale) for ex, ey in elems)

    def steady_state(self, V: float) -> np.ndarray:
        """Straight rolling at the gear's held slip κ: the gear's equilibrium and the elements' steady
        deflections (the rigid wheel's `fepost.shimmy.equations.equilibrium` with the brush's forces)."""
        from scipy.optimize import root

        if self.spin or self.energy or self.crab:
            raise ArgumentError("the steady state is for the held slip (spin=False, energy=False, crab=0)")
        g, tire = self.gear, self.tire
        vr = (1.0 - g.slip_ratio) * V

        def state(q):
            X = np.zeros(self.n_state)
            X[0], X[2] = q
            cr = math.cos(g.rake)
            c, s = math.cos(q[0] * cr), math.sin(q[0] * cr)
            for j, _ in enumerate(g.offsets):
                ex, ey = tire.steady(V * c - vr, -V * s, 0.0, vr)
                i = 4 + 2 * j * tire.n
                X[i : i + tire.n], X[i + tire.n : i + 2 * tire.n] = ex, ey
            return X

        f = self.rhs(V)
        sol = root(lambda q: f(0.0, state(q))[[1, 3]], np.zeros(2), method="hybr", options={"xtol": 1e-13})
        if not sol.success and np.max(np.abs(f(0.0, state(sol.x))[[1, 3]])) > 1e-6:
            raise ArgumentError(
                f"no steady rolling state found for this gear on the brush tire ({sol.message})"
            )
        return state(sol.x)

    def jacobian(self, V: float, X0: np.ndarray | None = None) -> np.ndarray:
        """∂f/∂X at the steady state (central differences, steps scaled by the states' sizes)."""
        X0 = self.steady_state(V) if X0 is None else X0
        f = self._sliding_branch(X0).rhs(V)
        n = X0.size
        typical = np.full(n, max(float(np.max(np.abs(X0[4:]), initial=0.0)), 1e-6))
        typical[:4] = 1e-3
        steps = 1e-6 * np.maximum(np.abs(X0), typical)
        jac = np.empty((n, n))
        f0 = f(0.0, X0)
        outward = self._on_limit(X0) if isinstance(self.tire, BrushTire) else np.zeros(n, bool)
        for k in range(n):
            h = steps[k]
            xp = X0.copy()
            if outward[k]:  # one-sided, off the friction limit outwards: the sliding branch
                xp[k] += h * np.sign(X0[k])
                jac[:, k] = (f(0.0, xp) - f0) / (h * np.sign(X0[k]))
                continue
            xm = X0.copy()
            xp[k] += h
            xm[k] -= h
            jac[:, k] = (f(0.0, xp) - f(0.0, xm)) / (2 * h)
        return jac

    def _sliding_branch(self, X0) -> GripModel:
        """The model whose carcass tire keeps the elements sliding at ``X0`` on their sliding branch
        (`fepost.shimmy.carcass.CarcassTire.frozen_at`): a step on any element moves the carcass and
        with it every element, so the lumped brush's one-sided steps cannot keep the branch."""
        if not isinstance(self.tire, CarcassTire):
            return self
        masks = [self.tire.on_limit(ex, ey) for ex, ey in self.blocks(X0)[2]]
        if any(not np.array_equal(m, masks[0]) for m in masks[1:]):
            raise ArgumentError(
                "the wheels slide on different elements: no common sliding branch to linearise"
            )
        return replace(self, tire=self.tire.frozen_at(masks[0]))

    def _on_limit(self, X) -> np.ndarray:
        """Mask of the states that are sliding elements' deflections (|F_i| at f n_i to 1e-9)."""
        mask = np.zeros(X.size, bool)
        for (ex, ey), (mask_x, mask_y) in zip(self.blocks(X)[2], self.blocks(mask)[2], strict=True):
            mask_x[:] = mask_y[:] = self.tire.on_limit(ex, ey)
        return mask

    def eigenvalues(self, V: float) -> np.ndarray:
        """Eigenvalues (1/s) of the linearisation at speed V."""
        return np.linalg.eigvals(self.jacobian(V))

    def growth_rate(self, V: float) -> float:
        """Largest real part of the eigenvalues (1/s)."""
        return float(np.max(self.eigenvalues(V).real))
