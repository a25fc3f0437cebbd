"""How often the lack-of-fit verdict fires on data that have no lack of fit: a parametric bootstrap.

A model is fitted to measured data as ``diagnose`` fits its chosen model (the
robust screen, the rows kept, the noise structure per channel, the Gaussian fit).
Data sets are then drawn from that fit: its prediction on the rows kept plus
Gaussian noise with the fitted noise model's σ, at the same test points (so with
the same replicates). Each is fitted again with the same candidate and noise
structure, and `fepost.diagnose.lackfit.lack_of_fit` judges its residuals. Every
"detected" is a false alarm, so the share of them estimates the verdict's real
level, to set against its stated one (`LOF_LEVEL`); the raw p-values of each
channel's pure-error test should be uniform on [0, 1].

``benchmarks/bench_lackfit_fitted.py`` runs it on the documented examples;
the tests check the rate and the p-values' uniformity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .causes import Predictor, build_candidates
from .fitting import Fit, fit
from .lackfit import LOF_LEVEL, lack_of_fit
from .measured import CHANNELS, MeasuredData
from .models import Candidate
from .pipeline import screen
from .simulation import Simulation


@dataclass(frozen=True)
class FittedCause:
    """One cause's candidate fitted to ``data`` on the rows the screen kept."""

    data: MeasuredData
    candidate: Candidate
    fit: Fit
    Y: np.ndarray
    rows: np.ndarray

    def prediction(self, values: np.ndarray | None = None) -> np.ndarray:
        """The fitted model's dimensionless channels (n, 3) at ``values`` (default the fit's)."""
        model = self.fit.model if self.fit.model is not None else self.candidate
        return model.predict(self.fit.values if values is None else values)

    def verdict(self) -> dict:
        """`lack_of_fit` of this fit, as ``diagnose`` runs it on its chosen model."""
        pred = self.prediction()
        sigma = self.fit.noise.sigma()[self.rows]
        res = (self.Y - pred)[self.rows]
        return lack_of_fit(self.data, self.rows, res, pred[self.rows], sigma, self.fit.jacobian)


def fit_cause(data: MeasuredData, sim: Simulation, cause: str) -> FittedCause:
    """Screen ``data`` and fit the candidate of ``cause`` as ``diagnose`` fits its chosen model."""
    pred = Predictor(sim, data)
    cands = build_candidates(pred)
    if cause not in cands:
        raise ValueError(f"cause must be one of {', '.join(cands)}, got {cause!r}")
    Y = data.forces / pred.scale
    rob, rows, noise, _ = screen(cands, Y)
    start = rob.fits[cause].values if cause in rob.fits else None
    return FittedCause(data, cands[cause], fit(cands[cause], Y, rows, start=start, noise=noise), Y, rows)


@dataclass(frozen=True)
class FalseAlarms:
    """The verdicts on ``draws`` data sets drawn from one fit."""

    draws: int
    detected: int
    channels: dict[str, int]
    p_raw: dict[str, np.ndarray]
    level: float = LOF_LEVEL

    @property
    def rate(self) -> float:
        return self.detected / self.draws


def false_alarms(fitted: FittedCause, draws: int, *, seed: int = 0) -> FalseAlarms:
    """Draw ``draws`` data sets from ``fitted`` (module docstring), refit and judge each one."""
    clean = fitted.prediction()
    sigma = fitted.fit.noise.sigma()[fitted.rows]
    rng = np.random.default_rng(seed)
    detected, channels = 0, dict.fromkeys(CHANNELS, 0)
    p_raw: dict[str, list[float]] = {ch: [] for ch in CHANNELS}
    for _ in range(draws):
        Y = fitted.Y.copy()
        Y[fitted.rows] = clean[fitted.rows] + sigma * rng.standard_normal(sigma.shape)
        again = fit(fitted.candidate, Y, fitted.rows, start=fitted.fit.values, noise=fitted.fit.noise)
        lof = FittedCause(fitted.data, fitted.candidate, again, Y, fitted.rows).verdict()
        detected += bool(lof["detected"])
        for ch, v in lof["channels"].items():
            channels[ch] += bool(v["detected"])
            if v["p_raw"] is not None:
                p_raw[ch].append(v["p_raw"])
    return FalseAlarms(draws, detected, channels, {ch: np.array(p) for ch, p in p_raw.items()})
