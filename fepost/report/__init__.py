"""The report: every figure, the coefficients and Table 1 in one folder (``fepost report``).

`build_report` runs the pipeline on a static (and optionally a rolling) FE
map and writes into ``out``:

==============================  ====================================================
``report.html``                 the report, self-contained: figures embedded as
                                ``data:`` URIs, style inlined
``fig1_static.png``             Figure 1: static pressure over the FE patch (3-D)
``fig2_rolling.png``            Figure 2: rolling pressure (3-D; with a rolling map)
``fig3_sections.*``             Figure 3: pressure along the x and y diameters
                                (PNG, SVG, PDF)
``patch_plan.*``                the loaded region in plan with the circularity check
``fig4_f_parallel.*``           Figure 4: F∥(ψ)
``fig5_torque.*``               Figure 5: M_C(υ)
``fig6_f_perp.*``               Figure 6: F⊥(υ) (with a rolling map)
``error_map.*``                 error of the closed forms and of the generalised
                                model over the kinematic sphere (PNG, SVG, PDF;
                                ``error_map_rolling.*`` with a rolling map)
``error_map.json``              `fepost.friction.sphere.ErrorMap.to_dict`
                                of that map (``error_map_rolling.json``)
``coefficients.json``           `fepost.analysis.Analysis.to_dict`
``table1.json``                 `fepost.table1.Table1.to_dict` (``rows`` of
                                name, theory, fitted, ci95)
``closed_form_vs_exact.json``   `FrictionCurves.errors_dict`: largest gap
                                between the closed forms and the exact integrals
``curves.csv``                  the curves of Figures 4–6 in long form
``static_map.vtu``              the polar maps, patches and outlines as VTK files
``static_patch.vtp``            for ParaView (`fepost.report.vtkfiles`; and
``static_outline.vtp``          ``rolling_*`` with a rolling map)
``sweep/``                      the optional sections' files: the load sweep of the
                                sample tire in its report (`.sections`)
==============================  ====================================================

Everything is written into a temporary folder beside ``out`` and moved into
place only when every step succeeded (`fepost.output.staged_folder`).

Table 1 is `fepost.table1.table1` with its defaults (the same call as
``fepost table1``, so ``table1.json`` equals ``fepost table1 --json`` on the same
inputs and seed, default `fepost.table1.DEFAULT_SEED`): the closed-form
curves (1.8) with the map's coefficients, 20 % uniform noise, a joint
least-squares fit, and the same fit on exact-integral data for the bias of the
approximation. Figures 4–6 show its test points and fitted curves with their
95 % prediction band (`fepost.identify.Identification.prediction_band`),
and the generalised model of the FE maps (Table 1's generalised form).

The subpackage, by job: `.assemble` (the data the page shows),
`.figures` (saving and embedding figures), `.vtkfiles` (VTK output),
`.sections` (what an optional section is), `.providers` (the sections
the report registers), `.sweepsection` (a sweep as a section),
`.sweeppage` and `.sweepembed` (a sweep's trends page and its
embeddable HTML section), `.html` (the Jinja2 templates in
``templates/``), `.build` (the steps), `.samples` (the default inputs),
`.rollinglabel` (what the rolling map is, from its sidecar).
Names are imported on first use, so ``import fepost.report`` stays cheap.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .assemble import (
        CURVE_POINTS,
        DEFAULT_INFLATION_PRESSURE,
        FrictionCurves,
        friction_curves,
        resolve_inflation_pressure,
    )
    from .build import ReportResult, build_report
    from .sections import ReportData, Section

_WHERE = {
    "build_report": "build",
    "ReportResult": "build",
    "FrictionCurves": "assemble",
    "friction_curves": "assemble",
    "resolve_inflation_pressure": "assemble",
    "DEFAULT_INFLATION_PRESSURE": "assemble",
    "CURVE_POINTS": "assemble",
    "Section": "sections",
    "ReportData": "sections",
}

__all__ = [
    "CURVE_POINTS",
    "DEFAULT_INFLATION_PRESSURE",
    "FrictionCurves",
    "ReportData",
    "ReportResult",
    "Section",
    "build_report",
    "friction_curves",
    "resolve_inflation_pressure",
]


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        from importlib import import_module

        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
