"""How far the paper's closed forms stray from the exact Coulomb integrals.

For sliding along x at v = υ·u with u = ω_z R (ω_z > 0), over a range of υ, the
exact resultants of a pressure map give the curves

    F∥/F0 = −F_x/F0,   M_C/M0 = −M_z/M0,   F⊥/(|k_x| M0/2R) = −sgn(k_x) F_y/(|k_x| M0/2R),

which the closed forms approximate by 1/√(1 + a/υ²), 1/√(1 + mυ²) and
1/√(1 + mυ²/4). `approximation_error` reports the largest and the RMS
absolute difference on that υ grid (in units of F0, M0 and |k_x| M0/2R), once with
the asymptotic a, m (`asymptotic_coefficients`)
and once with a fitted to the F∥ curve and m to the M_C curve by least squares.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .._arrays import frozen
from ..errors import ArgumentError, FitError
from ..friction_coefficient import DEFAULT_FRICTION
from .closed_form import (
    asymptotic_coefficients,
    f_parallel_ratio,
    f_perpendicular_ratio,
    torque_ratio,
)
from .exact import friction_resultants
from .law import FrictionLaw
from .quadrature import PressureQuadrature

#: |k_x| below this counts as no rolling shift (the F⊥ errors are then NaN).
K_X_ZERO = 1e-9

#: Default υ grid: 81 points, 1e-2 … 1e2, log-spaced.
DEFAULT_UPSILON = np.geomspace(1e-2, 1e2, 81)


@dataclass(frozen=True)
class CurveErrors:
    """Errors of the closed forms for one choice of a, m (dimensionless).

    ``max_*`` and ``rms_*`` are the largest and root-mean-square absolute
    differences on the υ grid, in units of F0 (parallel), M0 (torque) and
    |k_x| M0/2R (perpendicular; NaN when k_x = 0).
    """

    a: float
    m: float
    max_parallel: float
    rms_parallel: float
    max_torque: float
    rms_torque: float
    max_perpendicular: float
    rms_perpendicular: float

    def to_dict(self) -> dict:
        return {k: float(v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class ApproximationError:
    """The exact curves on the υ grid and the closed forms' errors against them.

    ``radius`` R (m), ``F0`` (N), ``M0`` (N·m), ``k_x`` (dimensionless) are the
    scales used; ``upsilon`` υ = v/u; ``parallel``, ``torque``, ``perpendicular``
    the exact normalised curves (see the module docstring).
    """

    radius: float
    F0: float
    M0: float
    k_x: float
    upsilon: np.ndarray
    parallel: np.ndarray
    torque: np.ndarray
    perpendicular: np.ndarray
    asymptotic: CurveErrors
    fitted: CurveErrors

    def __post_init__(self) -> None:
        for name in ("upsilon", "parallel", "torque", "perpendicular"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def to_dict(self) -> dict:
        return {
            "radius": self.radius,
            "F0": self.F0,
            "M0": self.M0,
            "k_x": self.k_x,
            "upsilon": self.upsilon.tolist(),
            "parallel": self.parallel.tolist(),
            "torque": self.torque.tolist(),
            "perpendicular": self.perpendicular.tolist(),
            "asymptotic": self.asymptotic.to_dict(),
            "fitted": self.fitted.to_dict(),
        }


def rolling_shift(quad: PressureQuadrature, radius: float) -> float:
    """k_x = R x_c/⟨x²⟩ of the map itself, about the origin (dimensionless, the moment form)."""
    n = quad.load
    xc = float(quad.sigma @ (quad.x * quad.dA)) / n
    x2 = float(quad.sigma @ (quad.x**2 * quad.dA)) / n
    return radius * xc / x2


def _errors(a, m, ups, par, tor, perp) -> CurveErrors:
    e_par = f_parallel_ratio(1.0 / ups, a) - par
    e_tor = torque_ratio(ups, m) - tor
    e_perp = f_perpendicular_ratio(ups, m) - perp

    def mx(e):
        return float(np.max(np.abs(e))) if np.all(np.isfinite(e)) else float("nan")

    def rms(e):
        return float(np.sqrt(np.mean(e**2))) if np.all(np.isfinite(e)) else float("nan")

    return CurveErrors(
        float(a), float(m), mx(e_par), rms(e_par), mx(e_tor), rms(e_tor), mx(e_perp), rms(e_perp)
    )


def _fit(model, start: float, data: np.ndarray, name: str) -> float:
    res = least_squares(lambda p: model(p[0]) - data, [start], bounds=(0.0, np.inf), x_scale=[start])
    if not res.success:
        raise FitError(f"fitting {name} to the exact curve failed: {res.message}")
    return float(res.x[0])


def approximation_error(
    quad: PressureQuadrature,
    f: float = DEFAULT_FRICTION,
    *,
    F0: float | None = None,
    M0: float | None = None,
    a: float | None = None,
    m: float | None = None,
    k_x: float | None = None,
    radius: float | None = None,
    upsilon=None,
) -> ApproximationError:
    """Errors of the closed forms against the exact integrals of ``quad`` (Coulomb, ``f``).

    Coefficients left as ``None`` come from the map: F0, M0, a, m from
    `asymptotic_coefficients`, k_x from
    `rolling_shift`, R from ``quad.radius``. ``upsilon``: υ = v/u grid
    (default `DEFAULT_UPSILON`).
    """
    ups = DEFAULT_UPSILON if upsilon is None else np.asarray(upsilon, float).ravel()
    if ups.size < 2 or not np.all(np.isfinite(ups)) or np.any(ups <= 0):
        raise ArgumentError(f"upsilon must hold at least 2 positive finite values, got {ups!r}")
    asym = asymptotic_coefficients(quad, f, radius=radius)
    R = asym.radius
    F0 = asym.F0 if F0 is None else float(F0)
    M0 = asym.M0 if M0 is None else float(M0)
    a = asym.a if a is None else float(a)
    m = asym.m if m is None else float(m)
    k_x = rolling_shift(quad, R) if k_x is None else float(k_x)
    for name, value in (("F0", F0), ("M0", M0), ("a", a), ("m", m)):
        if not (np.isfinite(value) and value > 0):
            raise ArgumentError(f"{name} must be positive and finite, got {value!r}")
    wz = 1.0 / R  # u = 1 m/s
    res = friction_resultants(quad, ups, np.zeros_like(ups), np.full_like(ups, wz), FrictionLaw(f=f))
    par = -res.Fx / F0
    tor = -res.Mz / M0
    scale = abs(k_x) * M0 / (2.0 * R)
    if abs(k_x) > K_X_ZERO:
        perp = -np.sign(k_x) * res.Fy / scale
    else:
        perp = np.full_like(ups, np.nan)
    a_fit = _fit(lambda p: f_parallel_ratio(1.0 / ups, p), a, par, "a")
    m_fit = _fit(lambda p: torque_ratio(ups, p), m, tor, "m")
    return ApproximationError(
        radius=R,
        F0=F0,
        M0=M0,
        k_x=k_x,
        upsilon=ups,
        parallel=par,
        torque=tor,
        perpendicular=perp,
        asymptotic=_errors(a, m, ups, par, tor, perp),
        fitted=_errors(a_fit, m_fit, ups, par, tor, perp),
    )
