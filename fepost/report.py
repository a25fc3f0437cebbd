"""The report: every figure, the coefficients and Table 1 in one folder (``fepost report``).

:func:`build_report` runs the pipeline on a static (and optionally a rolling) FE
map and writes into ``out``:

==============================  ====================================================
``report.html``                 the report (opens from disk; figures linked relatively)
``fig1_static.png``             Figure 1: static pressure over the FE patch (3-D)
``fig2_rolling.png``            Figure 2: rolling pressure (3-D; with a rolling map)
``fig3_sections.*``             Figure 3: pressure along the x and y diameters
                                (PNG, SVG, PDF)
``patch_plan.*``                the loaded region in plan with the circularity check
``fig4_f_parallel.*``           Figure 4: F∥(ψ)
``fig5_torque.*``               Figure 5: M_C(υ)
``fig6_f_perp.*``               Figure 6: F⊥(υ) (with a rolling map)
``coefficients.json``           :meth:`fepost.analysis.Analysis.to_dict`
``table1.json``                 :meth:`fepost.table1.Table1.to_dict` (INTERFACE.md:
                                ``rows`` of name, theory, fitted, ci95)
``closed_form_vs_exact.json``   :meth:`FrictionCurves.errors_dict`: largest gap
                                between the closed forms and the exact integrals
``curves.csv``                  the curves of Figures 4–6 in long form
==============================  ====================================================

Everything is written into a temporary folder beside ``out`` and moved into
place only when every step succeeded (:func:`fepost.output.staged_folder`).

Table 1 is :func:`fepost.table1.table1` with its defaults (the same call as
``fepost table1``, so ``table1.json`` equals ``fepost table1 --json`` on the same
inputs and seed, default :data:`fepost.table1.DEFAULT_SEED`): the closed-form
curves (1.8) with the map's coefficients, 20 % uniform noise, a joint
least-squares fit, and the same fit on exact-integral data for the bias of the
approximation. Figures 4–6 show its test points and fitted curves with their
95 % prediction band (:meth:`fepost.identify.Identification.prediction_band`).
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from . import identify
from .analysis import Analysis, analyse
from .errors import ArgumentError
from .output import staged_folder, to_json
from .table1 import DEFAULT_SEED, Table1, table1

if TYPE_CHECKING:
    from .figures.curves import CurveData

#: Inflation pressure P* (Pa) when neither the option nor the sidecar gives one: the paper's.
DEFAULT_INFLATION_PRESSURE = 200e3
#: Points of the dense curves of Figures 4–6 (on [0, the span of Table 1's test curves]).
CURVE_POINTS = 201

Progress = Callable[[int, int, str, float], None]


@dataclass(frozen=True)
class ReportResult:
    """What :func:`build_report` wrote: the folder, its files and the time per step (s)."""

    out: Path
    files: tuple[str, ...]
    timings: tuple[tuple[str, float], ...]
    inflation_pressure: float
    inflation_pressure_source: str

    def to_dict(self) -> dict:
        return {
            "out": str(self.out),
            "files": list(self.files),
            "timings": [{"step": s, "seconds": t} for s, t in self.timings],
            "inflation_pressure": self.inflation_pressure,
            "inflation_pressure_source": self.inflation_pressure_source,
        }


@dataclass
class _Steps:
    """Runs named steps, timing each and telling ``progress``."""

    total: int
    progress: Progress | None
    done: list = field(default_factory=list)

    def run(self, name: str, func, *args, **kwargs):
        t0 = time.perf_counter()
        value = func(*args, **kwargs)
        dt = time.perf_counter() - t0
        self.done.append((name, dt))
        if self.progress is not None:
            self.progress(len(self.done), self.total, name, dt)
        return value


def _check_inflation_option(option) -> float:
    try:
        p = float(option)
    except (TypeError, ValueError):
        p = math.nan
    if not (math.isfinite(p) and p > 0):
        raise ArgumentError(f"--inflation-pressure must be a positive pressure in Pa, got {option!r}")
    return p


def resolve_inflation_pressure(option: float | None, analysis: Analysis) -> tuple[float, str]:
    """P* (Pa) and where it came from: the option, the static mesh's sidecar, or the default."""
    if option is not None:
        return _check_inflation_option(option), "option"
    side = analysis.static_field.sidecar or {}
    value = side.get("inflation_pressure")
    if value is not None:
        try:
            p = float(value)
        except (TypeError, ValueError):
            p = math.nan
        if not (math.isfinite(p) and p > 0):
            raise ArgumentError(
                f"{analysis.static_field.source}: sidecar inflation_pressure must be a positive pressure in Pa, "
                f"got {value!r}"
            )
        return p, "sidecar"
    return DEFAULT_INFLATION_PRESSURE, "default (the paper's 200 kPa)"


# --------------------------------------------------------------------------------------
# Curves of Figures 4–6
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class FrictionCurves:
    """The curves of Figures 4–6 and how far the closed forms lie from the exact integrals.

    ``curves``: one :class:`~fepost.figures.curves.CurveData` per figure (F∥, M_C and,
    with a rolling map, F⊥); ``errors``: per curve, the largest |exact − closed form|
    relative to the curve's scale (``max_abs_relative``), where (``at``, ψ or υ) and
    the scale (N or N·m).
    """

    curves: tuple[CurveData, ...]
    errors: Mapping[str, Mapping[str, Any]]

    def __post_init__(self) -> None:
        object.__setattr__(self, "curves", tuple(self.curves))
        object.__setattr__(
            self,
            "errors",
            MappingProxyType({k: MappingProxyType(dict(v)) for k, v in self.errors.items()}),
        )

    def errors_dict(self) -> dict:
        """``errors`` as plain dicts (the report's ``closed_form_vs_exact.json``)."""
        return {k: dict(v) for k, v in self.errors.items()}


def friction_curves(analysis: Analysis, table: Table1) -> FrictionCurves:
    """Assemble the arrays of Figures 4–6 from the analysis and its Table 1.

    Dense curves on :data:`CURVE_POINTS` values of ψ, υ in [0, ``table.span``]: the
    exact Coulomb integrals over the static map (F∥, M_C) and the rolling map (F⊥);
    the closed forms (1.8) with the theoretical coefficients of ``table``; the fitted
    curves with their 95 % prediction band
    (:meth:`fepost.identify.Identification.prediction_band`); and the noisy test
    points of ``table.curves``. Figure 6 only with a rolling map.
    """
    from .figures.curves import CurveData
    from .friction.quadrature import PressureQuadrature

    c = analysis.coefficients
    R = table.R
    quad = PressureQuadrature.from_polar(analysis.static_map)
    rolling_map = analysis.rolling_map
    rquad = PressureQuadrature.from_polar(rolling_map) if rolling_map is not None else None
    has_roll = rquad is not None
    x = np.linspace(0.0, table.span, CURVE_POINTS)
    exact = dict(
        zip(
            identify.CURVES,
            identify.exact_curves(quad, x, x, R, rolling_quad=rquad, friction=c.f),
            strict=True,
        )
    )
    theory = [table.row(name).theory for name in identify.PARAMETERS]
    closed = {name: identify.curve_model(name, x, theory, R)[0] for name in identify.CURVES}
    scales = {
        "f_parallel": ("psi", "F0", theory[0]),
        "torque": ("upsilon", "M0", theory[1]),
        "f_perp": ("upsilon", "|k_x| M0 / 2R", abs(theory[4]) * theory[1] / (2.0 * R)),
    }
    shown = ("f_parallel", "torque") + (("f_perp",) if has_roll else ())
    errors = {}
    for key in shown:
        x_name, scale_name, scale = scales[key]
        if scale == 0:
            continue
        d = np.abs(exact[key] - closed[key])
        i = int(np.argmax(d))
        errors[key] = {
            "max_abs_relative": float(d[i] / scale),
            "at": float(x[i]),
            "scale": float(scale),
            "x_name": x_name,
            "scale_name": scale_name,
        }
    fit = table.identification
    curves = []
    for key in shown:
        name, title, x_name, x_label, y_label, unit = _FIGURES[key]
        y, lo, hi = fit.prediction_band(key, x)
        test_x, test_y = table.curves.data(key)
        curves.append(
            CurveData(
                name=name,
                title=title,
                x_name=x_name,
                x_label=x_label,
                y_label=y_label,
                unit=unit,
                x=x,
                closed_form=closed[key],
                exact=exact[key],
                fit=y,
                band_lo=lo,
                band_hi=hi,
                test_x=test_x,
                test_y=test_y,
            )
        )
    return FrictionCurves(tuple(curves), errors)


#: Figures 4–6: curve -> (figure name, title, x name, x label, y label, unit).
_FIGURES = {
    "f_parallel": (
        "F_parallel",
        "Figure 4: longitudinal friction force F∥ against ψ = u/v",
        "psi",
        "ψ = ω_z R / v",
        "F∥ (N)",
        "N",
    ),
    "torque": (
        "M_C",
        "Figure 5: friction torque M_C against υ = v/u",
        "upsilon",
        "υ = v / (ω_z R)",
        "M_C (N·m)",
        "N m",
    ),
    "f_perp": (
        "F_perp",
        "Figure 6: lateral friction force F⊥ against υ = v/u (rolling map)",
        "upsilon",
        "υ = v / (ω_z R)",
        "F⊥ = −F_y (N)",
        "N",
    ),
}


# --------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------
def _save_mpl(fig, folder: Path, stem: str) -> list[str]:
    import matplotlib.pyplot as plt

    names = []
    for ext in ("png", "svg", "pdf"):
        kw = {"metadata": {"Date": None}} if ext in ("svg", "pdf") else {}
        if ext == "pdf":
            kw = {"metadata": {"CreationDate": None, "ModDate": None}}
        fig.savefig(folder / f"{stem}.{ext}", **kw)
        names.append(f"{stem}.{ext}")
    plt.close(fig)
    return names


def _render(patch, path: Path, *, title: str, p_star: float, height_scale: float, clim) -> None:
    from .figures.render import pressure_surface

    pl = pressure_surface(patch, inflation_pressure=p_star, title=title, height_scale=height_scale, clim=clim)
    try:
        pl.screenshot(str(path))
    finally:
        pl.close()


def _num(value, key: str | None, fmt: str = "{:.6g}") -> str:
    """A table cell showing ``value`` and carrying its exact JSON value and key
    (the dotted path of the value in ``coefficients.json`` or ``table1.json``)."""
    if value is None:
        return "<td>—</td>"
    v = float(value)
    shown = fmt.format(v) if math.isfinite(v) else "n/a"
    if key is None:
        return f'<td class="num">{shown}</td>'
    return f'<td class="num" data-key="{html.escape(key)}" data-value="{v!r}">{shown}</td>'


def _esc(s) -> str:
    return html.escape(str(s))


_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Arial,sans-serif;max-width:1180px;margin:2em auto;
padding:0 1.2em;color:#1b1b1b;line-height:1.45}
h1{font-size:1.7em;margin-bottom:.2em}h2{margin-top:2em;border-bottom:1px solid #ddd;padding-bottom:.2em}
table{border-collapse:collapse;margin:.8em 0;font-size:.93em}th,td{border:1px solid #d5d5d5;padding:.3em .6em}
th{background:#f3f4f6;text-align:left}td.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:1.4em 0;text-align:center}figure img{max-width:min(100%,900px);border:1px solid #e3e3e3}
figcaption{font-size:.92em;color:#333;margin-top:.4em;text-align:left}
.verdict{font-weight:600}.ok{color:#1a7f37}.bad{color:#b42318}.note{color:#555;font-size:.92em}
code{background:#f6f8fa;padding:0 .25em}.small{font-size:.88em;color:#555}
"""


def _html(ctx: dict) -> str:
    a: Analysis = ctx["analysis"]
    c = a.coefficients
    p = a.static_patch
    coef = ctx["coef_json"]
    out = io.StringIO()
    w = out.write
    w("<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>")
    w("<title>fepost report: tire-road contact and dry-friction model</title>")
    w(f"<style>{_CSS}</style></head><body>\n")
    w("<h1>Tire–road contact: coefficients of the coupled dry-friction model</h1>\n")
    w(
        f"<p class='small'>fepost {_esc(ctx['version'])} · definitions of THEORY.md (which wins over the paper where "
        "they disagree) · SI units unless marked.</p>\n"
    )

    # Inputs and provenance
    w("<h2>Inputs and provenance</h2>\n<table>\n")
    rows = [
        (
            "static map",
            f"<code>{_esc(a.static_field.source)}</code> — array <code>{_esc(a.static_field.field)}</code>, "
            f"{_esc(p.location)} data, {len(p.triangles)} loaded faces",
        ),
    ]
    if a.rolling_field is not None:
        rows.append(
            (
                "rolling map",
                f"<code>{_esc(a.rolling_field.source)}</code> — array "
                f"<code>{_esc(a.rolling_field.field)}</code>",
            )
        )
    else:
        rows.append(("rolling map", "none (no Figure 2, no Figure 6; Table 1 assumes k_x)"))
    rows += [
        ("friction coefficient f", f"{c.f:g}"),
        ("inflation pressure P*", f"{ctx['p_star'] / 1e3:g} kPa ({_esc(ctx['p_star_source'])})"),
        ("noise seed (Table 1)", _esc(ctx["seed"])),
        ("polar grid", f"{a.grid.rule}, {a.grid.shape[0]} × {a.grid.shape[1]} (r × φ)"),
        ("R used", f"r_max = {c.R * 1e3:.4g} mm: {_esc(coef.get('R_definition', ''))}"),
    ]
    for k, v in rows:
        w(f"<tr><th>{_esc(k)}</th><td>{v}</td></tr>\n")
    w("</table>\n")

    # Coefficients
    w("<h2>Coefficients</h2>\n")
    w(
        f"<p>All R-dependent coefficients use <b>R = r_max = {c.R * 1e3:.4g} mm</b>. "
        "a·R², m/R² and k_x/R do not depend on the choice of R.</p>\n<table>\n"
    )
    w("<tr><th>quantity</th><th>value</th><th>unit</th><th>definition</th></tr>\n")
    defs = [
        ("N", "N", "∬ σ dA on the polar grid"),
        ("N_fe", "N", "exact integral over the FE faces"),
        ("R", "m", "r_max about the static centre of pressure"),
        ("F0", "N", "2π f R² A¹ = f N"),
        ("M0", "N m", "2π f R³ A²"),
        ("a", "", "(2A¹/A⁰)²"),
        ("m", "", "(2A²/A³)²"),
        ("b", "", "m/4"),
        ("b1", "N m", "M0/2"),
        ("f", "", "friction coefficient"),
        ("aR2", "m²", "a·R²"),
        ("m_over_R2", "1/m²", "m/R²"),
        ("k_x", "", "R·x_c/⟨x²⟩"),
        ("x_c", "m", "centre of pressure of the rolling map"),
    ]
    for key, unit, d in defs:
        if coef.get(key) is None:
            continue
        w(
            f"<tr><th>{_esc(key)}</th>{_num(coef[key], 'coefficients.' + key)}<td>{_esc(unit)}</td>"
            f"<td>{_esc(d)}</td></tr>\n"
        )
    for j in range(4):
        w(
            f"<tr><th>A{j}</th>{_num(coef['A'][j], f'coefficients.A.{j}')}<td>Pa</td>"
            f"<td>∫₀¹ σ̄₀(ρ) ρ^{j} dρ</td></tr>\n"
        )
    if coef.get("reaction_z") is not None:
        w(
            f"<tr><th>solver reaction</th>{_num(coef['reaction_z'], 'coefficients.reaction_z')}<td>N</td>"
            "<td>from the sidecar JSON</td></tr>\n"
        )
    w("</table>\n")

    # Patch
    pd = coef["patch"]
    verdict_cls = "ok" if pd["circular"] else "bad"
    w("<h2>Contact patch and circularity</h2>\n")
    w(
        f"<p class='verdict {verdict_cls}'>The static patch is {'circular' if pd['circular'] else 'NOT circular'} "
        f"(rule: {_esc(pd['circular_rule'])}).</p>\n<table>\n"
    )
    for key, unit in (
        ("r_max", "m"),
        ("r_equiv", "m"),
        ("aspect", ""),
        ("area", "m²"),
        ("load_outside_r_equiv", ""),
        ("planarity_rms", "m"),
    ):
        w(f"<tr><th>{_esc(key)}</th>{_num(pd[key], 'coefficients.patch.' + key)}<td>{_esc(unit)}</td></tr>\n")
    w(
        f"<tr><th>r_max / r_equiv</th>{_num(pd['r_max'] / pd['r_equiv'], None, '{:.4f}')}"
        "<td></td></tr>\n</table>\n"
    )
    for n in p.notes:
        w(f"<p class='note'>Note: {_esc(n)}</p>\n")
    w(ctx["figure_html"]["patch"])

    # Figures 1-3
    w("<h2>Contact pressure (Figures 1–3)</h2>\n")
    for key in ("fig1", "fig2", "fig3"):
        if key in ctx["figure_html"]:
            w(ctx["figure_html"][key])

    # Table 1
    t1 = ctx["table1"]
    settings = t1["settings"]
    noise = t1["noise_description"]
    w("<h2>Table 1: identification from noisy test curves</h2>\n")
    w(
        "<p>The paper's procedure (THEORY.md §6), as <code>fepost table1</code> runs it: "
        f"the {_esc(settings['source'].replace('_', '-'))} curves with this map's coefficients, "
        f"perturbed by {_esc(noise['kind'])} noise of amplitude {noise['fraction']:.0%} of each "
        f"curve's maximum (seed {_esc(settings['seed'])}), {settings['n_points_per_curve']} points "
        f"per curve on [0, {settings['span']:g}], fitted jointly by nonlinear least squares; "
        f"f = F0/N. Bounds are Wald 95 % bounds. k_x theory: {_esc(settings['k_x_source'])}.</p>\n"
    )
    w(
        "<table>\n<tr><th rowspan='2'>coef</th><th colspan='3'>this map</th><th colspan='3'>the paper's Table 1</th>"
        "</tr>\n<tr><th>theory</th><th>fitted</th><th>95 % bounds</th><th>theory</th><th>fitted</th>"
        "<th>95 % bounds</th></tr>\n"
    )
    for i, r in enumerate(t1["rows"]):
        lo, hi = r["ci95"]
        pp = r["paper"]
        w(
            f"<tr><th>{_esc(r['name'])}{' (' + _esc(r['unit']) + ')' if r['unit'] else ''}</th>"
            f"{_num(r['theory'], f'table1.rows.{i}.theory')}{_num(r['fitted'], f'table1.rows.{i}.fitted')}"
            f"<td class='num'><span data-key='table1.rows.{i}.ci95.0' data-value='{lo!r}'>{lo:.5g}</span>, "
            f"<span data-key='table1.rows.{i}.ci95.1' data-value='{hi!r}'>{hi:.5g}</span></td>"
            f"<td class='num'>{pp['theory']:g}</td><td class='num'>{pp['fitted']:g}</td>"
            f"<td class='num'>{pp['ci95'][0]:g}, {pp['ci95'][1]:g}</td></tr>\n"
        )
    w("</table>\n")
    notes = t1["notes"]
    w("<ul>\n")
    for n in notes:
        if not n.startswith("paper:"):
            w(f"<li class='note'>{_esc(n)}</li>\n")
    w("</ul>\n<p><b>The paper's numbers are not self-consistent</b> (THEORY.md §6):</p>\n<ul>\n")
    for n in notes:
        if n.startswith("paper:"):
            w(f"<li class='note'>{_esc(n.removeprefix('paper:').strip())}</li>\n")
    w("</ul>\n")
    b = t1.get("exact_bias")
    if b:
        w(
            "<p>Going further: the same fit on data made from the <em>exact</em> integrals (noise-free, then with "
            "the same noise). The noise-free fit's departure from the asymptotic values is the bias the "
            "square-root approximation itself causes.</p>\n<table>\n<tr><th>coef</th><th>asymptotic</th>"
            "<th>fit to exact, noise-free</th><th>relative bias</th><th>fit to exact + noise</th>"
            "<th>95 % bounds</th><th>bounds hold the asymptotic value</th></tr>\n"
        )
        for name in ("F0", "M0", "a", "m", "k_x"):
            nz = b["noisy_fit"][name]
            w(
                f"<tr><th>{name}</th>{_num(b['theory'][name], f'table1.exact_bias.theory.{name}')}"
                f"{_num(b['noise_free_fit'][name], f'table1.exact_bias.noise_free_fit.{name}')}"
                f"{_num(b['relative_bias'][name], f'table1.exact_bias.relative_bias.{name}', '{:+.2%}')}"
                f"{_num(nz['value'], f'table1.exact_bias.noisy_fit.{name}.value')}"
                f"<td class='num'>{nz['ci95'][0]:.5g}, {nz['ci95'][1]:.5g}</td>"
                f"<td>{'yes' if b['noisy_ci_covers_theory'][name] else '<b>no</b>'}</td></tr>\n"
            )
        w("</table>\n")

    # Closed form vs exact
    w("<h2>Closed forms against the exact integrals</h2>\n")
    w(
        "<p>The square-root closed forms (1.8) are approximations: with the asymptotic a and m of this map they depart "
        "from the exact Coulomb integrals (THEORY.md §3) by up to:</p>\n<table>\n<tr><th>curve</th>"
        "<th>max |exact − closed form| / scale</th><th>at</th><th>scale</th></tr>\n"
    )
    for key, e in ctx["errors"].items():
        cell = _num(e["max_abs_relative"], f"closed_form_vs_exact.{key}.max_abs_relative", "{:.3f}")
        w(
            f"<tr><th>{_esc(key)}</th>{cell}"
            f"<td>{_esc(e['x_name'])} = {e['at']:.3g}</td><td>{_esc(e['scale_name'])}</td></tr>\n"
        )
    w(
        "</table>\n<p class='note'>This is a finding about the model, not a numerical error: the exact integrals are "
        "computed with the singularity at the instantaneous centre of rotation subtracted analytically.</p>\n"
    )

    w("<h2>Friction curves (Figures 4–6)</h2>\n")
    for key in ("fig4", "fig5", "fig6"):
        if key in ctx["figure_html"]:
            w(ctx["figure_html"][key])

    w("<h2>Files</h2>\n<ul>\n")
    for f in ctx["files"]:
        w(f"<li><a href='{_esc(f)}'>{_esc(f)}</a></li>\n")
    w("</ul>\n")
    w(
        "<p class='small'>Step timings: "
        + ", ".join(f"{_esc(s)} {t:.1f} s" for s, t in ctx["timings"])
        + "</p>\n"
    )
    w("</body></html>\n")
    return out.getvalue()


def _figure(src: str, caption: str, extra: list[str] | None = None) -> str:
    links = ""
    if extra:
        links = (
            " ("
            + ", ".join(f"<a href='{_esc(e)}'>{_esc(e.rsplit('.', 1)[1].upper())}</a>" for e in extra)
            + ")"
        )
    return (
        f"<figure><img src='{_esc(src)}' alt='{_esc(caption.split('.')[0])}'>"
        f"<figcaption>{caption}{links}</figcaption></figure>\n"
    )


def build_report(
    static,
    rolling=None,
    out: str | Path = "report",
    *,
    force: bool = False,
    friction: float = 0.3,
    inflation_pressure: float | None = None,
    seed: int | None = DEFAULT_SEED,
    analysis_kwargs: dict | None = None,
    progress: Progress | None = None,
) -> ReportResult:
    """Run the pipeline and write the report folder ``out`` (see the module docstring).

    ``static``, ``rolling``: FE exports (paths) or :class:`~fepost.field.ContactField`;
    ``friction``: f; ``inflation_pressure``: P* in Pa (default: the static mesh's
    sidecar key ``inflation_pressure``, else 200 kPa); ``seed``: noise of Table 1
    (default :data:`fepost.table1.DEFAULT_SEED`, as ``fepost table1``);
    ``analysis_kwargs``: passed to :func:`fepost.analysis.analyse`;
    ``progress(k, n, step, seconds)``: called after each step.
    Raises :class:`~fepost.errors.OutputError` when ``out`` exists and is not
    empty (without ``force``) or cannot be written; nothing is left behind on error.
    """
    import matplotlib

    matplotlib.use("Agg")
    from importlib.metadata import PackageNotFoundError, version

    try:
        pkg_version = version("fepost")
    except PackageNotFoundError:
        pkg_version = "unknown"
    from .figures import diameter_sections, plot_curve, plot_patch_plan, plot_sections
    from .figures.curves import curve_table
    from .figures.patchplan import circularity_verdict
    from .figures.render import default_height_scale

    out = Path(out)
    if inflation_pressure is not None:
        _check_inflation_option(inflation_pressure)
    has_roll = rolling is not None
    steps = _Steps(total=8 + (1 if has_roll else 0), progress=progress)
    with staged_folder(out, force=force) as tmp:
        a = steps.run(
            "read and analyse the FE maps",
            analyse,
            static,
            rolling,
            friction=friction,
            **(analysis_kwargs or {}),
        )
        p_star, p_src = resolve_inflation_pressure(inflation_pressure, a)
        patches = [a.static_patch] + ([a.rolling_patch] if has_roll else [])
        hs = default_height_scale(*patches, inflation_pressure=p_star)
        clim = (0.0, max(float(np.max(pp.values)) for pp in patches) / 1e3)
        figs: dict[str, str] = {}
        files: list[str] = []

        steps.run(
            "render Figure 1 (static pressure)",
            _render,
            a.static_patch,
            tmp / "fig1_static.png",
            title="Figure 1: static contact pressure",
            p_star=p_star,
            height_scale=hs,
            clim=clim,
        )
        files.append("fig1_static.png")
        figs["fig1"] = _figure(
            "fig1_static.png",
            f"<b>Figure 1.</b> Static contact pressure over the FE contact patch: height σ₀/P* "
            f"(P* = {p_star / 1e3:g} kPa), colour σ₀ in kPa, lengths in mm in the patch frame (origin at the static "
            "centre of pressure, x = rolling direction). Black: the r_max circle (R); orange: the fitted ellipse.",
        )
        if has_roll:
            steps.run(
                "render Figure 2 (rolling pressure)",
                _render,
                a.rolling_patch,
                tmp / "fig2_rolling.png",
                title="Figure 2: rolling contact pressure",
                p_star=p_star,
                height_scale=hs,
                clim=clim,
            )
            files.append("fig2_rolling.png")
            figs["fig2"] = _figure(
                "fig2_rolling.png",
                "<b>Figure 2.</b> Contact pressure of the rolling tire at the same deflection, in the static patch's "
                "frame, same scales as Figure 1. Black: the r_max circle of the rolling map about the static origin; "
                "orange: its fitted ellipse.",
            )

        def fig3():
            sec = diameter_sections(a.static_patch, a.rolling_patch, inflation_pressure=p_star)
            return sec, _save_mpl(plot_sections(sec), tmp, "fig3_sections")

        sec, names = steps.run("Figure 3 (diameter sections)", fig3)
        files += names
        figs["fig3"] = _figure(
            "fig3_sections.png",
            "<b>Figure 3.</b> Contact pressure σ/P* along the x (rolling) and y (lateral) diameters through the "
            "static centre of pressure, interpolated with the FE elements themselves (not the polar map); "
            "static solid, rolling dashed; dotted lines at ±r_max.",
            names[1:],
        )
        names = steps.run(
            "patch plan figure",
            lambda: _save_mpl(plot_patch_plan(a.static_patch), tmp, "patch_plan"),
        )
        files += names
        figs["patch"] = _figure(
            "patch_plan.png",
            f"<b>Loaded region in plan.</b> FE faces coloured by the static pressure (kPa); black: r_max circle about "
            f"the centre of pressure (+); grey dashed: r_equiv = √(area/π); orange: the ellipse with the same second "
            f"moments of area. Verdict: {_esc(circularity_verdict(a.static_patch))}.",
            names[1:],
        )

        t = steps.run("Table 1 (identification fit and exact-data bias)", table1, a, seed=seed)
        fc = steps.run("exact friction integrals (Figures 4-6)", friction_curves, a, t)

        def curve_figs():
            out_names = []
            stems = {"F_parallel": "fig4_f_parallel", "M_C": "fig5_torque", "F_perp": "fig6_f_perp"}
            for cd in fc.curves:
                out_names.append(_save_mpl(plot_curve(cd), tmp, stems[cd.name]))
            return out_names

        caps = {
            "F_parallel": (
                "fig4",
                "<b>Figure 4.</b> Longitudinal friction force F∥ = −F_x against ψ = ω_z R/v.",
            ),
            "M_C": ("fig5", "<b>Figure 5.</b> Friction torque M_C = −M_z against υ = v/(ω_z R)."),
            "F_perp": (
                "fig6",
                "<b>Figure 6.</b> Lateral friction force F⊥ = −F_y against υ, on the rolling map.",
            ),
        }
        common = (
            " Blue: exact Coulomb integral over the FE map (THEORY.md §3); green dashed: the closed form (1.8) "
            "with this map's coefficients; grey points: the noisy test data of Table 1; red dash-dot: the "
            "fitted curve with its 95 % prediction band (shaded)."
        )
        for cd, names in zip(fc.curves, steps.run("Figures 4-6 (friction curves)", curve_figs), strict=True):
            files += names
            key, cap = caps[cd.name]
            figs[key] = _figure(names[0], cap + common, names[1:])

        def write_data():
            coef = a.to_dict()
            (tmp / "coefficients.json").write_text(to_json(coef) + "\n")
            t1_text = to_json(t.to_dict())
            (tmp / "table1.json").write_text(t1_text + "\n")
            errors_text = to_json(fc.errors_dict())
            (tmp / "closed_form_vs_exact.json").write_text(errors_text + "\n")
            header, rows = curve_table(fc.curves)
            with open(tmp / "curves.csv", "w", newline="") as fh:
                wr = csv.writer(fh)
                wr.writerow(header)
                wr.writerows(rows)
            all_files = sorted(
                files + ["coefficients.json", "table1.json", "closed_form_vs_exact.json", "curves.csv"]
            )
            ctx = {
                "analysis": a,
                "coef_json": json.loads(to_json(coef)),
                "table1": json.loads(t1_text),
                "errors": json.loads(errors_text),
                "figure_html": figs,
                "files": all_files,
                "p_star": p_star,
                "p_star_source": p_src,
                "seed": seed,
                "version": pkg_version,
                "timings": steps.done,
            }
            (tmp / "report.html").write_text(_html(ctx), encoding="utf-8")
            return all_files + ["report.html"]

        written = steps.run("write HTML, JSON and CSV", write_data)
    return ReportResult(out, tuple(written), tuple(steps.done), p_star, p_src)
