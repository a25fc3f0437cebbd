"""Identification data: the three friction curves of Table 1, measured or synthetic.

`TestCurves` holds F∥ against ψ = u/v and M_C, F⊥ against υ = v/u
(u = ω_z R, v = |v|). `make_test_curves` makes them as the paper does
(its closed forms (1.8) plus noise of amplitude 0.2·max of each curve) or from
the exact Coulomb integrals over a pressure map (the ground truth);
`exact_curves` gives the noise-free exact curves.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError, DataError
from ..friction.closed_form import f_parallel_ratio, f_perpendicular_ratio, torque_ratio
from ..friction.exact import friction_resultants
from ..friction.law import FrictionLaw
from ..friction.quadrature import PressureQuadrature
from ..friction_coefficient import DEFAULT_FRICTION

#: Fitted parameters, in this order.
PARAMETERS = ("F0", "M0", "a", "m", "k_x")
#: The three curves, in this order: F∥ vs ψ, M_C vs υ, F⊥ vs υ.
CURVES = ("f_parallel", "torque", "f_perp")
#: Units of the curves and of the parameters.
CURVE_UNITS = {"f_parallel": "N", "torque": "N m", "f_perp": "N"}
PARAMETER_UNITS = {"F0": "N", "M0": "N m", "a": "1", "m": "1", "k_x": "1", "f": "1"}

#: Points per curve and the largest ψ (for F∥) and υ (for M_C, F⊥) by default.
DEFAULT_N_POINTS = 50
DEFAULT_SPAN = 5.0
#: The paper's "20 % measurement error": noise amplitude / max of each curve.
DEFAULT_AMPLITUDE = 0.2
NOISE_KINDS = ("uniform", "gaussian")


def _check_array(name: str, value, n: int | None = None) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"{name} must be an array of numbers, got {type(value).__name__}") from None
    if arr.ndim != 1:
        raise DataError(f"{name} must be one-dimensional, got shape {arr.shape}")
    if n is not None and arr.size != n:
        raise DataError(f"{name} must have {n} entries like its abscissa, got {arr.size}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise DataError(f"{name} must be finite, got {float(arr[bad[0]])!r} at index {int(bad[0])}")
    return frozen(arr)


@dataclass(frozen=True)
class TestCurves:
    """Friction curves for identification, measured or synthetic.

    ``psi`` (ψ = u/v) with ``f_parallel`` F∥ (N); ``upsilon`` (υ = v/u) with
    ``torque`` M_C (N·m) and ``f_perp`` F⊥ (N, signed: −F_y on the tire for
    v_x > 0, ω_z > 0, positive when the pressure is shifted forward). ``R`` (m) is
    the patch radius of u = ω_z R. Synthetic curves also carry the noise-free
    values (``*_true``), the coefficients they were made from (``truth``), their
    ``source`` (``"closed_form"`` or ``"exact"``) and a description of the ``noise``.
    Arrays are read-only; non-finite values raise `DataError`.
    """

    __test__ = False  # not a pytest test class

    psi: np.ndarray
    f_parallel: np.ndarray
    upsilon: np.ndarray
    torque: np.ndarray
    f_perp: np.ndarray
    R: float
    f_parallel_true: np.ndarray | None = None
    torque_true: np.ndarray | None = None
    f_perp_true: np.ndarray | None = None
    truth: Mapping[str, float] | None = None
    source: str = "data"
    noise: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        psi = _check_array("psi", self.psi)
        ups = _check_array("upsilon", self.upsilon)
        object.__setattr__(self, "psi", psi)
        object.__setattr__(self, "upsilon", ups)
        for name, n in (("f_parallel", psi.size), ("torque", ups.size), ("f_perp", ups.size)):
            object.__setattr__(self, name, _check_array(name, getattr(self, name), n))
            true = getattr(self, f"{name}_true")
            if true is not None:
                object.__setattr__(self, f"{name}_true", _check_array(f"{name}_true", true, n))
        if not (np.isfinite(self.R) and self.R > 0):
            raise DataError(f"R must be a positive finite radius in m, got {self.R!r}")
        object.__setattr__(self, "R", float(self.R))
        if self.truth is not None:
            object.__setattr__(self, "truth", MappingProxyType({k: float(v) for k, v in self.truth.items()}))
        object.__setattr__(self, "noise", MappingProxyType(dict(self.noise)))

    @property
    def n_points(self) -> int:
        """Total number of data points of the three curves."""
        return self.psi.size + 2 * self.upsilon.size

    def data(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(abscissa, values) of curve ``name`` (one of `CURVES`)."""
        if name not in CURVES:
            raise ArgumentError(f"name must be one of {', '.join(CURVES)}, got {name!r}")
        return (self.psi if name == "f_parallel" else self.upsilon), getattr(self, name)

    def to_dict(self) -> dict:
        d: dict[str, Any] = {
            "source": self.source,
            "R": self.R,
            "psi": self.psi.tolist(),
            "upsilon": self.upsilon.tolist(),
            "noise": dict(self.noise),
            "truth": dict(self.truth) if self.truth is not None else None,
        }
        for name in CURVES:
            d[name] = getattr(self, name).tolist()
            true = getattr(self, f"{name}_true")
            d[f"{name}_true"] = true.tolist() if true is not None else None
        return d


def abscissa(x) -> np.ndarray:
    """ψ or υ values for evaluating a fitted curve: finite numbers, any shape.

    Parameters
    ----------
    x : array_like
        The abscissae.

    Returns
    -------
    ndarray of float
        ``x`` as floats, same shape.

    Raises
    ------
    ArgumentError
        ``x`` is not numeric, or holds a NaN or an infinity (named with its index).
    """
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentError(f"x must be an array of numbers, got {type(x).__name__}") from None
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        value = float(arr.flat[bad[0]])
        raise ArgumentError(f"x must be finite, got {value!r} at index {int(bad[0])}")
    return arr


def coefficient_values(coefficients) -> dict[str, float]:
    """F0, M0, a, m, k_x, R, N from a Coefficients-like object or a mapping.

    Parameters
    ----------
    coefficients : Coefficients or mapping
        Anything with these attributes or keys (e.g. ``fepost.coefficients.Coefficients``).

    Returns
    -------
    dict of str to float
        The seven values, finite floats.

    Raises
    ------
    ArgumentError
        A value is missing (k_x: without a rolling map), not a number or not finite.
    """
    out = {}
    for key in ("F0", "M0", "a", "m", "k_x", "R", "N"):
        if isinstance(coefficients, Mapping):
            value = coefficients.get(key)
        else:
            value = getattr(coefficients, key, None)
        if value is None:
            hint = " (no rolling map: give k_x explicitly)" if key == "k_x" else ""
            raise ArgumentError(f"coefficients.{key} is missing{hint}")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ArgumentError(f"coefficients.{key} must be a number, got {value!r}") from None
        if not np.isfinite(value):
            raise ArgumentError(f"coefficients.{key} must be finite, got {value!r}")
        out[key] = value
    for key in ("F0", "M0", "a", "m", "R", "N"):
        if out[key] <= 0:
            raise ArgumentError(f"coefficients.{key} must be positive, got {out[key]!r}")
    return out


def rolling_model(quad: PressureQuadrature, k_x: float, R: float) -> PressureQuadrature:
    """The rolling map σ0(1 + k_x x/R) (first order in k_x) of a static map."""
    if not isinstance(quad, PressureQuadrature):
        raise ArgumentError(f"quad must be a PressureQuadrature, got {type(quad).__name__}")
    k, R = float(k_x), float(R)
    inner = quad.sigma_at

    def sigma_at(px, py):
        return np.asarray(inner(px, py), float) * (1.0 + k * np.asarray(px, float) / R)

    return PressureQuadrature(
        x=quad.x,
        y=quad.y,
        dA=quad.dA,
        sigma=quad.sigma * (1.0 + k * quad.x / R),
        domain=quad.domain,
        sigma_at=sigma_at,
        source=f"{quad.source} rolling(k_x={k:g})".strip(),
    )


def exact_curves(
    quad: PressureQuadrature,
    psi,
    upsilon,
    R: float,
    *,
    rolling_quad: PressureQuadrature | None = None,
    friction: float = DEFAULT_FRICTION,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """F∥(ψ), M_C(υ), F⊥(υ) (N, N·m, N) from the exact Coulomb integrals.

    F∥: sliding v_x = 1 m/s with ω_z = ψ·(1 m/s)/R, F∥ = −F_x (on ``quad``).
    M_C, F⊥: ω_z = (1 m/s)/R, v_x = υ·(1 m/s); M_C = −M_z on ``quad`` and
    F⊥ = −F_y on ``rolling_quad`` (the rolling map). Coulomb friction is rate
    independent, so only the ratios ψ, υ matter.
    """
    law = FrictionLaw(f=friction)
    psi = np.asarray(psi, float)
    ups = np.asarray(upsilon, float)
    par = friction_resultants(quad, 1.0, 0.0, psi / R, law)
    spin = friction_resultants(quad, ups, 0.0, 1.0 / R, law)
    roll = quad if rolling_quad is None else rolling_quad
    lat = spin if rolling_quad is None else friction_resultants(roll, ups, 0.0, 1.0 / R, law)
    return -np.asarray(par.Fx), -np.asarray(spin.Mz), -np.asarray(lat.Fy)


def make_test_curves(
    source: str,
    coefficients,
    *,
    quad: PressureQuadrature | None = None,
    rolling_quad: PressureQuadrature | None = None,
    n_points: int = DEFAULT_N_POINTS,
    span: float = DEFAULT_SPAN,
    noise: str = "uniform",
    amplitude: float = DEFAULT_AMPLITUDE,
    seed: int | None = None,
) -> TestCurves:
    """Synthetic identification data: the three curves plus seeded noise.

    ``source``: ``"closed_form"`` (the paper's procedure: the curves (1.8) with
    ``coefficients``) or ``"exact"`` (the exact integrals on ``quad``, the static
    map, and for F⊥ on ``rolling_quad``, or, when that is None, on the rolling
    model σ0(1 + k_x x/R) of ``quad``; f = F0/N).
    ``coefficients``: a `Coefficients` or a mapping with
    F0 (N), M0 (N·m), a, m, k_x (R-based, dimensionless), R (m), N (N).
    Grids: ψ and υ = ``n_points`` equally spaced values on [0, ``span``].
    ``noise``: ``"uniform"`` on [−A, A] (the paper's) or ``"gaussian"`` with the
    same variance, standard deviation A/√3; A = ``amplitude``·max|curve| per curve
    (0.2·max F∥, 0.2·max M_C, 0.2·max |F⊥|). ``amplitude = 0`` gives noise-free
    data. Noise from ``numpy.random.default_rng(seed)``, drawn F∥, M_C, F⊥ in turn.
    """
    if source not in ("closed_form", "exact"):
        raise ArgumentError(f"source must be 'closed_form' or 'exact', got {source!r}")
    if noise not in NOISE_KINDS:
        raise ArgumentError(f"noise must be one of {', '.join(NOISE_KINDS)}, got {noise!r}")
    if isinstance(n_points, bool) or int(n_points) != n_points or n_points < 2:
        raise ArgumentError(f"n_points must be an integer >= 2, got {n_points!r}")
    if not (np.isfinite(span) and span > 0):
        raise ArgumentError(f"span must be a positive finite ratio, got {span!r}")
    if not (np.isfinite(amplitude) and amplitude >= 0):
        raise ArgumentError(f"amplitude must be a finite fraction >= 0, got {amplitude!r}")
    c = coefficient_values(coefficients)
    grid = np.linspace(0.0, float(span), int(n_points))
    if source == "closed_form":
        fpar = c["F0"] * f_parallel_ratio(grid, c["a"])
        torque = c["M0"] * torque_ratio(grid, c["m"])
        fperp = c["k_x"] * c["M0"] / (2.0 * c["R"]) * f_perpendicular_ratio(grid, c["m"])
        rolling_source = None
    else:
        if quad is None:
            raise ArgumentError(
                "quad must be a PressureQuadrature of the static map for source='exact', got None"
            )
        roll = rolling_quad if rolling_quad is not None else rolling_model(quad, c["k_x"], c["R"])
        rolling_source = "rolling map" if rolling_quad is not None else "model sigma0(1 + k_x x/R)"
        fpar, torque, fperp = exact_curves(
            quad, grid, grid, c["R"], rolling_quad=roll, friction=c["F0"] / c["N"]
        )
    clean = TestCurves(
        psi=grid,
        f_parallel=fpar,
        upsilon=grid,
        torque=torque,
        f_perp=fperp,
        R=c["R"],
        f_parallel_true=fpar,
        torque_true=torque,
        f_perp_true=fperp,
        truth=c,
        source=source,
        noise={"f_perp_map": rolling_source} if rolling_source is not None else {},
    )
    return with_noise(clean, noise=noise, amplitude=amplitude, seed=seed)


def with_noise(
    curves: TestCurves,
    *,
    noise: str = "uniform",
    amplitude: float = DEFAULT_AMPLITUDE,
    seed: int | None = None,
) -> TestCurves:
    """``curves`` with fresh seeded noise added to their noise-free values (``*_true``).

    The noise of `make_test_curves` (which calls this): ``"uniform"`` on
    [−A, A] or ``"gaussian"`` with standard deviation A/√3, A = ``amplitude``·max|curve|,
    drawn F∥, M_C, F⊥ in turn from ``numpy.random.default_rng(seed)``. Lets a
    Monte-Carlo study integrate the exact curves once.
    """
    if not isinstance(curves, TestCurves):
        raise ArgumentError(f"curves must be TestCurves, got {type(curves).__name__}")
    if noise not in NOISE_KINDS:
        raise ArgumentError(f"noise must be one of {', '.join(NOISE_KINDS)}, got {noise!r}")
    if not (np.isfinite(amplitude) and amplitude >= 0):
        raise ArgumentError(f"amplitude must be a finite fraction >= 0, got {amplitude!r}")
    truths = {name: getattr(curves, f"{name}_true") for name in CURVES}
    if any(v is None for v in truths.values()):
        raise ArgumentError("curves must carry their noise-free values (*_true) to add noise to")
    rng = np.random.default_rng(seed)
    amps = {}
    noisy = {}
    for name, true in truths.items():
        A = amplitude * float(np.max(np.abs(true)))
        amps[name] = A
        if noise == "uniform":
            e = rng.uniform(-A, A, true.size)
        else:
            e = rng.normal(0.0, A / math.sqrt(3.0), true.size)
        noisy[name] = true + e
    description: dict[str, Any] = {
        "kind": noise,
        "fraction": float(amplitude),
        "amplitude": amps,
        "std": {k: v / math.sqrt(3.0) for k, v in amps.items()},
        "seed": seed,
        "rule": "uniform on [-A, A]" if noise == "uniform" else "normal, std A/sqrt(3)",
    }
    if "f_perp_map" in curves.noise:
        description["f_perp_map"] = curves.noise["f_perp_map"]
    return TestCurves(
        psi=curves.psi,
        f_parallel=noisy["f_parallel"],
        upsilon=curves.upsilon,
        torque=noisy["torque"],
        f_perp=noisy["f_perp"],
        R=curves.R,
        f_parallel_true=truths["f_parallel"],
        torque_true=truths["torque"],
        f_perp_true=truths["f_perp"],
        truth=curves.truth,
        source=curves.source,
        noise=description,
    )
