"""The curve forms fitted to the test curves, with their gradients in the parameters.

Both take the parameters (F0 (N), M0 (N·m), a, m, k_x) in the order of
`PARAMETERS` and return a curve and its gradient:

* `curve_model`: the paper's closed forms (1.8), analytic gradient;
* `GeneralisedCurves`: the generalised friction model
  (`fepost.friction.model`) restricted to the test kinematics (sliding
  along x), with F0, M0, a = a(0°), m = m(0°) and k_x substituted into the model
  built from the FE maps; its shape beyond those five numbers (the off-axis
  tensors and the fitted correction) stays the map's. Gradient by central
  differences.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ArgumentError
from ..friction.closed_form import f_parallel_ratio, f_perpendicular_ratio, torque_ratio
from ..friction.model import GeneralisedModel
from .curves import CURVES, PARAMETERS


def curve_model(name: str, x, values, R: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form curve ``name`` at ``x`` and its gradient in the parameters.

    ``values``: (F0 (N), M0 (N·m), a, m, k_x), the order of `PARAMETERS`;
    ``x``: ψ for ``"f_parallel"``, υ for ``"torque"`` and ``"f_perp"``; ``R`` (m).
    Returns y (N, N·m or N; shape of ``x``) and ∂y/∂(F0, M0, a, m, k_x) (shape of
    ``x`` + (5,)), analytic:

        F∥ = F0 g1,  g1 = (1 + a ψ²)^(-1/2)          ∂/∂a = −½ F0 ψ² g1³
        M_C = M0 g2, g2 = (1 + m υ²)^(-1/2)          ∂/∂m = −½ M0 υ² g2³
        F⊥ = k_x M0/(2R) g3, g3 = (1 + m υ²/4)^(-1/2)  ∂/∂m = −⅛ k_x M0/(2R) υ² g3³
    """
    x = np.asarray(x, float)
    F0, M0, a, m, kx = (float(v) for v in values)
    grad = np.zeros(x.shape + (len(PARAMETERS),))
    x2 = x * x
    if name == "f_parallel":
        g = f_parallel_ratio(x, a)
        grad[..., 0] = g
        grad[..., 2] = -0.5 * F0 * x2 * g**3
        return F0 * g, grad
    if name == "torque":
        g = torque_ratio(x, m)
        grad[..., 1] = g
        grad[..., 3] = -0.5 * M0 * x2 * g**3
        return M0 * g, grad
    if name == "f_perp":
        c = 1.0 / (2.0 * R)
        g = f_perpendicular_ratio(x, m)
        grad[..., 1] = kx * c * g
        grad[..., 3] = -0.125 * kx * M0 * c * x2 * g**3
        grad[..., 4] = M0 * c * g
        return kx * M0 * c * g, grad
    raise ArgumentError(f"name must be one of {', '.join(CURVES)}, got {name!r}")


class PaperCurves:
    """The paper's closed forms as a curve form.

    A curve form has ``form(name, x, values, R) -> (y, grad)`` and
    ``form.values(name, x, values, R) -> y`` (the curve alone, for the fit's
    residuals and the fitted curves).
    """

    name = "paper"

    def __call__(self, name: str, x, values, R: float) -> tuple[np.ndarray, np.ndarray]:
        return curve_model(name, x, values, R)

    def values(self, name: str, x, values, R: float) -> np.ndarray:
        return curve_model(name, x, values, R)[0]

    def __repr__(self) -> str:
        return "PaperCurves()"


#: The default form of `fit_table1`.
PAPER = PaperCurves()

#: Relative step of the central differences of `GeneralisedCurves`
#: (the model is smooth in its coefficients; truncation ~h², round-off ~eps/h).
FD_STEP = 1e-6


@dataclass(frozen=True)
class GeneralisedCurves:
    """The generalised model as a curve form (module docstring).

    ``static``: the model of the static map (F∥ and M_C curves); ``rolling``: the
    model of the rolling map (F⊥ curve), whose asymmetric part (ĝ, x̂) belongs to
    ``k_ref``, the rolling shift that map has; F⊥ scales it by k_x/k_ref.
    """

    static: GeneralisedModel
    rolling: GeneralisedModel
    k_ref: float
    name: str = "generalised"
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        for attr in ("static", "rolling"):
            if not isinstance(getattr(self, attr), GeneralisedModel):
                raise ArgumentError(
                    f"{attr} must be a GeneralisedModel, got {type(getattr(self, attr)).__name__}"
                )
        if not (np.isfinite(self.k_ref) and self.k_ref != 0.0):
            raise ArgumentError(f"k_ref must be a finite non-zero rolling shift, got {self.k_ref!r}")
        if self.rolling.R != self.static.R:
            raise ArgumentError(f"rolling.R ({self.rolling.R!r} m) must equal static.R ({self.static.R!r} m)")

    @property
    def R(self) -> float:
        return self.static.R

    def theory(self) -> dict[str, float]:
        """F0, M0, a, m along x (β = 0) and k_x of the FE maps: the values the fit should find."""
        d = self.static.direction_coefficients(0.0)
        return {
            "F0": self.static.F0,
            "M0": self.static.M0,
            "a": float(d["a"]),
            "m": float(d["m"]),
            "k_x": float(self.k_ref),
        }

    def models(self, values) -> tuple[GeneralisedModel, GeneralisedModel]:
        """The two models with (F0, M0, a, m, k_x) = ``values`` substituted (module docstring).

        The last few are kept (a fit asks for the three curves of one parameter
        vector in a row)."""
        key = np.asarray(values, float).tobytes()
        hit = self._cache.get(key)
        if hit is None:
            hit = self._substitute(values)
            if len(self._cache) >= 32:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = hit
        return hit

    def _substitute(self, values) -> tuple[GeneralisedModel, GeneralisedModel]:
        F0, M0, a, m, kx = (float(v) for v in values)
        if not (F0 > 0 and M0 > 0 and a > 0 and m > 0):
            raise ArgumentError(f"F0, M0, a, m must be positive, got {values!r}")
        s0 = self.static
        u0 = M0 / (F0 * s0.R)
        lam_s = (1.0 / math.sqrt(a)) / s0.S[0, 0]
        lam_q = (u0 / math.sqrt(m)) / s0.Q[0, 0]
        static = s0.substituted(F0=F0, M0=M0, S=s0.S * lam_s, Q=s0.Q * lam_q)
        r0 = self.rolling
        k = kx / self.k_ref
        rolling = r0.substituted(
            F0=r0.F0 * F0 / s0.F0,
            M0=r0.M0 * M0 / s0.M0,
            S=r0.S * lam_s,
            Q=r0.Q * lam_q,
            g=r0.g * k,
            xc=r0.xc * k,
        )
        return static, rolling

    def values(self, name: str, x, values, R: float) -> np.ndarray:
        """Curve ``name`` at ``x`` (the form's value alone)."""
        if not math.isclose(R, self.R, rel_tol=1e-9):
            raise ArgumentError(f"R must be the models' radius {self.R!r} m, got {R!r}")
        return self.values_of(name, x, values)

    def values_of(self, name: str, x, values) -> np.ndarray:
        """Curve ``name`` at ``x`` (ψ for F∥, υ otherwise) for parameters ``values``."""
        if name not in CURVES:
            raise ArgumentError(f"name must be one of {', '.join(CURVES)}, got {name!r}")
        static, rolling = self.models(values)
        x = np.asarray(x, float)
        R = self.R
        if name == "f_parallel":
            return -static(np.ones_like(x), 0.0, x / R)[0]
        if name == "torque":
            return -static(x, 0.0, np.full_like(x, 1.0 / R))[2]
        return -rolling(x, 0.0, np.full_like(x, 1.0 / R))[1]

    def __call__(self, name: str, x, values, R: float) -> tuple[np.ndarray, np.ndarray]:
        if not math.isclose(R, self.R, rel_tol=1e-9):
            raise ArgumentError(f"R must be the models' radius {self.R!r} m, got {R!r}")
        values = np.asarray(values, float)
        y = self.values_of(name, x, values)
        grad = np.empty(np.shape(y) + (len(PARAMETERS),))
        for j in range(len(PARAMETERS)):
            h = FD_STEP * max(abs(values[j]), 1e-3)
            up, dn = values.copy(), values.copy()
            up[j] += h
            dn[j] -= h
            grad[..., j] = (self.values_of(name, x, up) - self.values_of(name, x, dn)) / (2.0 * h)
        return y, grad

    def curves(self, x) -> dict[str, np.ndarray]:
        """The three curves at the FE maps' own values (`theory`), for Figures 4–6:
        F∥ (N) at ψ = ``x``, M_C (N·m) and F⊥ (N) at υ = ``x``."""
        th = self.theory()
        values = [th[p] for p in PARAMETERS]
        return {name: self.values_of(name, x, values) for name in CURVES}
