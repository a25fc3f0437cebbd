"""Gross outliers: a robust fit of every candidate, and the outlier rule.

A load-cell glitch (a sign flip, a spike of several times the reading) pulls a
least-squares fit far from the rest of the data and can hide a real effect or
invent one. Before any model is scored, every single-cause candidate is fitted
robustly (`fit` with ``loss="huber"``: Huber's loss
with k = 1.345 noise SDs and the ``combined`` noise model of
`noise`, its scale from Huber's scale equation started at
1.4826 × MAD; the reference magnitudes are those of the simulation). A
candidate that moves the pressure map is fitted here on its second-order
expansion about the no-effect geometry (one set of exact integrals, no
iteration): its residuals need only be good enough to tell a glitch from the
data, and the error of the expansion is third order in the effect.

**Outlier rule.** Let z_ic = r_ic/σ_ic be the standardised residuals of a
candidate's robust fit. A row is an outlier when, under *every* candidate, one of
its three channels lies beyond

    c = Φ⁻¹(1 − α/(2·3n)),   α = `OUTLIER_ALPHA` = 0.05,

i.e. when no cause in the vocabulary explains it. c is the Bonferroni bound over
the 3n residuals: on clean Gaussian data the chance that any row at all is
flagged is below 5 % (c = 4.1 for 400 rows); a flagged row costs one test point.
A misfit that a candidate explains (a real effect) is not flagged, because that
candidate's residuals are small there. When more than
`MAX_OUTLIER_FRACTION` of the rows lie beyond c, they are not isolated
glitches but structure: none is removed, and the lack-of-fit tests
(`lackfit`) speak for them.

Outliers are left out of every later fit, score, interval and test.

**Reference for the noise model.** The robust fit of lowest BIC (with the Huber
log-likelihood) is the reference: its predicted |F| are the magnitudes g of the
noise model for every candidate, and its residuals on the remaining rows choose
each channel's noise structure (`select_structure`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtri

from .._arrays import frozen
from .fitting import Fit, fit
from .models import Candidate
from .noise import Noise

#: Family-wise chance of flagging a row of clean data (Bonferroni over 3n residuals).
OUTLIER_ALPHA = 0.05
#: At most this share of the rows is treated as isolated glitches.
MAX_OUTLIER_FRACTION = 0.10


def outlier_threshold(n_rows: int, alpha: float = OUTLIER_ALPHA) -> float:
    """c = Φ⁻¹(1 − α/(2·3n)): the standardised residual beyond which a row may be an outlier."""
    return float(ndtri(1.0 - alpha / (2.0 * 3 * n_rows)))


@dataclass(frozen=True)
class RobustPass:
    """Robust fits, the outlier verdict and the noise reference.

    ``outliers``: 0-based data rows left out; ``beyond``: rows past the threshold
    under every candidate (equal to ``outliers`` unless there were too many);
    ``worst``: per row, the smallest over candidates of its largest |z|;
    ``reference``: the candidate whose prediction sets the noise magnitudes.
    """

    fits: dict
    threshold: float
    worst: np.ndarray
    beyond: np.ndarray
    outliers: np.ndarray
    reference: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "worst", frozen(self.worst))
        object.__setattr__(self, "beyond", frozen(self.beyond, dtype=int))
        object.__setattr__(self, "outliers", frozen(self.outliers, dtype=int))

    @property
    def widespread(self) -> bool:
        """True when too many rows were beyond the threshold to be removed as glitches."""
        return self.beyond.size > 0 and self.outliers.size == 0

    def to_dict(self) -> dict:
        return {
            "rule": (
                "a row is an outlier when, under the robust (Huber) fit of every candidate, one of its "
                f"channels lies beyond {self.threshold:.3g} noise SDs (Bonferroni 5 % over all residuals); "
                f"at most {MAX_OUTLIER_FRACTION:.0%} of the rows"
            ),
            "threshold": self.threshold,
            "beyond_threshold": self.beyond.tolist(),
            "removed": self.outliers.tolist(),
            "widespread": self.widespread,
            "reference": self.reference,
            "robust_bic": {k: f.bic for k, f in self.fits.items()},
        }


def robust_pass(cands: dict[str, Candidate], Y: np.ndarray, g: np.ndarray) -> RobustPass:
    """Fit every candidate robustly and apply the outlier rule (module docstring)."""
    n = Y.shape[0]
    start = Noise.start("combined", g)
    fits: dict[str, Fit] = {}
    for name, c in cands.items():
        model = c if c.expand is None else c.expand(np.array([p.start for p in c.parameters]))
        fits[name] = fit(model, Y, noise=start, loss="huber", intervals=False)
    worst = np.full(n, np.inf)
    for f in fits.values():
        assert f.model is not None
        z = (Y - f.model.predict(f.values)) / f.noise.sigma()
        worst = np.minimum(worst, np.max(np.abs(z), axis=1))
    threshold = outlier_threshold(n)
    beyond = np.flatnonzero(worst > threshold)
    outliers = beyond if beyond.size <= MAX_OUTLIER_FRACTION * n else np.zeros(0, int)
    reference = min(fits, key=lambda k: fits[k].bic)
    return RobustPass(fits, threshold, worst, beyond, outliers, reference)
