"""``fepost diagnose``: what the simulation gets wrong against rig data, and why.

:func:`diagnose` compares measured Fx, Fy, Mz (the measured-data CSV of docs/diagnose.md) with the
exact friction integrals over the FE contact pressure, fits every candidate cause
(:data:`~fepost.diagnose.causes.CAUSES`) as a physical extension of the model,
names the one the data support (BIC with nesting tests and a held-out check,
:mod:`~fepost.diagnose.selection`) and measures the gain. :mod:`.synthetic` makes
test data with one effect hidden in it.
"""

from .causes import CAUSES
from .measured import MeasuredData, read_measured
from .pipeline import diagnose
from .result import Diagnosis, ParameterEstimate

__all__ = ["CAUSES", "Diagnosis", "MeasuredData", "ParameterEstimate", "diagnose", "read_measured"]
