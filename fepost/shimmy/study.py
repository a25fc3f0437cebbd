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
from .linear import Linearisation, parameter_map, stability_map
from .result import ModelStability, ShimmyResult, Simulation
from .simulate import DURATION, amplitude_sweep, simulate
from .table import DirectionTable

#: Default speed sweep (m/s): 200 speeds.
DEFAULT_SPEEDS = (1.0, 150.0, 200)
#: Friction levels across f's interval at which the map-based models' V_c is recomputed.
F_POINTS = 9
#: The stability maps: trails from 0 to `TRAIL_SPAN` times the gear's (0.3 m for no trail),
#: and `TRAIL_SPEEDS` speeds over the sweep's range.
TRAIL_SPAN, TRAIL_SPEEDS = 3.0, 60
#: Speeds of the time simulations, as fractions of each critical speed.
SIMULATION_FRACTIONS = (0.8, 1.2)
#: The other stability maps: torsional damping from 0 to this fraction of the torsional mode's
#: critical damping 2√(k_ψ I_ψ) (at least 3 times the gear's), torsional stiffness over this
#: range of multiples of the gear's.
DAMPING_SPAN, STIFFNESS_SPAN = 0.05, (0.25, 2.0)
#: Speeds of the limit-cycle sweep (`fepost.shimmy.simulate.amplitude_sweep`).
BRANCH_SPEEDS = 8


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


def _first_onset(gear: Gear, contact: Contact, speeds: np.ndarray) -> float | None:
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
            if h == 0.0:  # a coefficient the fit holds exactly adds nothing
                continue
            ends = []
            for sign in (1.0, -1.0):
                t = theta.copy()
                t[i] += sign * h
                v = _first_onset(
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


class _Stages:
    """Counts the study's stages and reports each one as it ends: ``progress(k, n, step, s)``."""

    def __init__(self, total: int, progress, timings: dict[str, float]) -> None:
        self.k, self.total, self.progress, self.timings = 0, total, progress, timings

    def run(self, step: str, key: str, fun):
        t0 = time.perf_counter()
        out = fun()
        seconds = time.perf_counter() - t0
        self.timings[key] = seconds
        self.k += 1
        if self.progress is not None:
            self.progress(self.k, self.total, step, seconds)
        return out


def _maps(gear: Gear, lin: Linearisation, contact: Contact, speeds: np.ndarray, n: int) -> dict:
    """The stability maps over speed × trail, × torsional damping and × torsional stiffness
    (`DAMPING_SPAN`, `STIFFNESS_SPAN`), ``n`` values each, on `TRAIL_SPEEDS` speeds over the sweep's range."""
    tspeeds = np.linspace(speeds[0], speeds[-1], TRAIL_SPEEDS)
    out = {}
    for key, values in map_values(gear, n).items():
        out[key] = parameter_map(lin, contact, key, values, tspeeds)
    return out


def map_values(gear: Gear, n: int) -> dict[str, np.ndarray]:
    """The values of each mapped parameter (`DAMPING_SPAN`, `STIFFNESS_SPAN`)."""
    critical_damping = 2.0 * np.sqrt(max(gear.torsional_stiffness, 1.0) * gear.yaw_inertia)
    top_trail = TRAIL_SPAN * gear.trail if gear.trail > 0 else 0.3
    top_damping = max(DAMPING_SPAN * critical_damping, 3.0 * gear.torsional_damping)
    k = gear.torsional_stiffness if gear.torsional_stiffness > 0 else 1e6
    lo, hi = STIFFNESS_SPAN
    return {
        "trail": np.linspace(0.0, top_trail, n),
        "torsional_damping": np.linspace(0.0, top_damping, n),
        "torsional_stiffness": np.linspace(lo * k, hi * k, n),
    }


def _simulations(gear, contact, lin, smap, name, duration, stages, n_branch) -> tuple[list, tuple]:
    """The two time histories (`SIMULATION_FRACTIONS` of the critical speed, or the sweep's ends)
    and the limit-cycle sweep (`BRANCH_SPEEDS` from 0.8 V_c, or the lowest unstable speed, up)."""
    sim_contact = stages.run(
        f"{name}: table over the sphere of directions",
        f"{name}_table",
        lambda: contact if contact.scalar is not None else DirectionTable.build(contact).as_contact(),
    )
    vc, top = smap.critical_speed, float(smap.speeds[-1])
    if vc is not None:
        run_speeds = [f * vc for f in SIMULATION_FRACTIONS]
    else:
        run_speeds = [float(smap.speeds[0]), top]
    sims = []
    for v in run_speeds:
        h = stages.run(
            f"{name}: {duration:g} s of motion at {v:.1f} m/s",
            f"{name}_simulation_{v:.4g}",
            lambda v=v: simulate(gear, sim_contact, v, equilibrium=lin.state, name=name, duration=duration),
        )
        sims.append(Simulation(h, f"time_{name}_{v:.2f}.csv", lin.growth(v)[0]))
    ranges = smap.unstable_ranges
    branch: tuple = ()
    if n_branch and ranges:
        start = 0.8 * vc if vc is not None else float(ranges[0][0])
        bspeeds = np.linspace(max(start, float(smap.speeds[0])), top, n_branch)
        branch = stages.run(
            f"{name}: limit-cycle amplitude, {n_branch} runs",
            f"{name}_limit_cycle_sweep",
            lambda: amplitude_sweep(gear, sim_contact, bspeeds, equilibrium=lin.state),
        )
    elif n_branch:
        stages.run(f"{name}: no unstable speed, no limit-cycle sweep", f"{name}_limit_cycle_sweep", tuple)
    return sims, branch


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
    branch_speeds: int = BRANCH_SPEEDS,
    progress=None,
) -> ShimmyResult:
    """Stability of ``gear`` on the tire of ``analysis`` with each friction model (module docstring).

    ``speeds``: the sweep (m/s, increasing; default `DEFAULT_SPEEDS`, 200 speeds
    from 1 to 150 m/s). ``intervals``: carry Table 1's intervals to the critical
    speeds. ``simulate_motion``: time histories at 0.8 and 1.2 times each critical
    speed (at the sweep's ends when there is none), ``duration`` seconds each, and the
    limit-cycle amplitude over speed at ``branch_speeds`` speeds (`amplitude_sweep`; 0:
    none). ``trails``: the stability maps over speed × trail, × torsional damping and
    × torsional stiffness at that many values each (`map_values`; 0: none). ``progress``: called as
    ``progress(k, n, step, seconds)`` after each of the n stages.
    """
    from .anchor import anchor_record

    if not isinstance(gear, Gear):
        raise ArgumentError(f"gear must be a Gear, got {type(gear).__name__}")
    speeds = np.linspace(*DEFAULT_SPEEDS) if speeds is None else np.asarray(speeds, float)
    timings: dict[str, float] = {}
    n_models = len(models)
    per_model = (
        1 + int(intervals) + int(bool(trails)) + (3 + int(branch_speeds > 0) if simulate_motion else 0)
    )
    stages = _Stages(1 + int(intervals) + n_models * per_model, progress, timings)
    found = stages.run("friction models", "contacts", lambda: contacts(analysis, models))
    t1 = None
    if intervals:
        from ..table1 import table1

        t1 = stages.run(
            "Table 1 identification (intervals)",
            "table1",
            lambda: table1(analysis, bias=False, profile=False, generalised=False),
        )
    results, sims = [], []
    for name, contact in found.items():
        stab, runs = _model_study(
            gear, name, contact, speeds, t1, stages,
            trails=trails, simulate_motion=simulate_motion, duration=duration, branch_speeds=branch_speeds,
        )  # fmt: skip
        results.append(stab)
        sims.extend(runs)
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


def _model_study(
    gear, name, contact, speeds, t1, stages, *, trails, simulate_motion, duration, branch_speeds
):
    """One friction model's part of `shimmy_study`: (its `ModelStability`, its simulations)."""
    lin, smap = stages.run(
        f"{name}: stability over {len(speeds)} speeds",
        f"{name}_stability_map",
        lambda: _linear(gear, contact, speeds),
    )
    ci, method = None, "not computed"
    if smap.critical_speed is None:
        method = "no onset of instability in the sweep"
    if t1 is not None:
        if smap.critical_speed is not None:
            ci, method = stages.run(
                f"{name}: 95 % interval of the critical speed",
                f"{name}_interval",
                lambda: critical_interval(gear, contact, smap.critical_speed, speeds, t1, lin),
            )
        else:
            stages.run(f"{name}: no interval ({method})", f"{name}_interval", lambda: None)
    info = {k: float(v) for k, v in contact.info.items() if isinstance(v, int | float)}
    maps = {}
    if trails:
        maps = stages.run(
            f"{name}: stability maps over speed x trail, damping, stiffness ({trails} values each)",
            f"{name}_maps",
            lambda: _maps(gear, lin, contact, speeds, trails),
        )
    branch: tuple = ()
    runs: list = []
    if simulate_motion:
        runs, branch = _simulations(gear, contact, lin, smap, name, duration, stages, branch_speeds)
    stab = ModelStability(
        name, smap, ci, method, {"F0": contact.F0, "M0": contact.M0, **info}, maps.get("trail"), maps, branch
    )
    return stab, runs


def _linear(gear: Gear, contact: Contact, speeds: np.ndarray):
    lin = Linearisation.of(gear, contact)
    return lin, stability_map(lin, speeds)
