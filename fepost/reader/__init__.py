"""Read FE contact results into a `fepost.field.ContactField`.

Formats are chosen by suffix; every format is read by a well-kept library, except
CalculiX `.frd`, which has none that reads binary files (see `frd`), and the binary
arrays of serial VTK XML files, decoded directly for speed (see `vtkdirect`; VTK
reads the same files to the same bits, and everything else of the format):

=============================== =============================================
suffix                          reader
=============================== =============================================
``.vtu .vtp`` (binary arrays)   fepost's decoder of the documented binary
                                layout (`vtkdirect`, numpy + zlib/lzma:
                                only the arrays needed, no VTK import),
                                after the checks of `xmlcheck`
``.vtu .vtp .vtk .vtm``         VTK's XML / legacy readers (`vtkfile`; XML
                                files with ASCII arrays, LZ4 or several
                                pieces), after the checks of `vtkcheck`
                                (`xmlcheck`, `legacycheck`)
``.vts .vtr``                   VTK's structured-grid readers (`vtkfile`),
                                the boundary taken as for volume meshes
``.pvtu .pvtp``                 VTK's parallel readers, piece by piece,
                                joined by `pieces`
``.e .exo .ex2 .exii``          the netCDF container read with netCDF4 (`exodus`)
``.xdmf .xmf`` (+ ``.h5``)      meshio (`xdmf`), after the checks of `xdmfcheck`
``.frd``                        CalculiX results, ASCII or binary (`frd`;
                                fixed-width records parsed by `frdparse`)
=============================== =============================================

Every file is read in a forked child process (`isolate`): a file that
crashes or hangs a C library becomes a one-line
`fepost.errors.InputFileError`, never a dead process.

Modules, one concern each: `vtkassemble` (a VTK data set's arrays into
element blocks, for both VTK paths), `transfer` (the child's answer to the
caller), `cells` (element types, faces, boundary),
`b64text` (base64 text checked and decoded as VTK decodes it), `xmlarrays`
(the lengths of a VTK XML file's arrays, from their headers),
`surface` (which body's faces carry the pressure), `names`
(which array is the pressure), `units` (unit systems, scale checks),
`sidecar` (the ``<stem>.json`` beside a file), `quadratic`
(shape functions, exact integrals and refinement of curved faces),
`contact` (the steps in order). ``docs/reading.md`` describes the rules.
"""

from __future__ import annotations

import errno
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputFileError
from . import isolate
from .names import CCX_CONTACT, DISPLACEMENT_NAMES, PRESSURE_NAMES, SENTINELS
from .suffixes import EXODUS_SUFFIXES, FRD_SUFFIXES, VTK_SUFFIXES, XDMF_SUFFIXES
from .units import SYSTEMS, UnitSystem, unit_system

if TYPE_CHECKING:
    from ..field import ContactField


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
    return VTK_SUFFIXES + EXODUS_SUFFIXES + XDMF_SUFFIXES + FRD_SUFFIXES


def _missing(path: Path, exc: OSError) -> InputFileError:
    """The error for a path that cannot be followed to a file: missing, a link loop, a dangling link."""
    if exc.errno == errno.ELOOP:
        return InputFileError(f"{path}: a symbolic-link loop (the links never reach a file)")
    if path.is_symlink():
        return InputFileError(f"{path}: a symbolic link to {os.readlink(path)!r}, which does not exist")
    if exc.errno in (errno.ENOENT, errno.ENOTDIR):
        return InputFileError(f"{path}: no such file")
    return InputFileError(f"{path}: cannot open ({exc.strerror or exc})")


#: Files a format names beside it (pieces, heavy data): their sizes count for the read's budget.
_COMPANIONS = {
    ".pvtu": (".vtu",),
    ".pvtp": (".vtp",),
    ".vtm": (".vtu", ".vtp", ".vtm"),
    ".xdmf": (".h5",),
    ".xmf": (".h5",),
}
#: Most folder entries looked at for companion files.
_MAX_ENTRIES = 10_000


def data_size(path: Path, size: int) -> int:
    """``size`` plus the sizes of the files beside ``path`` its format names (by their stem).

    Only the deadline and the memory budget of the read depend on it; no file is parsed here
    (that happens in the reading child).
    """
    kinds = _COMPANIONS.get(path.suffix.lower())
    if not kinds:
        return size
    total = size
    for folder in (path.parent, path.parent / path.stem):
        try:
            with os.scandir(folder) as entries:
                for k, entry in enumerate(entries):
                    if k >= _MAX_ENTRIES:
                        break
                    name = entry.name
                    if name.startswith(path.stem) and Path(name).suffix.lower() in kinds and entry.is_file():
                        total += entry.stat().st_size
        except OSError:
            continue
    return total


def _checked(path: str | Path) -> tuple[Path, int]:
    path = Path(path)
    try:
        os.stat(path)
    except OSError as exc:
        raise _missing(path, exc) from None
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
    return path, data_size(path, size)


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
        ``.vtu``, ``.vtp``, ``.vtk`` (legacy), ``.vtm``, ``.vts``, ``.vtr``, ``.pvtu``,
        ``.pvtp``, Exodus II ``.e``/``.exo``, XDMF ``.xdmf`` (with its ``.h5``) or
        CalculiX ``.frd``.
    field : str, optional
        Name of the pressure array (``NAME:k`` for component k, or a component
        name such as ``CPRESS``). Default: found by name among `PRESSURE_NAMES`.
    step : int, optional
        Time step of an Exodus file or an XDMF time series, or ``.frd`` increment
        (0-based; negative counts from the end). Default: last.
    displacement : str or None
        ``"auto"`` (default): add the displacement array if one is found;
        a name: add that array; ``None``: use the coordinates as written.
    units : str, optional
        The model's unit system (`fepost.reader.units.SYSTEMS`, e.g.
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

    Examples
    --------
    >>> from fepost.reader import read_contact
    >>> fld = read_contact("meshes/static.vtu")   # the CalculiX sample of the repository
    >>> fld.field, fld.location, fld.n_points
    ('CPRESS', 'point', 2961)
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
    """Start `read_contact` in the reading child and return at once.

    ``.result()`` on the returned object gives the `fepost.field.ContactField`
    (or raises what `read_contact` raises); ``.cancel()`` abandons the read.
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
    if path.suffix.lower() in EXODUS_SUFFIXES:
        from .exodus import read_steps

        return read_steps(path)
    if path.suffix.lower() in XDMF_SUFFIXES:
        from .xdmf import read_steps as xdmf_steps

        return xdmf_steps(path)
    if path.suffix.lower() in FRD_SUFFIXES:
        from .frd import read_steps as frd_steps

        return frd_steps(path)
    return None


def time_steps(path: str | Path, units: str | UnitSystem | None = None) -> tuple[TimeStep, ...]:
    """The states stored in an FE export, in order.

    Exodus files, XDMF time series and ``.frd`` files list every time step or
    increment (``TimeStep(k, t_k)``; an Exodus file without steps gives one
    ``TimeStep(None, None)``); VTK files and single-grid XDMF files hold one state
    (``TimeStep(None, None)``). ``units`` scales the times (``mm-kg-ms``: ms).
    Pass ``step=ts.index`` to `read_contact` / `fepost.analyse`.
    """
    path, size = _checked(path)
    system = unit_system(units)
    times = isolate.call(_steps_here, path, what=str(path), nbytes=size)
    if not times:
        return (TimeStep(None, None),)
    scale = 1.0 if system is None else system.time
    return tuple(TimeStep(k, float(t) * scale) for k, t in enumerate(times))
