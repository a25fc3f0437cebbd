"""Touchdown: the gear from first contact through the wheels' spin-up, on brush tires.

At t = 0 the wheels touch the road at the landing speed V without turning
(ω_j = 0), the tread undeflected, the strut at rest at a yaw ``yaw`` (rad, an
initial torsion of the strut) and the aircraft crabbed by ``crab`` (rad, its
direction of travel against its heading). The tire's vertical deflection grows
at the sink rate, and with it the load: the friction limits of the brush's
elements and their stiffness are scaled by s = N(t)/N = min(1, sink_rate t / tire_deflection)
(the patch grows with its load, `fepost.shimmy.brush.BrushTire.resultants`; the FE
tire's load grows nearly linearly with deflection: `meshes/aircraft/load_deflection.csv`,
5.4 kN at 6 mm to 198.6 kN at 102 mm). The wheels spin up under the coupled
friction force and torque of their patches (`fepost.shimmy.gripping.GripModel`
with ``spin``): each element slides until the wheel's rolling speed ω R_e
catches up with the road, then grips. Strut torsion and lateral bending respond
through the gear's equations, with the wheels' gyroscopic coupling where the gear
file gives ``bending_slope``.

With the gear's ``tread_slip_stiffness`` the tire is the brush on a carcass
(`fepost.shimmy.carcass.CarcassTire`, `touchdown_tire`), whose carcass springs grow
with the load like its tread.

Integration: scipy's ``solve_ivp`` (`METHOD`, rtol `RTOL`; the stick-slip switch blended
over `BLEND` of the friction limit) with the work integrals
of `fepost.shimmy.gripping` alongside, so the energy balance is checked on every
run (``energy_residual``: the balance's error over the largest energy term).

Reading the run (`read_touchdown`):

* ``spin_up_time``: the first time the slowest wheel's rolling speed ω R_e is
  within `SPUN_UP` of the road speed along the wheel, V cos(δ − crab) (None when
  the run ends first: the oscillation is then read over the whole run);
* the strut's oscillation after it: the half peak-to-peak amplitude of ψ in
  `WINDOWS` equal windows from the spin-up to the end. ``decays`` when the last
  window's is below `QUIET` rad or below half the first's and not rising;
  ``grows`` when it rises by more than `SETTLED` from the window before;
  ``limit_cycle`` otherwise (settled at that amplitude);
* ``amplitude``: the largest |ψ| after the spin-up (rad).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ArgumentError
from .brush import BrushTire
from .carcass import CarcassTire
from .gear import Gear
from .gripping import GripModel

#: Relative tolerance of the integration, and the absolute ones (rad, m, J scale).
RTOL = 1e-6
#: The integrator (explicit: the patch's stiffness grows with its load, so an element's direction
#: follows its slip at the rate V K / (f N) of the full load, not faster; the lower order copes
#: better with the elements' stick-slip switches: 2.2 against 2.4 s of CPU for 2 s of motion).
METHOD = "RK23"
#: Spun up: rolling speed within this fraction of the road speed.
SPUN_UP = 0.01
#: Windows of the oscillation after spin-up; settled when the amplitude changes by less than
#: SETTLED; quiet below QUIET rad.
WINDOWS, SETTLED, QUIET = 5, 0.05, 1e-5
#: Default duration (s) and output sampling (Hz).
DURATION, SAMPLING = 2.0, 1000.0
#: Element grid (cells along x, y) of the command's touchdown runs (benchmarks/bench_touchdown.py).
GRID = (12, 4)
#: The touchdown tire's stick-slip switch, blended over this share of the friction limit
#: (`fepost.shimmy.brush.BrushTire`; 4.0 -> 2.4 s of CPU for 2 s of motion, the same verdicts).
BLEND = 0.02
#: Gear parameters the touchdown needs.
NEEDS = ("wheel_spin_inertia", "rolling_radius", "tire_stiffness_x", "tire_stiffness_y", "tire_deflection")


@dataclass(frozen=True)
class Touchdown:
    """One touchdown run: inputs, sampled history and its reading (module docstring)."""

    speed: float
    sink_rate: float
    yaw: float
    crab: float
    t: np.ndarray
    x: np.ndarray  # rows: psi, psi_dot, y, y_dot, omega per wheel
    load_share: np.ndarray
    spin_up_time: float | None
    verdict: str
    amplitude: float | None
    window_amplitudes: tuple[float, ...]
    energy_residual: float
    energy_terms: dict

    def row(self, csv: str) -> dict:
        """The ``touchdown`` row of shimmy.json (docs/touchdown.md), plus the run's inputs."""
        return {
            "speed": self.speed,
            "spin_up_time": self.spin_up_time,
            "verdict": self.verdict,
            "amplitude": self.amplitude,
            "csv": csv,
            "sink_rate": self.sink_rate,
            "initial_yaw": self.yaw,
            "crab_angle": self.crab,
            "window_amplitudes": list(self.window_amplitudes),
            "energy_residual": self.energy_residual,
        }

    def to_csv(self) -> str:
        wheels = self.x.shape[0] - 4
        head = ["t", "psi", "psi_dot", "y", "y_dot", *[f"omega_{j + 1}" for j in range(wheels)], "load_share"]
        buf = io.StringIO()
        buf.write(",".join(head) + "\n")
        np.savetxt(buf, np.column_stack([self.t, self.x.T, self.load_share]), delimiter=",", fmt="%.9g")
        return buf.getvalue()


def check_gear(gear: Gear, where: str = "gear") -> None:
    """`ArgumentError` naming the first parameter the touchdown needs and the gear lacks."""
    for key in NEEDS:
        if getattr(gear, key) <= 0:
            raise ArgumentError(
                f"{where}: the touchdown needs {key} > 0 in the gear file (docs/touchdown.md)"
            )


def touchdown_tire(gear: Gear, quad, f: float, **grid) -> BrushTire | CarcassTire:
    """The brush tire of the gear's stiffness over the pressure quadrature ``quad``: with the gear's
    ``tread_slip_stiffness`` the tread on a carcass (`fepost.shimmy.carcass.CarcassTire`; torsion
    with ``tire_stiffness_z``), else the lumped brush."""
    check_gear(gear)
    if gear.tread_slip_stiffness > 0:
        try:
            return CarcassTire.from_quadrature(
                quad,
                f=f,
                standstill=(gear.tire_stiffness_x, gear.tire_stiffness_y, gear.tire_stiffness_z),
                slip_stiffness=gear.tread_slip_stiffness,
                blend=BLEND,
                provenance={
                    key: gear.sources.get(key, "")
                    for key in (
                        "tire_stiffness_x",
                        "tire_stiffness_y",
                        "tire_stiffness_z",
                        "tread_slip_stiffness",
                    )
                },
                **grid,
            )
        except ArgumentError as exc:
            raise ArgumentError(f"gear: tread_slip_stiffness and the tire's stiffness: {exc}") from None
    tire = BrushTire.from_quadrature(
        quad,
        f=f,
        stiffness=(gear.tire_stiffness_x, gear.tire_stiffness_y),
        provenance={
            "K_x": gear.sources.get("tire_stiffness_x", ""),
            "K_y": gear.sources.get("tire_stiffness_y", ""),
        },
        **grid,
    )
    return replace(tire, blend=BLEND)


def simulate_touchdown(
    gear: Gear,
    tire: BrushTire | CarcassTire,
    speed: float,
    *,
    sink_rate: float = 1.5,
    yaw: float = 0.0,
    crab: float = 0.0,
    duration: float = DURATION,
    sampling: float = SAMPLING,
) -> Touchdown:
    """Integrate a touchdown at ``speed`` (m/s) and read it (module docstring)."""
    from scipy.integrate import solve_ivp

    check_gear(gear)
    for name, value in (
        ("speed", speed),
        ("sink_rate", sink_rate),
        ("duration", duration),
        ("sampling", sampling),
    ):
        if not (math.isfinite(value) and value > 0):
            raise ArgumentError(f"{name} must be positive and finite, got {value!r}")
    for name, value in (("yaw", yaw), ("crab", crab)):
        if not (math.isfinite(value) and abs(value) < 0.5):
            raise ArgumentError(f"{name} must be an angle below 0.5 rad, got {value!r}")
    model = GripModel(gear, tire, spin=True, energy=True, crab=crab)
    t_load = gear.tire_deflection / sink_rate

    def share(t):
        if t >= t_load:
            return 1.0, 0.0
        return max(t, 1e-12) / t_load, 1.0 / max(t, 1e-12)

    x0 = np.zeros(model.n_state)
    x0[0] = yaw
    t_eval = np.linspace(0.0, duration, int(round(duration * sampling)) + 1)
    atol = np.full(model.n_state, 1e-9)
    atol[-5:] = 1e-6 * tire.f * tire.load * speed * duration
    sol = solve_ivp(
        model.rhs(speed, share), (0.0, duration), x0, method=METHOD, t_eval=t_eval, rtol=RTOL, atol=atol
    )
    if sol.status != 0:
        raise ArgumentError(f"the touchdown integration at {speed:g} m/s failed: {sol.message}")
    w = gear.wheels
    keep = sol.y[: 4 + w]
    load = np.minimum(1.0, sol.t / t_load)
    energy = _energy_check(model, sol.y[:, 0], sol.y[:, -1], float(load[0]), float(load[-1]))
    spin_up, verdict, amp, windows = read_touchdown(sol.t, keep, gear, speed, crab)
    return Touchdown(speed, sink_rate, yaw, crab, sol.t, keep, load, spin_up, verdict, amp, windows, *energy)


def _energy_check(
    model: GripModel, x0: np.ndarray, x1: np.ndarray, s0: float, s1: float
) -> tuple[float, dict]:
    """(residual over the largest term, the terms in J) of the energy balance from x0 to x1."""
    forward, dampers, sliding, released, entering = x1[-5:]
    change = model.mechanical_energy(x1, s1) - model.mechanical_energy(x0, s0)
    residual = change - (-forward - dampers - sliding + released - entering)
    terms = {
        "energy_change": change,
        "work_forward": -forward,
        "dampers": dampers,
        "sliding": sliding,
        "released_at_trailing_edge": -released,
        "entering_tread": entering,
        "residual": residual,
    }
    scale = max(abs(change), abs(forward), abs(dampers), abs(sliding), abs(released), abs(entering))
    return abs(residual) / scale, {k: float(v) for k, v in terms.items()}


def read_touchdown(t, x, gear: Gear, speed: float, crab: float = 0.0):
    """(spin_up_time or None, verdict, amplitude or None, window amplitudes) of a run (module docstring)."""
    w = gear.wheels
    road = speed * np.cos(x[0] * math.cos(gear.rake) - crab)
    rolling = np.min(x[4 : 4 + w], axis=0) * gear.rolling_radius
    done = np.nonzero(rolling >= (1 - SPUN_UP) * road)[0]
    i0 = int(done[0]) if done.size else 0
    ts = float(t[i0]) if done.size else None
    psi = x[0, i0:]
    tt = t[i0:]
    if tt.size < 2 * WINDOWS:
        return ts, "decays", float(np.max(np.abs(psi))), ()
    edges = np.linspace(tt[0], tt[-1], WINDOWS + 1)
    amps = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        seg = psi[(tt >= a) & (tt <= b)]
        amps.append(0.5 * float(seg.max() - seg.min()))
    first, prev, last = amps[0], amps[-2], amps[-1]
    if last < QUIET or (last < 0.5 * first and last <= prev):
        verdict = "decays"
    elif last > (1 + SETTLED) * prev:
        verdict = "grows"
    else:
        verdict = "limit_cycle"
    return ts, verdict, float(np.max(np.abs(psi))), tuple(amps)


def touchdown_sweep(
    gear: Gear, tire: BrushTire | CarcassTire, speeds, sink_rates=(1.5,), yaws=(0.0,), crabs=(0.0,), **kw
):
    """`simulate_touchdown` over every combination (speed outermost)."""
    return [
        simulate_touchdown(gear, tire, float(v), sink_rate=float(s), yaw=float(p), crab=float(c), **kw)
        for v in speeds
        for s in sink_rates
        for p in yaws
        for c in crabs
    ]
