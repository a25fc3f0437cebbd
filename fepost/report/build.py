"""``build_report``: run the pipeline and write the report folder, step by step."""

from __future__ import annotations

import csv
import json
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import __version__
from ..analysis import analyse
from ..output import staged_folder, to_json
from ..table1 import DEFAULT_SEED, table1
from . import samples
from .assemble import check_inflation_option, friction_curves, page_context, resolve_inflation_pressure
from .figures import Figure, save_matplotlib, save_plotter
from .providers import DEFAULT_SECTIONS
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
#: Grid of the error maps: sliding directions β in [0°, 180°] and meridian points t in [0, 1]
#: (10° and 1/32 steps: the maps show where the errors lie; the largest errors of the
#: generalised model on its own, finer check grid are in coefficients.json "model").
ERROR_MAP_GRID = {"n_beta": 19, "n_t": 33}
#: Units of the closed-form error scales (curve -> unit).
CURVE_UNITS = {"f_parallel": "N", "torque": "N·m", "f_perp": "N"}


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


def build_report(
    static=None,
    rolling=None,
    out: str | Path = "report",
    *,
    force: bool = False,
    friction: float = 0.3,
    inflation_pressure: float | None = None,
    seed: int | None = DEFAULT_SEED,
    analysis_kwargs: dict | None = None,
    progress: Progress | None = None,
    sections: Sequence[SectionProvider] = DEFAULT_SECTIONS,
) -> ReportResult:
    """Run the pipeline and write the report folder ``out`` (see :mod:`fepost.report`).

    Parameters
    ----------
    static, rolling : path or ContactField, optional
        FE exports (or :class:`~fepost.field.ContactField`). Without ``static``
        the sample meshes of :mod:`fepost.report.samples` are used (both).
    out : path
        The folder to write; created whole or not at all.
    force : bool
        Replace a non-empty ``out``.
    friction : float
        Friction coefficient f (dimensionless).
    inflation_pressure : float, optional
        P* in Pa (default: the static mesh's sidecar key ``inflation_pressure``,
        else 200 kPa), the pressure scale of Figures 1–3.
    seed : int, optional
        Seed of Table 1's noise (default :data:`fepost.table1.DEFAULT_SEED`, as
        ``fepost table1``).
    analysis_kwargs : dict, optional
        Passed to :func:`fepost.analysis.analyse`.
    progress : callable, optional
        ``progress(k, n, step, seconds)``, called after each step.
    sections : sequence of section providers
        Optional sections (:mod:`fepost.report.sections`), default
        :data:`~fepost.report.providers.DEFAULT_SECTIONS`.

    Raises
    ------
    OutputError
        ``out`` exists and is not empty (without ``force``), holds the input
        files, the sample meshes, the current or the home folder (even with
        ``force``), or cannot be written; nothing is left behind on error.
    """
    import matplotlib

    matplotlib.use("Agg")
    from ..figures import diameter_sections, plot_curve, plot_patch_plan, plot_sections
    from ..figures.curves import curve_table
    from ..figures.patchplan import circularity_verdict
    from ..figures.render import EDGE_FRACTION, EXTENT_FACTOR, default_height_scale, pressure_surface
    from .html import render_report
    from .vtkfiles import write_vtk_files

    if static is None:
        static, rolling = samples.sample_inputs()
    out = Path(out)
    if inflation_pressure is not None:
        check_inflation_option(inflation_pressure)
    has_roll = rolling is not None
    steps = _Steps(total=12 + (1 if has_roll else 0), progress=progress)
    inputs = [Path(p) for p in (static, rolling) if isinstance(p, str | os.PathLike)]
    with staged_folder(
        out, force=force, protect=[*inputs, samples.meshes_folder()]
    ) as tmp:  # looked up now, not at import
        a = steps.run(
            "read and analyse the FE maps",
            analyse,
            static,
            rolling,
            friction=friction,
            **(analysis_kwargs or {}),
        )
        p_star, p_src = resolve_inflation_pressure(inflation_pressure, a)
        patches = [a.static_patch] + ([a.rolling_patch] if a.rolling_patch is not None else [])
        hs = default_height_scale(*patches, inflation_pressure=p_star)
        clim = (0.0, max(float(np.max(pp.values)) for pp in patches) / 1e3)
        figs: dict[str, Figure] = {}

        extent = max(pp.r_max for pp in patches) * EXTENT_FACTOR

        def render(patch, stem, key, title):
            pl = pressure_surface(
                patch, inflation_pressure=p_star, title=title, height_scale=hs, clim=clim, extent=extent
            )
            return save_plotter(pl, tmp, stem, key, title)

        figs["fig1"] = steps.run(
            "render Figure 1 (static pressure)",
            render,
            a.static_patch,
            "fig1_static",
            "fig1",
            "Figure 1: static contact pressure",
        )
        if a.rolling_patch is not None:
            figs["fig2"] = steps.run(
                "render Figure 2 (rolling pressure)",
                render,
                a.rolling_patch,
                "fig2_rolling",
                "fig2",
                "Figure 2: rolling contact pressure",
            )

        def fig3():
            sec = diameter_sections(a.static_patch, a.rolling_patch, inflation_pressure=p_star)
            alt = "Figure 3: contact pressure along the x and y diameters"
            return save_matplotlib(plot_sections(sec), tmp, "fig3_sections", "fig3", alt)

        figs["fig3"] = steps.run("Figure 3 (diameter sections)", fig3)
        figs["patch"] = steps.run(
            "patch plan figure",
            lambda: save_matplotlib(
                plot_patch_plan(a.static_patch), tmp, "patch_plan", "patch", "The loaded region in plan"
            ),
        )
        t = steps.run("Table 1 (identification fit and exact-data bias)", table1, a, seed=seed)
        fc = steps.run("exact friction integrals (Figures 4-6)", friction_curves, a, t)

        def curve_figs():
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

        figs.update(steps.run("Figures 4-6 (friction curves)", curve_figs))

        def error_maps():
            from ..figures.errormap import plot_error_map
            from ..friction.law import FrictionLaw
            from ..friction.summary import model_error_map

            made, docs = {}, {}
            for stem, rolling in (("error_map", False), ("error_map_rolling", True)):
                if rolling and a.rolling_map is None:
                    continue
                pmap = a.rolling_map if rolling else a.static_map
                model = a.model_summary.rolling if rolling else a.model_summary.static
                law = FrictionLaw(f=a.coefficients.f)
                em = model_error_map(
                    pmap, a.coefficients, law, model=model, rolling=rolling, **ERROR_MAP_GRID
                )
                key = stem.replace("_", "-")
                alt = (
                    f"Error map of the {'rolling' if rolling else 'static'} map: "
                    "closed forms and generalised model"
                )
                made[key] = save_matplotlib(plot_error_map(em), tmp, stem, key, alt)
                docs[stem] = em.to_dict()
            return made, docs

        steps.run("generalised friction model of the maps", lambda: a.model_summary)
        maps, map_docs = steps.run("error maps (closed forms and generalised model)", error_maps)
        figs.update(maps)

        def vtk_files():
            names = write_vtk_files(tmp, "static", a.static_map, a.static_patch, a.static_patch)
            if a.rolling_map is not None and a.rolling_patch is not None:
                names += write_vtk_files(tmp, "rolling", a.rolling_map, a.rolling_patch, a.static_patch)
            return names

        vtk_names = steps.run("VTK files of the polar maps and patches", vtk_files)
        data = ReportData(a, t, fc, p_star, seed, friction, analysis_kwargs or {})
        extra = steps.run("optional sections", run_providers, sections, data, tmp)

        def write_data():
            coef = a.to_dict()
            texts = {
                "coefficients.json": to_json(coef),
                "table1.json": to_json(t.to_dict()),
                "closed_form_vs_exact.json": to_json(fc.errors_dict()),
            }
            texts.update({f"{stem}.json": to_json(doc) for stem, doc in map_docs.items()})
            for name, text in texts.items():
                (tmp / name).write_text(text + "\n", encoding="utf-8")
            header, rows = curve_table(fc.curves)
            with open(tmp / "curves.csv", "w", newline="", encoding="utf-8") as fh:
                wr = csv.writer(fh)
                wr.writerow(header)
                wr.writerows(rows)
            files = [f for fig in figs.values() for f in fig.files] + vtk_names
            files += [f for s in extra for f in s.files]
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
                error_maps={stem: json.loads(texts[f"{stem}.json"]) for stem in map_docs},
            )
            ctx.update(
                figures=figs,
                files=files,
                file_notes=FILE_NOTES,
                sections=extra,
                timings=list(steps.done),
                verdict=circularity_verdict(a.static_patch),
                edge_fraction=EDGE_FRACTION,
                curve_units=CURVE_UNITS,
            )
            (tmp / "report.html").write_text(render_report(ctx), encoding="utf-8")
            return files + ["report.html"]

        written = steps.run("write HTML, JSON and CSV", write_data)
    return ReportResult(out, tuple(written), tuple(steps.done), p_star, p_src)
