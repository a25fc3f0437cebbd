"""The generalised friction model of a pressure map, as ``fepost coefficients`` shows it.

Physics takes values, never the pipeline: every function here takes the polar
map (``fepost.polar.PolarMap``), the paper's coefficients of that map
(``fepost.coefficients.Coefficients``: R, F0, M0, a, m, k_x) and the friction
law (``fepost.friction.law.FrictionLaw``), whoever computed them.

`map_model` builds the model of one map with the coefficients' R and the law,
and measures on the same check grid how far both the model and the paper's
closed forms (with F0, M0, a, m, k_x) lie from the exact integrals.
`summarise` does it for the static map (and the rolling one, when given);
`ModelSummary` turns that into the lines printed beside the paper's
coefficients and the ``model`` block of the coefficients JSON.
`model_error_map` is the error of the closed forms and of a model over the
whole kinematic sphere (the data of the report's error maps).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..coefficients import Coefficients
from ..errors import ArgumentError
from ..polar import PolarMap
from .build import build_model
from .closed_form import paper_model
from .law import FrictionLaw
from .model import GeneralisedModel
from .quadrature import PressureQuadrature

#: Where the model and its export format are explained.
DOCS = "docs/model.md"


def check_map_values(pmap, coefficients, law) -> None:
    """Raise a one-line `ArgumentError` when ``pmap``, ``coefficients`` or ``law`` is not a
    `PolarMap`, `Coefficients` or `FrictionLaw` (the checks of every function here)."""
    if not isinstance(pmap, PolarMap):
        raise ArgumentError(f"pmap must be a PolarMap, got {type(pmap).__name__}")
    if not isinstance(coefficients, Coefficients):
        raise ArgumentError(f"coefficients must be Coefficients, got {type(coefficients).__name__}")
    if not isinstance(law, FrictionLaw):
        raise ArgumentError(f"law must be a FrictionLaw, got {type(law).__name__}")


def paper_k_x(coefficients: Coefficients, *, rolling: bool) -> float:
    """The k_x of the paper's closed forms for a map: the coefficients' k_x for the
    rolling map (0 when it is unknown), 0 for the static map."""
    return coefficients.k_x if (rolling and coefficients.k_x is not None) else 0.0


def map_model(
    pmap: PolarMap,
    coefficients: Coefficients,
    law: FrictionLaw,
    *,
    rolling: bool = False,
    order="auto",
) -> GeneralisedModel:
    """The generalised model of the pressure map ``pmap``, with the coefficients' R and ``law``.

    Parameters
    ----------
    pmap : PolarMap
        The static map, or the rolling map in the static patch's frame (origin
        at the static centre of pressure), as ``fepost.analyse`` makes them.
    coefficients : Coefficients
        The paper's coefficients of the maps (R, F0, M0, a, m, k_x).
    law : FrictionLaw
        The friction law (coefficient f).
    rolling : bool
        ``pmap`` is the rolling map: the paper's closed forms it is compared
        with include k_x.
    order : "auto" or (K, L)
        Order of the model's correction (see ``fepost.friction.build.build_model``).

    Returns
    -------
    GeneralisedModel
        Its ``accuracy`` also holds the paper's closed forms' errors
        (``compare_force``, ``compare_torque``) on the same check grid.

    Examples
    --------
    >>> import fepost
    >>> from fepost.friction.law import FrictionLaw
    >>> from fepost.friction.summary import map_model
    >>> an = fepost.analyse("meshes/static.vtu")
    >>> c = an.coefficients
    >>> model = map_model(an.static_map, c, FrictionLaw(f=0.3))
    >>> Fx, Fy, Mz = model([0.1, 0.0], [0.0, 0.0], [0.0, 1.0])   # pure sliding, pure spin
    >>> round(float(Fx[0] / c.F0), 6), round(float(Mz[1] / c.M0), 6)
    (-1.0, -1.0)
    """
    check_map_values(pmap, coefficients, law)
    c = coefficients
    return build_model(
        PressureQuadrature.from_polar(pmap),
        law,
        radius=c.R,
        order=order,
        compare=paper_model(c.F0, c.M0, c.a, c.m, paper_k_x(c, rolling=rolling), c.R),
    )


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


def summarise(
    static_map: PolarMap,
    coefficients: Coefficients,
    law: FrictionLaw,
    *,
    rolling_map: PolarMap | None = None,
    circular: bool,
    aspect: float,
    order="auto",
) -> ModelSummary:
    """The `ModelSummary` of a static map (and of its rolling map, when given).

    Builds the models with `map_model`: about a second.

    Parameters
    ----------
    static_map : PolarMap
        The static map.
    coefficients : Coefficients
        The paper's coefficients of the maps.
    law : FrictionLaw
        The friction law.
    rolling_map : PolarMap, optional
        The rolling map in the static patch's frame.
    circular, aspect : bool, float
        The static patch's circularity verdict and aspect (they choose the recommendation).
    order : "auto" or (K, L)
        Order of the models' correction.
    """
    static = map_model(static_map, coefficients, law, order=order)
    rolling = None
    if rolling_map is not None:
        rolling = map_model(rolling_map, coefficients, law, rolling=True, order=order)
    return ModelSummary(
        static=static,
        rolling=rolling,
        circular=bool(circular),
        aspect=float(aspect),
        paper={"a": coefficients.a, "m": coefficients.m},
    )


def model_error_map(
    pmap: PolarMap,
    coefficients: Coefficients,
    law: FrictionLaw,
    *,
    model: GeneralisedModel,
    rolling: bool = False,
    n_beta: int = 37,
    n_t: int = 65,
):
    """The error of the paper's closed forms, the generalised base and ``model`` over the
    kinematic sphere of the map ``pmap``, scaled by the coefficients' F0 and M0.

    Parameters
    ----------
    pmap : PolarMap
        The static map, or the rolling map in the static patch's frame.
    coefficients : Coefficients
        The paper's coefficients (F0, M0, a, m, k_x, R).
    law : FrictionLaw
        The friction law of the exact integrals.
    model : GeneralisedModel
        The generalised model of ``pmap`` (`map_model`, or the one of an
        analysis's ``model_summary``).
    rolling : bool
        ``pmap`` is the rolling map: the closed forms include k_x.
    n_beta, n_t : int
        Points of the grid over the sliding direction and over ε.

    Returns
    -------
    ErrorMap
        ``fepost.friction.sphere.ErrorMap``: the data of ``fepost.figures.errormap.plot_error_map``.
    """
    from .sphere import error_map

    check_map_values(pmap, coefficients, law)
    if not isinstance(model, GeneralisedModel):
        raise ArgumentError(f"model must be a GeneralisedModel, got {type(model).__name__}")
    c = coefficients
    return error_map(
        PressureQuadrature.from_polar(pmap),
        {
            "paper": paper_model(c.F0, c.M0, c.a, c.m, paper_k_x(c, rolling=rolling), c.R),
            "base": model.without_correction(),
            "model": model,
        },
        law=law,
        F0=c.F0,
        M0=c.M0,
        R=c.R,
        n_beta=n_beta,
        n_t=n_t,
    )
