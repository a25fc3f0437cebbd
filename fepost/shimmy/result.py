"""The shimmy study's result and its JSON (the "shimmy JSON" of the outside contract)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from .gear import Gear
from .linear import ParameterMap, StabilityMap
from .simulate import BranchPoint, TimeHistory

#: The model's name and reference (the ``model`` key).
MODEL = {
    "name": "strut torsion + lateral bending, rigid tire sliding with multi-component dry friction",
    "equations": (
        "I_psi psi'' = -k_psi psi - c_psi psi' + sum_j(-e Fy_j - d_j Fx_j + Mz_j); "
        "m_y y'' = -k_y y - c_y y' + sum_j(Fx_j sin psi + Fy_j cos psi); "
        "contact j slides at vx = V cos psi + y' sin psi - psi' d_j - (1 - kappa) V, "
        "vy = -V sin psi + y' cos psi - psi' e, spins at wz = psi'"
    ),
    "steady_motion": "straight rolling with longitudinal sliding kappa V (touchdown spin-up or held slip)",
    "reference": (
        "Klimov and Zhuravlev's rigid wheel with multi-component dry friction (V. Ph. Zhuravlev, "
        "D. M. Klimov, Theory of the shimmy phenomenon, Mechanics of Solids 45(3):324-330, 2010); "
        "gear as in the classical simple models (torsion with trail, lateral bending): docs/shimmy.md"
    ),
}


@dataclass(frozen=True)
class ModelStability:
    """One friction model's stability: the map over speed, the critical speeds and their interval."""

    name: str
    stability: StabilityMap
    critical_speed_ci95: tuple[float, float] | None
    ci_method: str
    contact: Mapping[str, Any] = field(default_factory=dict)
    trail_map: ParameterMap | None = None
    maps: Mapping[str, ParameterMap] = field(default_factory=dict)
    branch: tuple[BranchPoint, ...] = ()

    def to_dict(self) -> dict:
        s = self.stability
        return {
            "critical_speed": s.critical_speed,
            "critical_speed_ci95": None
            if self.critical_speed_ci95 is None
            else list(self.critical_speed_ci95),
            "critical_speed_ci95_method": self.ci_method,
            "frequency_hz": s.critical_frequency,
            "verdict": s.verdict,
            "summary": s.summary(),
            "boundaries": [b.to_dict() for b in s.boundaries],
            "unstable_ranges": [list(r) for r in s.unstable_ranges],
            "growth_rate_tolerance": s.tolerance,
            "contact": dict(self.contact),
            "stability": s.rows(),
            "trail_map": None if self.trail_map is None else self.trail_map.rows(),
            "parameter_maps": {k: m.rows() for k, m in self.maps.items() if k != "trail"},
            "limit_cycle_branch": [p.to_dict() for p in self.branch],
        }


@dataclass(frozen=True)
class Simulation:
    """A time history, the CSV file it is written to and the linear verdict at its speed."""

    history: TimeHistory
    csv: str
    linear_growth_rate: float

    @property
    def agrees(self) -> bool:
        """Whether the nonlinear verdict matches the sign of the linear growth rate."""
        return (self.history.verdict == "decays") == (self.linear_growth_rate < 0)

    def to_dict(self) -> dict:
        h = self.history
        return {
            "speed": h.speed,
            "friction_model": h.friction_model,
            "csv": self.csv,
            "verdict": h.verdict,
            "amplitude": h.amplitude,
            "final_amplitude": h.final_amplitude,
            "perturbation": h.perturbation,
            "linear_growth_rate": self.linear_growth_rate,
            "agrees_with_linear": self.agrees,
        }


@dataclass(frozen=True)
class ShimmyResult:
    """Everything the study found (`fepost.shimmy.study.shimmy_study`)."""

    gear: Gear
    models: tuple[ModelStability, ...]
    simulations: tuple[Simulation, ...]
    anchor: Mapping[str, Any]
    source: Mapping[str, Any]
    timings: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("anchor", "source", "timings"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    def model(self, name: str) -> ModelStability:
        for m in self.models:
            if m.name == name:
                return m
        raise KeyError(name)

    def to_dict(self) -> dict:
        return {
            "gear": self.gear.to_dict(),
            "model": dict(MODEL),
            "friction_models": {m.name: m.to_dict() for m in self.models},
            "simulations": [s.to_dict() for s in self.simulations],
            "anchor": dict(self.anchor),
            "source": dict(self.source),
            "timings_s": dict(self.timings),
        }
