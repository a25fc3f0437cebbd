"""A load-transfer extension of the friction model, identified from the FE's own pressure maps.

The rig runs show that the static map's rigid-slip integrals miss mostly the
pressure redistribution under traction. This module adds the simplest law of
it, the ``load_transfer`` cause of the diagnosis: the centre of pressure
shifts with the friction force per load,

    dx = h_x Fx / N,    dy = h_y Fy / N,

with an effective height (h_x, h_y) (m) and the pressure shape otherwise the
static one. Everything here works on values; the rig study
(``scripts/rig_study.py``) reads the runs and calls it.

- ``identify_shift(shifts, forces)``: (h_x, h_y) by least squares through the
  origin, each axis on its own, with Student-t intervals (``ShiftLaw``). The
  data are the runs' own maps (the centre-of-pressure shift of each run's map
  against the static map, both in the static patch frame) and the run's
  friction force per load: the study uses the integral of the export's shear
  traction, not the solver's reactions the prediction is checked against.
- ``shifted_resultants(quad, vx, vy, wz, dx=, dy=)``: the exact Coulomb
  integrals over the static map moved rigidly by (dx, dy). No new quadrature
  is needed: with sigma'(p) = sigma(p - d), the slip at p = q + d is that of
  the kinematics (vx - wz dy, vy + wz dx, wz) at q, so the force is the static
  map's force at those kinematics and Mz about the origin adds d x F. It is
  exact to the static map's quadrature and equals the static integrals at d = 0.
- ``predict_shifted(quad, vx, vy, wz, law=)``: the fixed point d = h F(d) / N
  (the shift depends on the force, which depends on the shift) by plain
  iteration; it contracts when |h| |dF/dd| / N < 1, i.e. when h is small
  against the patch size, and raises ``FitError`` when it does not converge.
- ``cross_validate(...)``: leave-one-group-out: h identified on the other
  groups' maps, the held-out runs' forces predicted with it.

scipy gives the t quantile; the regressions are two one-parameter least
squares written out because their closed forms are one line each.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError, FitError
from ..friction.exact import Resultants, friction_resultants
from ..friction.law import FrictionLaw
from ..friction.quadrature import PressureQuadrature

#: Confidence level of the intervals on (h_x, h_y).
LEVEL = 0.95


@dataclass(frozen=True)
class ShiftLaw:
    """dx = h_x Fx / N, dy = h_y Fy / N (m), identified from ``n`` runs' maps.

    ``interval_x``, ``interval_y``: the `LEVEL` Student-t intervals of h_x, h_y
    (m); ``se_x``, ``se_y`` their standard errors; ``residual_x``, ``residual_y``:
    RMS of the shift left unexplained (m); ``scatter_x``, ``scatter_y``: RMS of
    the shift itself (m), so 1 - (residual / scatter)^2 is the share explained.
    """

    h_x: float
    h_y: float
    se_x: float
    se_y: float
    interval_x: tuple[float, float]
    interval_y: tuple[float, float]
    residual_x: float
    residual_y: float
    scatter_x: float
    scatter_y: float
    n: int
    level: float = LEVEL

    def to_dict(self) -> dict:
        return {
            "h_x": self.h_x,
            "h_y": self.h_y,
            "se_x": self.se_x,
            "se_y": self.se_y,
            "interval_x": list(self.interval_x),
            "interval_y": list(self.interval_y),
            "residual_x": self.residual_x,
            "residual_y": self.residual_y,
            "scatter_x": self.scatter_x,
            "scatter_y": self.scatter_y,
            "n": self.n,
            "level": self.level,
        }


#: Force per load below which a run has no force along an axis: the solver's rounding of a
#: force that is zero by symmetry (a pure spin's Fx/N, a longitudinal slide's Fy/N: 1e-16).
NO_FORCE = 1e-6


def _through_origin(
    y: np.ndarray, x: np.ndarray, level: float, axis: str
) -> tuple[float, float, tuple, float]:
    """Slope of y = h x (least squares), its standard error, interval and residual RMS;
    ``axis`` (x or y) names the component in the error when no run has a force along it."""
    from scipy import stats

    largest = float(np.max(np.abs(x))) if x.size else 0.0
    if not largest > NO_FORCE:
        raise FitError(
            f"identify_shift: no run has a force along {axis} (largest |F{axis}/N| {largest:.2g}); "
            f"h_{axis} cannot be identified"
        )
    sxx = float(x @ x)
    h = float(x @ y) / sxx
    res = y - h * x
    dof = y.size - 1
    s2 = float(res @ res) / dof
    se = float(np.sqrt(s2 / sxx))
    t = float(stats.t.ppf(0.5 + level / 2.0, dof))
    return h, se, (h - t * se, h + t * se), float(np.sqrt(np.mean(res**2)))


def identify_shift(shifts, forces, *, level: float = LEVEL) -> ShiftLaw:
    """The load-transfer law from runs' centre-of-pressure shifts and forces per load.

    Parameters
    ----------
    shifts : array_like, shape (n, 2)
        Each run's centre-of-pressure shift (dx, dy) against the static map (m).
    forces : array_like, shape (n, 2)
        Each run's friction force per load (Fx / N, Fy / N) on the tire.
    level : float
        Confidence level of the intervals (default `LEVEL`).

    Returns
    -------
    ShiftLaw
    """
    d = np.asarray(shifts, float)
    g = np.asarray(forces, float)
    if d.ndim != 2 or d.shape[1] != 2 or g.shape != d.shape:
        raise ArgumentError(
            f"identify_shift: shifts and forces must both be (n, 2), got {d.shape} and {g.shape}"
        )
    if d.shape[0] < 3:
        raise ArgumentError(f"identify_shift: need at least 3 runs, got {d.shape[0]}")
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(g))):
        raise ArgumentError("identify_shift: shifts and forces must be finite")
    if not 0.0 < level < 1.0:
        raise ArgumentError(f"identify_shift: level must be in (0, 1), got {level}")
    hx, sx, ix, rx = _through_origin(d[:, 0], g[:, 0], level, "x")
    hy, sy, iy, ry = _through_origin(d[:, 1], g[:, 1], level, "y")
    return ShiftLaw(
        h_x=hx,
        h_y=hy,
        se_x=sx,
        se_y=sy,
        interval_x=ix,
        interval_y=iy,
        residual_x=rx,
        residual_y=ry,
        scatter_x=float(np.sqrt(np.mean(d[:, 0] ** 2))),
        scatter_y=float(np.sqrt(np.mean(d[:, 1] ** 2))),
        n=int(d.shape[0]),
        level=level,
    )


def shifted_resultants(
    quad: PressureQuadrature, vx, vy, wz, *, dx, dy, law: FrictionLaw | None = None
) -> Resultants:
    """Exact Coulomb resultants over the map ``quad`` moved rigidly by (dx, dy) (m); Mz about the origin."""
    vx, vy, wz, dx, dy = (np.asarray(a, float) for a in np.broadcast_arrays(vx, vy, wz, dx, dy))
    base = friction_resultants(quad, vx - wz * dy, vy + wz * dx, wz, law)
    return Resultants(Fx=base.Fx, Fy=base.Fy, Mz=base.Mz + dx * base.Fy - dy * base.Fx)


@dataclass(frozen=True)
class ShiftedPrediction:
    """Resultants over the static map shifted by the law, at the fixed point.

    ``resultants``: Fx, Fy (N), Mz (N m) at the static map's load; ``dx``, ``dy``:
    the converged shifts (m); ``iterations``: iterations taken; ``change``: the
    last iteration's largest shift change (m).
    """

    resultants: Resultants
    dx: np.ndarray
    dy: np.ndarray
    iterations: int
    change: float

    def __post_init__(self) -> None:
        for name in ("dx", "dy"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def to_dict(self) -> dict:
        return {
            "resultants": self.resultants.to_dict(),
            "dx": self.dx.tolist(),
            "dy": self.dy.tolist(),
            "iterations": self.iterations,
            "change": self.change,
        }


def predict_shifted(
    quad: PressureQuadrature,
    vx,
    vy,
    wz,
    *,
    law: ShiftLaw,
    friction: FrictionLaw | None = None,
    tol: float = 1e-12,
    max_iter: int = 100,
) -> ShiftedPrediction:
    """Solve d = h F(d) / N by iteration from d = 0 (module docstring); ``tol`` in m."""
    if not isinstance(law, ShiftLaw):
        raise ArgumentError(f"law must be a ShiftLaw, got {type(law).__name__}")
    n_load = float(np.sum(quad.sigma * quad.dA))
    if not n_load > 0.0:
        raise ArgumentError("predict_shifted: the map carries no load")
    vx, vy, wz = (np.atleast_1d(np.asarray(a, float)) for a in np.broadcast_arrays(vx, vy, wz))
    dx, dy = np.zeros_like(vx), np.zeros_like(vx)
    change = np.inf
    for it in range(1, max_iter + 1):
        res = shifted_resultants(quad, vx, vy, wz, dx=dx, dy=dy, law=friction)
        nx, ny = law.h_x * res.Fx / n_load, law.h_y * res.Fy / n_load
        change = float(max(np.max(np.abs(nx - dx)), np.max(np.abs(ny - dy))))
        dx, dy = nx, ny
        if change <= tol:
            res = shifted_resultants(quad, vx, vy, wz, dx=dx, dy=dy, law=friction)
            return ShiftedPrediction(resultants=res, dx=dx, dy=dy, iterations=it, change=change)
    raise FitError(
        f"predict_shifted: no fixed point after {max_iter} iterations (last change {change:.3g} m)"
    )


@dataclass(frozen=True)
class CrossValidation:
    """Leave-one-group-out predictions: ``Fx``, ``Fy``, ``Mz`` per run at the static
    load, and the ``laws`` identified without each group (``groups`` in order)."""

    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray
    groups: tuple[str, ...]
    laws: tuple[ShiftLaw, ...]

    def __post_init__(self) -> None:
        for name in ("Fx", "Fy", "Mz"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def to_dict(self) -> dict:
        return {
            "Fx": self.Fx.tolist(),
            "Fy": self.Fy.tolist(),
            "Mz": self.Mz.tolist(),
            "groups": list(self.groups),
            "laws": [law.to_dict() for law in self.laws],
        }


def cross_validate(
    quad: PressureQuadrature,
    vx,
    vy,
    wz,
    *,
    shifts,
    forces,
    groups,
    friction: FrictionLaw | None = None,
) -> CrossValidation:
    """Each group's runs predicted with the law identified on the other groups' maps.

    ``shifts``, ``forces``: (n, 2) as in `identify_shift`; ``groups``: n labels
    (e.g. the sliding direction); vx, vy, wz: the n runs' kinematics.
    """
    labels = np.asarray(groups, dtype=object)
    vx, vy, wz = (np.atleast_1d(np.asarray(a, float)) for a in (vx, vy, wz))
    d, g = np.asarray(shifts, float), np.asarray(forces, float)
    if not (labels.size == vx.size == vy.size == wz.size == d.shape[0] == g.shape[0]):
        raise ArgumentError("cross_validate: groups, kinematics, shifts and forces must have one row per run")
    order = tuple(dict.fromkeys(str(x) for x in labels))
    if len(order) < 2:
        raise ArgumentError("cross_validate: need at least two groups")
    out = np.zeros((vx.size, 3))
    laws = []
    for name in order:
        held = np.array([str(x) == name for x in labels])
        if np.count_nonzero(~held) < 3:
            raise ArgumentError(
                f"cross_validate: holding out group {name!r} leaves {np.count_nonzero(~held)} run(s) "
                "to identify the law from; need at least 3"
            )
        try:
            law = identify_shift(d[~held], g[~held])
        except FitError as exc:
            raise FitError(f"cross_validate: holding out group {name!r}: {exc}") from None
        pred = predict_shifted(quad, vx[held], vy[held], wz[held], law=law, friction=friction)
        out[held] = np.column_stack([pred.resultants.Fx, pred.resultants.Fy, pred.resultants.Mz])
        laws.append(law)
    return CrossValidation(Fx=out[:, 0], Fy=out[:, 1], Mz=out[:, 2], groups=order, laws=tuple(laws))
