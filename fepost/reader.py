"""Read FE contact results into a :class:`~fepost.field.ContactField`.

Formats are chosen by suffix from a registry; every format is read by a
well-kept library (pyvista/VTK), never by a hand-written parser:

========================= =========================================
suffix                    reader
========================= =========================================
``.vtu .vtp .vtk .vtm``   VTK XML / legacy readers through pyvista
``.e .exo .ex2 .exii``    VTK's Exodus II reader (all time steps)
========================= =========================================

meshio reads only the first Exodus time step, so Exodus goes through VTK.

Conventions
-----------
* The contact pressure is found by name (case-insensitive; see
  :data:`PRESSURE_NAMES`) unless ``field`` is given. ``NAME:k`` selects
  component k of a vector array (e.g. ``CSTR:0``).
* Coordinates are taken as written. A displacement array (``displacement``
  ``"auto"``: the first of :data:`DISPLACEMENT_NAMES` found) is added to them,
  as solvers write undeformed coordinates plus displacements. Pass
  ``displacement=None`` to use the coordinates as they are.
* Volume meshes are reduced to their boundary surface; faces are triangulated.
* Known sentinels for "no contact data" (:data:`SENTINELS`, e.g. MOOSE's
  −99999) are replaced by zero with a :class:`~fepost.errors.SentinelWarning`.
* A sidecar ``<stem>.json`` beside the file may carry ``reaction_z`` (N).
"""

from __future__ import annotations

import contextlib
import json
import logging
import re
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pyvista as pv
from pyvista.core.utilities.observers import VtkErrorCatcher

from ._arrays import adopted
from .errors import FieldError, InputFileError, SentinelWarning
from .field import ContactField

#: Normalised (lower-case, alphanumerics only) names taken as contact pressure.
PRESSURE_NAMES = (
    "cpress",
    "contactpressure",
    "contactpress",
    "contpress",
    "cpres",
    "pcontact",
    "pressurecontact",
    "normalcontactpressure",
    "contactnormalpressure",
    "pressure",
)
#: Normalised names taken as nodal displacement (3 components).
DISPLACEMENT_NAMES = ("displacement", "displacements", "displ", "disp", "u")
#: Values that mean "no contact data" rather than a pressure.
SENTINELS = (-99999.0, -999999.0, -9999.0, -1.0e30, -1.0e20)

_VTK_SUFFIXES = (".vtu", ".vtp", ".vtk", ".vtm")
_EXODUS_SUFFIXES = (".e", ".exo", ".ex2", ".exii")


def _norm(name: str) -> str:
    return re.sub(r"[^0-9a-z]", "", name.lower())


class _VtkErrors:
    """Collect VTK's error output instead of letting it reach the terminal."""

    def __enter__(self):
        self._stack = contextlib.ExitStack()
        self._stack.enter_context(pv.vtk_verbosity("off"))
        self._stack.enter_context(warnings.catch_warnings())
        warnings.simplefilter("ignore")
        logging.disable(logging.CRITICAL)
        self._stack.callback(logging.disable, logging.NOTSET)
        self._catcher = self._stack.enter_context(VtkErrorCatcher(raise_errors=False))
        self.messages: list[str] = []
        return self

    def __exit__(self, *exc):
        events = list(self._catcher.events)
        self._stack.__exit__(*exc)
        self.messages = [e.alert for e in events if e.kind == "ERROR"]
        return False


def _read_vtk(path: Path, step: int | None) -> tuple[pv.DataSet, int | None, float | None]:
    if step is not None:
        raise InputFileError(f"{path}: --step applies to Exodus time series, not to {path.suffix} files")
    with _VtkErrors() as err:
        try:
            raw = pv.read(str(path))
        except Exception as exc:  # VTK/pyvista raise a zoo of types for corrupt input
            raise InputFileError(f"{path}: cannot read {path.suffix} file ({_first_line(exc)})") from None
    data = _combine(raw) if isinstance(raw, pv.MultiBlock) else raw
    if err.messages and (data is None or data.n_points == 0):
        raise InputFileError(
            f"{path}: corrupt or truncated {path.suffix} file ({_first_line(err.messages[0])})"
        )
    if data is None:
        raise InputFileError(f"{path}: the file holds no mesh (0 nodes or 0 cells)")
    return data, None, None


def _read_exodus(path: Path, step: int | None) -> tuple[pv.DataSet, int | None, float | None]:
    with _VtkErrors() as err:
        try:
            reader = pv.get_reader(str(path))
            if hasattr(reader, "disable_displacements"):
                reader.disable_displacements()
            reader.enable_all_point_arrays()
            reader.enable_all_cell_arrays()
            n = int(reader.number_time_points)
            chosen = None
            time = None
            if n > 0:
                chosen = n - 1 if step is None else int(step)
                if chosen < 0:
                    chosen += n
                if not 0 <= chosen < n:
                    raise InputFileError(f"{path}: --step {step} out of range (file has {n} time steps)")
                reader.set_active_time_point(chosen)
                time = float(reader.time_values[chosen])
            elif step not in (None, 0, -1):
                raise InputFileError(f"{path}: --step {step} out of range (file has no time steps)")
            data = reader.read()
        except InputFileError:
            raise
        except Exception as exc:
            raise InputFileError(f"{path}: cannot read Exodus II file ({_first_line(exc)})") from None
    if isinstance(data, pv.MultiBlock):
        data = _combine(data)
    if data is None or data.n_points == 0:
        msg = err.messages[0] if err.messages else "no nodes found"
        raise InputFileError(f"{path}: corrupt or empty Exodus II file ({_first_line(msg)})")
    return data, chosen, time


_READERS: dict[str, Callable[[Path, int | None], tuple[pv.DataSet, int | None, float | None]]] = {
    **dict.fromkeys(_VTK_SUFFIXES, _read_vtk),
    **dict.fromkeys(_EXODUS_SUFFIXES, _read_exodus),
}


def supported_suffixes() -> tuple[str, ...]:
    return tuple(_READERS)


def _first_line(obj) -> str:
    text = str(obj).strip().splitlines()
    return text[0].strip() if text else type(obj).__name__


def _combine(mb: pv.MultiBlock) -> pv.DataSet | None:
    blocks = [b for b in _leaves(mb) if b is not None and b.n_points > 0]
    if not blocks:
        return None
    if len(blocks) == 1:
        return blocks[0]
    return pv.merge(blocks, merge_points=True)


def _leaves(mb):
    for b in mb:
        if isinstance(b, pv.MultiBlock):
            yield from _leaves(b)
        else:
            yield b


def _array_catalogue(data: pv.DataSet) -> dict[str, str]:
    names: dict[str, str] = {}
    for n in data.point_data.keys():
        names[n] = "point"
    for n in data.cell_data.keys():
        names.setdefault(n, "cell")  # same name in both: the nodal array wins
    return names


def _pick_field(path: Path, data: pv.DataSet, field: str | None) -> tuple[str, int | None, str]:
    """Return (array name, component or None, location)."""
    catalogue = _array_catalogue(data)
    listing = ", ".join(f"{n} ({loc})" for n, loc in catalogue.items()) or "none"
    if field is not None:
        name, comp = field, None
        m = re.fullmatch(r"(.+):(\d+)", field)
        if m and field not in catalogue:
            name, comp = m.group(1), int(m.group(2))
        if name not in catalogue:
            lower = {n.lower(): n for n in catalogue}
            if name.lower() in lower:
                name = lower[name.lower()]
            else:
                raise FieldError(f"{path}: no array named {name!r}; arrays found: {listing}")
        return name, comp, catalogue[name]
    hits = [n for n in catalogue if _norm(n) in PRESSURE_NAMES]
    if not hits:
        raise FieldError(
            f"{path}: no contact-pressure array found (looked for CPRESS, contact_pressure, "
            f"pressure, ...); arrays found: {listing}; name one with --field"
        )
    if len(hits) > 1:
        # One exact solver name beats generic ones only if it is the single specific hit.
        specific = [n for n in hits if _norm(n) != "pressure"]
        if len(specific) == 1:
            return specific[0], None, catalogue[specific[0]]
        cand = ", ".join(f"{n} ({catalogue[n]})" for n in hits)
        raise FieldError(
            f"{path}: several candidate contact-pressure arrays: {cand}; choose one with --field"
        )
    return hits[0], None, catalogue[hits[0]]


def _direct_faces(data: pv.DataSet) -> tuple[np.ndarray, np.ndarray] | None:
    """Triangles and their source cell ids straight from a mesh of triangles and quads.

    Returns None when the mesh holds other cell types (then VTK extracts the surface).
    """
    if not isinstance(data, pv.UnstructuredGrid):
        return None
    types = np.asarray(data.celltypes)
    is_tri = types == pv.CellType.TRIANGLE
    is_quad = types == pv.CellType.QUAD
    if not np.all(is_tri | is_quad):
        return None
    conn = np.asarray(data.cell_connectivity, np.int64)
    if is_tri.all() and conn.size == 3 * types.size:
        return conn.reshape(-1, 3), np.arange(types.size)
    off = np.asarray(data.cell_offsets, np.int64)[:-1]
    ids = np.arange(types.size)
    parts, src = [], []
    if is_tri.any():
        o = off[is_tri]
        parts.append(np.column_stack([conn[o], conn[o + 1], conn[o + 2]]))
        src.append(ids[is_tri])
    if is_quad.any():
        o = off[is_quad]
        q = np.column_stack([conn[o], conn[o + 1], conn[o + 2], conn[o + 3]])
        parts += [q[:, [0, 1, 2]], q[:, [0, 2, 3]]]
        src += [ids[is_quad], ids[is_quad]]
    return np.vstack(parts), np.concatenate(src)


def _extract(data: pv.DataSet, name: str, location: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the triangulated boundary surface: points, triangles, values."""
    direct = _direct_faces(data)
    if direct is not None:
        tri, src = direct
        arr = np.asarray(data.point_data[name] if location == "point" else data.cell_data[name], float)
        return np.asarray(data.points, float), tri, (arr if location == "point" else arr[src])
    if isinstance(data, pv.PolyData):
        surf = data
    else:
        surf = data.extract_surface(pass_pointid=False, pass_cellid=False, algorithm="dataset_surface")
    surf = surf.triangulate()
    if surf.n_lines or surf.n_verts:
        surf = surf.extract_cells_by_type(pv.CellType.TRIANGLE).extract_surface(algorithm="dataset_surface")
    faces = np.asarray(surf.faces)
    if surf.n_cells == 0 or faces.size == 0:
        return np.asarray(surf.points, float), np.empty((0, 3), np.int64), np.empty(0)
    tri = faces.reshape(-1, 4)[:, 1:]
    arr = surf.point_data[name] if location == "point" else surf.cell_data[name]
    return np.asarray(surf.points, float), np.asarray(tri, np.int64), np.asarray(arr, float)


def _sidecar(path: Path) -> dict | None:
    side = path.with_suffix(".json")
    if not side.is_file():
        return None
    try:
        return json.loads(side.read_text())
    except (OSError, ValueError) as exc:
        raise InputFileError(f"{side}: unreadable sidecar JSON ({_first_line(exc)})") from None


def read_contact(
    path: str | Path,
    field: str | None = None,
    step: int | None = None,
    displacement: str | None = "auto",
) -> ContactField:
    """Read the contact-pressure field of an FE export.

    Parameters
    ----------
    path : file path
        ``.vtu``, ``.vtp``, ``.vtk`` (legacy), ``.vtm`` or Exodus II ``.e``/``.exo``.
    field : str, optional
        Name of the pressure array (``NAME:k`` for component k). Default: found
        by name among :data:`PRESSURE_NAMES`.
    step : int, optional
        Exodus time step (0-based; negative counts from the end). Default: last.
    displacement : str or None
        ``"auto"`` (default): add the displacement array if one is found;
        a name: add that array; ``None``: use the coordinates as written.

    Raises
    ------
    InputFileError
        Missing, unreadable, corrupt or unsupported file.
    FieldError
        No pressure array, several candidates, or a named array is missing.
    """
    path = Path(path)
    if not path.exists():
        raise InputFileError(f"{path}: no such file")
    if not path.is_file():
        raise InputFileError(f"{path}: not a file")
    suffix = path.suffix.lower()
    reader = _READERS.get(suffix)
    if reader is None:
        raise InputFileError(
            f"{path}: unknown format {path.suffix or '(no suffix)'!r}; supported: {', '.join(_READERS)}"
        )
    if path.stat().st_size == 0:
        raise InputFileError(f"{path}: empty file")
    data, chosen, time = reader(path, step)
    if data.n_points == 0 or data.n_cells == 0:
        raise InputFileError(f"{path}: the file holds no mesh (0 nodes or 0 cells)")
    name, comp, location = _pick_field(path, data, field)

    disp_name = _pick_displacement(path, data, displacement)
    if disp_name is not None:
        data = data.copy(deep=False)
        u = np.asarray(data.point_data[disp_name], float)
        data.points = np.asarray(data.points, float) + u[:, :3]

    values = np.asarray(data.point_data[name] if location == "point" else data.cell_data[name], float)
    if values.ndim > 1:
        if comp is None:
            if values.shape[1] == 1:
                comp = 0
            else:
                raise FieldError(
                    f"{path}: array {name!r} has {values.shape[1]} components; "
                    f"choose one with --field {name}:K"
                )
        if comp >= values.shape[1]:
            raise FieldError(f"{path}: array {name!r} has no component {comp} (it has {values.shape[1]})")
        values = values[:, comp]
    elif comp not in (None, 0):
        raise FieldError(f"{path}: array {name!r} is scalar; it has no component {comp}")
    tmp = data.copy(deep=False)
    key = "__fepost_pressure__"
    if location == "point":
        tmp.point_data[key] = _mask_sentinels(path, values)
    else:
        tmp.cell_data[key] = _mask_sentinels(path, values)
    points, tri, vals = _extract(tmp, key, location)
    del tmp
    if tri.shape[0] == 0:
        raise InputFileError(f"{path}: the mesh has no surface faces (only points or lines)")
    side = _sidecar(path)
    reaction = None
    if side is not None and side.get("reaction_z") is not None:
        reaction = float(side["reaction_z"])
    label = name if comp is None else f"{name}:{comp}"
    # the arrays live in VTK objects made here and dropped on return: shared, not copied
    return ContactField(
        source=str(path),
        points=adopted(points),
        triangles=adopted(tri),
        values=adopted(vals),
        location=location,  # type: ignore[arg-type]
        field=label,
        step=chosen,
        time=time,
        reaction_z=reaction,
        arrays=tuple(_array_catalogue(data)),
        sidecar=side,
    )


def _pick_displacement(path: Path, data: pv.DataSet, displacement: str | None) -> str | None:
    if displacement is None or str(displacement).lower() == "none":
        return None
    if displacement == "auto":
        for n in data.point_data.keys():
            arr = data.point_data[n]
            if _norm(n) in DISPLACEMENT_NAMES and arr.ndim == 2 and arr.shape[1] >= 3:
                return n
        return None
    if displacement not in data.point_data.keys():
        names = ", ".join(data.point_data.keys()) or "none"
        raise FieldError(f"{path}: no nodal displacement array named {displacement!r}; point arrays: {names}")
    arr = data.point_data[displacement]
    if arr.ndim != 2 or arr.shape[1] < 3:
        raise FieldError(f"{path}: displacement array {displacement!r} is not a 3-vector per node")
    return displacement


def _mask_sentinels(path: Path, values: np.ndarray) -> np.ndarray:
    values = np.array(values, float)
    hit = np.isin(values, SENTINELS)
    if hit.any():
        warnings.warn(
            f"{path}: {int(hit.sum())} values equal to sentinel {values[hit][0]:g} "
            "(no contact data) were set to zero pressure",
            SentinelWarning,
            stacklevel=3,
        )
        values[hit] = 0.0
    return values
