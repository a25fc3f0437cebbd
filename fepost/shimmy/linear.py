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
frequency that eigenvalue's |Im|/2π (Hz). A speed is unstable when its growth rate
is above round-off (`GROWTH_RTOL` of the Jacobian's norm). Boundaries are where that
changes along the sweep, each refined by Brent's method and given its direction:
``onset`` (unstable above it) or ``end`` (stable again above it). The critical speed
is the first onset; a sweep unstable from its lowest speed has unstable ranges but
may have no onset at all.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import ArgumentError
from .contact import COMPLEX_STEP, Contact
from .equations import equilibrium, kinematics, rhs
from .gear import Gear

#: Agreement (relative to its largest entry) of the Jacobian from its speed terms with the direct
#: one, checked before the terms are used (`Linearisation.speed_terms`); round-off is about 1e-14.
AFFINE_RTOL = 1e-10
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
        """∂(dx/dt)/∂x at the steady state and speed V (4 × 4): from `speed_terms` when the
        Jacobian has been checked to be C0 + C1/V + C2 V, else by complex step (`direct_jacobian`)."""
        terms = self.speed_terms
        if terms is None:
            return self.direct_jacobian(V)
        return terms[0] + terms[1] / V + terms[2] * V

    @cached_property
    def speed_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(C0, C1, C2) with Jacobian(V) = C0 + C1/V + C2 V, or None when it is not of that form.

        The kinematics are linear in V (V a(x) + b(x)) and the linearised contact's gradient
        is G/V, so the contact's part is G a' + G b'/V; the gear's own terms are constant, a
        wheel's gyroscopic coupling proportional to V. The three terms come from the direct
        Jacobian at 1, 2 and 4 m/s and are checked against it at 3 and 50 m/s (`AFFINE_RTOL`
        of its norm): a sweep then costs a 4 × 4 sum per speed instead of four complex-step
        evaluations of the equations."""
        speeds = (1.0, 2.0, 4.0)
        jac = np.array([self.direct_jacobian(v) for v in speeds])
        basis = np.array([[1.0, 1.0 / v, v] for v in speeds])
        coef = np.linalg.solve(basis, jac.reshape(3, -1)).reshape(3, 4, 4)
        for v in (3.0, 50.0):
            want = self.direct_jacobian(v)
            got = coef[0] + coef[1] / v + coef[2] * v
            if np.max(np.abs(got - want)) > AFFINE_RTOL * max(float(np.max(np.abs(want))), 1e-300):
                return None
        return coef[0], coef[1], coef[2]

    def direct_jacobian(self, V: float) -> np.ndarray:
        """∂(dx/dt)/∂x at speed V by complex step of the equations with the linearised contact."""
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


#: Growth rates within this fraction of the Jacobian's norm of zero are round-off: neither
#: growing nor decaying. The eigenvalues' backward error is about 2e-16 of the norm; this
#: leaves room for an eigenvalue condition number up to about 5e5.
GROWTH_RTOL = 1e-10
#: Directions of a boundary: ``onset`` (unstable above it) and ``end`` (stable again above it).
ONSET, END = "onset", "end"


@dataclass(frozen=True)
class Boundary:
    """A speed where the growth rate changes sign, its direction (`ONSET` or `END`), the frequency
    of the mode that crosses, and that mode's shape (ψ, ψ̇, y, ẏ), scaled to ψ = 1 rad."""

    speed: float
    direction: str
    frequency_hz: float
    mode: np.ndarray

    def to_dict(self) -> dict:
        return {"speed": self.speed, "direction": self.direction, "frequency_hz": self.frequency_hz}


@dataclass(frozen=True)
class StabilityMap:
    """Growth rate and frequency over a speed sweep, the boundaries and the unstable ranges.

    ``tolerance``: growth rates within ± this (1/s) are zero to round-off (`GROWTH_RTOL`
    times the largest norm of the Jacobian over the sweep) and count as not growing.
    """

    speeds: np.ndarray
    growth_rate: np.ndarray
    frequency_hz: np.ndarray
    eigenvalues: np.ndarray  # (speeds, 4) complex
    boundaries: tuple[Boundary, ...]
    tolerance: float

    def rows(self) -> list[dict]:
        return [
            {"speed": float(v), "growth_rate": float(g), "frequency_hz": float(f)}
            for v, g, f in zip(self.speeds, self.growth_rate, self.frequency_hz, strict=True)
        ]

    @property
    def unstable(self) -> np.ndarray:
        """Whether each speed of the sweep is unstable (growth rate above `tolerance`)."""
        return self.growth_rate > self.tolerance

    @property
    def critical_speeds(self) -> tuple[float, ...]:
        """The onsets of instability (m/s), increasing."""
        return tuple(b.speed for b in self.boundaries if b.direction == ONSET)

    @property
    def critical_speed(self) -> float | None:
        """The first onset of instability (m/s), None when the sweep has none."""
        onsets = self.critical_speeds
        return onsets[0] if onsets else None

    @property
    def critical_frequency(self) -> float | None:
        """The frequency (Hz) of the mode that crosses at `critical_speed`."""
        return next((b.frequency_hz for b in self.boundaries if b.direction == ONSET), None)

    @property
    def unstable_ranges(self) -> tuple[tuple[float, float | None], ...]:
        """[from, to] (m/s) of each unstable range: ``from`` the sweep's lowest speed when unstable
        there, ``to`` None when still unstable at its highest."""
        out: list[tuple[float, float | None]] = []
        start = float(self.speeds[0]) if self.unstable[0] else None
        for b in self.boundaries:
            if b.direction == ONSET:
                start = b.speed
            else:
                out.append((float(self.speeds[0]) if start is None else start, b.speed))
                start = None
        if start is not None:
            out.append((start, None))
        return tuple(out)

    @property
    def verdict(self) -> str:
        """``stable`` (over the whole sweep), ``unstable`` (over the whole sweep) or ``mixed``."""
        if not self.boundaries:
            return "unstable" if self.unstable[0] else "stable"
        return "mixed"

    def summary(self) -> str:
        """One line: the verdict over the sweep in words."""
        lo, hi = float(self.speeds[0]), float(self.speeds[-1])
        if self.verdict == "stable":
            return f"stable over the whole range ({lo:g} to {hi:g} m/s)"
        if self.verdict == "unstable":
            return f"unstable over the whole range ({lo:g} to {hi:g} m/s)"
        parts = [f"{a:.2f} to {'the top' if b is None else f'{b:.2f}'}" for a, b in self.unstable_ranges]
        return "unstable from " + ", from ".join(parts) + " m/s"


def _refine(lin: Linearisation, lo: float, hi: float, g_lo: float, g_hi: float, tol: float) -> float:
    """The speed in [lo, hi] where the growth rate crosses zero (Brent); when one end is zero to
    round-off, where it crosses ``tol`` (the classification's threshold)."""
    from scipy.optimize import brentq

    shift = 0.0 if g_lo * g_hi < 0 else tol
    return float(brentq(lambda s: lin.growth(s)[0] - shift, lo, hi, xtol=1e-10, rtol=1e-12))


def _mode(lin: Linearisation, V: float) -> tuple[float, np.ndarray]:
    """(frequency in Hz, shape scaled to ψ = 1) of the least damped mode at speed V."""
    ev, vec = np.linalg.eig(lin.jacobian(V))
    i = int(np.argmax(ev.real))
    shape = vec[:, i]
    if abs(shape[0]) > 0:
        shape = shape / shape[0]
    return float(abs(ev[i].imag) / (2 * np.pi)), shape


def stability_map(lin: Linearisation, speeds) -> StabilityMap:
    """Eigenvalues over ``speeds`` (m/s, increasing, > 0) and the boundaries between stable and
    unstable speeds, each refined by Brent's method, with its direction and mode."""
    speeds = np.asarray(speeds, float)
    if speeds.ndim != 1 or speeds.size < 2 or np.any(speeds <= 0) or np.any(np.diff(speeds) <= 0):
        raise ArgumentError("speeds must be at least two increasing positive values (m/s)")
    jacs = [lin.jacobian(V) for V in speeds]
    eig = np.array([np.sort_complex(np.linalg.eigvals(j)) for j in jacs])
    tol = GROWTH_RTOL * max(float(np.linalg.norm(j)) for j in jacs)
    imax = np.argmax(eig.real, axis=1)
    top = eig[np.arange(len(speeds)), imax]
    growth = top.real
    freq = np.abs(top.imag) / (2 * np.pi)
    unstable = growth > tol
    bounds = []
    for i in np.nonzero(unstable[:-1] != unstable[1:])[0]:
        v = _refine(lin, speeds[i], speeds[i + 1], growth[i], growth[i + 1], tol)
        f, shape = _mode(lin, v)
        bounds.append(Boundary(v, ONSET if unstable[i + 1] else END, f, shape))
    return StabilityMap(speeds, growth, freq, eig, tuple(bounds), tol)


def critical_speed(lin: Linearisation, lo: float, hi: float, n: int = 60) -> float | None:
    """The first onset of instability in [lo, hi] (coarse sweep of ``n`` speeds, then Brent), or None."""
    return stability_map(lin, np.linspace(lo, hi, n)).critical_speed


@dataclass(frozen=True)
class ParameterMap:
    """Stability over speed × one gear parameter: the growth rate on the grid, and at each value
    the first onset of instability and the unstable ranges."""

    parameter: str
    values: np.ndarray
    speeds: np.ndarray
    growth_rate: np.ndarray  # (values, speeds), 1/s
    critical_speeds: tuple[float | None, ...]
    unstable_ranges: tuple[tuple[tuple[float, float | None], ...], ...]

    def rows(self) -> list[dict]:
        return [
            {self.parameter: float(t), "critical_speed": v, "unstable_ranges": [list(r) for r in rng]}
            for t, v, rng in zip(self.values, self.critical_speeds, self.unstable_ranges, strict=True)
        ]


def parameter_map(lin: Linearisation, contact: Contact, parameter: str, values, speeds) -> ParameterMap:
    """Stability over ``speeds`` for each of ``values`` of the gear's ``parameter`` (a `Gear`
    field), the gear otherwise ``lin``'s (the contact's Jacobian reused, `Linearisation.for_gear`)."""
    speeds = np.asarray(speeds, float)
    values = np.asarray(values, float)
    growth, crit, ranges = [], [], []
    for t in values:
        smap = stability_map(lin.for_gear(lin.gear.replace(**{parameter: float(t)}), contact), speeds)
        growth.append(smap.growth_rate)
        crit.append(smap.critical_speed)
        ranges.append(smap.unstable_ranges)
    return ParameterMap(parameter, values, speeds, np.array(growth), tuple(crit), tuple(ranges))


def trail_map(lin: Linearisation, contact: Contact, trails, speeds) -> ParameterMap:
    """First onset of instability over ``speeds`` for each of ``trails`` (m) (`parameter_map`)."""
    return parameter_map(lin, contact, "trail", trails, speeds)
