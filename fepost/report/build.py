"""``build_report``: run the pipeline and write the report folder, step by step."""

from __future__ import annotations

import csv
import json
import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import __version__
from ..analysis import analyse
from ..errors import ReaderWarning
from ..friction.summary import ACCURACY_GRID
from ..options import DEFAULT_FRICTION, AnalysisOptions
from ..output import staged_folder, to_json
from ..table1 import DEFAULT_SEED, table1
from . import samples
from .assemble import friction_curves, page_context, resolve_inflation_pressure
from .figures import Figure, save_matplotlib, save_plotter
from .providers import DEFAULT_SECTIONS
from .rollinglabel import own_mesh_k_x, rolling_label
from .sections import ReportData, SectionProvider, run_providers

Progress = Callable[[int, int, str, float], None]

#: What each data file beside the report holds (shown in the page's file list).
FILE_NOTES = {
    "coefficients.json": "the coefficients, the patch and the inputs (as fepost coefficients --json)",
    "table1.json": "Table 1 (as fepost table1 --json, without its inputs)",
    "closed_form_vs_exact.json": "largest gap between the closed forms and the exact integrals",
    "curves.csv": "the curves of Figures 4–6 in long form",
    "error_map.json": (
        "errors of the closed forms and the generalised model over the kinematic sphere, static map"
    ),
    "error_map_rolling.json": "the same for the rolling map",
    "static_map.vtu": "the static polar map (σ in Pa, quadrature weights dA in m²)",
    "rolling_map.vtu": "the rolling polar map",
    "static_patch.vtp": "the loaded FE faces of the static map with their pressure (Pa)",
    "rolling_patch.vtp": "the loaded FE faces of the rolling map",
    "static_outline.vtp": "static patch: outline, frame axes, R and r_equiv circles, best-fit ellipse",
    "sweep/coefficients.csv": "the load sweep's table, one row per load (as fepost sweep writes it)",
    "sweep/coefficients.parquet": "the same table as Parquet, with each column's unit",
    "rolling_outline.vtp": "rolling patch: the same, in the static frame",
}
#: Grid of the error maps: the grid of every stated accuracy (the summary's error maps are
#: drawn, not computed again: `fepost.friction.summary.ACCURACY_GRID`).
ERROR_MAP_GRID = ACCURACY_GRID
#: Units of the closed-form error scales (curve -> unit).
CURVE_UNITS = {"f_parallel": "N", "torque": "N·m", "f_perp": "N"}


#: Which model's errors an error map's ``worst`` block gives for the accuracy keys.
_ACCURACY_KEYS = {"model": "model", "base": "base", "paper": "compare"}
_MAP_SIDES = (("error_map", "static"), ("error_map_rolling", "rolling"))


def quote_error_maps(ctx: dict, map_docs: dict, summary) -> None:
    """Make the page quote the error maps' largest errors wherever it quotes an error.

    The error maps are the model summary's (`fepost.friction.summary.ACCURACY_GRID`, the
    densest grid fepost evaluates, denser than the model's own check grid), so the
    coefficient table's model errors are the largest errors the maps show, each row
    citing the error map's JSON key, and the recommendation is the summary's own
    (the same sentence as ``fepost coefficients``). Which grid those rows are from is
    said once, in the table's group heading (``model_rows_grid``).
    """
    rows = []
    quoted = False
    for row in ctx.get("model_rows", []):
        for stem, side in _MAP_SIDES:
            doc = map_docs.get(stem)
            for name, prefix in _ACCURACY_KEYS.items():
                for what in ("force", "torque"):
                    if doc is None or row["key"] != f"coefficients.model.{side}.accuracy.{prefix}_{what}":
                        continue
                    value = doc["worst"][name][what]
                    row = {**row, "key": f"{stem}.worst.{name}.{what}", "value": value}
                    quoted = True
        rows.append(row)
    ctx["model_rows"] = rows
    ctx["model_rows_grid"] = (
        "the largest errors over the error map's grid, the densest evaluated" if quoted else ""
    )
    if ctx.get("model_recommendation"):
        ctx["model_recommendation"] = summary.recommendation()


def inflation_pressure_of(option: float | None, a) -> tuple[float, str]:
    """P* and where it came from; a `ReaderWarning` when neither the option nor the sidecar gives it."""
    p_star, p_src = resolve_inflation_pressure(option, a)
    if p_src.startswith("default"):
        warnings.warn(
            f"{a.static_field.source}: no inflation pressure given (no sidecar 'inflation_pressure' or "
            f"'model.inflation_pressure', no --inflation-pressure): the paper's P* = {p_star / 1e3:g} kPa "
            "is assumed for sigma/P* in Figures 1-3",
            ReaderWarning,
            stacklevel=3,
        )
        p_src = (
            f"NOT GIVEN: the paper's {p_star / 1e3:g} kPa assumed (no sidecar inflation_pressure or "
            "model.inflation_pressure, no --inflation-pressure); the σ/P* axes of Figures 1–3 depend on it"
        )
    return p_star, p_src


@dataclass(frozen=True)
class ReportResult:
    """What `build_report` wrote: the folder, its files and the time per step (s)."""

    out: Path
    files: tuple[str, ...]
    timings: tuple[tuple[str, float], ...]
    inflation_pressure: float
    inflation_pressure_source: str

    def __repr__(self) -> str:
        total = sum(t for _, t in self.timings)
        return (
            f"ReportResult(out={str(self.out)!r}, files={len(self.files)}, seconds={total:.1f}, "
            f"inflation_pressure={self.inflation_pressure:g} Pa)"
        )

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


def build_report(
    static=None,
    rolling=None,
    out: str | Path = "report",
    *,
    force: bool = False,
    friction: float = DEFAULT_FRICTION,
    options: AnalysisOptions | None = None,
    inflation_pressure: float | None = None,
    seed: int | None = DEFAULT_SEED,
    progress: Progress | None = None,
    sections: Sequence[SectionProvider] = DEFAULT_SECTIONS,
    gear: str | Path | None = None,
) -> ReportResult:
    """Run the pipeline and write the report folder ``out`` (see `fepost.report`).

    Parameters
    ----------
    static, rolling : path or ContactField, optional
        FE exports (or `fepost.field.ContactField`). Without ``static`` the sample
        meshes of `fepost.report.samples` are used (both).
    out : path
        The folder to write; created whole or not at all.
    force : bool
        Replace a non-empty ``out``.
    friction : float
        Friction coefficient f (dimensionless).
    options : AnalysisOptions, optional
        How to read and resample the maps (`fepost.analysis.analyse`); its
        ``inflation_pressure`` is P* in Pa, the pressure scale of Figures 1–3
        (default: the static mesh's sidecar key ``inflation_pressure``, else the
        paper's 200 kPa, with a `ReaderWarning`).
    inflation_pressure : float, optional
        P* in Pa, replacing ``options.inflation_pressure``.
    seed : int, optional
        Seed of Table 1's noise (default `fepost.table1.DEFAULT_SEED`, as ``fepost table1``).
    progress : callable, optional
        ``progress(k, n, step, seconds)``, called after each step.
    sections : sequence of section providers
        Optional sections (`fepost.report.sections`), default
        `fepost.report.providers.DEFAULT_SECTIONS`.
    gear : path, optional
        A landing-gear file: adds the shimmy section (`fepost.report.shimmysection`).

    Raises
    ------
    OutputError
        ``out`` exists and is not empty (without ``force``), holds the input
        files, the sample meshes, the current or the home folder (even with
        ``force``), or cannot be written; nothing is left behind on error.
    """
    import matplotlib

    matplotlib.use("Agg")
    if static is None:
        static, rolling = samples.sample_inputs()
    opts = AnalysisOptions.make(options, inflation_pressure=inflation_pressure)
    steps = _Steps(total=12 + (1 if rolling is not None else 0), progress=progress)
    inputs = [Path(p) for p in (static, rolling) if isinstance(p, str | os.PathLike)]
    # the sample folder is looked up now, not at import
    with staged_folder(Path(out), force=force, protect=[*inputs, samples.meshes_folder()]) as tmp:
        a = steps.run(
            "read and analyse the FE maps", analyse, static, rolling, friction=friction, options=opts
        )
        p_star, p_src = inflation_pressure_of(opts.inflation_pressure, a)
        figs = _pressure_figures(steps, a, tmp, p_star)
        t = steps.run("Table 1 (identification fit and exact-data bias)", table1, a, seed=seed)
        fc = steps.run("exact friction integrals (Figures 4-6)", friction_curves, a, t)
        figs.update(steps.run("Figures 4-6 (friction curves)", _curve_figures, fc, tmp))
        steps.run("generalised friction model of the maps", lambda: a.model_summary)
        maps, map_docs = steps.run("error maps (closed forms and generalised model)", _error_maps, a, tmp)
        figs.update(maps)
        vtk_names = steps.run("VTK files of the polar maps and patches", _vtk_files, a, tmp)
        data = ReportData(
            a, t, fc, p_star, seed, a.coefficients.f, options=opts, gear=None if gear is None else str(gear)
        )
        extra = steps.run("optional sections", run_providers, sections, data, tmp)
        page = _Page(
            a, t, fc, map_docs, figs, [*vtk_names, *(f for x in extra for f in x.files)], extra, opts
        )
        written = steps.run("write HTML, JSON and CSV", _write_page, page, tmp, steps, p_star, p_src, seed)
    return ReportResult(Path(out), tuple(written), tuple(steps.done), p_star, p_src)


def _pressure_figures(steps: _Steps, a, tmp: Path, p_star: float) -> dict[str, Figure]:
    """Figures 1–3 (pressure surfaces and diameter sections) and the patch plan."""
    from ..figures import diameter_sections, plot_patch_plan, plot_sections
    from ..figures.patchplan import pressure_colour_range
    from ..figures.render import EXTENT_FACTOR, default_height_scale, pressure_surface

    patches = [a.static_patch] + ([a.rolling_patch] if a.rolling_patch is not None else [])
    hs = default_height_scale(*patches, inflation_pressure=p_star)
    clim = pressure_colour_range(*patches)  # one colour scale: Figures 1, 2 and the patch plan
    extent = max(pp.r_max for pp in patches) * EXTENT_FACTOR

    def render(patch, stem, key, title, symbol):
        pl = pressure_surface(
            patch,
            inflation_pressure=p_star,
            title=title,
            height_scale=hs,
            clim=clim,
            extent=extent,
            symbol=symbol,
        )
        return save_plotter(pl, tmp, stem, key, title)

    def fig3():
        sec = diameter_sections(a.static_patch, a.rolling_patch, inflation_pressure=p_star)
        alt = "Figure 3: contact pressure along the x and y diameters"
        return save_matplotlib(plot_sections(sec), tmp, "fig3_sections", "fig3", alt)

    figs: dict[str, Figure] = {}
    figs["fig1"] = steps.run(
        "render Figure 1 (static pressure)",
        render, a.static_patch, "fig1_static", "fig1", "Figure 1: static contact pressure", "σ₀",
    )  # fmt: skip
    if a.rolling_patch is not None:
        label = rolling_label(a.rolling_field.sidecar if a.rolling_field is not None else None)
        figs["fig2"] = steps.run(
            "render Figure 2 (rolling pressure)",
            render, a.rolling_patch, "fig2_rolling", "fig2",
            f"Figure 2: contact pressure, {label.short}", "σᵥ",
        )  # fmt: skip
    figs["fig3"] = steps.run("Figure 3 (diameter sections)", fig3)
    figs["patch"] = steps.run(
        "patch plan figure",
        lambda: save_matplotlib(
            plot_patch_plan(a.static_patch, clim=clim),
            tmp,
            "patch_plan",
            "patch",
            "The loaded region in plan",
        ),
    )
    return figs


def _curve_figures(fc, tmp: Path) -> dict[str, Figure]:
    """Figures 4–6: the friction curves."""
    from ..figures import plot_curve

    stems = {
        "F_parallel": ("fig4_f_parallel", "fig4"),
        "M_C": ("fig5_torque", "fig5"),
        "F_perp": ("fig6_f_perp", "fig6"),
    }
    made = {}
    for cd in fc.curves:
        stem, key = stems[cd.name]
        alt = cd.title.replace("$", "").replace("\\", "")
        made[key] = save_matplotlib(plot_curve(cd), tmp, stem, key, alt)
    return made


def _error_maps(a, tmp: Path) -> tuple[dict[str, Figure], dict[str, dict]]:
    """The error maps of the static (and rolling) map: figures and their JSON documents."""
    from ..figures.errormap import plot_error_map

    made, docs = {}, {}
    for stem, rolling in (("error_map", False), ("error_map_rolling", True)):
        if rolling and a.rolling_map is None:
            continue
        em = a.model_summary.rolling_errors if rolling else a.model_summary.static_errors
        key = stem.replace("_", "-")
        alt = f"Error map of the {'rolling' if rolling else 'static'} map: closed forms and generalised model"
        made[key] = save_matplotlib(plot_error_map(em), tmp, stem, key, alt)
        docs[stem] = em.to_dict()
    return made, docs


def _vtk_files(a, tmp: Path) -> list[str]:
    """VTK files of the polar maps and the patches."""
    from .vtkfiles import write_vtk_files

    names = write_vtk_files(tmp, "static", a.static_map, a.static_patch, a.static_patch)
    if a.rolling_map is not None and a.rolling_patch is not None:
        names += write_vtk_files(tmp, "rolling", a.rolling_map, a.rolling_patch, a.static_patch)
    return names


@dataclass(frozen=True)
class _Page:
    """What the page is written from: the results, the figures and the files made so far."""

    analysis: Any
    table1: Any
    curves: Any
    map_docs: dict
    figures: dict
    files: list
    sections: list
    options: AnalysisOptions | None = None


def _write_data(page: _Page, tmp: Path) -> dict[str, str]:
    """The JSON and CSV files beside the page; their texts by name."""
    from ..figures.curves import curve_table

    texts = {
        "coefficients.json": to_json(page.analysis.to_dict()),
        "table1.json": to_json(page.table1.to_dict()),
        "closed_form_vs_exact.json": to_json(page.curves.errors_dict()),
    }
    texts.update({f"{stem}.json": to_json(doc) for stem, doc in page.map_docs.items()})
    for name, text in texts.items():
        (tmp / name).write_text(text + "\n", encoding="utf-8")
    header, rows = curve_table(page.curves.curves)
    with open(tmp / "curves.csv", "w", newline="", encoding="utf-8") as fh:
        wr = csv.writer(fh)
        wr.writerow(header)
        wr.writerows(rows)
    return texts


def _write_page(page: _Page, tmp: Path, steps: _Steps, p_star, p_src, seed) -> list[str]:
    """Write the data files and ``report.html``; the names of everything written."""
    from ..figures.patchplan import circularity_verdict
    from ..figures.render import EDGE_FRACTION
    from .html import render_report

    a = page.analysis
    texts = _write_data(page, tmp)
    files = [f for fig in page.figures.values() for f in fig.files] + page.files
    files = sorted(set(files) | set(texts) | {"curves.csv"})
    ctx = page_context(
        a,
        json.loads(texts["coefficients.json"]),
        json.loads(texts["table1.json"]),
        json.loads(texts["closed_form_vs_exact.json"]),
        p_star=p_star,
        p_star_source=p_src,
        seed=seed,
        version=__version__,
        error_maps={stem: json.loads(texts[f"{stem}.json"]) for stem in page.map_docs},
        own_mesh=own_mesh_k_x(a, friction=a.coefficients.f, options=page.options),
    )
    quote_error_maps(ctx, page.map_docs, a.model_summary)
    ctx.update(
        figures=page.figures,
        files=files,
        file_notes=FILE_NOTES,
        sections=page.sections,
        timings=list(steps.done),
        verdict=circularity_verdict(a.static_patch),
        edge_fraction=EDGE_FRACTION,
        curve_units=CURVE_UNITS,
    )
    (tmp / "report.html").write_text(render_report(ctx), encoding="utf-8")
    return files + ["report.html"]
