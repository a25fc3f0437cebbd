"""The local friction law: Coulomb, optionally generalised.

At a tire point with contact pressure σ (Pa) sliding at w (m/s) relative to the
road, the traction on the tire (Pa) is

    τ = −μ σ (ŵ_x, α ŵ_y),    ŵ = w/|w| (0 where w = 0),

with the local coefficient (dimensionless)

    μ = f · max(0, 1 + c_p (σ/σ_ref − 1)) · max(0, 1 + c_v |w| / (1 m/s)).

``f`` is the friction coefficient along x at the reference pressure and at zero
sliding speed; ``pressure_coef`` c_p is the relative change of μ per relative
change of pressure about σ_ref; ``speed_coef`` c_v is the relative change of μ per
m/s of sliding speed; ``anisotropy`` α = f_y/f_x scales the lateral traction;
``pressure_ref`` σ_ref (Pa) defaults to the map's mean contact pressure N/area.
With c_p = c_v = 0 and α = 1 this is Coulomb's law: τ = −f σ ŵ.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ArgumentError
from ..options import DEFAULT_FRICTION, check_friction


def store_reals(obj, names: tuple[str, ...]) -> None:
    """Check that the fields ``names`` of the frozen dataclass ``obj`` are finite real
    numbers and store them as floats; `ArgumentError` naming the
    first that is not (a bool is not a number here)."""
    for name in names:
        value = getattr(obj, name)
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
            raise ArgumentError(f"{name} must be a real number, got {value!r}")
        if not np.isfinite(value):
            raise ArgumentError(f"{name} must be finite, got {value!r}")
        object.__setattr__(obj, name, float(value))


@dataclass(frozen=True)
class FrictionLaw:
    """Parameters of the local friction law (see the module docstring)."""

    f: float = DEFAULT_FRICTION
    pressure_coef: float = 0.0
    speed_coef: float = 0.0
    anisotropy: float = 1.0
    pressure_ref: float | None = None

    def __post_init__(self) -> None:
        store_reals(self, ("f", "pressure_coef", "speed_coef", "anisotropy"))
        check_friction(self.f, name="f")  # the one rule of fepost.options
        if self.anisotropy <= 0:
            raise ArgumentError(f"anisotropy must be > 0 (f_y/f_x), got {self.anisotropy!r}")
        ref = self.pressure_ref
        if ref is not None:
            if isinstance(ref, bool) or not isinstance(ref, (int, float, np.floating, np.integer)):
                raise ArgumentError(f"pressure_ref must be a pressure in Pa or None, got {ref!r}")
            if not (np.isfinite(ref) and ref > 0):
                raise ArgumentError(f"pressure_ref must be a positive finite pressure in Pa, got {ref!r}")
            object.__setattr__(self, "pressure_ref", float(ref))

    @property
    def depends_on_speed(self) -> bool:
        return self.speed_coef != 0.0

    def reference_pressure(self, mean_pressure: float) -> float:
        """σ_ref (Pa): ``pressure_ref`` if given, else ``mean_pressure``."""
        return self.pressure_ref if self.pressure_ref is not None else float(mean_pressure)

    def pressure_factor(self, sigma, sigma_ref: float) -> np.ndarray:
        """max(0, 1 + c_p (σ/σ_ref − 1)), dimensionless."""
        sigma = np.asarray(sigma, float)
        if self.pressure_coef == 0.0:
            return np.ones_like(sigma)
        if not sigma_ref > 0:
            raise ArgumentError(f"sigma_ref must be a positive pressure in Pa, got {sigma_ref!r}")
        return np.maximum(0.0, 1.0 + self.pressure_coef * (sigma / sigma_ref - 1.0))

    def speed_factor(self, speed) -> np.ndarray:
        """max(0, 1 + c_v |w| / (1 m/s)), dimensionless; ``speed`` = |w| in m/s."""
        speed = np.asarray(speed, float)
        if self.speed_coef == 0.0:
            return np.ones_like(speed)
        return np.maximum(0.0, 1.0 + self.speed_coef * speed)

    def coefficient(self, sigma, speed, sigma_ref: float) -> np.ndarray:
        """μ(σ, |w|) (dimensionless) for pressures σ (Pa) and sliding speeds |w| (m/s)."""
        return self.f * self.pressure_factor(sigma, sigma_ref) * self.speed_factor(speed)

    def to_dict(self) -> dict:
        return {
            "f": self.f,
            "pressure_coef": self.pressure_coef,
            "speed_coef": self.speed_coef,
            "anisotropy": self.anisotropy,
            "pressure_ref": self.pressure_ref,
        }
