"""Errors of friction models over the whole kinematic space (direction × ε, both spins).

Under Coulomb's law the resultants depend only on the direction of
(v_x, v_y, ω_z R): a point of a sphere. This module lays a grid on it,

* β ∈ [0°, 180°]: the sliding direction, v̂ = (cos β, sin β) (β + 180° with
  spin ω_z is −(β, −ω_z), so half a turn and both spin signs cover the sphere);
* t ∈ [0, 1], ε = tan(πt/2) = |v|/(|ω_z| R): t = 0 is pure spin, t = 1 pure
  sliding (ε = ∞); t is uniform on the sphere's meridians, so the grid is not
  crowded at either end;
* ω_z > 0 and ω_z < 0,

and measures, at each (β, t), the larger over the two spin signs of
|ΔF|/F0 (Euclidean norm of the force difference) and |ΔM_z|/M0, for any number
of models against the exact integrals. `ErrorMap` holds the result;
`fepost.figures.errormap.plot_error_map` draws it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError
from .exact import friction_resultants
from .law import FrictionLaw
from .quadrature import PressureQuadrature

Predictor = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]

#: Default grid: 37 directions (5° steps) × 65 meridian nodes (uniform in t).
N_BETA = 37
N_T = 65


def kinematic_grid(n_beta: int = N_BETA, n_t: int = N_T, R: float = 1.0):
    """β (deg, (n_beta,)), t ((n_t,)) and kinematics (v_x, v_y, ω_z), each (2, n_beta, n_t):
    index 0 spins positive, 1 negative; |v|² + (ω_z R)² = 1 (m/s)²."""
    for name, value, least in (("n_beta", n_beta, 2), ("n_t", n_t, 2)):
        if isinstance(value, bool) or int(value) != value or value < least:
            raise ArgumentError(f"{name} must be an integer >= {least}, got {value!r}")
    if not (np.isfinite(R) and R > 0):
        raise ArgumentError(f"R must be a positive finite radius in m, got {R!r}")
    beta = np.linspace(0.0, 180.0, int(n_beta))
    t = np.linspace(0.0, 1.0, int(n_t))
    b, tt = np.meshgrid(np.radians(beta), t, indexing="ij")
    speed = np.sin(0.5 * np.pi * tt)
    u = np.cos(0.5 * np.pi * tt)
    u = np.where(tt == 1.0, 0.0, u)  # exactly pure sliding at t = 1
    vx = np.stack([speed * np.cos(b)] * 2)
    vy = np.stack([speed * np.sin(b)] * 2)
    wz = np.stack([u / R, -u / R])
    return beta, t, (vx, vy, wz)


@dataclass(frozen=True)
class ErrorMap:
    """Errors of named models over direction × t (see the module docstring).

    ``beta`` (deg), ``t`` (ε = tan(πt/2)); ``force[name]`` and ``torque[name]``,
    arrays (n_beta, n_t): |ΔF|/F0 and |ΔM_z|/M0, the larger of the two spin signs;
    ``F0`` (N), ``M0`` (N·m), ``R`` (m) the scales; ``source`` the map.
    """

    beta: np.ndarray
    t: np.ndarray
    force: Mapping[str, np.ndarray]
    torque: Mapping[str, np.ndarray]
    F0: float
    M0: float
    R: float
    source: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "beta", frozen(self.beta))
        object.__setattr__(self, "t", frozen(self.t))
        shape = (self.beta.size, self.t.size)
        for attr in ("force", "torque"):
            maps = {k: frozen(v) for k, v in getattr(self, attr).items()}
            for k, v in maps.items():
                if v.shape != shape:
                    raise ArgumentError(f"{attr}[{k!r}] must have shape {shape}, got {v.shape}")
            object.__setattr__(self, attr, MappingProxyType(maps))
        if set(self.force) != set(self.torque):
            raise ArgumentError("force and torque must name the same models")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.force)

    @property
    def eps(self) -> np.ndarray:
        """ε = tan(πt/2) (inf at t = 1)."""
        with np.errstate(over="ignore"):
            e = np.tan(0.5 * np.pi * self.t)
        return frozen(np.where(self.t >= 1.0, np.inf, e))

    def worst(self, name: str) -> dict[str, float]:
        """Largest force and torque errors of ``name`` and where (β in deg, ε)."""
        if name not in self.force:
            raise ArgumentError(f"name must be one of {', '.join(self.names)}, got {name!r}")
        out: dict[str, float] = {}
        eps = self.eps
        for attr in ("force", "torque"):
            a = getattr(self, attr)[name]
            i, j = np.unravel_index(int(np.argmax(a)), a.shape)
            out[attr] = float(a[i, j])
            out[f"{attr}_beta"] = float(self.beta[i])
            out[f"{attr}_eps"] = float(eps[j])
        return out

    def to_dict(self) -> dict:
        return {
            "beta_deg": self.beta.tolist(),
            "t": self.t.tolist(),
            "eps": [None if not np.isfinite(e) else float(e) for e in self.eps],
            "force": {k: v.tolist() for k, v in self.force.items()},
            "torque": {k: v.tolist() for k, v in self.torque.items()},
            "worst": {k: self.worst(k) for k in self.names},
            "F0": self.F0,
            "M0": self.M0,
            "R": self.R,
            "source": self.source,
            "definition": "max over both spin signs of |F_model - F_exact|/F0 and |Mz_model - Mz_exact|/M0",
        }


def error_map(
    quad: PressureQuadrature,
    models: Mapping[str, Predictor],
    *,
    law: FrictionLaw | None = None,
    F0: float,
    M0: float,
    R: float,
    n_beta: int = N_BETA,
    n_t: int = N_T,
) -> ErrorMap:
    """Errors of each model in ``models`` (name → callable (vx, vy, wz) → (Fx, Fy, Mz))
    against the exact integrals of ``quad`` under ``law`` (default Coulomb, f = 0.3).

    ``F0`` (N) and ``M0`` (N·m) scale the errors; ``R`` (m) sets ω_z = u/R.
    """
    if not isinstance(quad, PressureQuadrature):
        raise ArgumentError(f"quad must be a PressureQuadrature, got {type(quad).__name__}")
    if not models:
        raise ArgumentError("models must name at least one model")
    for name, value in (("F0", F0), ("M0", M0)):
        if not (np.isfinite(value) and value > 0):
            raise ArgumentError(f"{name} must be positive and finite, got {value!r}")
    beta, t, (vx, vy, wz) = kinematic_grid(n_beta, n_t, R)
    law = FrictionLaw() if law is None else law
    ex = friction_resultants(quad, vx, vy, wz, law)
    force, torque = {}, {}
    for name, model in models.items():
        fx, fy, mz = (np.asarray(a, float) for a in model(vx, vy, wz))
        force[name] = np.max(np.hypot(fx - ex.Fx, fy - ex.Fy), axis=0) / F0
        torque[name] = np.max(np.abs(mz - ex.Mz), axis=0) / M0
    return ErrorMap(beta, t, force, torque, float(F0), float(M0), float(R), quad.source)
