"""The generalised friction model of an analysed FE map, as ``fepost coefficients`` shows it.

:func:`analysis_models` builds the model of the static map (and of the rolling
map, when the analysis has one) with the analysis's R and f, and measures on the
same check grid how far both the model and the paper's closed forms (with the
analysis's F0, M0, a, m, k_x) lie from the exact integrals. :class:`ModelSummary`
turns that into the lines printed beside the paper's coefficients and the
``model`` block of the coefficients JSON.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ArgumentError
from .build import build_model
from .closed_form import paper_model
from .law import FrictionLaw
from .model import GeneralisedModel
from .quadrature import PressureQuadrature

if TYPE_CHECKING:
    from ..analysis import Analysis

#: Where the model and its export format are explained.
DOCS = "docs/model.md"


def map_model(analysis: Analysis, rolling: bool = False, *, order="auto") -> GeneralisedModel:
    """The generalised model of the static (or rolling) map of ``analysis``, with its R and f.

    The rolling model is built on the rolling map in the static patch's frame
    (origin at the static centre of pressure). The model's ``accuracy`` also
    holds the paper's closed forms' errors (``compare_force``,
    ``compare_torque``; with k_x for the rolling map) on the same check grid.
    """
    from ..analysis import Analysis

    if not isinstance(analysis, Analysis):
        raise ArgumentError(f"analysis must be an Analysis, got {type(analysis).__name__}")
    c = analysis.coefficients
    pmap = analysis.rolling_map if rolling else analysis.static_map
    if pmap is None:
        raise ArgumentError("analysis has no rolling map (give one to analyse)")
    k_x = c.k_x if (rolling and c.k_x is not None) else 0.0
    return build_model(
        PressureQuadrature.from_polar(pmap),
        FrictionLaw(f=c.f),
        radius=c.R,
        order=order,
        compare=paper_model(c.F0, c.M0, c.a, c.m, k_x, c.R),
    )


def analysis_models(analysis: Analysis, *, order="auto") -> tuple[GeneralisedModel, GeneralisedModel | None]:
    """Generalised models of the static and (if any) rolling map of ``analysis`` (:func:`map_model`)."""
    static = map_model(analysis, order=order)
    rolling = map_model(analysis, True, order=order) if analysis.rolling_map is not None else None
    return static, rolling


@dataclass(frozen=True)
class ModelSummary:
    """The models of an analysis with what a user needs to choose between them."""

    static: GeneralisedModel
    rolling: GeneralisedModel | None
    circular: bool
    aspect: float
    paper: dict

    def recommendation(self, accuracy: Mapping[str, Any] | None = None) -> str:
        """Which model to use, in one sentence, from the patch shape and the measured errors
        (``accuracy``: errors measured on a denser grid, keys as the model's ``accuracy``)."""
        acc = self.static.accuracy if accuracy is None else accuracy
        paper = max(acc["compare_force"], acc["compare_torque"])
        model = max(acc["model_force"], acc["model_torque"])
        if not self.circular:
            return (
                f"the patch is not circular (aspect {self.aspect:.2f}): use the generalised model "
                f"(within {model:.1%} of the exact integrals; the paper's closed forms miss by up to "
                f"{paper:.0%}); its coefficients are exported by 'fepost predict --model-json'"
            )
        return (
            f"the patch is circular: the paper's coefficients apply, but its closed forms still miss the "
            f"exact integrals by up to {paper:.0%}; the generalised model keeps them and is within "
            f"{model:.1%}"
        )

    def lines(self) -> list[tuple[str, str]]:
        """(label, value) rows for the coefficients table."""
        m = self.static
        d = m.direction_coefficients(np.array([0.0, 0.5 * np.pi]))
        K, L = m.order
        acc = m.accuracy
        rows = [
            ("generalised model", f"dissipation potential, any patch shape ({DOCS})"),
            ("  a along x, y", f"{d['a'][0]:.6g}, {d['a'][1]:.6g}   (paper a = {self.paper['a']:.6g})"),
            ("  m along x, y", f"{d['m'][0]:.6g}, {d['m'][1]:.6g}   (paper m = {self.paper['m']:.6g})"),
            (
                "  kappa1, kappa2 along x",
                f"{d['kappa1'][0]:.4g}, {d['kappa2'][0]:.4g}   (1, 1 = ellipsoidal limit surface)",
            ),
            ("  Q^ (2nd moment / N R^2)", _mat(m.Q)),
            ("  S^ (R x 1/r moment / N)", _mat(m.S)),
            ("  correction", f"K = {K}, L = {L}: {(2 * K + 1) * L} numbers"),
            (
                "  max error (check grid)",
                f"generalised |dF|/F0 {acc['model_force']:.3f}, |dMz|/M0 {acc['model_torque']:.3f}; "
                f"paper's forms {acc['compare_force']:.3f}, {acc['compare_torque']:.3f}",
            ),
        ]
        if self.rolling is not None:
            r = self.rolling
            ra = r.accuracy
            rows += [
                (
                    "  rolling map: spin force g^",
                    f"({r.g[0]:.4g}, {r.g[1]:.4g}); CoP offset x^c = ({r.xc[0]:.4g}, {r.xc[1]:.4g})",
                ),
                (
                    "  rolling map: max error",
                    f"generalised {ra['model_force']:.3f}, {ra['model_torque']:.3f}; "
                    f"paper's forms (with k_x) {ra['compare_force']:.3f}, {ra['compare_torque']:.3f}",
                ),
            ]
        rows.append(("  use", self.recommendation()))
        return rows

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "static": self.static.to_dict(),
            "rolling": None if self.rolling is None else self.rolling.to_dict(),
            "direction_coefficients": {
                k: v.tolist()
                for k, v in self.static.direction_coefficients(np.array([0.0, 0.5 * np.pi])).items()
            },
            "direction_coefficients_beta_deg": [0.0, 90.0],
            "recommendation": self.recommendation(),
            "docs": DOCS,
        }
        return d


def _mat(a: np.ndarray) -> str:
    return f"[[{a[0, 0]:.4g}, {a[0, 1]:.4g}], [{a[1, 0]:.4g}, {a[1, 1]:.4g}]]"


def summarise(analysis: Analysis, *, order="auto") -> ModelSummary:
    """The :class:`ModelSummary` of ``analysis`` (builds the models: about a second)."""
    static, rolling = analysis_models(analysis, order=order)
    c = analysis.coefficients
    p = analysis.static_patch
    return ModelSummary(
        static=static,
        rolling=rolling,
        circular=bool(p.circular),
        aspect=float(p.aspect),
        paper={"a": c.a, "m": c.m},
    )


def analysis_error_map(analysis: Analysis, *, rolling: bool = False, n_beta: int = 37, n_t: int = 65):
    """The :class:`~fepost.friction.sphere.ErrorMap` of the paper's closed forms, the
    generalised base and the generalised model on the static (or rolling) map of
    ``analysis``, errors scaled by the analysis's F0 and M0 (the data of
    :func:`fepost.figures.errormap.plot_error_map`)."""
    from .sphere import error_map

    summary = analysis.model_summary
    model = summary.rolling if rolling else summary.static
    pmap = analysis.rolling_map if rolling else analysis.static_map
    if model is None or pmap is None:
        raise ArgumentError("analysis has no rolling map (give one to analyse)")
    c = analysis.coefficients
    k_x = c.k_x if (rolling and c.k_x is not None) else 0.0
    return error_map(
        PressureQuadrature.from_polar(pmap),
        {
            "paper": paper_model(c.F0, c.M0, c.a, c.m, k_x, c.R),
            "base": model.without_correction(),
            "model": model,
        },
        law=FrictionLaw(f=c.f),
        F0=c.F0,
        M0=c.M0,
        R=c.R,
        n_beta=n_beta,
        n_t=n_t,
    )
