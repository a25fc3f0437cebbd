"""fepost: FE tire–road contact results → coefficients of a coupled dry-friction model.

Python API (the CLI is a thin shell over it):

* :func:`fepost.reader.read_contact` – FE export → :class:`~fepost.field.ContactField`
* :func:`fepost.patch.build_patch` – loaded region, plane, frame, circularity
* :func:`fepost.resample.resample` – FE interpolation onto a :class:`~fepost.polar.PolarGrid`
* :func:`fepost.moments.moments`, :func:`fepost.coefficients.coefficients_from_moments`
* :func:`fepost.analysis.analyse` – all of the above in one call
"""

from .analysis import Analysis, analyse

__all__ = ["Analysis", "analyse", "__version__"]
__version__ = "0.1.0"
