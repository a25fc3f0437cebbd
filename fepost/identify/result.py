"""The result of a Table 1 fit: values, intervals, covariance and the fitted curves."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy import special

from .._arrays import frozen
from ..errors import ArgumentError
from .curves import CURVES, PARAMETER_UNITS, PARAMETERS, abscissa
from .forms import PAPER

#: Confidence level of every interval.
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Identification:
    """Result of `fit_table1`: the five fitted coefficients with 95 % bounds.

    ``values``, ``stderr``: F0 (N), M0 (N·m), a, m, k_x (order `PARAMETERS`);
    ``ci95`` (5, 2): Wald bounds from the t-quantile (NaN when the covariance is
    indeterminate); ``covariance`` (5, 5) in those units (delta method for a, m);
    ``profile_ci95``: profile-likelihood bounds of a and m, and ``profile_agrees``
    whether they match the Wald bounds within `PROFILE_TOLERANCE`;
    ``f``, ``f_ci95``: F0/N; ``N`` (N); ``noise_sigma``: estimated noise level σ_c
    of each curve (its units); ``dof_share``: h_c, the parameters each curve uses;
    ``residuals``: data − model per curve (its units); ``chi2`` (weighted), ``dof``,
    ``redchi``, ``aic``, ``bic`` (lmfit's conventions), ``nfev``, ``n_points``.
    """

    values: np.ndarray
    stderr: np.ndarray
    ci95: np.ndarray
    covariance: np.ndarray
    profile_ci95: Mapping[str, tuple[float, float]]
    profile_agrees: Mapping[str, bool]
    f: float
    f_stderr: float
    f_ci95: tuple[float, float]
    N: float
    R: float
    noise_sigma: Mapping[str, float]
    dof_share: Mapping[str, float]
    residuals: Mapping[str, np.ndarray]
    chi2: float
    dof: int
    redchi: float
    aic: float
    bic: float
    nfev: int
    n_points: int
    t_quantile: float
    determinate: bool
    confidence: float = CONFIDENCE
    names: tuple[str, ...] = PARAMETERS
    form: Any = PAPER

    def __post_init__(self) -> None:
        for name in ("values", "stderr", "ci95", "covariance"):
            object.__setattr__(self, name, frozen(getattr(self, name)))
        object.__setattr__(
            self, "residuals", MappingProxyType({k: frozen(v) for k, v in self.residuals.items()})
        )
        for name in ("profile_ci95", "profile_agrees", "noise_sigma", "dof_share"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    def _index(self, name: str) -> int:
        if name not in self.names:
            raise ArgumentError(f"name must be one of {', '.join(self.names)}, got {name!r}")
        return self.names.index(name)

    def value(self, name: str) -> float:
        """Fitted value of ``name`` (``"f"`` or one of `PARAMETERS`)."""
        return self.f if name == "f" else float(self.values[self._index(name)])

    def interval(self, name: str) -> tuple[float, float]:
        """Wald 95 % bounds of ``name`` (``"f"`` or one of `PARAMETERS`)."""
        if name == "f":
            return self.f_ci95
        lo, hi = self.ci95[self._index(name)]
        return float(lo), float(hi)

    @property
    def correlation(self) -> np.ndarray:
        """Correlation matrix of the parameters (NaN when indeterminate)."""
        sd = np.sqrt(np.diag(self.covariance))
        with np.errstate(invalid="ignore", divide="ignore"):
            return frozen(self.covariance / np.outer(sd, sd))

    def curve(self, name: str, x) -> np.ndarray:
        """Fitted closed-form curve ``name`` (one of `CURVES`) at ``x`` (ψ or υ).

        Units: N for ``"f_parallel"`` and ``"f_perp"``, N·m for ``"torque"``.
        """
        return frozen(self.form.values(name, abscissa(x), self.values, self.R))

    def curve_stderr(self, name: str, x) -> np.ndarray:
        """Standard error of the fitted curve at ``x``: √(gᵀΣg) (units of the curve).

        g = ∂ŷ/∂(F0, M0, a, m, k_x) (the form's gradient) and Σ =
        `covariance` (delta method, linearised about the fit). This is the
        uncertainty of the *mean* curve; ± t·curve_stderr is its confidence band.
        NaN when the covariance is indeterminate.
        """
        _, g = self.form(name, abscissa(x), self.values, self.R)
        var = np.einsum("...i,ij,...j->...", g, self.covariance, g)
        return frozen(np.sqrt(np.maximum(var, 0.0)))

    def prediction_band(
        self, name: str, x, level: float = CONFIDENCE
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Fitted curve ``name`` at ``x`` and its pointwise prediction band: (ŷ, lo, hi).

        A *prediction* band, not a confidence band: it holds a new measurement of
        the curve at x (same noise as the fitted data) with probability ``level``,
        pointwise (not simultaneously over x). Half-width t·√(gᵀΣg + s²σ_c²):

        * gᵀΣg, the parameter uncertainty propagated through the Jacobian g =
          ∂ŷ/∂(F0, M0, a, m, k_x) with the fit's covariance Σ (`curve_stderr`);
        * s²σ_c², the noise variance of one measurement of curve c: σ_c from
          `noise_sigma`, s² = `redchi` (the scale of the covariance,
          which is 1 at the fixed point of the reweighting);
        * t = Student-t quantile (1 + level)/2 with ν_c = n_c − h_c degrees of
          freedom, those of the σ_c estimate (n_c points, h_c = `dof_share`).
          The noise term dominates the variance; the Welch–Satterthwaite degrees
          of freedom of the sum lie between ν_c and `dof`, so using ν_c errs
          on the wide side (with `dof` instead, a band at 50 points per curve
          covers about 94.5 % rather than 95 %).

        For one curve with known shape and Gaussian noise this is the textbook
        ŷ ± t s √(1 + xᵀ(XᵀX)⁻¹x); here it holds to first order in the parameter
        errors. Units of the curve; NaN bounds when the covariance is indeterminate.
        """
        level = float(level)
        if not (0.0 < level < 1.0):
            raise ArgumentError(f"level must be a probability in (0, 1), got {level!r}")
        if name not in CURVES:
            raise ArgumentError(f"name must be one of {', '.join(CURVES)}, got {name!r}")
        x = abscissa(x)
        y = self.curve(name, x)
        var = self.curve_stderr(name, x) ** 2 + self.redchi * self.noise_sigma[name] ** 2
        nu = max(self.residuals[name].size - self.dof_share[name], 0.5)  # as in fit_table1
        t = float(special.stdtrit(nu, 0.5 + level / 2.0))
        half = t * np.sqrt(var)
        return y, frozen(y - half), frozen(y + half)

    def to_dict(self) -> dict:
        params = {
            name: {
                "value": float(self.values[i]),
                "stderr": float(self.stderr[i]),
                "ci95": [float(v) for v in self.ci95[i]],
                "unit": PARAMETER_UNITS[name],
            }
            for i, name in enumerate(self.names)
        }
        for name, (lo, hi) in self.profile_ci95.items():
            params[name]["profile_ci95"] = [lo, hi]
            params[name]["profile_agrees"] = self.profile_agrees[name]
        params["f"] = {
            "value": self.f,
            "stderr": self.f_stderr,
            "ci95": list(self.f_ci95),
            "unit": "1",
        }
        return {
            "parameters": params,
            "covariance": self.covariance.tolist(),
            "N": self.N,
            "R": self.R,
            "noise_sigma": dict(self.noise_sigma),
            "dof_share": dict(self.dof_share),
            "chi2": self.chi2,
            "dof": self.dof,
            "redchi": self.redchi,
            "aic": self.aic,
            "bic": self.bic,
            "nfev": self.nfev,
            "n_points": self.n_points,
            "confidence": self.confidence,
            "t_quantile": self.t_quantile,
            "determinate": self.determinate,
            "form": getattr(self.form, "name", type(self.form).__name__),
            "method": (
                "scipy least_squares (MINPACK lm), theta = (F0/sF, M0/sM, ln a, ln m, k_x); "
                "per-curve weights 1/sigma_c, sigma_c^2 = RSS_c/(n_c - h_c) iterated; "
                "covariance s^2 (J^T J)^-1 via SVD; Wald t-bounds; profile bounds for a, m"
            ),
        }
