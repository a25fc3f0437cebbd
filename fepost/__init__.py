"""fepost: FE tire–road contact results → coefficients of a coupled dry-friction model.

Python API (the CLI is a thin shell over it):

* `fepost.reader.read_contact` – FE export → `ContactField`
* `fepost.patch.build_patch` – loaded region, plane, frame, circularity
* `fepost.resample.resample` – FE interpolation onto a `PolarGrid`
* `fepost.moments.moments`, `fepost.coefficients.coefficients_from_moments`
* `fepost.analysis.analyse` – all of the above in one call

``import fepost`` is light: ``fepost.analyse`` and ``fepost.Analysis`` import the
pipeline (numpy, scipy, VTK) on first use, so the command line starts quickly.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._lazy import lazy_names

__all__ = ["Analysis", "analyse", "__version__"]
__version__ = "0.1.0"

#: Names re-exported from submodules, imported on first access.
_LAZY = {"Analysis": "analysis", "analyse": "analysis"}

if TYPE_CHECKING:
    from .analysis import Analysis, analyse

__getattr__, __dir__ = lazy_names(__name__, _LAZY, globals())
