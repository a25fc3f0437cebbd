"""The paper's Table 1 on our FE maps: theory, fitted values and 95 % bounds.

`table1` takes an `Analysis`, makes the test curves
(`fepost.identify.make_test_curves`; closed forms with the paper's 20 %
uniform noise by default), fits them (`fepost.identify.fit_table1`) and
lays the result beside the paper's printed table, with the inconsistencies
docs/theory.md lists. It also fits the closed forms to curves made by the exact
integrals (`fepost.identify.approximation_bias`) and reports the bias the
approximation itself causes.

k_x without a rolling map
-------------------------
The table1 JSON contract has a k_x row. With a rolling map, k_x is the moment form
R·x_c/⟨x²⟩ and the exact F⊥ curve is integrated over the real
rolling map. Without one, the theoretical k_x is *assumed* to be the paper's
0.130 (`PAPER_K_X`, or the ``k_x`` argument), the F⊥ curve is made with it
(closed form, or the exact integrals over σ0(1 + k_x x/R)), and the table says so:
the k_x row then checks the identification procedure only, not our FE model.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from .analysis import Analysis
from .coefficients import Coefficients
from .errors import ArgumentError
from .friction.quadrature import PressureQuadrature
from .identify import (
    DEFAULT_AMPLITUDE,
    DEFAULT_N_POINTS,
    DEFAULT_SPAN,
    BiasReport,
    GeneralisedCurves,
    Identification,
    TestCurves,
    approximation_bias,
    fit_table1,
    make_test_curves,
    rolling_model,
    with_noise,
)

#: Seed of the committed Table 1 (``fepost table1`` without ``--seed``).
DEFAULT_SEED = 20240611
#: Row names, in the order of the table1 JSON contract.
ROW_NAMES = ("f", "F0", "M0", "a", "m", "k_x")
#: k_x assumed when no rolling map is given: the paper's theoretical value.
PAPER_K_X = 0.130

#: The paper's Table 1 as printed: (theory, fitted, (lower, upper)).
PAPER_TABLE1: Mapping[str, tuple[float, float, tuple[float, float]]] = MappingProxyType(
    {
        "f": (0.3, 0.301, (0.296, 0.305)),
        "F0": (72219.0, 72370.0, (71200.0, 73530.0)),
        "M0": (3215.0, 3252.0, (3182.0, 3322.0)),
        "a": (0.690, 0.714, (0.603, 0.825)),
        "m": (1.595, 1.607, (1.348, 1.867)),
        "k_x": (0.130, 0.129, (0.128, 0.131)),
    }
)

#: Why the paper's numbers cannot be matched.
PAPER_NOTES = (
    "paper: N = 2.41e5 N with F0 = 72219 N fits f = 0.3, but M0/F0 = 0.045 m implies a patch "
    "radius near 7 cm, far too small for that load at P* = 200 kPa",
    "paper: m = 1.595 is impossible under sqrt(m) = 2 A2/A3 (A3 <= A2 forces m >= 4)",
    "paper: the text's 'm = 0.025 m, a = 0.052 m^1/2' conflicts with the table",
    "paper: it fits data made from the same formula only (a circular test); the number of "
    "points per curve is not stated. Bound widths scale as 1/sqrt(n): at 20 % uniform noise "
    "we get +-9 % on f with 50 points per curve, so its +-1.5 % needs about 2000 per curve",
    "paper: a, m, k_x depend on R (aR^2, m/R^2, k_x/R do not) and the paper's R is not given, "
    "so its a, m, k_x are not comparable with ours",
)

_UNITS = {"f": "", "F0": "N", "M0": "N m", "a": "", "m": "", "k_x": ""}


@dataclass(frozen=True)
class Row:
    """One coefficient: ``theory`` (from the moments), ``fitted`` and Wald ``ci95``;
    ``profile_ci95`` for a and m; ``paper``: the paper's (theory, fitted, bounds)."""

    name: str
    theory: float
    fitted: float
    ci95: tuple[float, float]
    profile_ci95: tuple[float, float] | None
    profile_agrees: bool | None
    unit: str
    paper: tuple[float, float, tuple[float, float]]

    @property
    def covered(self) -> bool:
        """Whether ``ci95`` holds ``theory``."""
        return bool(self.ci95[0] <= self.theory <= self.ci95[1])

    def to_dict(self) -> dict:
        d: dict[str, Any] = {
            "name": self.name,
            "theory": self.theory,
            "fitted": self.fitted,
            "ci95": [self.ci95[0], self.ci95[1]],
            "unit": self.unit,
            "covered": self.covered,
            "paper": {
                "theory": self.paper[0],
                "fitted": self.paper[1],
                "ci95": list(self.paper[2]),
            },
        }
        if self.profile_ci95 is not None:
            d["profile_ci95"] = list(self.profile_ci95)
            d["profile_agrees"] = self.profile_agrees
        return d


def _named_row(rows: tuple[Row, ...], name: str) -> Row:
    for r in rows:
        if r.name == name:
            return r
    raise ArgumentError(f"name must be one of {', '.join(ROW_NAMES)}, got {name!r}")


@dataclass(frozen=True)
class GeneralisedTable:
    """The generalised model fitted to the exact-integral curves (same grid, noise and seed).

    ``rows``: f, F0, M0, a, m, k_x with ``theory`` from the FE maps (a, m along x,
    β = 0: the direction of the test curves); ``identification``: the fit;
    ``curves``: the noisy exact-integral data; ``form``: the fitted
    `GeneralisedCurves` (its two models).
    """

    rows: tuple[Row, ...]
    identification: Identification
    curves: TestCurves
    form: GeneralisedCurves

    def row(self, name: str) -> Row:
        """The row of ``name`` (one of `ROW_NAMES`)."""
        return _named_row(self.rows, name)

    def to_dict(self) -> dict:
        models = {}
        for tag, m in (("static", self.form.static), ("rolling", self.form.rolling)):
            K, L = m.order
            # the paper's forms' errors (compare_*) belong to the coefficients JSON, not here
            acc = {k: v for k, v in m.accuracy.items() if not k.startswith("compare_")}
            models[tag] = {"order": [K, L], "accuracy": acc, "source": m.source}
        return {
            "rows": [r.to_dict() for r in self.rows],
            "source": self.curves.source,
            "form": "generalised",
            "theory": "F0, M0 and a, m along x (beta = 0) of the generalised model built from the FE maps",
            "fit": self.identification.to_dict(),
            "models": models,
        }


@dataclass(frozen=True)
class Table1:
    """The identification experiment's result (see the module docstring).

    ``rows``: f, F0, M0, a, m, k_x; ``identification``: the full fit;
    ``curves``: the test data; ``bias``: the exact-data bias study (or None);
    ``k_x_source``: where the theoretical k_x came from; ``notes``: caveats,
    including the paper's inconsistencies; settings ``seed``, ``source``, ``noise``,
    ``amplitude``, ``n_points``, ``span``; ``R`` (m, r_max) and ``N`` (N).
    """

    rows: tuple[Row, ...]
    identification: Identification
    curves: TestCurves
    bias: BiasReport | None
    k_x_source: str
    notes: tuple[str, ...]
    seed: int | None
    source: str
    noise: str
    amplitude: float
    n_points: int
    span: float
    R: float
    N: float
    generalised: GeneralisedTable | None = None

    def row(self, name: str) -> Row:
        """The row of ``name`` (one of `ROW_NAMES`)."""
        return _named_row(self.rows, name)

    def to_dict(self) -> dict:
        """The table1 JSON (``rows``, the contract) with settings, bias, generalised rows and notes."""
        return {
            "rows": [r.to_dict() for r in self.rows],
            "settings": {
                "seed": self.seed,
                "source": self.source,
                "noise": self.noise,
                "amplitude": self.amplitude,
                "n_points_per_curve": self.n_points,
                "span": self.span,
                "R": self.R,
                "R_definition": (
                    "r_max: smallest circle about the static centre of pressure holding every loaded point"
                ),
                "N": self.N,
                "k_x_source": self.k_x_source,
            },
            "fit": self.identification.to_dict(),
            "noise_description": dict(self.curves.noise),
            "exact_bias": self.bias.to_dict() if self.bias is not None else None,
            "generalised": self.generalised.to_dict() if self.generalised is not None else None,
            "notes": list(self.notes),
        }


def _num(v: float) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "nan"
    return f"{v:.4g}"


def format_table(t: Table1) -> str:
    """Readable text: theory | fitted | 95 % bounds | profile bounds | the paper's row."""
    head = (
        f"Table 1 (the paper's identification experiment): {t.source} curves, "
        f"{t.noise} noise {t.amplitude:g} x max, "
        f"seed {t.seed}, "
        f"{t.n_points} points per curve on [0, {t.span:g}]\n"
        f"R = {t.R:.5g} m (r_max), N = {t.N:.6g} N, k_x theory: {t.k_x_source}"
    )
    cols = (
        "coef",
        "theory",
        "fitted",
        "95 % bounds",
        "profile 95 %",
        "paper theory",
        "paper fitted",
        "paper bounds",
    )
    body = []
    for r in t.rows:
        prof = f"{_num(r.profile_ci95[0])}, {_num(r.profile_ci95[1])}" if r.profile_ci95 else ""
        if r.profile_ci95 and r.profile_agrees is False:
            prof += " *"
        body.append(
            (
                r.name + (f" ({r.unit})" if r.unit else ""),
                _num(r.theory),
                _num(r.fitted),
                f"{_num(r.ci95[0])}, {_num(r.ci95[1])}" + ("" if r.covered else " !"),
                prof,
                _num(r.paper[0]),
                _num(r.paper[1]),
                f"{_num(r.paper[2][0])}, {_num(r.paper[2][1])}",
            )
        )
    widths = [max(len(c), *(len(b[i]) for b in body)) for i, c in enumerate(cols)]
    line = lambda cells: "  ".join(f"{c:<{w}}" for c, w in zip(cells, widths, strict=True)).rstrip()  # noqa: E731
    out = [head, "", line(cols), line(tuple("-" * w for w in widths))] + [line(b) for b in body]
    fit = t.identification
    sig = ", ".join(f"{k} {v:.4g}" for k, v in fit.noise_sigma.items())
    out += [
        "",
        f"fit: chi2/dof = {fit.redchi:.3g} (dof {fit.dof}), noise levels estimated per curve: {sig}",
        "'!' = the 95 % bounds miss the theoretical value; "
        "'*' = profile and Wald bounds differ by more than 10 % of the half-width",
    ]
    if t.bias is not None:
        b = t.bias
        rel = ", ".join(f"{n} {100 * b.relative_bias(n):+.1f} %" for n in ("F0", "M0", "a", "m", "k_x"))
        st = b.structure
        errs = ", ".join(f"{k} {v['max_abs_error_relative']:.3f}" for k, v in st.items())
        ac = ", ".join(f"{k} {v['lag1_autocorrelation']:.2f}" for k, v in st.items())
        rp = ", ".join(f"{k} {v['runs_p']:.1e}" for k, v in st.items())
        missed = [n for n, c in b.covered.items() if not c]
        out += [
            "",
            "approximation bias: closed forms fitted to noise-free exact-integral curves, "
            "vs their asymptotic values:",
            f"  {rel}",
            f"  largest |exact - fitted closed form| / curve max: {errs}",
            f"  residual lag-1 autocorrelation {ac}; runs test p {rp} (systematic, not noise)",
            "  with the paper's noise, the 95 % bounds miss the asymptotic value of: "
            + (", ".join(missed) if missed else "none (the noise hides the bias at this sample size)"),
        ]
    if t.generalised is not None:
        out += ["", _format_generalised(t.generalised)]
    out += [""] + [f"note: {n}" for n in t.notes]
    return "\n".join(out)


def _format_generalised(g: GeneralisedTable) -> str:
    cols = ("coef", "theory", "fitted", "95 % bounds")
    body = [
        (
            r.name + (f" ({r.unit})" if r.unit else ""),
            _num(r.theory),
            _num(r.fitted),
            f"{_num(r.ci95[0])}, {_num(r.ci95[1])}" + ("" if r.covered else " !"),
        )
        for r in g.rows
    ]
    widths = [max(len(c), *(len(b[i]) for b in body)) for i, c in enumerate(cols)]
    line = lambda cells: "  ".join(f"{c:<{w}}" for c, w in zip(cells, widths, strict=True)).rstrip()  # noqa: E731
    head = (
        "generalised model fitted to the exact-integral curves (same points, noise and seed); "
        "theory a, m along x (beta = 0)\n"
        "the model's accuracy against the exact integrals: 'max error' of fepost coefficients"
    )
    return "\n".join([head, "", line(cols), line(tuple("-" * w for w in widths))] + [line(b) for b in body])


def table1(
    analysis: Analysis,
    seed: int | None = DEFAULT_SEED,
    source: str = "closed_form",
    *,
    noise: str = "uniform",
    amplitude: float = DEFAULT_AMPLITUDE,
    n_points: int = DEFAULT_N_POINTS,
    span: float = DEFAULT_SPAN,
    k_x: float | None = None,
    bias: bool = True,
    profile: bool = True,
    generalised: bool = True,
) -> Table1:
    """Run the identification experiment on ``analysis`` (see the module docstring).

    ``source``: ``"closed_form"`` (the paper's) or ``"exact"`` (curves from the exact
    integrals). ``noise``, ``amplitude``, ``n_points``, ``span``, ``seed``: as in
    `fepost.identify.make_test_curves`. ``k_x``: the assumed k_x when the
    analysis has no rolling map (default `PAPER_K_X`); an error when it has one.
    ``bias``: also run `fepost.identify.approximation_bias` (exact integrals).
    ``profile``: profile-likelihood bounds for a and m.
    ``generalised``: also fit the generalised model to exact-integral curves made
    with the same points, noise and seed (`GeneralisedTable`).
    """
    if not isinstance(analysis, Analysis):
        raise ArgumentError(f"analysis must be an Analysis, got {type(analysis).__name__}")
    c = analysis.coefficients
    kx, kx_source, rolling_quad = _k_x_choice(analysis, k_x)
    truth = {"F0": c.F0, "M0": c.M0, "a": c.a, "m": c.m, "k_x": kx, "R": c.R, "N": c.N}
    quad = PressureQuadrature.from_polar(analysis.static_map)
    # the experiment's design: the same points, noise and seed for every set of curves
    design: dict[str, Any] = {
        "n_points": n_points,
        "span": span,
        "noise": noise,
        "amplitude": amplitude,
        "seed": seed,
    }
    curves = make_test_curves(source, truth, quad=quad, rolling_quad=rolling_quad, **design)
    fit = fit_table1(curves, c.N, profile=profile)
    report = approximation_bias(truth, quad, rolling_quad=rolling_quad, **design) if bias else None
    gen = _generalised_table(analysis, quad, rolling_quad, kx, **design) if generalised else None
    theory = {"f": c.f, **{k: truth[k] for k in ("F0", "M0", "a", "m", "k_x")}}
    return Table1(
        rows=_rows(fit, theory),
        identification=fit,
        curves=curves,
        bias=report,
        k_x_source=kx_source,
        notes=_notes(c, source=source, kx_source=kx_source),
        seed=seed,
        source=source,
        noise=noise,
        amplitude=float(amplitude),
        n_points=int(n_points),
        span=float(span),
        R=float(c.R),
        N=float(c.N),
        generalised=gen,
    )


def _k_x_choice(analysis: Analysis, k_x: float | None) -> tuple[float, str, PressureQuadrature | None]:
    """The k_x of the experiment, where it came from, and the rolling map's quadrature (None
    without a rolling map: then k_x is the given or the paper's value)."""
    c = analysis.coefficients
    if c.k_x is not None:
        if k_x is not None:
            raise ArgumentError("k_x must be None when the analysis has a rolling map (k_x comes from it)")
        rolling_map = analysis.rolling_map
        if rolling_map is None:
            raise ArgumentError("analysis has k_x but no rolling_map; run analyse with the rolling map")
        return float(c.k_x), "rolling map, k_x = R x_c / <x^2>", PressureQuadrature.from_polar(rolling_map)
    kx = PAPER_K_X if k_x is None else float(k_x)
    if not math.isfinite(kx):
        raise ArgumentError(f"k_x must be finite, got {k_x!r}")
    kx_source = (
        f"assumed {kx:g} (no rolling map{'; the paper value' if k_x is None else ''}): "
        "the k_x row tests the procedure only"
    )
    return kx, kx_source, None


def _rows(fit: Identification, theory: dict[str, float]) -> tuple[Row, ...]:
    """One row per coefficient: theory, fitted value, bounds, the paper's row."""
    rows = []
    for name in ROW_NAMES:
        prof = fit.profile_ci95.get(name)
        rows.append(
            Row(
                name=name,
                theory=float(theory[name]),
                fitted=fit.value(name),
                ci95=fit.interval(name),
                profile_ci95=(float(prof[0]), float(prof[1])) if prof is not None else None,
                profile_agrees=fit.profile_agrees.get(name),
                unit=_UNITS[name],
                paper=PAPER_TABLE1[name],
            )
        )
    return tuple(rows)


def _notes(c: Coefficients, *, source: str, kx_source: str) -> tuple[str, ...]:
    """What the table's numbers mean and where they came from."""
    notes = [
        f"theory: a, m from the moments (asymptotic values), R = r_max = {c.R:.5g} m; f = F0/N with N known",
        "bounds: Wald, t-quantile on the covariance (theta = F0, M0, ln a, ln m, k_x; "
        "curves weighted by their own noise level estimated from the residuals); "
        "profile bounds by re-fits for a and m",
    ]
    if source == "exact":
        notes.append("source exact: the fitted values carry the approximation's bias as well as noise")
    if c.k_x is None:
        notes.append(f"k_x: {kx_source}")
    notes.extend(PAPER_NOTES)
    return tuple(notes)


def _generalised_table(
    analysis, quad, rolling_quad, kx, *, n_points, span, noise, amplitude, seed
) -> GeneralisedTable:
    """Take the analysis's generalised models (built once, shared with
    `model_summary`; without a rolling map the
    rolling model is built on σ0(1 + k_x x/R)), make the exact curves, fit (no
    profile bounds)."""
    c = analysis.coefficients
    summary = analysis.model_summary
    if rolling_quad is not None:
        roll, rolling = rolling_quad, summary.rolling
    else:
        from .friction.build import build_model
        from .friction.law import FrictionLaw

        roll = rolling_model(quad, kx, c.R)
        rolling = build_model(roll, FrictionLaw(f=c.f), radius=c.R)
    form = GeneralisedCurves(static=summary.static, rolling=rolling, k_ref=kx)
    truth = {"F0": c.F0, "M0": c.M0, "a": c.a, "m": c.m, "k_x": kx, "R": c.R, "N": c.N}
    clean = make_test_curves(
        "exact", truth, quad=quad, rolling_quad=roll, n_points=n_points, span=span, amplitude=0.0
    )
    curves = with_noise(clean, noise=noise, amplitude=amplitude, seed=seed)
    fit = fit_table1(curves, c.N, form=form, profile=False)
    theory = {"f": form.static.F0 / c.N, **form.theory()}
    rows = tuple(
        Row(
            name=name,
            theory=float(theory[name]),
            fitted=fit.value(name),
            ci95=fit.interval(name),
            profile_ci95=None,
            profile_agrees=None,
            unit=_UNITS[name],
            paper=PAPER_TABLE1[name],
        )
        for name in ROW_NAMES
    )
    return GeneralisedTable(rows=rows, identification=fit, curves=curves, form=form)
