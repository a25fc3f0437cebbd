"""Nonlinear time simulation of the gear from a small perturbation (scipy's solve_ivp).

The motion starts at the steady state with the yaw angle perturbed by
``perturbation`` (rad) and is integrated for ``duration`` seconds (Dormand–Prince
8(5,3), rtol 1e-7) on `fepost.shimmy.equations.scalar_rhs`. The contact is the
friction model's one-point evaluation (`fepost.shimmy.contact.Contact.scalar`):
the closed forms themselves, or for the map-based models their
`fepost.shimmy.table.DirectionTable` (the same model tabulated over the sphere
of directions, so the integration does not repeat the map's integrals).

Verdict, from the yaw deviation |ψ − ψ_eq| over the windows [0.6, 0.8] T (A_mid)
and [0.8, 1] T (A_end) of the duration T, with A_0 the perturbation. The motion is
classed by where it settles, never against the size of the kick (a limit cycle
smaller than the kick is a limit cycle):

* ``decays``: A_end < `DECAYED` A_0 (died away), or A_end < (1 − `SETTLED`) A_mid
  (still falling at the end);
* ``grows``: A_end > (1 + `SETTLED`) A_mid (still growing at the end);
* ``limit_cycle``: otherwise: the amplitude changed by at most `SETTLED` between the
  two windows; it has settled on an oscillation of amplitude A_end (rad).

Close to a boundary the linear growth rate σ is small and A_end/A_mid ≈ exp(0.2 σ T):
with |σ| below about 0.25/T the motion is read as settled whatever its sign.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from .equations import STATE, scalar_rhs
from .gear import Gear

#: Relative change of the amplitude between the last two windows read as "settled".
SETTLED = 0.05
#: Amplitude, as a fraction of the perturbation, below which the motion has died away (far
#: above the integrator's absolute tolerance of 1e-10 rad).
DECAYED = 1e-3
#: Default perturbation of the yaw angle (rad) and duration (s); output sampling (Hz).
PERTURBATION, DURATION, SAMPLING = 1e-3, 10.0, 1000.0
VERDICTS = ("decays", "grows", "limit_cycle")
#: Duration (s) of each run of the limit-cycle sweep (`amplitude_sweep`).
BRANCH_DURATION = 3.0
#: Times a run of the limit-cycle sweep is continued while it has neither settled nor died away.
BRANCH_EXTENSIONS = 3


@dataclass(frozen=True)
class TimeHistory:
    """A simulated motion: times (s), the states (rows of ψ, ψ̇, y, ẏ), the verdict."""

    speed: float
    friction_model: str
    t: np.ndarray
    x: np.ndarray
    equilibrium: np.ndarray
    perturbation: float
    verdict: str
    amplitude: float | None
    final_amplitude: float

    def to_csv(self) -> str:
        buf = io.StringIO()
        buf.write("t," + ",".join(STATE) + "\n")
        np.savetxt(buf, np.column_stack([self.t, self.x.T]), delimiter=",", fmt="%.9g")
        return buf.getvalue()


def verdict_of(t: np.ndarray, dev: np.ndarray, a0: float) -> tuple[str, float | None, float]:
    """(verdict, limit-cycle amplitude or None, final amplitude) of a deviation history (module docstring)."""
    T = t[-1]
    a_mid = float(np.max(dev[(t >= 0.6 * T) & (t < 0.8 * T)]))
    a_end = float(np.max(dev[t >= 0.8 * T]))
    if a_end < DECAYED * a0 or a_end < (1 - SETTLED) * a_mid:
        return "decays", None, a_end
    if a_end > (1 + SETTLED) * a_mid:
        return "grows", None, a_end
    return "limit_cycle", a_end, a_end


def simulate(
    gear: Gear,
    contact,
    speed: float,
    *,
    equilibrium: np.ndarray,
    name: str = "",
    perturbation: float = PERTURBATION,
    duration: float = DURATION,
    sampling: float = SAMPLING,
) -> TimeHistory:
    """Integrate the motion at ``speed`` (m/s) from the steady state plus a yaw ``perturbation``.

    ``contact``: a `fepost.shimmy.contact.Contact` with a one-point ``scalar``
    evaluation (the closed forms, or a `fepost.shimmy.table.DirectionTable`'s contact).
    """
    from scipy.integrate import solve_ivp

    if not (speed > 0 and duration > 0 and perturbation > 0 and sampling > 0):
        raise ArgumentError("speed, duration, perturbation and sampling must be positive")
    if getattr(contact, "scalar", None) is None:
        raise ArgumentError(
            f"contact {getattr(contact, 'name', contact)!r} has no one-point evaluation: tabulate it "
            "(fepost.shimmy.table.DirectionTable)"
        )
    x0 = np.array(equilibrium, float)
    x0[0] += perturbation
    t_eval = np.linspace(0.0, duration, int(round(duration * sampling)) + 1)
    sol = solve_ivp(
        scalar_rhs(gear, speed, contact.scalar),
        (0.0, duration),
        x0,
        method="DOP853",
        t_eval=t_eval,
        rtol=1e-7,
        atol=1e-10,
    )
    if sol.status != 0:
        raise ArgumentError(f"the time integration at {speed:g} m/s failed: {sol.message}")
    dev = np.abs(sol.y[0] - equilibrium[0])
    verdict, amplitude, final = verdict_of(sol.t, dev, perturbation)
    return TimeHistory(
        speed, name, sol.t, sol.y, np.array(equilibrium), perturbation, verdict, amplitude, final
    )


@dataclass(frozen=True)
class BranchPoint:
    """One run of `amplitude_sweep`: the speed, the verdict and the amplitude at the end (rad)."""

    speed: float
    verdict: str
    amplitude: float

    def to_dict(self) -> dict:
        return {"speed": self.speed, "verdict": self.verdict, "amplitude": self.amplitude}


def amplitude_sweep(
    gear: Gear,
    contact,
    speeds,
    *,
    equilibrium: np.ndarray,
    perturbation: float = PERTURBATION,
    duration: float = BRANCH_DURATION,
) -> tuple[BranchPoint, ...]:
    """The limit-cycle branch by a sweep of simulations down ``speeds`` (m/s).

    The highest speed starts from the steady state plus the yaw ``perturbation``; each
    lower speed starts where the run above it ended (natural continuation: it starts
    near that speed's cycle when there is one, so ``duration`` seconds mostly suffice
    to settle; a run that has neither settled nor died away goes on for up to
    `BRANCH_EXTENSIONS` more ``duration`` seconds, as near the onset, where the growth
    rate is small). Below the speed where the branch starts, the motion decays (amplitude
    → 0 at a supercritical Hopf point); a branch that goes on below the linear
    critical speed is subcritical (a large enough disturbance shimmies below it).
    Points in increasing speed.
    """
    from scipy.integrate import solve_ivp

    eq = np.array(equilibrium, float)
    x0 = eq.copy()
    x0[0] += perturbation
    out = []
    for v in sorted((float(s) for s in speeds), reverse=True):
        f = scalar_rhs(gear, v, contact.scalar)
        start = x0
        for _ in range(BRANCH_EXTENSIONS + 1):  # run on while neither settled nor died away
            t_eval = np.linspace(0.0, duration, int(round(duration * 400.0)) + 1)
            sol = solve_ivp(f, (0.0, duration), start, method="DOP853", t_eval=t_eval, rtol=1e-7, atol=1e-10)
            if sol.status != 0:
                raise ArgumentError(f"the time integration at {v:g} m/s failed: {sol.message}")
            dev = np.abs(sol.y[0] - eq[0])
            verdict, _, final = verdict_of(sol.t, dev, perturbation)
            start = sol.y[:, -1]
            if verdict == "limit_cycle" or final < DECAYED * perturbation:
                break
        out.append(BranchPoint(v, verdict, final))
        if final > DECAYED * perturbation:
            x0 = sol.y[:, -1]
        else:  # died away: the next speed starts from the kick again
            x0 = eq.copy()
            x0[0] += perturbation
    return tuple(reversed(out))
