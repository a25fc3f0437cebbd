"""``fepost diagnose``: what the simulation gets wrong against rig data, and why.

`diagnose` compares measured Fx, Fy, Mz (the measured-data CSV of
docs/diagnose.md) with the exact friction integrals over the FE contact
pressure. It fits every candidate cause (`CAUSES`)
as a physical extension of the model, robustly first to flag gross outliers
(`robust`) and under a noise model chosen per channel
(`noise`); names the cause the data support (BIC with
nesting tests and a held-out check, `selection`) and a
second one on top when the same rules admit it (`pairs`);
tests what is left for lack of fit (`lackfit`) and
measures the gain. `.synthetic` makes test data with effects, noise, gross
errors and drift hidden in them; `.example` writes an example CSV.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names
from .causenames import CAUSES

__all__ = ["CAUSES", "Diagnosis", "MeasuredData", "ParameterEstimate", "diagnose", "read_measured"]

#: Names re-exported from submodules, imported on first access: ``import fepost.diagnose``
#: (the command line's ``--cause`` choices) imports no numpy.
_LAZY = {
    "Diagnosis": "result",
    "MeasuredData": "measured",
    "ParameterEstimate": "result",
    "diagnose": "pipeline",
    "read_measured": "measured",
}

if TYPE_CHECKING:
    from .measured import MeasuredData, read_measured
    from .pipeline import diagnose
    from .result import Diagnosis, ParameterEstimate

__getattr__, __dir__ = lazy_names(__name__, _LAZY, globals())
