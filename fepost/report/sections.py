"""Optional sections of the report: shown only when their data exist.

A section provider is a function ``provider(data, folder) -> Section | None``:
it gets the `ReportData` (the analysis, Table 1, the friction curves,
P*, ...) and the folder being written (to save figures or tables into), and
returns a `Section`, or ``None`` when it has nothing to show (then the
report has no trace of it). This module knows no provider: the report
registers the ones it runs, in page order, in ``fepost.report.providers``
(``DEFAULT_SECTIONS``); they come after the friction curves.

A section renders ``templates/sections/<template>`` with the names ``section``
(the `Section`) and ``figure`` (the figure macro) in scope; the generic
template ``generic.html.j2`` shows ``section.paragraphs`` (plain text),
``section.table`` (a header row and rows of plain values) and
``section.figures`` (each with ``section.captions[figure.key]``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from ..options import AnalysisOptions

if TYPE_CHECKING:
    from ..analysis import Analysis
    from ..table1 import Table1
    from .assemble import FrictionCurves
    from .figures import Figure


@dataclass(frozen=True)
class ReportData:
    """What a section provider may look at: the report's results, never recomputed.

    ``options``: the `fepost.options.AnalysisOptions` the report passed to
    `fepost.analysis.analyse`, so a provider that analyses further files can use
    the same ones.
    """

    analysis: Analysis
    table1: Table1
    curves: FrictionCurves
    inflation_pressure: float
    seed: int | None
    friction: float
    options: AnalysisOptions = field(default_factory=AnalysisOptions)
    gear: str | None = None


@dataclass(frozen=True)
class Section:
    """An optional section: ``key`` (HTML id), ``title`` and what its template shows.

    ``files``: names the provider wrote into the folder (listed under "Files");
    ``context``: anything else its own template needs.
    """

    key: str
    title: str
    template: str = "generic.html.j2"
    paragraphs: tuple[str, ...] = ()
    table: tuple[tuple[Any, ...], ...] = ()
    figures: tuple[Figure, ...] = ()
    captions: Mapping[str, str] = field(default_factory=dict)
    files: tuple[str, ...] = ()
    context: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "captions", MappingProxyType(dict(self.captions)))
        object.__setattr__(self, "context", MappingProxyType(dict(self.context)))
        files = tuple(self.files) + tuple(f for fig in self.figures for f in fig.files)
        object.__setattr__(self, "files", tuple(dict.fromkeys(files)))


SectionProvider = Callable[[ReportData, Path], "Section | None"]


def run_providers(providers, data: ReportData, folder: Path) -> list[Section]:
    """The sections the providers return, in order, skipping those that return ``None``."""
    out = []
    for provider in providers:
        section = provider(data, folder)
        if section is not None:
            out.append(section)
    return out
