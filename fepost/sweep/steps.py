"""Which time steps an FE export holds: the one question the sweep asks the reader.

:func:`time_steps` is an adapter: it lists the time values of an Exodus II
series through VTK's Exodus reader (metadata only, no field data), the reader
:func:`fepost.reader.read_contact` itself uses. It is kept to this one function
so that it can be replaced by the reader's own step listing without touching
the rest of the sweep.
"""

from __future__ import annotations

import logging
import warnings
from pathlib import Path

from ..errors import InputFileError

#: Suffixes of formats that hold a series of time steps (Exodus II).
SERIES_SUFFIXES = (".e", ".exo", ".ex2", ".exii")


def time_steps(path: str | Path) -> tuple[float, ...] | None:
    """Time values (s, or the solver's own time unit) of the steps in ``path``.

    Step ``k`` of the result is the ``step=k`` of :func:`fepost.reader.read_contact`.

    Returns
    -------
    tuple of float, or None
        None for a file that is not a time series (VTK files) or an Exodus file
        without time steps: such a file is one row, read with ``step=None``.

    Raises
    ------
    InputFileError
        The file is missing or its Exodus header cannot be read.
    """
    path = Path(path)
    if path.suffix.lower() not in SERIES_SUFFIXES:
        return None
    if not path.is_file():
        raise InputFileError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise InputFileError(f"{path}: empty file")
    import pyvista as pv

    logging.disable(logging.CRITICAL)  # pyvista logs VTK's errors; the exception says enough
    with pv.vtk_verbosity("off"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            reader = pv.get_reader(str(path))
            n = int(reader.number_time_points)
            times = tuple(float(t) for t in reader.time_values) if n > 0 else ()
        except Exception as exc:  # VTK raises many types on a corrupt header
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise InputFileError(f"{path}: cannot list the Exodus time steps ({first})") from None
        finally:
            logging.disable(logging.NOTSET)
    return times or None
