"""The optional sections ``fepost report`` runs: the report registers them here.

``fepost.report.sections`` defines what a section is (``ReportData``,
``Section``, ``run_providers``) and knows no provider; each provider module
imports it, and this module lists the providers, in page order, so no
provider is imported by the module it depends on (no import cycle).

Two providers: the load sweep of the sample aircraft tire
(``fepost.report.sweepsection.sample_sweep_section``), shown in the report of
one of its cases, and the slide/spin rig runs beside the report's static map
(``fepost.report.rigsection.rig_section``). Each imports its heavier parts only
when it runs.
"""

from __future__ import annotations

from .rigsection import rig_section
from .sections import SectionProvider
from .shimmysection import shimmy_section
from .sweepsection import sample_sweep_section

#: Providers run by ``fepost report``, in page order.
DEFAULT_SECTIONS: tuple[SectionProvider, ...] = (sample_sweep_section, rig_section, shimmy_section)
