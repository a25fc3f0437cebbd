"""``diagnose``: measured rig data against the simulation, the cause and the gain.

The steps (each a module of this package):

1. :mod:`~fepost.diagnose.measured` reads and checks the CSV;
   :mod:`~fepost.diagnose.simulation` puts the FE maps on the fit grid.
2. :mod:`~fepost.diagnose.causes` builds every candidate cause as a model over
   the exact integrals; :mod:`~fepost.diagnose.fitting` fits each to all points
   and, for the held-out check, to each training fold.
3. :mod:`~fepost.diagnose.selection` scores them (BIC, nesting tests, held-out
   log density) and names the cause.
4. :mod:`~fepost.diagnose.residuals` says whether the misfit before and after
   is noise or structure; the paper's closed forms (THEORY.md §4) are compared
   with the data and with the exact integrals.
"""

from __future__ import annotations

import time

import numpy as np

from ..friction.closed_form import components
from .causes import Predictor, build_candidates
from .fitting import fit
from .measured import MeasuredData, check_plausible, read_measured
from .residuals import kinematic_variables, residual_structure
from .result import Diagnosis, ParameterEstimate
from .selection import (
    FOLDS,
    crossvalidate,
    design_notes,
    folds,
    indistinguishable,
    score_candidates,
)
from .simulation import FIT_NPHI, FIT_NR, Simulation, load_simulation


def _rmse(res: np.ndarray) -> float:
    return float(np.sqrt(np.mean(res**2)))


def closed_form_prediction(sim: Simulation, data: MeasuredData) -> np.ndarray:
    """The paper's closed forms (THEORY.md §4) at the data's points, (n, 3) in SI.

    F0, M0, a, m from the static map's moments (THEORY.md §2) with the nominal
    f; k_x from the rolling map (its sign flipped for roll = −1, 0 for roll = 0);
    F0 and M0 scale with the row's load N/N_sim.
    """
    c = sim.coefficients
    lam = data.loads(c.N) / c.N
    k_x = (c.k_x or 0.0) * np.asarray(data.roll, float)
    out = np.empty((len(data), 3))
    for kx in np.unique(k_x):
        for la in np.unique(lam):
            i = np.flatnonzero((k_x == kx) & (lam == la))
            if not i.size:
                continue
            fx, fy, mz = components(
                data.vx[i],
                data.vy[i],
                data.wz[i],
                F0=c.F0 * la,
                M0=c.M0 * la,
                a=c.a,
                m=c.m,
                k_x=float(kx),
                radius=c.R,
            )
            out[i] = np.column_stack([fx, fy, mz])
    return out


def diagnose(
    simulation,
    measured,
    *,
    rolling=None,
    friction: float = 0.3,
    seed: int = 0,
    n_folds: int = FOLDS,
    nr: int = FIT_NR,
    nphi: int = FIT_NPHI,
    analyse_kwargs: dict | None = None,
) -> Diagnosis:
    """Compare measured friction data with the simulation and name the cause of the misfit.

    ``simulation``/``rolling``: FE exports (paths or ContactFields, through
    :func:`fepost.analysis.analyse`), polar maps in the patch frame, or a ready
    :class:`~fepost.diagnose.simulation.Simulation`. ``measured``: a CSV path or
    :class:`~fepost.diagnose.measured.MeasuredData`. ``friction``: nominal f.
    ``seed`` shuffles the cross-validation folds. ``nr``/``nphi``: the fit grid.
    Raises :class:`~fepost.errors.DataError` on unusable data.
    """
    t0 = time.perf_counter()
    sim = load_simulation(simulation, rolling, friction=friction, nr=nr, nphi=nphi, **(analyse_kwargs or {}))
    data = measured if isinstance(measured, MeasuredData) else read_measured(measured)
    check_plausible(
        data,
        friction=sim.friction,
        load=sim.load,
        radius=sim.radius,
        has_rolling=sim.rolling is not None,
    )

    pred = Predictor(sim, data)
    cands = build_candidates(pred)
    Y = data.forces / pred.scale
    fits = {name: fit(c, Y) for name, c in cands.items()}
    parts = folds(len(data), n_folds, seed)
    cvs = {name: crossvalidate(c, Y, parts, fits[name]) for name, c in cands.items()}
    scores = score_candidates(cands, fits, cvs)
    best = scores[0]
    cause = best.name
    cand = cands[cause]
    bf = fits[cause]
    params = {
        p.name: ParameterEstimate(p.name, float(v), (float(lo), float(hi)), p.unit, p.description)
        for p, v, (lo, hi) in zip(cand.parameters, bf.values, bf.ci95, strict=True)
    }

    scale = pred.scale
    before = cands["none"].predict(np.empty(0)) * scale
    after = cand.predict(bf.values) * scale
    heldout = data.forces - cvs[cause].residuals * scale
    closed = closed_form_prediction(sim, data)
    meas = data.forces

    gain = {
        "rmse_before": cvs["none"].rmse,
        "rmse_after": cvs[cause].rmse,
        "delta_bic": best.delta_bic,
        "delta_aicc": best.delta_aicc,
        "rmse_before_channels": cvs["none"].rmse_channels.tolist(),
        "rmse_after_channels": cvs[cause].rmse_channels.tolist(),
        "rmse_units": "scaled: Fx, Fy by f0 N; Mz by f0 N R",
        "heldout": f"{n_folds}-fold cross-validation (folds shuffled with seed {seed})",
        "delta": "score(cause) - score(none); negative favours the cause",
    }
    variables = kinematic_variables(data.vx, data.vy, data.wz, sim.radius, data.loads(sim.load), data.roll)
    residuals = {
        "before": residual_structure((meas - before) / scale, variables),
        "after": residual_structure((meas - heldout) / scale, variables),
    }
    closed_form = {
        "rmse_vs_data": _rmse((meas - closed) / scale),
        "rmse_vs_exact": _rmse((closed - before) / scale),
        "exact_rmse_vs_data": _rmse((meas - before) / scale),
        "max_abs_vs_exact": np.max(np.abs(closed - before) / scale, axis=0).tolist(),
        "coefficients": {k: sim.coefficients.to_dict()[k] for k in ("F0", "M0", "a", "m", "R")}
        | {"k_x": sim.coefficients.k_x},
        "note": "F0, M0, a, m from the static map's moments (THEORY.md §2); scaled RMSEs",
    }
    notes = design_notes(data.vx, data.vy, data.wz, sim.radius, data.N)
    elapsed = time.perf_counter() - t0
    return Diagnosis(
        cause=cause,
        parameters=params,
        gain=gain,
        candidates=tuple(scores),
        indistinguishable=tuple(indistinguishable(scores, cands)),
        design_notes=tuple(notes),
        residuals=residuals,
        closed_form=closed_form,
        simulation=sim.to_dict(),
        data=data,
        predictions={
            "before": before,
            "after": after,
            "after_heldout": heldout,
            "closed_form": closed,
        },
        scales=scale,
        variables=variables,
        info={
            "folds": n_folds,
            "seed": seed,
            "seconds": elapsed,
            "exact_evaluations": pred.evaluations,
        },
    )
