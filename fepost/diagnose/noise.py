"""Noise models of the measured channels: constant, growing with |F|, or both.

Per channel c and test point i the measurement error is taken as Gaussian with
variance

    σ_ic² = a_c + b_c g_ic²,

where g_ic is the magnitude of a **reference prediction** of that channel
(dimensionless units of `Simulation.scales
<fepost.diagnose.simulation.Simulation.scales>`). The reference is fixed before
the candidates are fitted and is the same for all of them (see
`pipeline`), so every candidate is judged under one
variance family: their likelihoods stay comparable and nested, and the
variance does not depend on the mean parameters (the weighted least squares of
`fitting` then maximise the likelihood exactly).

Structures (``a``, ``b`` ≥ 0):

================  ==================================  ==========
structure         variance                            parameters
================  ==================================  ==========
``constant``      a  (b = 0)                          1
``proportional``  FLOOR² + b g²   (a = FLOOR²)        1
``combined``      a + b g²  (a ≥ FLOOR²)              2
================  ==================================  ==========

`NOISE_FLOOR` is a floor on every standard deviation: the model's own
numerical accuracy. Without it, a purely proportional model would trust a point
whose predicted force is zero (Fy of a straight slide along x) without limit.

**Which structure.** `select_structure` takes one channel's residuals
of the reference fit and picks the structure of lowest BIC = −2ℓ + k ln n (k
above, n points), ties going to the simpler (the order of the table). Constant
and proportional have one parameter each, so between them the likelihood
decides; the combined model must gain more than ln n in −2ℓ.

**Estimation.** For given residuals r the maximum-likelihood (a, b) solve the
score equations Σ w_i (r_i² − σ_i²)(1, g_i²) = 0 with w_i = 1/σ_i⁴: Fisher
scoring is a weighted regression of r² on (1, g²), iterated, with the bounds
enforced on the free parameters (`fit_channel`). For the robust pass the
squared residuals are replaced by Huber's bounded version σ_i² min(z², k²)/β
(z = r/σ, β = E[min(Z², k²)] for Z ~ N(0, 1), so that the estimate is unbiased
at the normal): the scale equation of Huber's "Proposal 2", whose influence is
bounded (a gross error counts as k noise SDs, however large it is); the first
scale is 1.4826 × MAD.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from .._arrays import frozen

STRUCTURES = ("constant", "proportional", "combined")
#: Variance parameters of each structure.
N_PARAMS = {"constant": 1, "proportional": 1, "combined": 2}
#: Smallest standard deviation of any channel (dimensionless: 1e-3 f₀N, f₀NR):
#: twice the fit grid's largest error against the generator's 48 × 96 grid
#: (tests/test_diagnose_causes.py), about its error against a 128 × 256 grid.
NOISE_FLOOR = 1e-3
#: Huber's tuning constant: 95 % efficiency at the normal.
HUBER_K = 1.345
#: E[ψ_k(Z)²] = E[min(Z², k²)] for Z ~ N(0, 1): the consistency constant of Huber's scale.
HUBER_BETA = float(
    (2.0 * ndtr(HUBER_K) - 1.0)
    - 2.0 * HUBER_K * np.exp(-0.5 * HUBER_K**2) / np.sqrt(2.0 * np.pi)
    + 2.0 * HUBER_K**2 * (1.0 - ndtr(HUBER_K))
)
#: Normal-consistent MAD.
MAD_FACTOR = 1.482602218505602

_ITER = 200
_RTOL = 1e-10


@dataclass(frozen=True)
class Noise:
    """Variance model of the three channels: ``structure`` per channel, ``a``, ``b`` (3,),
    and ``g`` (n, 3): the reference magnitudes of every row of the data."""

    structure: tuple[str, str, str]
    a: np.ndarray
    b: np.ndarray
    g: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "structure", tuple(self.structure))
        for name in ("a", "b", "g"):
            object.__setattr__(self, name, frozen(np.asarray(getattr(self, name), float)))

    @classmethod
    def start(cls, structure, g: np.ndarray) -> Noise:
        """Unfitted parameters (nan: estimated from the first residuals) of ``structure``
        (one name or three) for the reference magnitudes ``g``."""
        s = (structure,) * 3 if isinstance(structure, str) else tuple(structure)
        return cls(s, np.full(3, np.nan), np.full(3, np.nan), g)

    @property
    def fitted(self) -> bool:
        return bool(np.all(np.isfinite(self.a)) and np.all(np.isfinite(self.b)))

    @property
    def n_params(self) -> int:
        return sum(N_PARAMS[s] for s in self.structure)

    def variance(self, rows=None) -> np.ndarray:
        """σ² (n_rows, 3) of ``rows`` (default all)."""
        g = self.g if rows is None else self.g[rows]
        return self.a[None, :] + self.b[None, :] * g**2

    def sigma(self, rows=None) -> np.ndarray:
        """σ (n_rows, 3) of ``rows`` (default all)."""
        return np.sqrt(self.variance(rows))

    def refit(self, res: np.ndarray, rows, *, robust: bool = False) -> Noise:
        """The maximum-likelihood (or, ``robust``, Huber) parameters for residuals ``res`` of ``rows``."""
        g = self.g[rows]
        a, b = np.empty(3), np.empty(3)
        for c in range(3):
            a[c], b[c] = fit_channel(
                res[:, c], g[:, c], self.structure[c], start=(self.a[c], self.b[c]), robust=robust
            )
        return Noise(self.structure, a, b, self.g)

    def log_likelihood(self, res: np.ndarray, rows) -> np.ndarray:
        """Gaussian log-likelihood per channel (3,) of residuals ``res`` of ``rows`` (nats)."""
        s2 = self.variance(rows)
        return -0.5 * np.sum(np.log(2.0 * np.pi * s2) + res**2 / s2, axis=0)

    def to_dict(self) -> dict:
        from .measured import CHANNELS

        return {
            ch: {
                "model": self.structure[c],
                "s0": float(np.sqrt(self.a[c])),
                "s1": float(np.sqrt(self.b[c])),
                "variance": "s0^2 + (s1 |F_ref|)^2, scaled units",
            }
            for c, ch in enumerate(CHANNELS)
        }


def _channel_loglik(r, g, a, b) -> float:
    s2 = a + b * g**2
    return float(-0.5 * np.sum(np.log(2.0 * np.pi * s2) + r**2 / s2))


def _targets(r, s2, robust: bool) -> np.ndarray:
    """Squared residuals, or Huber's bounded version at the current variances."""
    if not robust:
        return r**2
    z2 = r * r / s2
    return s2 * np.minimum(z2, HUBER_K**2) / HUBER_BETA


def _scoring_step(t, g2, s2, structure: str, floor2: float) -> tuple[float, float]:
    """One Fisher-scoring step: weighted regression of ``t`` on (1, g²), weights 1/σ⁴, bounded."""
    w = 1.0 / s2**2
    if structure == "constant":
        return max(float(np.sum(w * t) / np.sum(w)), floor2), 0.0
    if structure == "proportional":
        den = float(np.sum(w * g2 * g2))
        b = float(np.sum(w * g2 * (t - floor2)) / den) if den > 0 else 0.0
        return floor2, max(b, 0.0)
    s0, s1, s2w = np.sum(w), np.sum(w * g2), np.sum(w * g2 * g2)
    t0, t1 = np.sum(w * t), np.sum(w * g2 * t)
    det = s0 * s2w - s1 * s1
    if det > 1e-12 * s0 * s2w:
        a = (s2w * t0 - s1 * t1) / det
        b = (s0 * t1 - s1 * t0) / det
        if a >= floor2 and b >= 0.0:
            return float(a), float(b)
    # on a bound: the better of (a = floor, b free) and (b = 0, a free)
    b1 = max(float((t1 - floor2 * s1) / s2w), 0.0) if s2w > 0 else 0.0
    a2 = max(float(t0 / s0), floor2)
    cand = [(floor2, b1), (a2, 0.0)]
    err = [float(np.sum(w * (t - a - b * g2) ** 2)) for a, b in cand]
    return cand[int(np.argmin(err))]


def fit_channel(
    r: np.ndarray,
    g: np.ndarray,
    structure: str,
    *,
    start: tuple[float, float] | None = None,
    robust: bool = False,
    floor: float = NOISE_FLOOR,
) -> tuple[float, float]:
    """(a, b) of one channel for residuals ``r`` and reference magnitudes ``g`` (module docstring)."""
    r = np.asarray(r, float)
    g2 = np.asarray(g, float) ** 2
    floor2 = floor * floor
    if structure not in N_PARAMS:
        raise ValueError(f"unknown noise structure {structure!r}")
    if start is None or not np.all(np.isfinite(start)):
        scale2 = (MAD_FACTOR * float(np.median(np.abs(r)))) ** 2 if robust else float(np.mean(r**2))
        scale2 = max(scale2, floor2)
        if structure == "constant":
            a, b = scale2, 0.0
        elif structure == "proportional":
            gm = float(np.mean(g2))
            a, b = floor2, (max(scale2 - floor2, 0.0) / gm if gm > 0 else 0.0)
        else:
            gm = float(np.mean(g2))
            a, b = max(0.5 * scale2, floor2), (0.5 * scale2 / gm if gm > 0 else 0.0)
    else:
        a, b = float(start[0]), float(start[1])
        a = floor2 if structure == "proportional" else max(a, floor2)
        b = 0.0 if structure == "constant" else max(b, 0.0)
    if not robust and structure == "constant":
        return max(float(np.mean(r**2)), floor2), 0.0
    ll = _channel_loglik(r, np.sqrt(g2), a, b) if not robust else 0.0
    for _ in range(_ITER):
        s2 = a + b * g2
        na, nb = _scoring_step(_targets(r, s2, robust), g2, s2, structure, floor2)
        if not robust:
            # Fisher scoring can overshoot far from the optimum: halve the step until ℓ rises.
            new = _channel_loglik(r, np.sqrt(g2), na, nb)
            for _half in range(30):
                if new >= ll - 1e-12 * abs(ll):
                    break
                na, nb = 0.5 * (a + na), 0.5 * (b + nb)
                new = _channel_loglik(r, np.sqrt(g2), na, nb)
            ll = new
        done = abs(na - a) <= _RTOL * max(a, floor2) and abs(nb - b) <= _RTOL * max(b, 1e-300)
        a, b = na, nb
        if done:
            break
    return a, b


def select_structure(r: np.ndarray, g: np.ndarray) -> tuple[str, dict]:
    """The structure of lowest BIC for one channel's residuals ``r`` (see the module docstring).

    Returns the name and a table {structure: {"bic", "log_likelihood", "s0", "s1"}}.
    """
    n = r.size
    table = {}
    for s in STRUCTURES:
        a, b = fit_channel(r, g, s)
        ll = _channel_loglik(r, g, a, b)
        table[s] = {
            "bic": -2.0 * ll + N_PARAMS[s] * np.log(n),
            "log_likelihood": ll,
            "s0": float(np.sqrt(a)),
            "s1": float(np.sqrt(b)),
        }
    best = min(STRUCTURES, key=lambda s: (table[s]["bic"], STRUCTURES.index(s)))
    return best, table
