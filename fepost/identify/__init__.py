"""Identification of friction-model coefficients from test curves (the paper's Table 1).

The paper's experiment: take the curves (1.8)

    F∥(ψ)  = F0 / √(1 + a ψ²)                      ψ = u/v      (N)
    M_C(υ) = M0 / √(1 + m υ²)                      υ = v/u      (N·m)
    F⊥(υ)  = k_x M0/(2R) / √(1 + (m/4) υ²)                      (N)

(u = ω_z R, v = |v|, with the 1/R the paper omits in F⊥), perturb them by noise
of amplitude 0.2·max of each curve, and recover F0, M0, a, m, k_x by nonlinear
least squares with 95 % bounds; f = F0/N.

One module per job:

* `curves`: the test curves (`TestCurves`,
  `make_test_curves`, `exact_curves`, `with_noise`);
* `forms`: what is fitted to them: the paper's closed
  forms (`curve_model`) or the generalised model (`GeneralisedCurves`);
* `fit`: the fit and its intervals (`fit_table1`);
* `result`: what it returns (`Identification`);
* `bias`: what the closed forms' own error does to the fit
  (`approximation_bias`, `BiasReport`, residual tests).
"""

from .bias import BiasReport, approximation_bias, lag1_autocorrelation, runs_test
from .curves import (
    CURVE_UNITS,
    CURVES,
    DEFAULT_AMPLITUDE,
    DEFAULT_N_POINTS,
    DEFAULT_SPAN,
    NOISE_KINDS,
    PARAMETER_UNITS,
    PARAMETERS,
    TestCurves,
    exact_curves,
    make_test_curves,
    rolling_model,
    with_noise,
)
from .fit import fit_table1
from .forms import PAPER, GeneralisedCurves, PaperCurves, curve_model
from .result import CONFIDENCE, Identification

__all__ = [
    "BiasReport",
    "CONFIDENCE",
    "CURVES",
    "CURVE_UNITS",
    "DEFAULT_AMPLITUDE",
    "DEFAULT_N_POINTS",
    "DEFAULT_SPAN",
    "GeneralisedCurves",
    "Identification",
    "NOISE_KINDS",
    "PAPER",
    "PARAMETERS",
    "PARAMETER_UNITS",
    "PaperCurves",
    "TestCurves",
    "approximation_bias",
    "curve_model",
    "exact_curves",
    "fit_table1",
    "lag1_autocorrelation",
    "make_test_curves",
    "rolling_model",
    "runs_test",
    "with_noise",
]
