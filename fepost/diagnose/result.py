"""The diagnosis as an immutable result: cause, extension, gain, ranking, evidence."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._arrays import frozen
from .measured import MeasuredData
from .selection import Score


@dataclass(frozen=True)
class ParameterEstimate:
    """A fitted parameter: ``value`` and 95 % interval ``ci95`` in ``unit``."""

    name: str
    value: float
    ci95: tuple[float, float]
    unit: str
    description: str = ""

    def covers(self, truth: float) -> bool:
        return self.ci95[0] <= truth <= self.ci95[1]

    def to_dict(self) -> dict:
        return {
            "value": self.value,
            "ci95": [self.ci95[0], self.ci95[1]],
            "unit": self.unit,
            "description": self.description,
        }


@dataclass(frozen=True)
class Diagnosis:
    """What the simulation gets wrong, its most likely cause and the gain of fixing it.

    ``predictions`` hold (n, 3) arrays in SI (Fx, Fy in N, Mz in N·m):
    ``before`` (the simulation: exact integrals, nominal f), ``after`` (the named
    extension fitted to all points), ``after_heldout`` (each point predicted by the
    fit without its fold) and ``closed_form`` (the paper's formulas, THEORY.md §4).
    ``scales`` are the channel scales (f₀N, f₀N, f₀NR) that make RMSEs dimensionless.
    """

    cause: str
    parameters: dict
    gain: dict
    candidates: tuple[Score, ...]
    indistinguishable: tuple[str, ...]
    design_notes: tuple[str, ...]
    residuals: dict
    closed_form: dict
    simulation: dict
    data: MeasuredData
    predictions: dict
    scales: np.ndarray
    variables: dict
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "predictions", {k: frozen(v) for k, v in self.predictions.items()})
        object.__setattr__(self, "variables", {k: frozen(v) for k, v in self.variables.items()})
        object.__setattr__(self, "scales", frozen(self.scales))
        object.__setattr__(self, "candidates", tuple(self.candidates))

    @property
    def confident(self) -> bool:
        """False when other causes explain the data as well (see ``indistinguishable``)."""
        return not self.indistinguishable

    def score(self, name: str) -> Score:
        for s in self.candidates:
            if s.name == name:
                return s
        raise KeyError(name)

    def to_dict(self) -> dict:
        """The diagnosis JSON of INTERFACE.md, with the evidence under extra keys."""
        return {
            "cause": self.cause,
            "parameters": {k: p.to_dict() for k, p in self.parameters.items()},
            "gain": dict(self.gain),
            "candidates": [s.to_dict() for s in self.candidates],
            "criterion": "BIC",
            "confident": self.confident,
            "indistinguishable": list(self.indistinguishable),
            "design_notes": list(self.design_notes),
            "residuals": self.residuals,
            "closed_form": self.closed_form,
            "simulation": self.simulation,
            "scaling": {
                "Fx": "Fx / (f0 N)",
                "Fy": "Fy / (f0 N)",
                "Mz": "Mz / (f0 N R)",
                "scales_SI": [float(s) for s in self.scales],
                "note": "nominal f0 and the static map's N and R; RMSEs are over all three scaled channels",
            },
            "n_points": len(self.data),
            "measured_source": self.data.source,
            **self.info,
        }

    def summary(self) -> str:
        """A short human-readable account (the ``summary.txt`` of ``fepost diagnose``)."""
        g = self.gain
        lines = [f"cause: {self.cause}"]
        best = self.candidates[0]
        if self.cause == "none":
            lines.append("no extension earns its parameters: the misfit is within the noise")
        else:
            lines.append(f"  {best.fit.name}: {self._describe()}")
            for name, p in self.parameters.items():
                lines.append(
                    f"  {name} = {p.value:.6g} {p.unit}  (95 % CI {p.ci95[0]:.6g} .. {p.ci95[1]:.6g})"
                )
        lines.append(
            f"held-out RMSE (scaled, {self.info.get('folds', 5)}-fold): before {g['rmse_before']:.4g}, "
            f"after {g['rmse_after']:.4g}; delta BIC vs the simulation {g['delta_bic']:.1f}"
        )
        if self.indistinguishable:
            lines.append(
                "indistinguishable on these data (delta BIC < 10, both pass the nesting tests): "
                + ", ".join(self.indistinguishable)
            )
        for note in self.design_notes:
            lines.append(f"design: {note}")
        for key, title in (("before", "simulation"), ("after", "extended model")):
            parts = []
            for ch, st in self.residuals[key].items():
                parts.append(
                    f"{ch} {st['verdict']} (rmse {st['rmse']:.3g}, worst: {st['strongest']}, "
                    f"p={st['p_adjusted']:.2g})"
                )
            lines.append(f"residuals of the {title}: " + "; ".join(parts))
        cf = self.closed_form
        lines.append(
            f"paper closed forms: RMSE vs data {cf['rmse_vs_data']:.4g}, vs exact integrals "
            f"{cf['rmse_vs_exact']:.4g} (exact vs data {cf['exact_rmse_vs_data']:.4g}), scaled"
        )
        lines.append("candidates (BIC, lower is better; admissible first):")
        for s in self.candidates:
            mark = "*" if s.admissible else " "
            lines.append(
                f" {mark} {s.name:<29} BIC {s.fit.bic:11.1f}  dBIC {s.delta_bic:9.1f}  "
                f"cv-rmse {s.cv.rmse:.4g}"
            )
        return "\n".join(lines) + "\n"

    def _describe(self) -> str:
        return {
            "friction_level": "one friction coefficient other than the nominal one",
            "pressure_dependent_friction": "the local friction coefficient depends on the contact pressure",
            "speed_dependent_friction": "the local friction coefficient depends on the sliding speed",
            "elliptic_patch": "the real patch is elongated relative to the simulated one",
            "anisotropic_friction": "friction differs along x and along y",
            "pressure_shift": "the real centre of pressure lies elsewhere",
            "sensor_offset": "constant offsets in the measured channels",
        }.get(self.cause, "")
