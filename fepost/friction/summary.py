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

Every accuracy fepost states for the generalised model (``fepost coefficients``,
``fepost predict``, the report, the docs) is a `StatedAccuracy`: the largest
errors on the error maps of `ACCURACY_GRID`, the densest grid fepost evaluates,
computed once per map (`ModelSummary.error_map`) and put into words by
`StatedAccuracy.sentence` alone. The model's own ``accuracy`` (its build's
check grid, 32 × 33 points, coarser) only steers the choice of its order.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
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
#: The grid of every stated accuracy (`accuracy_error_map`; n_beta, n_t as `model_error_map`'s):
#: 33 sliding directions 0–180° (5.625° steps) × both spin signs × 33 points from pure spin to
#: pure sliding, 2178 kinematic points per map: denser than the model's check grid (1056
#: points), whose largest errors it exceeds (aircraft tire, static map: 0.68 % there, 0.81 %
#: here). Its 2 (n_beta − 1) = 64 directions over a full turn divide the polar map's 128
#: angles, so the exact integrals are turned sums (`fepost.friction.turns`): about 1/64 of
#: the direct work.
ACCURACY_GRID = {"n_beta": 33, "n_t": 33}
ACCURACY_GRID_NAME = (
    "error-map grid: 33 sliding directions 0-180 deg, both spin signs, 33 sliding/spin ratios"
)


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
class StatedAccuracy:
    """The largest errors of the generalised model and of the paper's closed forms against the
    exact integrals (fractions of F0 and M0) over `ACCURACY_GRID`, for the maps named in ``maps``.

    The one source of every accuracy figure fepost prints or writes; `sentence` the one wording.
    """

    model_force: float
    model_torque: float
    paper_force: float
    paper_torque: float
    maps: str
    grid: str = ACCURACY_GRID_NAME

    @classmethod
    def of(cls, error_maps: Mapping[str, Any]) -> StatedAccuracy:
        """The largest errors over the `fepost.friction.sphere.ErrorMap` of each named map."""
        worst = {(name, q): 0.0 for name in ("model", "paper") for q in ("force", "torque")}
        for em in error_maps.values():
            for name, q in worst:
                worst[name, q] = max(worst[name, q], em.worst(name)[q])
        return cls(
            model_force=worst["model", "force"],
            model_torque=worst["model", "torque"],
            paper_force=worst["paper", "force"],
            paper_torque=worst["paper", "torque"],
            maps=" and ".join(error_maps) + (" map" if len(error_maps) == 1 else " maps"),
        )

    @property
    def model(self) -> float:
        """The generalised model's largest error, force or torque (fraction)."""
        return max(self.model_force, self.model_torque)

    @property
    def paper(self) -> float:
        """The closed forms' largest error, force or torque (fraction)."""
        return max(self.paper_force, self.paper_torque)

    def sentence(self) -> str:
        """The generalised model's accuracy in words: the figure, the maps and the grid."""
        return (
            f"within {self.model:.1%} of the exact integrals (largest |dF|/F0 {self.model_force:.1%}, "
            f"|dMz|/M0 {self.model_torque:.1%} over the {self.maps} on the {self.grid}); "
            f"the paper's closed forms miss by up to {self.paper:.0%}"
        )

    def values(self) -> str:
        """The four figures as fractions, for the coefficients table."""
        return (
            f"generalised |dF|/F0 {self.model_force:.3f}, |dMz|/M0 {self.model_torque:.3f}; "
            f"paper's forms {self.paper_force:.3f}, {self.paper_torque:.3f}"
        )

    def to_dict(self) -> dict[str, Any]:
        return {**self.__dict__, "grid_points": dict(ACCURACY_GRID)}


@dataclass(frozen=True)
class ModelSummary:
    """The models of an analysis with what a user needs to choose between them.

    ``inputs``: (static map, rolling map or None, coefficients, law), from which the
    error maps of the stated accuracy are computed on first use (`static_errors`).
    """

    static: GeneralisedModel
    rolling: GeneralisedModel | None
    circular: bool
    aspect: float
    paper: dict
    inputs: tuple = field(default=(), repr=False, compare=False)

    def _error_map(self, rolling: bool):
        if len(self.inputs) != 4:
            raise ArgumentError("this ModelSummary has no maps to measure its accuracy on (use summarise)")
        static_map, rolling_map, coefficients, law = self.inputs
        pmap, model = (rolling_map, self.rolling) if rolling else (static_map, self.static)
        if pmap is None or model is None:
            return None
        return accuracy_error_map(pmap, coefficients, law, model=model, rolling=rolling)

    @cached_property
    def static_errors(self):
        """`fepost.friction.sphere.ErrorMap` of the static map on `ACCURACY_GRID` (computed once)."""
        return self._error_map(False)

    @cached_property
    def rolling_errors(self):
        """The same for the rolling map (None without one)."""
        return self._error_map(True)

    def error_maps(self) -> dict[str, Any]:
        """{"static": ErrorMap, "rolling": ErrorMap} (rolling only with a rolling map)."""
        maps = {"static": self.static_errors, "rolling": self.rolling_errors}
        return {k: v for k, v in maps.items() if v is not None}

    @cached_property
    def accuracy(self) -> StatedAccuracy:
        """The stated accuracy over all the maps (static and rolling): the recommendation's."""
        return StatedAccuracy.of(self.error_maps())

    def map_accuracy(self, rolling: bool = False) -> StatedAccuracy:
        """The stated accuracy of one map's model."""
        name = "rolling" if rolling else "static"
        return StatedAccuracy.of({name: self.error_maps()[name]})

    def recommendation(self) -> str:
        """Which model to use, in one sentence, from the patch shape and the stated accuracy."""
        acc = self.accuracy
        if not self.circular:
            return (
                f"the patch is not circular (aspect {self.aspect:.2f}): use the generalised model, "
                f"{acc.sentence()}; its coefficients are exported by 'fepost predict --model-json'"
            )
        return (
            f"the patch is circular: the paper's coefficients apply, but the generalised model is "
            f"{acc.sentence()}"
        )

    def lines(self) -> list[tuple[str, str]]:
        """(label, value) rows for the coefficients table."""
        m = self.static
        d = m.direction_coefficients(np.array([0.0, 0.5 * np.pi]))
        K, L = m.order
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
            ("  max error", f"{self.map_accuracy().values()}   ({ACCURACY_GRID_NAME})"),
        ]
        if self.rolling is not None:
            r = self.rolling
            rows += [
                (
                    "  rolling map: spin force g^",
                    f"({r.g[0]:.4g}, {r.g[1]:.4g}); CoP offset x^c = ({r.xc[0]:.4g}, {r.xc[1]:.4g})",
                ),
                ("  rolling map: max error", f"{self.map_accuracy(True).values()} (paper's forms with k_x)"),
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
            "stated_accuracy": {
                "all_maps": self.accuracy.to_dict(),
                **{name: StatedAccuracy.of({name: em}).to_dict() for name, em in self.error_maps().items()},
            },
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
        inputs=(static_map, rolling_map, coefficients, law),
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


def accuracy_error_map(
    pmap: PolarMap,
    coefficients: Coefficients,
    law: FrictionLaw,
    *,
    model: GeneralisedModel,
    rolling: bool = False,
):
    """`model_error_map` on `ACCURACY_GRID`, its exact integrals as turned sums.

    The grid's directions β (0–180°) are the first half of T = 2 (n_beta − 1) directions
    over a full turn; each spin sign's T × n_t points are laid out as T turned groups
    (`fepost.friction.exact.friction_resultants`' ``turns``), the same numbers as
    `model_error_map` to round-off (tests/test_doc_examples.py compares them).
    """
    from .exact import friction_resultants
    from .sphere import ErrorMap

    check_map_values(pmap, coefficients, law)
    if not isinstance(model, GeneralisedModel):
        raise ArgumentError(f"model must be a GeneralisedModel, got {type(model).__name__}")
    c = coefficients
    quad = PressureQuadrature.from_polar(pmap)
    models = {
        "paper": paper_model(c.F0, c.M0, c.a, c.m, paper_k_x(c, rolling=rolling), c.R),
        "base": model.without_correction(),
        "model": model,
    }
    n_beta, n_t = ACCURACY_GRID["n_beta"], ACCURACY_GRID["n_t"]
    turns = 2 * (n_beta - 1)
    theta = np.arange(turns) * (2.0 * np.pi / turns)
    t = np.linspace(0.0, 1.0, n_t)
    speed, u = np.sin(0.5 * np.pi * t), np.where(t == 1.0, 0.0, np.cos(0.5 * np.pi * t))
    vx, vy = np.outer(np.cos(theta), speed).ravel(), np.outer(np.sin(theta), speed).ravel()
    force: dict[str, np.ndarray] = {}
    torque: dict[str, np.ndarray] = {}
    for sign in (1.0, -1.0):
        wz = np.tile(sign * u / c.R, turns)
        ex = friction_resultants(quad, vx, vy, wz, law, turns=turns)
        for name, m in models.items():
            fx, fy, mz = (np.asarray(a, float) for a in m(vx, vy, wz))
            df = (np.hypot(fx - ex.Fx, fy - ex.Fy) / c.F0).reshape(turns, n_t)[:n_beta]
            dm = (np.abs(mz - ex.Mz) / c.M0).reshape(turns, n_t)[:n_beta]
            force[name] = np.maximum(force[name], df) if name in force else df
            torque[name] = np.maximum(torque[name], dm) if name in torque else dm
    return ErrorMap(
        np.degrees(theta[:n_beta]), t, force, torque, float(c.F0), float(c.M0), float(c.R), quad.source
    )
