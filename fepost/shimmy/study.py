"""The whole shimmy study on FE maps: `shimmy_study`.

For each friction model asked for (``closed_forms``, ``generalised``, ``exact``,
`fepost.shimmy.contact`) built from an `fepost.analysis.Analysis` (the rolling
map and k_x when the analysis has one, else the static map and k_x = 0), it
linearises the gear about the steady rolling with sliding, sweeps the speeds
(`fepost.shimmy.linear.stability_map`), carries the coefficients' 95 % intervals
to the critical speed (`critical_interval`), and simulates the nonlinear motion
below and above each critical speed (`fepost.shimmy.simulate`); it adds the
outside anchor (`fepost.shimmy.anchor`).

Intervals (`critical_interval`), from the paper's identification experiment run on
the same maps (`fepost.table1.table1`, the default seed and noise):

* closed forms: the delta method, V_c ± t·√(gᵀ Σ g), with Σ the fit's covariance of
  (F0, M0, a, m, k_x) and g = ∂V_c/∂(F0, M0, a, m, k_x) by central differences;
* generalised and exact: those models have no F0 … k_x to perturb; the one
  identified quantity that maps onto them unchanged is the friction level f (every
  force and torque is proportional to f), so V_c is recomputed with the forces
  scaled over f's interval (`F_POINTS` levels from end to end, and the nominal one;
  the interval is their range, as V_c need not be monotonic in f).
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from ..errors import ArgumentError
from .contact import MODEL_NAMES, Contact, closed_forms_contact, exact_contact, model_contact
from .gear import Gear
from .linear import Linearisation, stability_map, trail_map
from .result import ModelStability, ShimmyResult, Simulation
from .simulate import DURATION, simulate
from .table import DirectionTable

#: Default speed sweep (m/s): 200 speeds.
DEFAULT_SPEEDS = (1.0, 150.0, 200)
#: Friction levels across f's interval at which the map-based models' V_c is recomputed.
F_POINTS = 9
#: The speed × trail map: trails from 0 to `TRAIL_SPAN` times the gear's (0.3 m for no trail),
#: and speeds over the sweep's range.
TRAIL_SPAN, TRAIL_SPEEDS = 3.0, 60
#: Speeds of the time simulations, as fractions of each critical speed.
SIMULATION_FRACTIONS = (0.8, 1.2)


def contacts(analysis, names: Sequence[str] = MODEL_NAMES) -> dict[str, Contact]:
    """The friction models of ``analysis`` as contacts (module docstring)."""
    from ..friction.law import FrictionLaw
    from ..friction.quadrature import PressureQuadrature

    unknown = [n for n in names if n not in MODEL_NAMES]
    if unknown:
        raise ArgumentError(f"friction model must be one of {', '.join(MODEL_NAMES)}, got {unknown[0]!r}")
    c = analysis.coefficients
    rolling = analysis.rolling_map is not None
    out: dict[str, Contact] = {}
    for name in names:
        if name == "closed_forms":
            k_x = float(c.k_x) if c.k_x is not None else 0.0
            out[name] = closed_forms_contact(F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=k_x, R=c.R)
        elif name == "generalised":
            summary = analysis.model_summary
            out[name] = model_contact(summary.rolling if rolling else summary.static)
        else:
            pmap = analysis.rolling_map if rolling else analysis.static_map
            out[name] = exact_contact(PressureQuadrature.from_polar(pmap), FrictionLaw(f=c.f), c.R)
    return out


def _lowest_critical(gear: Gear, contact: Contact, speeds: np.ndarray) -> float | None:
    return stability_map(Linearisation.of(gear, contact), speeds).critical_speed


def critical_interval(gear: Gear, contact: Contact, vc: float, speeds: np.ndarray, table1, lin=None) -> tuple:
    """(lo, hi) of the critical speed from Table 1's intervals, and the method (module docstring)."""
    fit = table1.identification
    if contact.name == "closed_forms":
        info = contact.info
        names = ("F0", "M0", "a", "m", "k_x")
        theta = np.array([info[n] for n in names], float)
        cov = np.asarray(fit.covariance, float)
        grad = np.zeros(5)
        window = np.linspace(0.5 * vc, 1.5 * vc, 41)
        for i in range(5):
            h = 0.05 * float(np.sqrt(cov[i, i]))
            ends = []
            for sign in (1.0, -1.0):
                t = theta.copy()
                t[i] += sign * h
                v = _lowest_critical(
                    gear, closed_forms_contact(**dict(zip(names, t, strict=True)), R=info["R"]), window
                )
                if v is None:
                    return None, "delta method: the critical speed left the window under a perturbation"
                ends.append(v)
            grad[i] = (ends[0] - ends[1]) / (2 * h)
        sd = float(np.sqrt(grad @ cov @ grad))
        half = fit.t_quantile * sd
        return (vc - half, vc + half), "delta method on Table 1's covariance of F0, M0, a, m, k_x"
    row = next(r for r in table1.rows if r.name == "f")
    lin = Linearisation.of(gear, contact) if lin is None else lin
    found = [vc]
    for level in np.linspace(row.ci95[0], row.ci95[1], F_POINTS):
        v = stability_map(lin.scaled(level / row.fitted, contact), speeds).critical_speed
        if v is None:
            return None, "friction level f across its interval: no critical speed in the sweep at one end"
        found.append(v)
    return (min(found), max(found)), f"forces scaled across Table 1's interval of f ({F_POINTS} levels)"


def shimmy_study(
    analysis,
    gear: Gear,
    *,
    speeds=None,
    models: Sequence[str] = MODEL_NAMES,
    intervals: bool = True,
    simulate_motion: bool = True,
    duration: float = DURATION,
    anchor: bool = True,
    trails: int = 16,
) -> ShimmyResult:
    """Stability of ``gear`` on the tire of ``analysis`` with each friction model (module docstring).

    ``speeds``: the sweep (m/s, increasing; default `DEFAULT_SPEEDS`, 200 speeds
    from 1 to 150 m/s). ``intervals``: carry Table 1's intervals to the critical
    speeds. ``simulate_motion``: time histories at 0.8 and 1.2 times each critical
    speed (at the top speed when there is none), ``duration`` seconds each.
    ``trails``: the boundary over speed × trail at that many trails (`TRAIL_SPAN`; 0: none).
    """
    from .anchor import anchor_record

    if not isinstance(gear, Gear):
        raise ArgumentError(f"gear must be a Gear, got {type(gear).__name__}")
    speeds = np.linspace(*DEFAULT_SPEEDS) if speeds is None else np.asarray(speeds, float)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    found = contacts(analysis, models)
    timings["contacts"] = time.perf_counter() - t0
    t1 = None
    if intervals:
        from ..table1 import table1

        t1 = table1(analysis, bias=False, profile=False, generalised=False)
    results, sims = [], []
    for name, contact in found.items():
        t0 = time.perf_counter()
        lin = Linearisation.of(gear, contact)
        smap = stability_map(lin, speeds)
        timings[f"{name}_stability_map"] = time.perf_counter() - t0
        ci, method = None, "not computed"
        if t1 is not None and smap.critical_speed is not None:
            ci, method = critical_interval(gear, contact, smap.critical_speed, speeds, t1, lin)
        elif smap.critical_speed is None:
            method = "no critical speed in the sweep"
        info = {k: float(v) for k, v in contact.info.items() if isinstance(v, int | float)}
        tmap = None
        if trails:
            t0 = time.perf_counter()
            top = TRAIL_SPAN * gear.trail if gear.trail > 0 else 0.3
            tspeeds = np.linspace(speeds[0], speeds[-1], TRAIL_SPEEDS)
            tmap = trail_map(lin, contact, np.linspace(0.0, top, trails), tspeeds)
            timings[f"{name}_trail_map"] = time.perf_counter() - t0
        stab = ModelStability(name, smap, ci, method, {"F0": contact.F0, "M0": contact.M0, **info}, tmap)
        results.append(stab)
        if simulate_motion:
            t0 = time.perf_counter()
            sim_contact = (
                contact if contact.scalar is not None else DirectionTable.build(contact).as_contact()
            )
            timings[f"{name}_table"] = time.perf_counter() - t0
            vc = smap.critical_speed
            run_speeds = [f * vc for f in SIMULATION_FRACTIONS] if vc is not None else [float(speeds[-1])]
            for v in run_speeds:
                t0 = time.perf_counter()
                h = simulate(gear, sim_contact, v, equilibrium=lin.state, name=name, duration=duration)
                timings[f"{name}_simulation_{v:.4g}"] = time.perf_counter() - t0
                sims.append(Simulation(h, f"time_{name}_{v:.2f}.csv", lin.growth(v)[0]))
    c = analysis.coefficients
    source = {
        "static": str(analysis.static_field.source),
        "rolling": None if analysis.rolling_field is None else str(analysis.rolling_field.source),
        "map": "rolling" if analysis.rolling_map is not None else "static (k_x = 0)",
        "N": c.N,
        "R": c.R,
        "f": c.f,
        "wheel_load_note": "each wheel of the gear carries the FE tire's load N",
    }
    return ShimmyResult(
        gear=gear,
        models=tuple(results),
        simulations=tuple(sims),
        anchor=anchor_record() if anchor else {},
        source=source,
        timings=timings,
    )
