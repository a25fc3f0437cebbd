"""The rig as an optional section of ``fepost report``: the friction model against the FE with friction.

`rig_section` is registered in ``fepost.report.providers.DEFAULT_SECTIONS``.
When the report's static map sits in a folder holding slide/spin rig runs (a
run is ``<name>.vtu`` with a sidecar ``<name>.json`` that has ``kinematics``,
as ``meshes/rig/`` holds them beside its ``static.vtu``) it compares each run's
forces (the solver's reactions) with the exact Coulomb integrals over the
report's static map and with the same over the static map shifted by the
load-transfer law identified from the runs' own maps (`fepost.rig.compare`),
and returns a `fepost.report.Section` with the per-run table. Otherwise
(no runs beside the static map) it returns None and the report has no trace
of it. The runs are read only when they exist.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .sections import ReportData, Section

#: Title of the section.
TITLE = "The friction model against the FE with friction"


def rig_runs(folder: Path) -> list[Path]:
    """The rig runs in ``folder``: ``<name>.vtu`` whose sidecar ``<name>.json`` has ``kinematics``."""
    out = []
    for side in sorted(Path(folder).glob("*.json")):
        try:
            data = json.loads(side.read_text())
        except (OSError, ValueError):
            continue
        run = side.with_suffix(".vtu")
        if isinstance(data, dict) and "kinematics" in data and run.is_file():
            out.append(run)
    return out


#: Values below this (in f N or f N R) are rounding of sums that cancel: shown as 0.
ROUNDOFF = 1e-9


def shown(value: float) -> float:
    """``value`` as the table shows it: 0 (never −0, never −3.6e−16) within `ROUNDOFF` of zero."""
    v = float(value)
    return 0.0 if abs(v) < ROUNDOFF else v


def _text(m: dict) -> str:
    return (
        f"RMS |dF| {m['rms_F']:.4f} fN (max {m['max_F']:.4f}), "
        f"RMS dMz {m['rms_Mz']:.4f} fNR (max {m['max_Mz']:.4f})"
    )


def rig_section(data: ReportData, folder: Path) -> Section | None:
    """The rig comparison section, or None when no rig runs sit beside the report's static map."""
    source = getattr(data.analysis.static_field, "source", None)
    if not source:
        return None
    runs = rig_runs(Path(str(source)).parent)
    if not runs:
        return None
    from ..rig.compare import compare_runs
    from .sections import Section

    cmp = compare_runs(data.analysis, runs, options=getattr(data, "options", None))
    law = cmp.law
    pct = f"{law.level:.0%}"
    paragraphs = (
        f"{len(runs)} slide/spin runs of this tire on a rigid road with Coulomb friction "
        f"f = {cmp.friction:g} (the FE model as a test rig, fepost rig): forces of the road on "
        "the tire from the solver's reactions, in units of f N (Mz about the static patch "
        f"origin in f N R, R = {cmp.radius:.4g} m), N each run's load.",
        f"(b) exact Coulomb integrals over this static map: {_text(cmp.misfit('static'))}.",
        "(e) the same over the static map shifted by load transfer, dx = h_x Fx/N, dy = h_y Fy/N, "
        "h identified from the runs' own pressure maps (centre-of-pressure shift against the "
        f"shear-traction force per load): h_x = {law.h_x * 1e3:.2f} mm "
        f"({pct} interval {law.interval_x[0] * 1e3:.2f} to {law.interval_x[1] * 1e3:.2f}), "
        f"h_y = {law.h_y * 1e3:.2f} mm ({law.interval_y[0] * 1e3:.2f} to "
        f"{law.interval_y[1] * 1e3:.2f}); {_text(cmp.misfit('shifted'))}. h is identified on "
        "all these runs here; the held-out measure is in the rig study (scripts/rig_study.py).",
    )
    head = (
        "run",
        "vx (m/s)",
        "vy (m/s)",
        "wz (rad/s)",
        "Fx/fN",
        "Fy/fN",
        "Mz/fNR",
        "(b) |dF|/fN",
        "(e) |dF|/fN",
    )
    rows = []
    for i, name in enumerate(cmp.names):
        db = cmp.static[i, :2] - cmp.fe[i, :2]
        de = cmp.shifted[i, :2] - cmp.fe[i, :2]
        rows.append(
            (name, *(shown(v) for v in cmp.kinematics[i]), *(shown(v) for v in cmp.fe[i]),
             shown((db**2).sum() ** 0.5), shown((de**2).sum() ** 0.5))
        )  # fmt: skip
    return Section(key="rig", title=TITLE, paragraphs=paragraphs, table=(head, *rows))
