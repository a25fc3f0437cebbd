"""Linear stability of the steady rolling with sliding: eigenvalues of the Jacobian.

The Jacobian of `fepost.shimmy.equations.rhs` about the steady state is taken by
complex step (exact to round-off) with the contact replaced by its linearisation
F_j + G_j (k − k_j), where G_j = ∂(Fx, Fy, Mz)/∂(vx, vy, wz) at wheel j's steady
kinematics comes from `fepost.shimmy.contact.Contact.jacobian` (complex step for
the closed forms, adaptive high-order differences for the others). The friction
models are homogeneous of degree 0 in the kinematics, and the steady state does
not depend on V, so G at speed V is G at V = 1 divided by V: one contact Jacobian
serves a whole speed sweep (`Linearisation`).

The growth rate at V is the largest real part of the eigenvalues (1/s), the
frequency that eigenvalue's |Im|/2π (Hz). Critical speeds are where the growth
rate changes sign along the sweep, each refined by Brent's method.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from .contact import COMPLEX_STEP, Contact
from .equations import equilibrium, kinematics, rhs
from .gear import Gear

#: Largest change of the steady kinematics (m/s at V = 1, so a turn of the sliding direction in
#: rad) for which a contact Jacobian is reused: the Jacobian then changes by about this fraction.
REUSE_TOL = 1e-5


@dataclass(frozen=True)
class Linearisation:
    """The contact linearised about the steady state (at V = 1 m/s)."""

    gear: Gear
    state: np.ndarray
    forces: tuple[np.ndarray, np.ndarray, np.ndarray]
    kinematics: np.ndarray  # (3, wheels) at V = 1
    gradients: np.ndarray  # (wheels, 3, 3) at V = 1

    @classmethod
    def of(cls, gear: Gear, contact: Contact) -> Linearisation:
        x0 = equilibrium(gear, contact)
        k = np.array(kinematics(x0, 1.0, gear), float)
        grads = np.array([contact.jacobian(*k[:, j]) for j in range(k.shape[1])])
        forces = tuple(np.asarray(f, float) for f in contact(*k))
        return cls(gear, x0, forces, k, grads)  # type: ignore[arg-type]

    def for_gear(self, gear: Gear, contact: Contact) -> Linearisation:
        """The linearisation of another ``gear`` on the same ``contact``: the steady state is
        solved again; the contact's gradients are reused when the wheels' steady kinematics
        are those of this linearisation (to `REUSE_TOL` m/s at V = 1), else recomputed."""
        x0 = equilibrium(gear, contact)
        k = np.array(kinematics(x0, 1.0, gear), float)
        if k.shape != self.kinematics.shape or np.max(np.abs(k - self.kinematics)) > REUSE_TOL:
            return Linearisation.of(gear, contact)
        return Linearisation(gear, x0, self.forces, self.kinematics, self.gradients)

    def scaled(self, factor: float, contact: Contact) -> Linearisation:
        """The linearisation of ``contact.scaled(factor)`` (a friction level f'/f): forces and
        gradients times ``factor`` (every model is linear in f), the steady state solved again."""
        x0 = equilibrium(self.gear, contact.scaled(factor))
        forces = tuple(factor * f for f in self.forces)
        return Linearisation(self.gear, x0, forces, self.kinematics, factor * self.gradients)  # type: ignore[arg-type]

    def contact_at(self, V: float):
        """The linearised contact at speed V: (vx, vy, wz) -> (Fx, Fy, Mz), complex allowed."""
        k0 = self.kinematics * V
        g = self.gradients / V
        f0 = self.forces

        def linear(vx, vy, wz):
            dk = np.array([vx, vy, wz]) - k0
            out = np.einsum("jab,bj->aj", g, dk)
            return f0[0] + out[0], f0[1] + out[1], f0[2] + out[2]

        return linear

    def jacobian(self, V: float) -> np.ndarray:
        """∂(dx/dt)/∂x at the steady state and speed V (4 × 4)."""
        contact = self.contact_at(V)
        jac = np.empty((4, 4))
        for j in range(4):
            x = self.state.astype(complex)
            x[j] += 1j * COMPLEX_STEP
            jac[:, j] = np.imag(rhs(x, V, self.gear, contact)) / COMPLEX_STEP
        return jac

    def eigenvalues(self, V: float) -> np.ndarray:
        return np.linalg.eigvals(self.jacobian(V))

    def growth(self, V: float) -> tuple[float, float]:
        """(largest real part in 1/s, its frequency in Hz) at speed V."""
        ev = self.eigenvalues(V)
        i = int(np.argmax(ev.real))
        return float(ev[i].real), float(abs(ev[i].imag) / (2 * np.pi))


@dataclass(frozen=True)
class StabilityMap:
    """Growth rate and frequency over a speed sweep, and the critical speeds."""

    speeds: np.ndarray
    growth_rate: np.ndarray
    frequency_hz: np.ndarray
    eigenvalues: np.ndarray  # (speeds, 4) complex
    critical_speeds: tuple[float, ...]
    critical_frequencies: tuple[float, ...]

    def rows(self) -> list[dict]:
        return [
            {"speed": float(v), "growth_rate": float(g), "frequency_hz": float(f)}
            for v, g, f in zip(self.speeds, self.growth_rate, self.frequency_hz, strict=True)
        ]

    @property
    def critical_speed(self) -> float | None:
        """The lowest critical speed (m/s), None when the sweep has none."""
        return self.critical_speeds[0] if self.critical_speeds else None


def stability_map(lin: Linearisation, speeds) -> StabilityMap:
    """Eigenvalues over ``speeds`` (m/s, increasing, > 0) and the sign changes of the growth rate."""
    from scipy.optimize import brentq

    speeds = np.asarray(speeds, float)
    if speeds.ndim != 1 or speeds.size < 2 or np.any(speeds <= 0) or np.any(np.diff(speeds) <= 0):
        raise ArgumentError("speeds must be at least two increasing positive values (m/s)")
    eig = np.array([np.sort_complex(lin.eigenvalues(V)) for V in speeds])
    imax = np.argmax(eig.real, axis=1)
    top = eig[np.arange(len(speeds)), imax]
    growth = top.real
    freq = np.abs(top.imag) / (2 * np.pi)
    crit, fcrit = [], []
    for i in np.nonzero(np.sign(growth[:-1]) * np.sign(growth[1:]) < 0)[0]:
        v = brentq(lambda s: lin.growth(s)[0], speeds[i], speeds[i + 1], xtol=1e-10, rtol=1e-12)
        crit.append(float(v))
        fcrit.append(lin.growth(v)[1])
    return StabilityMap(speeds, growth, freq, eig, tuple(crit), tuple(fcrit))


def critical_speed(lin: Linearisation, lo: float, hi: float, n: int = 60) -> float | None:
    """The lowest critical speed in [lo, hi] (coarse sweep of ``n`` speeds, then Brent), or None."""
    return stability_map(lin, np.linspace(lo, hi, n)).critical_speed


@dataclass(frozen=True)
class TrailMap:
    """The stability boundary over speed × trail: the lowest critical speed at each trail."""

    trails: np.ndarray
    critical_speeds: tuple[float | None, ...]
    speeds: tuple[float, float]

    def rows(self) -> list[dict]:
        return [
            {"trail": float(t), "critical_speed": v}
            for t, v in zip(self.trails, self.critical_speeds, strict=True)
        ]


def trail_map(lin: Linearisation, contact: Contact, trails, speeds) -> TrailMap:
    """Lowest critical speed over ``speeds`` for each of ``trails`` (m), the gear otherwise
    ``lin``'s (the contact's Jacobian reused, `Linearisation.for_gear`)."""
    speeds = np.asarray(speeds, float)
    crit = []
    for t in np.asarray(trails, float):
        other = lin.for_gear(lin.gear.replace(trail=float(t)), contact)
        crit.append(stability_map(other, speeds).critical_speed)
    return TrailMap(np.asarray(trails, float), tuple(crit), (float(speeds[0]), float(speeds[-1])))
