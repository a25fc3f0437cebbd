"""``diagnose``: measured rig data against the simulation, the cause(s) and the gain.

The steps (each a module of this package):

1. `measured` reads and checks the CSV of test points, or
   `recording` and `holds` read a
   rig recording and reduce its steady holds to test points
   (`load_measured` decides which);
   `simulation` puts the FE maps on the fit grid.
2. `causes` builds every candidate cause as a model over
   the exact integrals (`models`).
3. `robust` fits every candidate with Huber's loss, flags
   the rows no candidate explains (outliers, left out from here on) and picks
   the reference prediction of the noise model; each channel's noise structure
   (constant, proportional, combined) is chosen by BIC (`noise`).
4. `fitting` fits each candidate by maximum likelihood
   under that noise model, to all kept rows and, for the held-out check, to each
   training fold; `selection` scores them (BIC, nesting
   tests, held-out log density) and names the primary cause.
5. `pairs` tries a second cause on top of it by the same
   rules, and a friction level other than nominal.
6. `lackfit` asks whether the chosen model leaves
   structure (pure error per channel, from replicates or from the scatter
   within holds; residual structure per channel; run-order drift); `residuals`
   tests the residuals against the kinematics; the paper's closed forms are
   compared with the data and with the exact integrals.
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import ArgumentError
from ..friction.closed_form import components
from ..friction_coefficient import DEFAULT_FRICTION
from .causes import EXTENSIONS, Predictor, build_candidates, extension_parameters, joint_candidate
from .fitting import fit
from .holds import HoldRule
from .inputs import load_measured
from .lackfit import lack_of_fit
from .measured import CHANNELS, MeasuredData, check_plausible
from .noise import Noise, select_structure
from .pairs import correlated_parameters, friction_test, search_pairs
from .recording import Columns
from .residuals import kinematic_variables, residual_structure
from .result import Diagnosis, ParameterEstimate
from .robust import robust_pass
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
    """The paper's closed forms (docs/theory.md) at the data's points, (n, 3) in SI.

    F0, M0, a, m from the static map's moments (docs/theory.md) with the nominal
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


def screen(cands: dict, Y: np.ndarray):
    """Step 3: the robust pass, the rows kept and the noise model (with its selection tables)."""
    g0 = np.abs(cands["none"].predict(np.empty(0)))
    rob = robust_pass(cands, Y, g0)
    rows = np.setdiff1d(np.arange(Y.shape[0]), rob.outliers)
    noise, tables = _noise_model(rob, cands, Y, rows)
    return rob, rows, noise, tables


def _noise_model(rob, cands, Y, rows) -> tuple[Noise, dict]:
    """The noise model of every Gaussian fit: reference magnitudes and per-channel structure."""
    ref = rob.fits[rob.reference]
    g = np.abs(ref.model.predict(ref.values))
    res = (Y - ref.model.predict(ref.values))[rows]
    structure, tables = [], {}
    for c, ch in enumerate(CHANNELS):
        best, table = select_structure(res[:, c], g[rows, c])
        structure.append(best)
        tables[ch] = table
    return Noise.start(tuple(structure), g), tables


def _check_arguments(seed, n_folds) -> None:
    if isinstance(seed, bool) or int(seed) != seed or seed < 0:
        raise ArgumentError(f"seed must be a non-negative integer, got {seed!r}")
    if isinstance(n_folds, bool) or int(n_folds) != n_folds or n_folds < 2:
        raise ArgumentError(f"n_folds must be an integer of at least 2, got {n_folds!r}")


def _single_causes(cands, Y, rob, rows, noise, n_folds, seed):
    """Step 4: Gaussian fits on the kept rows, held-out check, scores (primary first)."""
    fits = {
        name: fit(c, Y, rows, start=rob.fits[name].values if c.n_params else None, noise=noise)
        for name, c in cands.items()
    }
    parts = folds(rows, n_folds, seed)
    cvs = {name: crossvalidate(c, Y, parts, fits[name]) for name, c in cands.items()}
    return fits, cvs, parts, score_candidates(cands, fits, cvs)


def _second_cause(pred, cands, fits, cvs, primary, Y, parts, table, friction, pairs):
    """Step 5: a second cause and a friction level on top of the primary; the final model."""
    search = None
    final = (cands[primary], fits[primary], cvs[primary])
    causes = [primary]
    if pairs and primary in EXTENSIONS:
        search = search_pairs(pred, cands, fits, cvs, primary, Y, parts, table)
        chosen = search.chosen
        if chosen is not None and chosen.fit is not None and chosen.cv is not None:
            final = (joint_candidate(pred, (primary, chosen.second), table), chosen.fit, chosen.cv)
            causes.append(chosen.second)
        ft = friction_test(*final, Y, parts, friction)
        search = type(search)(search.primary, search.trials, search.chosen, ft, search.indistinguishable)
        if ft.get("admissible"):
            causes.append("friction_level")
    return final, causes, search


def _parameters(final_cand, final_fit, table) -> tuple[dict, dict]:
    """The chosen model's parameter estimates and which cause owns each parameter."""
    owner = {p.name: ext for ext in final_cand.extensions for p in table[ext]}
    params = {
        p.name: ParameterEstimate(
            p.name,
            float(v),
            (float(lo), float(hi)),
            p.unit,
            p.description,
            owner.get(p.name, "friction_level"),
        )  # fmt: skip
        for p, v, (lo, hi) in zip(final_cand.parameters, final_fit.values, final_fit.ci95, strict=True)
    }
    return params, owner


def _residual_evidence(data, sim, rows, meas, before, heldout, scale, sigma) -> dict:
    variables = kinematic_variables(data.vx, data.vy, data.wz, sim.radius, data.loads(sim.load), data.roll)
    kept_vars = {k: np.asarray(v)[rows] for k, v in variables.items()}
    residuals: dict = {
        "before": residual_structure(((meas - before) / scale / sigma)[rows], kept_vars),
        "after": residual_structure(((meas - heldout) / scale / sigma)[rows], kept_vars),
        "units": "standardised: residual / noise SD of the chosen model (outliers left out)",
    }
    for key in ("before", "after"):
        for c, ch in enumerate(CHANNELS):
            r = ((meas - (before if key == "before" else heldout)) / scale)[rows, c]
            residuals[key][ch]["rmse"] = _rmse(r)
            residuals[key][ch]["mean"] = float(np.mean(r))
    return {"variables": variables, "residuals": residuals}


def _closed_form_evidence(sim, meas, closed, before, scale, rows) -> dict:
    return {
        "rmse_vs_data": _rmse(((meas - closed) / scale)[rows]),
        "rmse_vs_exact": _rmse((closed - before) / scale),
        "exact_rmse_vs_data": _rmse(((meas - before) / scale)[rows]),
        "max_abs_vs_exact": np.max(np.abs(closed - before) / scale, axis=0).tolist(),
        "coefficients": {k: sim.coefficients.to_dict()[k] for k in ("F0", "M0", "a", "m", "R")}
        | {"k_x": sim.coefficients.k_x},
        "note": "F0, M0, a, m from the static map's moments; scaled RMSEs",
    }


def _separation_notes(final_cand, final_fit, table, causes, owner) -> list[str]:
    separation = []
    if len(final_cand.extensions) > 1:
        first, second = (tuple(q.name for q in table[e]) for e in final_cand.extensions[:2])
        for a, b, r in correlated_parameters(final_fit, first, second):
            separation.append(
                f"{a} ({final_cand.extensions[0]}) and {b} ({final_cand.extensions[1]}) are correlated "
                f"(r = {r:+.2f}) on this programme: other test points would separate them better"
            )
    if "friction_level" in causes[1:]:
        for _f, b, r in correlated_parameters(final_fit, ("f",), tuple(owner)):
            separation.append(
                f"f and {b} ({owner[b]}) are correlated (r = {r:+.2f}): the friction level is "
                "partly confounded with it on this programme"
            )
    return separation


def _noise_summary(final_fit, noise_tables, reference) -> dict:
    noise_info = final_fit.noise.to_dict()
    for ch, table_c in noise_tables.items():
        noise_info[ch]["bic"] = {k: v["bic"] for k, v in table_c.items()}
    noise_info["criterion"] = (
        "per channel, lowest BIC among constant, proportional and combined on the residuals of the "
        f"reference fit ({reference}); |F_ref| = its predicted magnitude"
    )
    return noise_info


def _gain(final_fit, fits, final_cv, none_cv, final_name, n_folds, seed) -> dict:
    return {
        "rmse_before": none_cv.rmse,
        "rmse_after": final_cv.rmse,
        "delta_bic": final_fit.bic - fits["none"].bic,
        "delta_aicc": final_fit.aicc - fits["none"].aicc,
        "rmse_before_channels": none_cv.rmse_channels.tolist(),
        "rmse_after_channels": final_cv.rmse_channels.tolist(),
        "rmse_units": "scaled: Fx, Fy by f0 N; Mz by f0 N R",
        "heldout": f"{n_folds}-fold cross-validation (folds shuffled with seed {seed}), outliers left out",
        "delta": "score(chosen model) - score(none); negative favours the model",
        "model": final_name,
    }


def diagnose(
    simulation,
    measured,
    *,
    rolling=None,
    friction: float = DEFAULT_FRICTION,
    seed: int = 0,
    n_folds: int = FOLDS,
    nr: int = FIT_NR,
    nphi: int = FIT_NPHI,
    pairs: bool = True,
    analyse_kwargs: dict | None = None,
    columns: Columns | None = None,
    hold_rule: HoldRule | None = None,
    layout: str = "auto",
) -> Diagnosis:
    """Compare measured friction data with the simulation and name the cause(s) of the misfit.

    ``simulation``/``rolling``: FE exports (paths or ContactFields, through
    `fepost.analysis.analyse`), polar maps in the patch frame, or a ready
    `Simulation`. ``measured``: a CSV of test points, a rig recording (CSV,
    Parquet, MATLAB, TYDEX; ``columns`` maps its channels and units,
    ``hold_rule`` finds its holds, ``layout`` is ``"auto"``, ``"points"`` or
    ``"recording"``: `fepost.diagnose.inputs.load_measured`), `MeasuredData` or
    `Holds`. ``friction``: nominal f. ``seed`` shuffles the cross-validation
    folds. ``nr``/``nphi``: the fit grid. ``pairs``: look for a second cause
    (module docstring, step 5). Raises `DataError` on unusable data.
    """
    t0 = time.perf_counter()
    _check_arguments(seed, n_folds)
    sim = load_simulation(simulation, rolling, friction=friction, nr=nr, nphi=nphi, **(analyse_kwargs or {}))
    data, holds = load_measured(measured, columns=columns, hold_rule=hold_rule, layout=layout)
    check_plausible(
        data, friction=sim.friction, load=sim.load, radius=sim.radius, has_rolling=sim.rolling is not None
    )
    pred = Predictor(sim, data)
    cands = build_candidates(pred)
    table = extension_parameters(pred)
    scale = pred.scale
    Y = data.forces / scale

    rob, rows, noise, noise_tables = screen(cands, Y)  # 3.
    t_robust = time.perf_counter() - t0
    fits, cvs, parts, scores = _single_causes(cands, Y, rob, rows, noise, n_folds, seed)  # 4.
    primary = scores[0].name
    t_single = time.perf_counter() - t0
    (final_cand, final_fit, final_cv), causes, search = _second_cause(
        pred, cands, fits, cvs, primary, Y, parts, table, sim.friction, pairs
    )  # 5.
    t_pairs = time.perf_counter() - t0

    model = final_fit.model if final_fit.model is not None else final_cand
    params, owner = _parameters(final_cand, final_fit, table)
    before = cands["none"].predict(np.empty(0)) * scale
    after = model.predict(final_fit.values) * scale
    heldout = after.copy()
    heldout[final_cv.rows] = data.forces[final_cv.rows] - final_cv.residuals * scale
    closed = closed_form_prediction(sim, data)
    sigma = final_fit.noise.sigma()
    evidence = _residual_evidence(data, sim, rows, data.forces, before, heldout, scale, sigma)
    pure = None if holds is None else tuple(np.asarray(x)[rows] for x in holds.pure_error())
    lof = lack_of_fit(
        data, rows, (Y - model.predict(final_fit.values))[rows], model.predict(final_fit.values)[rows],
        sigma[rows], final_fit.jacobian,
        pure_error=None if pure is None else (pure[0] / scale, pure[1]),
    )  # fmt: skip
    indist = (
        tuple(indistinguishable(scores, cands)) if search is None or search.chosen is None
        else search.indistinguishable
    )  # fmt: skip
    info = {
        "folds": n_folds, "seed": seed, "seconds": time.perf_counter() - t0, "seconds_robust": t_robust,
        "seconds_single": t_single, "seconds_pairs": t_pairs - t_single,
        "exact_evaluations": pred.evaluations,
    }  # fmt: skip
    return Diagnosis(
        cause=primary,
        causes=tuple(causes),
        parameters=params,
        gain=_gain(final_fit, fits, final_cv, cvs["none"], final_cand.name, n_folds, seed),
        candidates=tuple(scores),
        indistinguishable=indist,
        design_notes=tuple(design_notes(data.vx, data.vy, data.wz, sim.radius, data.N)),
        separation=tuple(_separation_notes(final_cand, final_fit, table, causes, owner)),
        residuals=evidence["residuals"],
        closed_form=_closed_form_evidence(sim, data.forces, closed, before, scale, rows),
        simulation=sim.to_dict(),
        data=data,
        predictions={"before": before, "after": after, "after_heldout": heldout, "closed_form": closed},
        scales=scale,
        variables=evidence["variables"],
        outliers=tuple(int(i) for i in rob.outliers),
        lack_of_fit=lof,
        noise=_noise_summary(final_fit, noise_tables, rob.reference),
        sigma=sigma,
        robust=rob.to_dict(),
        pairs=None if search is None else search.to_dict(),
        info=info,
        holds=holds,
    )
