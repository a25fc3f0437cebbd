"""Landing-gear shimmy as an optional section of ``fepost report --gear GEAR.json``.

`shimmy_section` is registered in ``fepost.report.providers.DEFAULT_SECTIONS``. With a
gear file (``ReportData.gear``) it runs the shimmy study on the report's analysis
(`fepost.shimmy.study.shimmy_study`, linear stability with the coefficients'
intervals; the time simulations are left to ``fepost shimmy``), writes
``shimmy/shimmy.json`` and the stability-map figure, and returns a `Section`
with one row per friction model. Without a gear file it returns None.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .sections import ReportData, Section

#: Title of the section.
TITLE = "Landing-gear shimmy with the coupled friction model"


def _speed(stability) -> str:
    """The critical speed (the first onset), or the verdict over the sweep in words."""
    v = stability.critical_speed
    return stability.summary() if v is None else f"{v:.1f}"


def _ranges(ranges) -> str:
    if not ranges:
        return "none"
    return ", ".join(f"{a:.1f} to {'top' if b is None else f'{b:.1f}'}" for a, b in ranges)


def shimmy_section(data: ReportData, folder: Path) -> Section | None:
    """The shimmy section, or None when the report was given no gear file."""
    gear_path = getattr(data, "gear", None)
    if not gear_path:
        return None
    import matplotlib.pyplot as plt

    from ..output import to_json
    from ..shimmy import load_gear
    from ..shimmy.figures import STYLE, stability_figure
    from ..shimmy.study import shimmy_study
    from .figures import save_matplotlib
    from .sections import Section

    gear = load_gear(gear_path)
    result = shimmy_study(data.analysis, gear, simulate_motion=False, trails=0)
    sub = Path(folder) / "shimmy"
    sub.mkdir(exist_ok=True)
    (sub / "shimmy.json").write_text(to_json(result.to_dict()) + "\n", encoding="utf-8")
    import matplotlib

    with matplotlib.rc_context(STYLE):  # type: ignore[arg-type]  # matplotlib types keys as Literal
        fig = plt.figure()
        stability_figure(result, fig)
        fig.tight_layout()
        figure = save_matplotlib(
            fig, folder, "shimmy_stability", "shimmy_stability", "growth rate of the gear's motion over speed"
        )
    head = (
        "friction model",
        "critical speed (m/s)",
        "95 % interval (m/s)",
        "frequency (Hz)",
        "unstable (m/s)",
    )
    rows = []
    for m in result.models:
        ci = m.critical_speed_ci95
        freq = m.stability.critical_frequency
        rows.append(
            (
                m.name,
                _speed(m.stability),
                "" if ci is None else f"{ci[0]:.1f} to {ci[1]:.1f}",
                "" if freq is None else f"{freq:.1f}",
                _ranges(m.stability.unstable_ranges),
            )
        )
    name = gear.name or Path(str(gear_path)).name
    paragraphs = (
        f"Gear: {name} ({gear.wheels} wheel(s), trail {gear.trail:g} m, slip ratio {gear.slip_ratio:g}), "
        "each wheel carrying this tire's load. Straight rolling with longitudinal sliding is stable "
        "below the critical speed; the interval carries the coefficients' 95 % intervals of Table 1.",
        "Model, equations and the published anchor: docs/shimmy.md; the full study with time "
        "histories: fepost shimmy.",
    )
    return Section(
        key="shimmy",
        title=TITLE,
        paragraphs=paragraphs,
        table=(head, *rows),
        figures=(figure,),
        captions={figure.key: "Largest real part of the eigenvalues over speed, per friction model."},
        files=("shimmy/shimmy.json",),
    )
