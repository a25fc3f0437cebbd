"""Read FE contact results into a :class:`~fepost.field.ContactField`.

Formats are chosen by suffix; every format is read by a well-kept library,
never by a hand-written parser:

========================= ===================================================
suffix                    reader
========================= ===================================================
``.vtu .vtp .vtk .vtm``   VTK's XML / legacy readers (:mod:`.vtkfile`),
                          after the checks of :mod:`.vtkcheck`
                          (:mod:`.xmlcheck`, :mod:`.legacycheck`)
``.e .exo .ex2 .exii``    the netCDF container read with netCDF4 (:mod:`.exodus`)
``.frd``                  CalculiX results, ASCII or binary (:mod:`.frd`)
========================= ===================================================

Every file is read in a forked child process (:mod:`.isolate`): a file that
crashes or hangs a C library becomes a one-line
:class:`~fepost.errors.InputFileError`, never a dead process.

Modules, one concern each: :mod:`.cells` (element types, faces, boundary),
:mod:`.surface` (which body's faces carry the pressure), :mod:`.names`
(which array is the pressure), :mod:`.units` (unit systems, scale checks),
:mod:`.sidecar` (the ``<stem>.json`` beside a file), :mod:`.quadratic`
(shape functions, exact integrals and refinement of curved faces),
:mod:`.contact` (the steps in order). ``docs/reading.md`` describes the rules.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputFileError
from . import isolate
from .names import CCX_CONTACT, DISPLACEMENT_NAMES, PRESSURE_NAMES
from .units import SYSTEMS, UnitSystem, unit_system

if TYPE_CHECKING:
    from ..field import ContactField

VTK_SUFFIXES = (".vtu", ".vtp", ".vtk", ".vtm")
EXODUS_SUFFIXES = (".e", ".exo", ".ex2", ".exii")
FRD_SUFFIXES = (".frd",)
#: Values that mean "no contact data" rather than a pressure (MOOSE writes −99999).
SENTINELS = (-99999.0, -999999.0, -9999.0, -1.0e30, -1.0e20)

__all__ = [
    "CCX_CONTACT",
    "DISPLACEMENT_NAMES",
    "PRESSURE_NAMES",
    "SENTINELS",
    "SYSTEMS",
    "TimeStep",
    "UnitSystem",
    "read_contact",
    "start_reading",
    "supported_suffixes",
    "time_steps",
    "unit_system",
]


def supported_suffixes() -> tuple[str, ...]:
    return VTK_SUFFIXES + EXODUS_SUFFIXES + FRD_SUFFIXES


def _checked(path: str | Path) -> tuple[Path, int]:
    path = Path(path)
    if not path.exists():
        raise InputFileError(f"{path}: no such file")
    if not path.is_file():
        raise InputFileError(f"{path}: not a file")
    if path.suffix.lower() not in supported_suffixes():
        raise InputFileError(
            f"{path}: unknown format {path.suffix or '(no suffix)'!r}; "
            f"supported: {', '.join(supported_suffixes())}"
        )
    try:
        size = path.stat().st_size
        with open(path, "rb"):
            pass
    except OSError as exc:
        raise InputFileError(f"{path}: cannot open ({exc.strerror or exc})") from None
    if size == 0:
        raise InputFileError(f"{path}: empty file")
    return path, size


def read_contact(
    path: str | Path,
    field: str | None = None,
    step: int | None = None,
    displacement: str | None = "auto",
    *,
    units: str | UnitSystem | None = None,
    surface: str | None = None,
) -> ContactField:
    """Read the contact-pressure field of an FE export.

    Parameters
    ----------
    path : file path
        ``.vtu``, ``.vtp``, ``.vtk`` (legacy), ``.vtm``, Exodus II ``.e``/``.exo`` or CalculiX ``.frd``.
    field : str, optional
        Name of the pressure array (``NAME:k`` for component k, or a component
        name such as ``CPRESS``). Default: found by name among :data:`PRESSURE_NAMES`.
    step : int, optional
        Exodus time step or ``.frd`` increment (0-based; negative counts from the end). Default: last.
    displacement : str or None
        ``"auto"`` (default): add the displacement array if one is found;
        a name: add that array; ``None``: use the coordinates as written.
    units : str, optional
        The model's unit system (:data:`~fepost.reader.units.SYSTEMS`, e.g.
        ``"mm-N-MPa"``); everything is converted to SI. Default: SI, assumed
        (implausible scales are then refused downstream).
    surface : str, optional
        Restrict the faces to an Exodus side set or element block (name or id).

    Raises
    ------
    InputFileError
        Missing, unreadable, corrupt, malformed or unsupported file (also when
        the reading library crashes or hangs on it).
    FieldError
        No pressure array, several candidates, or a named array is missing.
    DimensionError
        A 2-D (plane or axisymmetric) model.
    PressureError
        No positive pressure at the step read (the steps that have some are named).
    """
    return start_reading(path, field, step, displacement, units=units, surface=surface).result()


def start_reading(
    path: str | Path,
    field: str | None = None,
    step: int | None = None,
    displacement: str | None = "auto",
    *,
    units: str | UnitSystem | None = None,
    surface: str | None = None,
) -> isolate.Pending:
    """Start :func:`read_contact` in the reading child and return at once.

    ``.result()`` on the returned object gives the :class:`~fepost.field.ContactField`
    (or raises what :func:`read_contact` raises); ``.cancel()`` abandons the read.
    Meanwhile the caller may import, compute, or start reading a second file.
    A missing file, an unknown suffix or an unknown unit system raise at once.
    """
    from .contact import read_here

    path, size = _checked(path)
    system = unit_system(units)
    return isolate.start(
        read_here, path, field, step, displacement, system, surface, what=str(path), nbytes=size
    )


@dataclass(frozen=True)
class TimeStep:
    """One stored state of an export.

    ``index``: 0-based Exodus step (None for single-state files); ``time``: its time, s.
    """

    index: int | None
    time: float | None


def _steps_here(path: Path) -> tuple[float, ...] | None:
    from .contact import EXODUS_SUFFIXES as exo

    if path.suffix.lower() in exo:
        from .exodus import read_steps

        return read_steps(path)
    if path.suffix.lower() in FRD_SUFFIXES:
        from .frd import read_steps as frd_steps

        return frd_steps(path)
    return None


def time_steps(path: str | Path, units: str | UnitSystem | None = None) -> tuple[TimeStep, ...]:
    """The states stored in an FE export, in order.

    Exodus files list every time step and ``.frd`` files every increment (``TimeStep(k, t_k)``; a file
    without steps gives one ``TimeStep(None, None)``); VTK files hold one state
    (``TimeStep(None, None)``). ``units`` scales the times (``mm-kg-ms``: ms).
    Pass ``step=ts.index`` to :func:`read_contact` / :func:`fepost.analyse`.
    """
    path, size = _checked(path)
    system = unit_system(units)
    times = isolate.call(_steps_here, path, what=str(path), nbytes=size)
    if not times:
        return (TimeStep(None, None),)
    scale = 1.0 if system is None else system.time
    return tuple(TimeStep(k, float(t) * scale) for k, t in enumerate(times))
