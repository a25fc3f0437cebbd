"""The exceptions and warnings fepost raises.

Every exception subclasses both `FepostError` and the matching built-in,
so callers may catch either. Messages are one line and name the file or the
argument at fault. The library raises and warns; only the CLI prints and exits.
"""

from __future__ import annotations


class FepostError(Exception):
    """Base class of every error fepost raises on purpose."""


class InputFileError(FepostError, OSError):
    """A file is missing, unreadable, corrupt or of an unknown format."""


class FieldError(FepostError, KeyError):
    """The contact-pressure (or another named) array is missing or ambiguous."""

    def __str__(self) -> str:  # KeyError quotes its message; keep it one plain line
        return str(self.args[0]) if self.args else ""


class PressureError(FepostError, ValueError):
    """The pressure values are unusable (NaN, negative, all zero, ...)."""


class PatchError(FepostError, ValueError):
    """The contact patch is empty, split, non-planar or otherwise unusable."""


class DimensionError(FepostError, ValueError):
    """A 2-D model (plane strain/stress or axisymmetric): its contact is a line, not a patch."""


class ScaleError(FepostError, ValueError):
    """Lengths or pressures at an implausible scale (a model read in the wrong units?)."""


class ArgumentError(FepostError, ValueError):
    """A function or command argument is out of its valid range."""


class DataError(FepostError, ValueError):
    """Measured or test data (CSV, curves) are malformed or implausible."""


class FitError(FepostError, RuntimeError):
    """A least-squares fit failed to converge or is not identifiable."""


class OutputError(FepostError, OSError):
    """An output file or folder cannot be written."""


class FepostWarning(UserWarning):
    """Base class of every warning fepost issues."""


class SentinelWarning(FepostWarning):
    """Sentinel values (e.g. -99999 for 'no contact data') were masked."""


class PressureWarning(FepostWarning):
    """Small negative pressures were clipped or values were otherwise repaired."""


class ReaderWarning(FepostWarning):
    """A file was read, but something in it was skipped, assumed or repaired."""


class ScaleWarning(FepostWarning):
    """Lengths, pressures or the load look implausible, or N disagrees with the solver's reaction."""


class PatchWarning(FepostWarning):
    """The patch is usable but departs from the method's assumptions."""


class FitWarning(FepostWarning):
    """A fit converged but its uncertainty is poorly determined."""


class OptionWarning(FepostWarning):
    """A command-line option is valid but implausible (e.g. ``--friction 3``)."""


class ClusterError(FepostError, RuntimeError):
    """The Dask cluster of a sweep cannot be reached, has no workers or went away."""
