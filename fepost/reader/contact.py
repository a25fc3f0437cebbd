"""From a file's content to a `fepost.field.ContactField` (runs inside the reading child).

Order of the steps, each in its own module: read the file
(`fepost.reader.vtkfile` / `fepost.reader.exodus`), refuse 2-D
models, choose the pressure array (`fepost.reader.names`), mask
sentinels, add the displacement, convert to SI (`fepost.reader.units`),
choose the loaded surface (`fepost.reader.surface`), attach the solver's
reactions and the sidecar (`fepost.reader.sidecar`).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from .._arrays import adopted
from ..errors import DimensionError, FepostError, FieldError, InputFileError, PressureError, SentinelWarning
from ..field import OTHER_FACE_TYPES, ContactField
from .cells import SPECS
from .exodus import read_exodus
from .frd import read_frd
from .names import SENTINELS, ArrayInfo, FieldChoice, norm, pick_displacement, pick_field
from .raw import RawMesh
from .sidecar import at_step, read_sidecar
from .suffixes import EXODUS_SUFFIXES, FRD_SUFFIXES, XDMF_SUFFIXES
from .surface import Surface, loaded_surfaces, select_surface
from .units import UnitSystem
from .vtkfile import read_vtk
from .xdmf import read_xdmf

#: Global variables read as the solver's reaction or contact force (normalised names containing these).
REACTION_WORDS = ("react", "force")
#: Largest magnitude accepted for a coordinate or a displacement (file units): beyond it the numbers
#: are corrupt, whatever the units (the plausible scales are checked later, in SI).
MAX_COORDINATE = 1e12
#: Largest magnitude accepted for a pressure value (file units).
MAX_PRESSURE = 1e30


def _range(values: np.ndarray) -> tuple[float, float]:
    """(smallest, largest) value, NaN passed over (±inf kept); (nan, nan) when all are NaN or none."""
    if values.size == 0:
        return float("nan"), float("nan")
    return float(np.fmin.reduce(values, axis=None)), float(np.fmax.reduce(values, axis=None))


def _absurd(source: str, what: str, values: np.ndarray, limit: float) -> None:
    lo, hi = _range(values)
    big = max(abs(lo), abs(hi)) if np.isfinite(lo) and np.isfinite(hi) else np.nan
    if not big <= limit:
        finite = values[np.isfinite(values)]  # the slow path, only on refusal
        if not finite.size or np.abs(finite).max() <= limit:
            return
        raise InputFileError(
            f"{source}: {what} up to {np.abs(finite).max():.3g} (beyond {limit:g}, in any unit system): "
            "corrupt file?"
        )


def read_raw(
    path: Path,
    step: int | None,
    field: str | None = None,
    displacement: str | None = "auto",
    surface: str | None = None,
) -> RawMesh:
    """The file's content (Exodus by netCDF4, VTK files by VTK's readers, the arrays
    ``field`` and ``displacement`` choose decoded first; of an Exodus file whose side set
    ``surface`` names, only that side set's elements: `RawMesh.partial`)."""
    if path.suffix.lower() in EXODUS_SUFFIXES:
        return read_exodus(path, step, surface)
    if path.suffix.lower() in XDMF_SUFFIXES:
        return read_xdmf(path, step)
    if path.suffix.lower() in FRD_SUFFIXES:
        return read_frd(path, step)
    if step is not None:
        raise InputFileError(f"{path}: --step applies to Exodus time series, not to {path.suffix} files")
    return read_vtk(path, field=field, displacement=displacement)


def read_here(
    path: Path,
    field: str | None = None,
    step: int | None = None,
    displacement: str | None = "auto",
    units: UnitSystem | None = None,
    surface: str | None = None,
) -> ContactField:
    """`fepost.reader.read_contact` without the child process (see there)."""
    raw = read_raw(path, step, field, displacement, surface)
    if raw.partial:
        got = _from_part(raw, path, field, displacement, units, surface)
        if got is not None:
            return got
        raw = read_raw(path, step, field, displacement)
    try:
        return _contact(raw, path, field, displacement, units, surface)
    finally:
        raw.close()


class _WholeMesh(Exception):
    """The field needs more of the mesh than the side set's elements (element values)."""


def _from_part(raw: RawMesh, path, field, displacement, units, surface) -> ContactField | None:
    """The field from the side set's elements alone (the same field as from the whole mesh:
    nodal pressure on the side set's faces), or None where it needs the whole mesh: element
    values, or a refusal, which is then worded from the whole mesh as it always is. Warnings
    are passed on only with the field."""
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        try:
            got = _contact(raw, path, field, displacement, units, surface)
        except (FepostError, _WholeMesh):
            got = None
        finally:
            raw.close()
    if got is not None:
        for w in seen:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)
    return got


def _catalogue(raw: RawMesh) -> list[ArrayInfo]:
    out: dict[str, ArrayInfo] = {}
    for name in raw.point_data:
        ncomp = raw.ncomp.get(name)
        if ncomp is None:
            a = raw.point_data[name]
            ncomp = 1 if a.ndim == 1 else int(a.shape[1])
        out[name] = ArrayInfo(name, "point", ncomp, raw.components.get(name, ()))
    for b in raw.blocks:
        for name in b.cell_data:
            if name in out:
                continue  # same name at nodes and elements: the nodal array wins
            a = b.cell_data[name]
            ncomp = 1 if a.ndim == 1 else int(a.shape[1])
            out[name] = ArrayInfo(name, "cell", ncomp, raw.components.get(name, ()))
    return list(out.values())


def _column(a: np.ndarray, comp: int | None, what: str) -> np.ndarray:
    if a.dtype.kind not in "fiub":
        raise FieldError(f"{what} is not numeric (type {a.dtype})")
    if a.ndim == 1:
        return np.asarray(a, float)
    if comp is None:
        if a.shape[1] == 1:
            return np.asarray(a[:, 0], float)
        raise FieldError(f"{what} has {a.shape[1]} components; choose one with --field NAME:K")
    return np.asarray(a[:, comp], float)


def _mask_sentinels(source: str, values: np.ndarray) -> np.ndarray:
    hit = np.isin(values, SENTINELS)
    if hit.any():
        warnings.warn(
            f"{source}: {int(hit.sum())} values equal to sentinel {values[hit][0]:g} "
            "(no contact data) were set to zero pressure",
            SentinelWarning,
            stacklevel=3,
        )
        values = np.where(hit, 0.0, values)
    return values


def _no_contact(raw: RawMesh, path: Path, choice: FieldChoice, values: np.ndarray) -> None:
    """Refuse a step without contact: tension when the values are negative, else naming the steps
    that carry contact (Exodus series)."""
    where = f"at step {raw.step} (t = {raw.time:g})" if raw.step is not None and raw.time is not None else ""
    lo = _range(values)[0]
    if lo < 0:
        n = int(np.sum(values < 0))
        what = "nodes" if choice.location == "point" else "faces"
        raise PressureError(
            f"{path}: pressure array {choice.label!r} has no positive value {where}".rstrip()
            + f" and is negative at {n} {what} (down to {lo:.4g}): the interface is in tension "
            "(a tied interface pulled apart), not pressed into contact; fepost reads compression "
            "as positive pressure"
        )
    others = ""
    if raw.step_values is not None and choice.location == "point" and choice.component is None:
        try:
            series = raw.step_values(choice.name)
        except (InputFileError, KeyError, ValueError):
            series = None
        if series is not None and series.ndim == 2:
            peak = np.nanmax(np.where(np.isin(series, SENTINELS), 0.0, series), axis=1)
            hot = [k for k in np.flatnonzero(peak > 0)]
            if hot:
                listed = ", ".join(f"{k} (t = {raw.steps[k]:g})" for k in hot[:10])
                more = f" and {len(hot) - 10} more" if len(hot) > 10 else ""
                others = f"; contact pressure is positive at step(s) {listed}{more}: choose one with --step"
            else:
                others = f"; it is zero at all {series.shape[0]} steps"
    raise PressureError(
        f"{path}: pressure array {choice.label!r} is zero everywhere {where}".rstrip()
        + f" (no contact){others}"
    )


def _reactions(raw: RawMesh, units: UnitSystem | None) -> dict[str, float]:
    scale = 1.0 if units is None else units.force
    out = {}
    for name, value in raw.globals.items():
        n = norm(name)
        if any(w in n for w in REACTION_WORDS) and np.isfinite(value):
            out[name] = float(value) * scale
    return out


def _scaled_sidecar(side: dict | None, units: UnitSystem | None) -> dict | None:
    if side is None or units is None or units.is_si:
        return side
    scale = {
        "reaction_z": units.force,
        "cpress_integral": units.force,
        "load": units.force,
        "inflation_pressure": units.pressure,
        "deflection": units.length,
    }
    return {k: (v * scale[k] if k in scale and isinstance(v, int | float) else v) for k, v in side.items()}


def _check_mesh(raw: RawMesh, source: str) -> None:
    """Refuse 2-D models and files without surface cells."""
    if raw.dim < 3:
        raise DimensionError(
            f"{source}: 2-D model (num_dim = {raw.dim}: plane strain, plane stress or axisymmetric): "
            "the contact is a line, not a patch; fepost needs a 3-D contact surface"
        )
    if len(raw.points) == 0:
        raise InputFileError(f"{source}: the file holds no mesh (0 nodes or 0 cells)")
    surfaces = [b for b in raw.blocks if SPECS[b.cell_type].dim >= 2 and len(b.conn)]
    if not surfaces:
        skipped = ", ".join(f"{n} {k}" for k, n in raw.skipped.items())
        lines = [b for b in raw.blocks if SPECS[b.cell_type].dim < 2 and len(b.conn)]
        if not raw.blocks or (not lines and not skipped):
            raise InputFileError(f"{source}: the file holds no mesh (0 nodes or 0 cells)")
        extra = f"; not read: {skipped}" if skipped else ""
        raise InputFileError(f"{source}: the mesh has no surface faces (only points or lines){extra}")


def _pressures(
    raw: RawMesh, source: str, choice: FieldChoice
) -> tuple[np.ndarray | None, list[np.ndarray] | None, np.ndarray]:
    """(nodal values or None, per-block cell values or None, all values) of the chosen array."""
    what = f"{source}: array {choice.name!r}"
    if choice.location == "point":
        values = _mask_sentinels(source, _column(raw.point_data[choice.name], choice.component, what))
        return values, None, values
    cell_values = []
    for b in raw.blocks:
        if choice.name in b.cell_data:
            cell_values.append(_column(b.cell_data[choice.name], choice.component, what))
        else:
            cell_values.append(np.zeros(len(b.conn)))
    allv = _mask_sentinels(source, np.concatenate(cell_values)) if cell_values else np.empty(0)
    sizes = np.cumsum([len(v) for v in cell_values])[:-1]
    return None, np.split(allv, sizes), allv


def _deformed(
    raw: RawMesh, source: str, catalogue: list[ArrayInfo], displacement: str | None, units: UnitSystem | None
) -> tuple[np.ndarray, str | None]:
    """The node coordinates with the displacement added, in SI (a new array when changed),
    and the name of the displacement array added (None: the coordinates as written)."""
    points = np.asarray(raw.points, float)
    _absurd(source, "node coordinates", points, MAX_COORDINATE)
    disp = pick_displacement(source, catalogue, displacement)
    if disp is not None or (units is not None and not units.is_si):
        points = points.copy()  # changed below: the file's array stays as read
    if disp is not None:
        u = np.asarray(raw.point_data[disp], float)
        if u.ndim != 2 or len(u) != len(points):
            raise FieldError(f"{source}: displacement array {disp!r} is not a vector per node")
        if not np.all(np.isfinite(u)):
            raise FieldError(f"{source}: displacement array {disp!r} holds NaN or infinite values")
        _absurd(source, f"displacements {disp!r}", u, MAX_COORDINATE)
        points[:, : min(3, u.shape[1])] += u[:, :3]
    if units is not None and not units.is_si:
        points *= units.length
    return points, disp


def _surface(
    raw: RawMesh,
    source: str,
    choice: FieldChoice,
    point_values: np.ndarray | None,
    cell_values: list[np.ndarray] | None,
    surface: str | None,
) -> Surface:
    """The loaded faces; a surface named with --surface that carries no pressure is refused."""
    surf = select_surface(raw, choice.location, point_values, cell_values, surface)
    if not surf.conn:
        raise InputFileError(f"{source}: the mesh has no surface faces carrying {choice.label!r}")
    if surface is not None:
        if point_values is not None:
            peak = max(_range(point_values[np.concatenate([c.ravel() for c in surf.conn.values()])])[1], 0.0)
        else:
            vals = surf.values or {}
            peak = max((_range(v)[1] for v in vals.values() if len(v)), default=0.0)
        if not peak > 0:
            where = loaded_surfaces(raw, point_values, cell_values)
            elsewhere = (
                f"; the pressure is on {', '.join(where)}: choose one of them with --surface"
                if where
                else " (nor does any other side set or block)"
            )
            raise PressureError(
                f"{source}: surface {surface!r} ({surf.body}) carries no positive {choice.label!r}{elsewhere}"
            )
    return surf


def _contact(
    raw: RawMesh,
    path: Path,
    field: str | None,
    displacement: str | None,
    units: UnitSystem | None,
    surface: str | None,
) -> ContactField:
    source = str(path)
    _check_mesh(raw, source)
    catalogue = _catalogue(raw)
    choice = pick_field(source, catalogue, field)
    if raw.partial and choice.location != "point":
        raise _WholeMesh
    notes = [*raw.notes, choice.note]
    if raw.skipped:
        notes.append("cells not read: " + ", ".join(f"{n} {k}" for k, n in raw.skipped.items()))
    point_values, cell_values, checked = _pressures(raw, source, choice)
    if not _range(checked)[1] > 0:  # NaN passed over; +inf counts (refused later as not finite)
        _no_contact(raw, path, choice, checked)
    _absurd(source, f"pressure values of {choice.label!r}", checked, MAX_PRESSURE)
    points, disp = _deformed(raw, source, catalogue, displacement, units)
    if units is not None and not units.is_si:
        if point_values is not None:
            point_values = point_values * units.pressure
        else:
            cell_values = [v * units.pressure for v in cell_values or []]

    surf = _surface(raw, source, choice, point_values, cell_values, surface)
    notes += surf.notes
    if choice.location == "point" and any(SPECS[b.cell_type].dim == 3 for b in raw.blocks):
        points, point_values, surf.conn = _used_nodes(points, point_values, surf.conn)

    tri = surf.conn.get("tri3", np.empty((0, 3), np.int64))
    faces = {t: surf.conn[t] for t in OTHER_FACE_TYPES if t in surf.conn}
    if point_values is not None:
        values = point_values
    else:
        vals = surf.values or {}
        order = ["tri3", *OTHER_FACE_TYPES]
        values = np.concatenate([vals[t] for t in order if t in surf.conn]) if vals else np.empty(0)
    side = _scaled_sidecar(at_step(read_sidecar(path), path, raw.step, len(raw.steps)), units)
    reaction = None if side is None else side.get("reaction_z")
    scale = 1.0 if units is None else units.time
    # every array here was made by this reader from the file: shared with the field, not copied
    return ContactField(
        source=source,
        points=adopted(np.ascontiguousarray(points)),
        triangles=adopted(np.ascontiguousarray(tri, dtype=np.int64)),
        values=adopted(np.ascontiguousarray(values, dtype=float)),
        location=choice.location,  # type: ignore[arg-type]
        field=choice.label,
        step=raw.step,
        time=None if raw.time is None else raw.time * scale,
        reaction_z=None if reaction is None else float(reaction),
        arrays=tuple(a.name for a in catalogue),
        sidecar=side,
        faces={t: adopted(np.ascontiguousarray(c, dtype=np.int64)) for t, c in faces.items()},
        reactions=_reactions(raw, units),
        steps=tuple(t * scale for t in raw.steps),
        body=surf.body,
        units=units,
        notes=tuple(n for n in notes if n),
        format=raw.format,
        displacement=disp,
    )


def _used_nodes(
    points: np.ndarray, point_values: np.ndarray | None, conn: dict[str, np.ndarray]
) -> tuple[np.ndarray, np.ndarray | None, dict[str, np.ndarray]]:
    """Only the nodes the faces use (a volume mesh's interior nodes dropped), renumbered."""
    used = np.zeros(len(points), bool)
    for c in conn.values():
        used[c.ravel()] = True
    if used.all() or point_values is None:
        return points, point_values, conn
    remap = np.cumsum(used) - 1
    return points[used], point_values[used], {t: remap[c] for t, c in conn.items()}
