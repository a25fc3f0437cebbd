"""How the closed forms fit exact-integral data: the bias the approximation itself causes.

`approximation_bias` fits the paper's closed forms to noise-free and to
noisy curves made from the exact integrals, and measures the structure left in
the residuals (lag-1 autocorrelation, Wald–Wolfowitz runs test).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from scipy import special

from ..friction.quadrature import PressureQuadrature
from .curves import (
    CURVES,
    DEFAULT_AMPLITUDE,
    DEFAULT_N_POINTS,
    DEFAULT_SPAN,
    coefficient_values,
    make_test_curves,
    with_noise,
)
from .fit import fit_table1
from .result import Identification


def lag1_autocorrelation(x) -> float:
    """Lag-1 autocorrelation Σ(x_i − x̄)(x_{i+1} − x̄)/Σ(x_i − x̄)² (≈ 0 for white noise)."""
    x = np.asarray(x, float)
    d = x - x.mean()
    den = float(d @ d)
    return float(d[:-1] @ d[1:] / den) if den > 0 else math.nan


def runs_test(x) -> tuple[int, float, float]:
    """Wald–Wolfowitz runs test on the signs of ``x`` about 0 (zeros dropped).

    Returns (runs, expected runs, two-sided p-value by the normal approximation);
    few runs (long same-sign stretches, p small) mean systematic residuals.
    """
    s = np.sign(np.asarray(x, float))
    s = s[s != 0]
    n1, n2 = int(np.sum(s > 0)), int(np.sum(s < 0))
    n = n1 + n2
    if n1 == 0 or n2 == 0:
        return (1 if n else 0), math.nan, 0.0 if n > 1 else math.nan
    runs = 1 + int(np.sum(s[1:] != s[:-1]))
    mu = 2.0 * n1 * n2 / n + 1.0
    var = 2.0 * n1 * n2 * (2.0 * n1 * n2 - n) / (n * n * (n - 1.0))
    z = (runs - mu) / math.sqrt(var) if var > 0 else 0.0
    return runs, mu, float(2.0 * special.ndtr(-abs(z)))  # two-sided normal tail


@dataclass(frozen=True)
class BiasReport:
    """How the closed forms fit exact-integral data (the study the paper does not make).

    ``theory``: the asymptotic coefficients (from the moments); ``noise_free``: the
    fit to noise-free exact curves, so its departures from ``theory`` are the bias
    the approximation itself causes; ``noisy``: the same fit on noisy exact curves
    (same noise as the paper's experiment); ``structure``: per curve, for the
    noise-free fit, the largest |data − model| relative to the curve's scale, the
    lag-1 autocorrelation of the residuals and the runs test, and the same two
    tests on the noisy fit's residuals; ``covered``: whether each noisy 95 %
    interval holds the asymptotic value.
    """

    theory: Mapping[str, float]
    noise_free: Identification
    noisy: Identification
    structure: Mapping[str, Mapping[str, float]]
    covered: Mapping[str, bool]

    def __post_init__(self) -> None:
        object.__setattr__(self, "theory", MappingProxyType(dict(self.theory)))
        object.__setattr__(
            self,
            "structure",
            MappingProxyType({k: MappingProxyType(dict(v)) for k, v in self.structure.items()}),
        )
        object.__setattr__(self, "covered", MappingProxyType(dict(self.covered)))

    def bias(self, name: str) -> float:
        """Noise-free fitted − asymptotic value of ``name``."""
        return self.noise_free.value(name) - self.theory[name]

    def relative_bias(self, name: str) -> float:
        t = self.theory[name]
        return self.bias(name) / t if t != 0 else math.nan

    def to_dict(self) -> dict:
        names = ("F0", "M0", "a", "m", "k_x")
        return {
            "theory": dict(self.theory),
            "noise_free_fit": {n: self.noise_free.value(n) for n in names},
            "bias": {n: self.bias(n) for n in names},
            "relative_bias": {n: self.relative_bias(n) for n in names},
            "noisy_fit": {
                n: {"value": self.noisy.value(n), "ci95": list(self.noisy.interval(n))} for n in names
            },
            "noisy_ci_covers_theory": dict(self.covered),
            "residual_structure": {k: dict(v) for k, v in self.structure.items()},
        }


def approximation_bias(
    coefficients,
    quad: PressureQuadrature,
    *,
    rolling_quad: PressureQuadrature | None = None,
    n_points: int = DEFAULT_N_POINTS,
    span: float = DEFAULT_SPAN,
    noise: str = "uniform",
    amplitude: float = DEFAULT_AMPLITUDE,
    seed: int | None = None,
) -> BiasReport:
    """Fit the closed forms to exact-integral curves and measure the bias and structure.

    Same arguments as `make_test_curves` with ``source="exact"``. The noise-free
    fit gives the bias of a, m (and F0, M0, k_x) against their asymptotic values; the
    noisy fit shows whether the paper's 20 % noise would hide it.
    """
    c = coefficient_values(coefficients)
    clean = make_test_curves(
        "exact",
        c,
        quad=quad,
        rolling_quad=rolling_quad,
        n_points=n_points,
        span=span,
        noise=noise,
        amplitude=0.0,
    )
    noisy = with_noise(clean, noise=noise, amplitude=amplitude, seed=seed)  # integrated once
    fit0 = fit_table1(clean, c["N"], profile=False)
    fit1 = fit_table1(noisy, c["N"], profile=False)
    structure = {}
    for name in CURVES:
        scale = float(np.max(np.abs(getattr(clean, f"{name}_true"))))
        r0, r1 = fit0.residuals[name], fit1.residuals[name]
        runs0, mu0, p0 = runs_test(r0)
        runs1, mu1, p1 = runs_test(r1)
        structure[name] = {
            "max_abs_error_relative": float(np.max(np.abs(r0)) / scale) if scale > 0 else math.nan,
            "lag1_autocorrelation": lag1_autocorrelation(r0),
            "runs": runs0,
            "runs_expected": mu0,
            "runs_p": p0,
            "noisy_lag1_autocorrelation": lag1_autocorrelation(r1),
            "noisy_runs_p": p1,
        }
    covered = {}
    for name in ("F0", "M0", "a", "m", "k_x"):
        lo, hi = fit1.interval(name)
        covered[name] = bool(lo <= c[name] <= hi)
    theory = {k: c[k] for k in ("F0", "M0", "a", "m", "k_x")}
    return BiasReport(theory=theory, noise_free=fit0, noisy=fit1, structure=structure, covered=covered)
