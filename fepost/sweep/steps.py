"""Which time steps an FE export holds: the one question the sweep asks the reader.

A thin adapter over `fepost.reader.time_steps` (which reads the Exodus
header in a child process, so a hostile file cannot take the worker down),
giving the sweep what it needs: the time values, or None for a file that is
one state.
"""

from __future__ import annotations

from pathlib import Path

from ..reader import EXODUS_SUFFIXES, FRD_SUFFIXES, XDMF_SUFFIXES

#: Suffixes of formats that hold a series of time steps (Exodus II, XDMF time series,
#: CalculiX .frd increments).
SERIES_SUFFIXES = tuple(s.lower() for s in (*EXODUS_SUFFIXES, *XDMF_SUFFIXES, *FRD_SUFFIXES))


def time_steps(path: str | Path, units=None) -> tuple[float, ...] | None:
    """Time values (s) of the steps in ``path``.

    Step ``k`` of the result is the ``step=k`` of `fepost.reader.read_contact`.
    ``units`` is the model's unit system (it scales the times), as in the reader.

    Returns
    -------
    tuple of float, or None
        None for a file that is not a time series (VTK files) or an Exodus file
        without time steps: such a file is one row, read with ``step=None``.

    Raises
    ------
    InputFileError
        The file is missing, unreadable or not a supported FE export.
    """
    from ..reader import time_steps as reader_steps

    steps = reader_steps(path, units=units)
    if len(steps) == 1 and steps[0].index is None:
        return None
    return tuple(float(s.time) if s.time is not None else float("nan") for s in steps)
