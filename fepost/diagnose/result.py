"""The diagnosis as an immutable result: cause(s), extension, gain, ranking, evidence."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._arrays import frozen
from .holds import Holds
from .measured import MeasuredData
from .selection import Score


@dataclass(frozen=True)
class ParameterEstimate:
    """A fitted parameter: ``value`` and 95 % interval ``ci95`` in ``unit``; ``cause`` it belongs to."""

    name: str
    value: float
    ci95: tuple[float, float]
    unit: str
    description: str = ""
    cause: str = ""

    def covers(self, truth: float) -> bool:
        return self.ci95[0] <= truth <= self.ci95[1]

    def to_dict(self) -> dict:
        return {
            "value": self.value,
            "ci95": [self.ci95[0], self.ci95[1]],
            "unit": self.unit,
            "description": self.description,
            "cause": self.cause,
        }


@dataclass(frozen=True)
class Diagnosis:
    """What the simulation gets wrong, its most likely cause and the gain of fixing it.

    ``predictions`` hold (n, 3) arrays in SI (Fx, Fy in N, Mz in N·m):
    ``before`` (the simulation: exact integrals, nominal f), ``after`` (the named
    extension fitted to all points), ``after_heldout`` (each point predicted by the
    fit without its fold) and ``closed_form`` (the paper's formulas, docs/theory.md).
    ``scales`` are the channel scales (f₀N, f₀N, f₀NR) that make RMSEs dimensionless.

    ``cause`` is the primary cause and ``causes`` every cause of the chosen model
    (primary first); ``parameters`` and ``gain`` are the chosen model's.
    ``outliers`` are 0-based data rows left out of every fit; ``sigma`` (n, 3)
    the noise SD of every row under the chosen noise model (scaled units);
    ``lack_of_fit`` the verdict of `lack_of_fit`;
    ``separation`` what the test programme cannot separate within the chosen model;
    ``holds`` the steady holds the data came from when they were a recording.
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
    causes: tuple[str, ...] = ()
    separation: tuple[str, ...] = ()
    outliers: tuple[int, ...] = ()
    lack_of_fit: dict = field(default_factory=dict)
    noise: dict = field(default_factory=dict)
    sigma: np.ndarray | None = None
    robust: dict = field(default_factory=dict)
    pairs: dict | None = None
    info: dict = field(default_factory=dict)
    holds: Holds | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "predictions", {k: frozen(v) for k, v in self.predictions.items()})
        object.__setattr__(self, "variables", {k: frozen(v) for k, v in self.variables.items()})
        object.__setattr__(self, "scales", frozen(self.scales))
        object.__setattr__(self, "candidates", tuple(self.candidates))
        object.__setattr__(self, "causes", tuple(self.causes) or (self.cause,))
        object.__setattr__(self, "outliers", tuple(int(i) for i in self.outliers))
        if self.sigma is not None:
            object.__setattr__(self, "sigma", frozen(self.sigma))

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
        """The diagnosis JSON (keys in docs/diagnose.md), with the evidence under extra keys."""
        lines = self.data.lines
        return {
            "cause": self.cause,
            "causes": list(self.causes),
            "parameters": {k: p.to_dict() for k, p in self.parameters.items()},
            "gain": dict(self.gain),
            "candidates": [s.to_dict() for s in self.candidates],
            "lack_of_fit": dict(self.lack_of_fit),
            "outliers": list(self.outliers),
            "outlier_lines": [int(lines[i]) for i in self.outliers] if lines is not None else [],
            "outlier_rule": dict(self.robust),
            "noise_model": dict(self.noise),
            "pairs": self.pairs,
            "separation": list(self.separation),
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
            **({"holds": self.holds.to_dict()} if self.holds is not None else {}),
            **self.info,
        }

    def summary(self) -> str:
        """A short human-readable account (the ``summary.txt`` of ``fepost diagnose``)."""
        from .summary import summary_text

        return summary_text(self)
