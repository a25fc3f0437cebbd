"""Two causes at once: a second extension on top of the chosen one, by the same rules.

Once the single-cause rule of `selection` has named an
extension C₁, each other extension C₂ is a candidate second cause. The joint
model C₁ + C₂ (`joint_candidate`: f shared, both
parameter sets, the effects combined exactly) nests C₁, C₂, ``friction_level``
and ``none``, and is **admissible** when against each of them its BIC is lower,
its likelihood-ratio test has p < `PAIR_ALPHA` = 0.01/9 (Bonferroni over
the second causes tried: at most the eight other extensions that combine with
it, ``load_transfer`` only with the sensor causes, and a friction level other
than nominal), and its held-out log density is higher. The family-wise
level is 1 %, not the 5 % of the single causes: a data set with one cause is
then reported with two at most about one time in a hundred
(``benchmarks/bench_diagnose_pairs.py`` measures it), while real second causes
of the size a rig sees pass with likelihood ratios in the hundreds. The admissible
joint model of lowest BIC is the answer; its ``causes`` are [C₁, C₂].

A friction level other than nominal is the last second cause: every extension
already fits f, so it is tested inside the final model, against the same model
with f = f₀, by the same three rules; if it passes, ``friction_level`` joins the
causes.

**Screening** (the speed). Fitting a joint model with geometry costs as much as
the single-cause fits together, so each second cause is first screened by Rao's
score test at C₁'s fit: the whitened residuals' sum of squares on the joint
model's whitened Jacobian at C₂'s no-effect values, ~ χ² with C₂'s number of
parameters. The Jacobian's C₁ columns are C₁'s own at its fit; its C₂ columns
are C₂'s derivatives at no effect with C₁'s effect left out (the neglected
interaction is of the order of the product of the two effects, and the
derivatives are already cached from the single-cause fits, so the screen costs
no new integrals). The score test is the likelihood-ratio test's first-order
twin, so only a joint model whose score statistic reaches `SCREEN_FRACTION`
of the likelihood ratio it would need to be admitted (the larger of the χ²
quantile at PAIR_ALPHA and the BIC's q ln n_obs, q its new parameters) is
fitted, at most `MAX_PAIR_FITS` of them, the strongest first. The friction
level is screened by the Wald test of f = f₀ at the same fraction.

**What the programme cannot separate.** For the chosen joint model, parameters
of the two causes whose estimates are correlated beyond
`CORRELATION_NOTE` (from the fit's covariance) are reported: the test
programme moves them together, and only other test points could tell them
apart; admissible joint models within ΔBIC 10 of the chosen one are listed as
indistinguishable.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from ..errors import FitWarning
from ..lsq import jacobian_svd
from .causes import EXTENSIONS, combinable, joint_candidate, pair_name
from .fitting import Fit, fit
from .models import Candidate, with_fixed
from .selection import INDISTINGUISHABLE_DBIC, CrossValidation, crossvalidate, nesting_tests

#: Level of each second-cause likelihood-ratio test (Bonferroni: 1 % over at most the other
#: extensions and a friction level other than nominal, as many as the extensions).
PAIR_ALPHA = 0.01 / len(EXTENSIONS)
#: A joint model is fitted when its score (or Wald) statistic reaches this share of the
#: likelihood ratio it needs to be admitted (module docstring).
SCREEN_FRACTION = 0.5
#: Joint models fitted at most (those with the strongest screens).
MAX_PAIR_FITS = 2
#: Parameter correlations above this are reported as not separated by the programme.
CORRELATION_NOTE = 0.8


@dataclass(frozen=True)
class Trial:
    """One second cause: its screen and, when fitted, the joint model's scores."""

    second: str
    name: str
    screen_statistic: float
    screen_p: float
    needed: float
    fit: Fit | None = field(default=None, repr=False)
    cv: CrossValidation | None = field(default=None, repr=False)
    lrt_p: dict = field(default_factory=dict)
    delta_bic: float = float("nan")  # BIC − BIC(primary)
    admissible: bool = False
    reasons: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        out = {
            "second": self.second,
            "model": self.name,
            "screen": {"statistic": self.screen_statistic, "p": self.screen_p, "needed": self.needed},
            "fitted": self.fit is not None,
        }
        if self.fit is not None and self.cv is not None:
            out |= {
                "bic": self.fit.bic,
                "delta_bic_vs_primary": self.delta_bic,
                "lrt_p": dict(self.lrt_p),
                "cv_rmse": self.cv.rmse,
                "cv_log_score": self.cv.log_score,
                "admissible": self.admissible,
                "reasons": list(self.reasons),
            }
        return out


def numeric_jacobian(cand: Candidate, at: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """d prediction/d parameter at ``at`` on ``rows``: (len(rows), 3, p), central differences.

    Geometric models are differentiated through their local linear model
    (``expand(at, order=1)``), i.e. with the geometric step of
    `models`; the other parameters enter at most bilinearly.
    """
    local = cand.expand(at, order=1) if cand.expand is not None else cand
    at = np.asarray(at, float)
    out = np.empty((rows.size, 3, at.size))
    for j, p in enumerate(cand.parameters):
        h = 1e-3 * p.scale
        up, dn = at.copy(), at.copy()
        up[j] = min(at[j] + h, p.upper)
        dn[j] = max(at[j] - h, p.lower)
        out[:, :, j] = (local.predict(up)[rows] - local.predict(dn)[rows]) / (up[j] - dn[j])
    return out


def score_test(base: Fit, second: Candidate, Y: np.ndarray) -> tuple[float, float]:
    """Rao's score statistic for adding ``second``'s parameters to ``base`` (module docstring) and its p."""
    rows = base.rows
    sig = base.noise.sigma(rows)
    model = base.model
    assert model is not None and base.jacobian is not None
    r = (Y[rows] - model.predict(base.values)[rows]) / sig
    j = base.names.index("f") if "f" in base.names else None
    f = float(base.values[j]) if j is not None else float(second.parameters[0].start)
    at = np.array([f] + [q.null for q in second.parameters[1:]])
    extra = (numeric_jacobian(second, at, rows)[:, :, 1:] / sig[:, :, None]).reshape(-1, at.size - 1)
    J = np.column_stack([base.jacobian, extra])
    u, s, _ = np.linalg.svd(J, full_matrices=False)
    keep = s > 1e-9 * (s[0] if s.size else 0.0)
    stat = float(np.sum((u[:, keep].T @ r.ravel()) ** 2))
    return stat, float(stats.chi2.sf(stat, at.size - 1))


def _quiet_fit(*args, **kwargs) -> tuple[Fit, list[str]]:
    """`fit`, with its FitWarnings returned as reasons instead of shown: a joint
    model the data cannot identify is simply not admitted."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FitWarning)
        result = fit(*args, **kwargs)
    return result, [str(w.message) for w in caught if issubclass(w.category, FitWarning)]


def needed_ratio(q: int, n_obs: int) -> float:
    """The smallest likelihood-ratio statistic 2Δℓ with which q new parameters can be admitted."""
    return float(max(stats.chi2.isf(PAIR_ALPHA, q), q * np.log(n_obs)))


@dataclass(frozen=True)
class PairSearch:
    """The second-cause search: every trial, the chosen joint model (or None) and the friction-level test."""

    primary: str
    trials: tuple[Trial, ...]
    chosen: Trial | None
    friction: dict
    indistinguishable: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return {
            "primary": self.primary,
            "alpha": PAIR_ALPHA,
            "trials": [t.to_dict() for t in self.trials],
            "chosen": None if self.chosen is None else self.chosen.name,
            "friction_level": self.friction,
            "indistinguishable": list(self.indistinguishable),
        }


def search_pairs(
    pred,
    cands: dict[str, Candidate],
    fits: dict[str, Fit],
    cvs: dict[str, CrossValidation],
    primary: str,
    Y: np.ndarray,
    parts: list[np.ndarray],
    table: dict,
) -> PairSearch:
    """Screen, fit and judge every second cause on top of ``primary`` (module docstring)."""
    base = fits[primary]
    screened: list[tuple[str, float, float, float]] = []
    for second in EXTENSIONS:
        if second == primary or not combinable((primary, second)):
            continue
        stat, p = score_test(base, cands[second], Y)
        screened.append((second, stat, p, needed_ratio(len(table[second]), base.n_obs)))
    screened.sort(key=lambda t: t[1] / t[3], reverse=True)
    done: list[Trial] = []
    for k, (second, stat, p, need) in enumerate(screened):
        joint = joint_candidate(pred, (primary, second), table)
        if stat < SCREEN_FRACTION * need or k >= MAX_PAIR_FITS:
            done.append(Trial(second, joint.name, stat, p, need))
            continue
        at = np.concatenate([base.values, [q.null for q in table[second]]])
        jf, trouble = _quiet_fit(joint, Y, base.rows, start=at, noise=base.noise)
        jcv = crossvalidate(joint, Y, parts, jf)
        against = {name: (fits[name], cvs[name]) for name in ("none", "friction_level", primary, second)}
        pvals, reasons = nesting_tests(jf, jcv, against, PAIR_ALPHA)
        reasons += trouble
        done.append(
            Trial(
                second,
                joint.name,
                stat,
                p,
                need,
                jf,
                jcv,
                pvals,
                jf.bic - base.bic,
                not reasons,
                tuple(reasons),
            )  # fmt: skip
        )
    admissible = sorted(
        (t for t in done if t.admissible and t.fit is not None),
        key=lambda t: t.fit.bic,  # type: ignore[union-attr]
    )
    chosen = admissible[0] if admissible else None
    twins: tuple[str, ...] = ()
    if chosen is not None and chosen.fit is not None:
        best = chosen.fit.bic
        close = [
            t.name for t in admissible[1:] if t.fit is not None and t.fit.bic - best < INDISTINGUISHABLE_DBIC
        ]
        twins = (chosen.name, *close) if close else ()
    return PairSearch(primary, tuple(done), chosen, {}, twins)


def friction_test(cand: Candidate, full: Fit, cv: CrossValidation, Y: np.ndarray, parts, f0: float) -> dict:
    """Is the friction level of the final model other than nominal? (module docstring)."""
    j = full.names.index("f")
    se = float(full.stderr[j])
    z = (float(full.values[j]) - f0) / se if np.isfinite(se) and se > 0 else 0.0
    wald_p = float(2.0 * stats.norm.sf(abs(z)))
    out: dict = {"f": float(full.values[j]), "f0": f0, "wald_z": z, "screen_p": wald_p, "fitted": False}
    if z * z < SCREEN_FRACTION * needed_ratio(1, full.n_obs):
        out["admissible"] = False
        return out
    fixed = with_fixed(cand, "f", f0, f"{cand.name}|f=f0")
    ff, trouble = _quiet_fit(fixed, Y, full.rows, start=np.delete(full.values, j), noise=full.noise)
    fcv = crossvalidate(fixed, Y, parts, ff)
    pvals, reasons = nesting_tests(full, cv, {fixed.name: (ff, fcv)}, PAIR_ALPHA)
    reasons = [r for r in reasons if not r.startswith("parameter(s) at a bound")] + trouble
    out |= {
        "fitted": True,
        "lrt_p": pvals[fixed.name],
        "delta_bic": full.bic - ff.bic,
        "admissible": not reasons,
        "reasons": reasons,
    }
    return out


def correlated_parameters(full: Fit, first: tuple[str, ...], second: tuple[str, ...]) -> list[tuple]:
    """(name₁, name₂, r) for parameters of two causes correlated beyond `CORRELATION_NOTE`."""
    if full.jacobian is None:
        return []
    svd = jacobian_svd(full.jacobian)
    cov = svd.inverse
    sd = np.sqrt(np.diag(cov))
    out = []
    for a in first:
        for b in second:
            i, j = full.names.index(a), full.names.index(b)
            if sd[i] > 0 and sd[j] > 0:
                r = float(cov[i, j] / (sd[i] * sd[j]))
                if abs(r) > CORRELATION_NOTE:
                    out.append((a, b, r))
    return out


__all__ = ["PAIR_ALPHA", "PairSearch", "Trial", "friction_test", "pair_name", "search_pairs"]
