"""Choosing the cause: BIC, a nesting test and a held-out check.

Every candidate is fitted to the rows kept (outliers left out,
`fepost.diagnose.robust`) by maximum likelihood (`fepost.diagnose.fitting`)
and scored by the Bayesian information criterion BIC = −2ℓ + k ln(n_obs), with ℓ
the Gaussian log-likelihood under the noise model of
`fepost.diagnose.noise` (its parameters estimated with the model's),
k = model parameters + noise parameters, n_obs = 3 × rows.

A candidate other than ``none`` is **admissible** when, against every model
nested in it (``none`` and, for the extensions, ``friction_level``; see
`fepost.diagnose.causes`):

1. its BIC is lower;
2. the likelihood-ratio statistic 2Δℓ exceeds the χ² quantile with Δk degrees
   of freedom at level `ALPHA` = 0.05/10 (Bonferroni over the ten
   candidates other than ``none``: ``friction_level`` and the nine extensions,
   so that on data with no effect the chance of naming any cause stays below
   5 %; without the nesting test the richer of two nested models
   wins on AIC about one time in six, P(χ²₁ > 2) = 0.157);
3. its mean held-out log predictive density per observation under
   `FOLDS`-fold cross-validation (noise parameters re-estimated on each
   training set) is higher.

``none`` is always admissible. The cause is the admissible candidate of lowest
BIC. Candidates are ranked admissible first, then by BIC.

**Indistinguishable.** Admissible candidates that are not nested in one another
and lie within `INDISTINGUISHABLE_DBIC` = 10 of the winner's BIC (a
Bayes factor below e⁵ ≈ 150, "very strong" on the Kass–Raftery scale) are
listed as ``indistinguishable``: the data support them about equally, and the
output says so rather than pretending to know. `design_notes` adds what the
test programme itself cannot separate (e.g. no two absolute speeds at one ratio).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from .causenames import CAUSES
from .fitting import Fit, fit
from .models import Candidate

#: Folds of the held-out check.
FOLDS = 5
#: Level of each nesting likelihood-ratio test (Bonferroni: 5 % over the 9 extensions).
ALPHA = 0.05 / (len(CAUSES) - 1)
#: BIC difference below which two admissible, non-nested candidates are indistinguishable.
INDISTINGUISHABLE_DBIC = 10.0


@dataclass(frozen=True)
class CrossValidation:
    """Held-out residuals (n_rows, 3) of ``rows`` and the mean log density per observation."""

    residuals: np.ndarray
    log_score: float
    rows: np.ndarray

    @property
    def rmse(self) -> float:
        return float(np.sqrt(np.mean(self.residuals**2)))

    @property
    def rmse_channels(self) -> np.ndarray:
        return np.sqrt(np.mean(self.residuals**2, axis=0))


def folds(n, k: int = FOLDS, seed: int = 0) -> list[np.ndarray]:
    """``k`` disjoint held-out index sets covering ``range(n)`` (or the rows ``n``), shuffled by ``seed``."""
    rows = np.arange(n) if np.ndim(n) == 0 else np.asarray(n)
    order = rows[np.random.default_rng([seed, 11]).permutation(rows.size)]
    return [np.sort(part) for part in np.array_split(order, k)]


def crossvalidate(cand: Candidate, Y: np.ndarray, parts: list[np.ndarray], full: Fit) -> CrossValidation:
    """Fit ``cand`` without each part (warm-started at ``full``) and predict the part.

    A geometric candidate is refitted in its second-order expansion about the
    full-data fit (``full.model``): the fold estimates differ from the full one
    by O(n^-1/2), so the Taylor error is third order in that difference.
    """
    cand = full.model if full.model is not None else cand
    rows = np.sort(np.concatenate(parts))
    res = np.full_like(Y, np.nan)
    logp = 0.0
    for held in parts:
        train = np.setdiff1d(rows, held)
        f = fit(
            cand,
            Y,
            train,
            start=full.values if cand.n_params else None,
            noise=full.noise,
            intervals=False,
        )
        r = Y[held] - cand.predict(f.values)[held]
        res[held] = r
        logp += float(np.sum(stats.norm.logpdf(r, scale=f.noise.sigma(held))))
    return CrossValidation(res[rows], logp / (3 * rows.size), rows)


@dataclass(frozen=True)
class Score:
    """One candidate's fit, scores and verdict (``reasons`` says why it is not admissible)."""

    name: str
    fit: Fit
    cv: CrossValidation
    delta_bic: float  # BIC − BIC(none)
    delta_aicc: float  # AICc − AICc(none)
    lrt_p: dict
    admissible: bool
    reasons: tuple[str, ...]

    @property
    def bic(self) -> float:
        return self.fit.bic

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "score": self.fit.bic,
            "criterion": "BIC",
            "delta_bic": self.delta_bic,
            "aicc": self.fit.aicc,
            "delta_aicc": self.delta_aicc,
            "log_likelihood": self.fit.log_likelihood,
            "n_params": self.fit.n_params,
            "lrt_p": dict(self.lrt_p),
            "cv_rmse": self.cv.rmse,
            "cv_log_score": self.cv.log_score,
            "admissible": self.admissible,
            "reasons": list(self.reasons),
            "parameters": self.fit.to_dict()["parameters"],
        }


def nesting_tests(
    ft: Fit, cv: CrossValidation, nested: dict[str, tuple[Fit, CrossValidation]], alpha: float
) -> tuple[dict[str, float], list[str]]:
    """The rules of admissibility (module docstring) for the fit ``ft`` with held-out check ``cv``.

    ``nested``: name -> (fit, held-out check) of each model nested in it; ``alpha``: the level
    of each likelihood-ratio test. Returns the LR p-value against each nested model and the
    reasons the fit is not admissible (none: admissible); a parameter at a bound is one.
    """
    pvals, reasons = {}, []
    for parent, (pf, pcv) in nested.items():
        lr = max(0.0, 2.0 * (ft.log_likelihood - pf.log_likelihood))
        p = float(stats.chi2.sf(lr, ft.n_params - pf.n_params))
        pvals[parent] = p
        if ft.bic >= pf.bic:
            reasons.append(f"BIC not below {parent}")
        if p >= alpha:
            reasons.append(f"likelihood-ratio test vs {parent}: p = {p:.3g} >= {alpha:.3g}")
        if cv.log_score <= pcv.log_score:
            reasons.append(f"held-out log density not above {parent}")
    if ft.at_bound:
        reasons.append(f"parameter(s) at a bound: {', '.join(ft.at_bound)}")
    return pvals, reasons


def score_candidates(
    cands: dict[str, Candidate], fits: dict[str, Fit], cvs: dict[str, CrossValidation]
) -> list[Score]:
    """Nesting tests and admissibility for every candidate; ranked admissible first, then by BIC."""
    base = fits["none"]
    scores = []
    for name, cand in cands.items():
        ft, cv = fits[name], cvs[name]
        pvals, reasons = nesting_tests(ft, cv, {p: (fits[p], cvs[p]) for p in cand.nested}, ALPHA)
        scores.append(
            Score(
                name,
                ft,
                cv,
                ft.bic - base.bic,
                ft.aicc - base.aicc,
                pvals,
                not reasons,
                tuple(reasons),
            )
        )
    scores.sort(key=lambda s: (not s.admissible, s.bic))
    return scores


def indistinguishable(scores: list[Score], cands: dict[str, Candidate]) -> list[str]:
    """Names of admissible candidates as good as the winner (see the module docstring), winner first."""
    best = scores[0]
    if best.name == "none":
        return []
    out = [best.name]
    for s in scores[1:]:
        if not s.admissible or s.name == "none":
            continue
        nested = s.name in cands[best.name].nested or best.name in cands[s.name].nested
        if not nested and s.bic - best.bic < INDISTINGUISHABLE_DBIC:
            out.append(s.name)
    return out if len(out) > 1 else []


def design_notes(vx, vy, wz, radius: float, loads=None) -> list[str]:
    """What the test programme cannot separate, from the kinematics alone.

    Coulomb friction is scale-free: only ε = |v|/(|ω|R) and the directions
    matter. A speed-dependent law is seen only through points at the same ε and
    direction but different absolute speeds (a factor ≥ 1.5 apart); without
    them it is confounded with the shape-type effects (pressure dependence,
    elliptic patch). Pressure-dependent friction shows mostly through
    different loads (the mean μ then changes with N); at one load it differs
    from a friction-level change only through the map's pressure shape.
    """
    notes = []
    v = np.hypot(vx, vy)
    u = np.abs(wz) * radius
    speed = np.where(u > 0, u, v)  # the scale of each point
    eps = np.where(u > 0, v / np.where(u > 0, u, 1.0), np.inf)
    key_eps = np.where(np.isfinite(eps), np.round(eps, 2), -1.0)
    key_dir = np.where(v > 0, np.round(np.degrees(np.arctan2(vy, vx)) / 5.0), 999)
    groups: dict[tuple, list[float]] = {}
    for ke, kd, sg, sp in zip(key_eps, key_dir, np.sign(wz), speed, strict=True):
        groups.setdefault((ke, kd, sg), []).append(sp)
    spread = any(max(g) >= 1.5 * min(g) for g in groups.values() if min(g) > 0)
    if not spread:
        notes.append(
            "no test points share a speed ratio and direction at absolute speeds 1.5x apart: "
            "speed_dependent_friction cannot be told from shape effects "
            "(pressure_dependent_friction, elliptic_patch)"
        )
    if loads is None or np.unique(np.round(np.asarray(loads, float), 6)).size < 2:
        notes.append(
            "all points at one load: pressure_dependent_friction is told from friction_level "
            "only through the pressure map's shape (test at several loads to separate them)"
        )
    if not np.any((u > 0) & (v == 0)):
        notes.append("no pure-spin points: the spin torque level M0 is seen only through combined points")
    if not np.any((u == 0) & (v > 0)):
        notes.append("no pure-sliding points: friction_level and anisotropic_friction are weakly separated")
    dirs = np.unique(key_dir[v > 0])
    if dirs.size < 3:
        notes.append(
            f"only {dirs.size} sliding direction(s): anisotropic_friction, elliptic_patch and pressure_shift "
            "are poorly separated"
        )
    if not (np.any(wz > 0) and np.any(wz < 0)):
        notes.append("one spin sign only: sensor offsets in Mz and Fy are confounded with asymmetric effects")
    return notes
