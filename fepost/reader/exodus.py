"""Exodus II files read as the netCDF containers they are (netCDF4).

Why netCDF4 and not VTK's Exodus reader: an Exodus II file is a netCDF file
with documented variable names, and Unidata's netCDF4 library reads every
flavour of it (classic, 64-bit offset, netCDF-4/HDF5) and reports errors as
exceptions. Reading the variables directly gives what VTK's reader hides or
mixes: element blocks kept apart, side sets as (element, side) pairs instead of
extra surfaces, global variables (reaction and contact-force postprocessors),
the true element types (HEX20 stays quadratic), 2-D models recognised by
``num_dim``, and every size and index checked before use. The Exodus C library
inside VTK aborts the process on some malformed files; netCDF4 does not need it.

Conventions: variable names follow the Exodus II specification
(``coordx``/``coord``, ``connect<k>`` with attribute ``elem_type``,
``vals_nod_var<k>`` or the older ``vals_nod_var``, ``vals_elem_var<i>eb<k>``,
``elem_ss<k>``/``side_ss<k>``, ``vals_glo_var``, ``time_whole``). Nodal
variables named ``<base>_x``, ``<base>_y``, ``<base>_z`` (or ``<base>X`` …) are
also offered as one vector ``<base>`` (e.g. ``disp``, ``displacement``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import InputFileError
from .cells import SPECS, check_connectivity, exodus_type
from .raw import Block, RawMesh, SideSet
from .transfer import fresh_array

#: Largest node or element count accepted from a header (beyond any contact model).
MAX_ENTITIES = 1 << 31


def _open(path: Path):
    import netCDF4

    try:
        ds = netCDF4.Dataset(str(path), "r")
    except (OSError, RuntimeError, ValueError) as exc:
        raise InputFileError(
            f"{path}: cannot read Exodus II file (not a netCDF file: {_one_line(exc)})"
        ) from None
    ds.set_auto_mask(False)
    return ds


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror:
        msg = str(exc.strerror)  # netCDF4 repeats the file name after the message
    else:
        text = str(exc).strip().splitlines()
        msg = text[0].strip() if text else type(exc).__name__
    return msg[:200]


def _dim(ds, name: str, default: int | None = None) -> int:
    d = ds.dimensions.get(name)
    if d is None:
        if default is None:
            raise KeyError(name)
        return default
    n = len(d)
    if n < 0 or n > MAX_ENTITIES:
        raise ValueError(f"dimension {name} = {n} is out of range")
    return n


def _names(ds, var: str, count: int) -> list[str]:
    v = ds.variables.get(var)
    if v is None or count == 0:
        return [""] * count
    raw = np.asarray(v[:])
    if raw.ndim != 2 or raw.shape[0] != count:
        raise ValueError(f"{var} has shape {raw.shape}, expected ({count}, len_name)")
    out = []
    for row in raw:
        b = (
            row.tobytes()
            if row.dtype.kind in "SU" or row.dtype == np.uint8
            else np.asarray(row, "S1").tobytes()
        )
        out.append(b.split(b"\0", 1)[0].decode("utf-8", "replace").strip())
    return out


def _ids(ds, var: str, count: int) -> list[int]:
    v = ds.variables.get(var)
    if v is None:
        return list(range(1, count + 1))
    ids = np.asarray(v[:]).ravel()
    if ids.size != count:
        raise ValueError(f"{var} holds {ids.size} ids, expected {count}")
    return [int(i) for i in ids]


def _read(ds, name: str, shape: tuple[int, ...] | None = None, dtype=float) -> np.ndarray:
    v = ds.variables.get(name)
    if v is None:
        raise KeyError(name)
    a = np.asarray(v[:])
    if shape is not None and a.shape != shape:
        raise ValueError(f"variable {name} has shape {a.shape}, expected {shape}")
    return np.asarray(a, dtype=dtype)


def _indices(ds, name: str, shape: tuple[int, ...], rows: np.ndarray | None = None) -> np.ndarray:
    """A 1-based index variable as 0-based int64, converted in one pass (one allocation: a
    million-element connectivity is 64 MB, and fresh memory is what costs). ``rows`` (sorted):
    only those rows, read as the one span from the first to the last."""
    v = ds.variables.get(name)
    if v is None:
        raise KeyError(name)
    if tuple(v.shape) != shape:
        raise ValueError(f"variable {name} has shape {tuple(v.shape)}, expected {shape}")
    if rows is None:
        a = np.asarray(v[:])
    else:
        span = _span(rows)
        a = np.asarray(v[span])[rows - span.start]
    return np.subtract(a, 1, out=fresh_array(a.shape, np.int64), casting="unsafe")


def _steps(ds, path: Path | str) -> np.ndarray:
    """The time values of the steps; a NaN or infinite one is refused, naming the step(s)."""
    if "time_whole" not in ds.variables:
        return np.empty(0)
    t = np.asarray(ds.variables["time_whole"][:], float).ravel()
    bad = np.flatnonzero(~np.isfinite(t))
    if len(bad):
        listed = ", ".join(f"step {k} (t = {t[k]})" for k in bad[:5])
        more = f" and {len(bad) - 5} more" if len(bad) > 5 else ""
        raise InputFileError(
            f"{path}: corrupt Exodus II time values: {listed}{more} "
            f"{'is' if len(bad) == 1 else 'are'} not a finite number"
        )
    return t


def read_steps(path: Path) -> tuple[float, ...]:
    """The time value of every step stored in an Exodus II file."""
    ds = _open(path)
    try:
        return tuple(float(t) for t in _steps(ds, path))
    except InputFileError:
        raise
    except (KeyError, ValueError, OSError, RuntimeError, IndexError) as exc:
        raise InputFileError(f"{path}: malformed Exodus II file ({_one_line(exc)})") from None
    finally:
        ds.close()


def choose_step(path: Path | str, step: int | None, n: int) -> int | None:
    """The 0-based step to read: the last by default; negative counts from the end."""
    if n == 0:
        if step not in (None, 0, -1):
            raise InputFileError(f"{path}: --step {step} out of range (file has no time steps)")
        return None
    chosen = n - 1 if step is None else int(step)
    if chosen < 0:
        chosen += n
    if not 0 <= chosen < n:
        raise InputFileError(f"{path}: --step {step} out of range (file has {n} time steps)")
    return chosen


_VEC = re.compile(r"^(.*?)(?:_)?([xyzXYZ])$")


def vector_groups(names: list[str]) -> dict[str, tuple[str, ...]]:
    """Scalar names that form a vector: ``disp_x, disp_y, disp_z`` → ``{"disp": (...)}``."""
    by_base: dict[str, dict[str, str]] = {}
    for n in names:
        m = _VEC.match(n)
        if m and m.group(1):
            base = m.group(1).rstrip("_")
            if base:
                by_base.setdefault(base, {})[m.group(2).lower()] = n
    out = {}
    for base, comps in by_base.items():
        if base in names:
            continue
        if {"x", "y"} <= set(comps):
            order = [c for c in "xyz" if c in comps]
            if order == ["x", "y"] or order == ["x", "y", "z"]:
                out[base] = tuple(comps[c] for c in order)
    return out


def read_exodus(path: Path, step: int | None, surface: str | None = None) -> RawMesh:
    """Read an Exodus II file into a `fepost.reader.raw.RawMesh` at ``step`` (default: last).

    ``surface``: when it names a side set (by name or id, as ``--surface`` does), only the
    connectivity of the elements that side set names is read — on a volume model the
    rest of the volume stays on disk — and the mesh is marked `RawMesh.partial`.
    """
    ds = _open(path)
    try:
        return _read_exodus(ds, path, step, surface)
    except InputFileError:
        ds.close()
        raise
    except (KeyError, ValueError, OSError, RuntimeError, IndexError, TypeError, OverflowError) as exc:
        ds.close()
        what = (
            f"missing variable or dimension {exc.args[0]!r}" if isinstance(exc, KeyError) else _one_line(exc)
        )
        raise InputFileError(f"{path}: malformed Exodus II file ({what})") from None


def _read_exodus(ds, path: Path, step: int | None, surface: str | None) -> RawMesh:
    ndim = _dim(ds, "num_dim")
    if ndim not in (1, 2, 3):
        raise ValueError(f"num_dim = {ndim}")
    n_nodes = _dim(ds, "num_nodes", 0)
    if "coordx" in ds.variables:
        cols = [_read(ds, f"coord{c}", (n_nodes,)) for c in "xyz"[:ndim]]
    elif "coord" in ds.variables:
        allc = _read(ds, "coord", (ndim, n_nodes))
        cols = [allc[k] for k in range(ndim)]
    elif n_nodes == 0:
        cols = [np.empty(0)] * ndim
    else:
        raise KeyError("coordx")
    points = fresh_array((n_nodes, 3), float)
    for k, c in enumerate(cols):
        points[:, k] = c
    if not np.all(np.isfinite(points)):
        bad = int(np.sum(~np.isfinite(points).all(axis=1)))
        raise InputFileError(f"{path}: {bad} node coordinates are NaN or infinite")

    times = _steps(ds, path)
    n_steps = len(times)
    if n_steps and "time_step" in ds.dimensions and len(ds.dimensions["time_step"]) < n_steps:
        raise ValueError("time_whole is longer than the time_step dimension")
    chosen = choose_step(path, step, n_steps)

    counts = _element_counts(ds)
    # with a surface named, the side sets first: which elements to read
    side_sets = None if surface is None else _side_sets(ds, sum(counts))
    named = None if side_sets is None or surface is None else _side_set_named(side_sets, surface)
    only = None if named is None else np.unique(named.elements)
    blocks = _blocks(ds, path, n_nodes, chosen, counts, only)
    raw = RawMesh(
        path=str(path),
        format=f"Exodus II ({ds.data_model})",
        points=points,
        blocks=[b for b, _ in blocks],
        dim=ndim,
        steps=tuple(float(t) for t in times),
        step=chosen,
    )
    raw.skipped = {}
    for b, skipped in blocks:
        if skipped:
            raw.skipped[skipped] = raw.skipped.get(skipped, 0) + len(b.conn)
    raw.blocks = [b for b in raw.blocks if b.cell_type in SPECS]
    raw.closer = ds.close
    _bodies(raw)
    _nodal(ds, raw, n_nodes, chosen)
    if named is None or only is None:
        raw.side_sets = _side_sets(ds, sum(counts)) if side_sets is None else side_sets
    else:  # the named side set alone, numbered over the elements read (in file order)
        raw.partial = True
        raw.side_sets = [
            SideSet(named.label, named.name, named.id, np.searchsorted(only, named.elements), named.sides)
        ]
    raw.globals = _globals(ds, chosen)
    return raw


def _side_set_named(side_sets: list[SideSet], surface: str) -> SideSet | None:
    """The side set ``surface`` names (by name or id, as `fepost.reader.surface` matches them)."""
    key = surface.strip().lower()
    return next((ss for ss in side_sets if key in (ss.name.lower(), str(ss.id))), None)


def _element_counts(ds) -> list[int]:
    """Elements of each block as numbered over the file (an inactive block counts none)."""
    nblk = _dim(ds, "num_el_blk", 0)
    status = (
        np.asarray(ds.variables["eb_status"][:]).ravel() if "eb_status" in ds.variables else np.ones(nblk)
    )
    return [
        0 if status.size == nblk and status[k] == 0 else _dim(ds, f"num_el_in_blk{k + 1}", 0)
        for k in range(nblk)
    ]


def _blocks(
    ds, path: Path, n_nodes: int, chosen: int | None, counts: list[int], only: np.ndarray | None
) -> list[tuple[Block, str | None]]:
    """The element blocks; ``only`` (sorted global element indices): read just those elements."""
    nblk = len(counts)
    names = _names(ds, "eb_names", nblk)
    ids = _ids(ds, "eb_prop1", nblk)
    n_evar = _dim(ds, "num_elem_var", 0)
    evar_names = _names(ds, "name_elem_var", n_evar)
    table = (
        _read(ds, "elem_var_tab", (nblk, n_evar), dtype=np.int64)
        if "elem_var_tab" in ds.variables and n_evar
        else np.ones((nblk, n_evar), np.int64)
    )
    out: list[tuple[Block, str | None]] = []
    first = start = 0  # the block's first element as stored (over the elements read) and in the file
    for k, m in enumerate(counts):
        label = f"element block {ids[k]}" + (f" '{names[k]}'" if names[k] else "")
        if m == 0:
            out.append((Block(label, "point", np.empty((0, 1), np.int64), first, k), None))
            continue
        rows = None
        if only is not None:
            lo, hi = np.searchsorted(only, (start, start + m))
            rows = only[lo:hi] - start
        start += m
        var = ds.variables.get(f"connect{k + 1}")
        if var is None:
            raise KeyError(f"connect{k + 1}")
        npe = _dim(ds, f"num_nod_per_el{k + 1}")
        etype = str(getattr(var, "elem_type", "") or "")
        conn = _indices(ds, f"connect{k + 1}", (m, npe), rows)
        check_connectivity(conn, n_nodes, f"{path}: {label}")
        canon = exodus_type(etype, npe)
        if canon is None:
            raise InputFileError(
                f"{path}: {label} has elements of type {etype or '(none)'!r} with {npe} nodes, "
                "which fepost cannot read"
            )
        block = Block(f"{label} ({canon.upper()}, {m} elements)", canon, conn, first, k)
        for i, name in enumerate(evar_names):
            key = f"vals_elem_var{i + 1}eb{k + 1}"
            if table[k, i] and key in ds.variables and chosen is not None:
                block.cell_data.add(name, _loader(ds, key, chosen, m, rows))
        out.append((block, None))
        first += len(conn)
    return out


def _span(rows: np.ndarray) -> slice:
    """The rows from the first to the last of ``rows`` (sorted): one read from the file."""
    return slice(int(rows[0]), int(rows[-1]) + 1) if rows.size else slice(0, 0)


def _loader(ds, key: str, chosen: int, size: int, rows: np.ndarray | None = None) -> Callable[[], np.ndarray]:
    def load() -> np.ndarray:
        v = ds.variables[key]
        if v.ndim != 2 or v.shape[1] != size or v.shape[0] <= chosen:
            raise InputFileError(
                f"{ds.filepath()}: variable {key} has shape {v.shape}, expected (steps, {size})"
            )
        if rows is None:
            return np.asarray(v[chosen, :], float)
        span = _span(rows)
        return np.asarray(v[chosen, span], float)[rows - span.start]

    return load


def _bodies(raw: RawMesh) -> None:
    """Blocks that share a node belong to one body (union-find over the blocks)."""
    nb = len(raw.blocks)
    parent = list(range(nb))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if nb > 1:
        owner = np.full(len(raw.points), -1, np.int64)
        for i, b in enumerate(raw.blocks):
            nodes = np.unique(b.conn)
            prev = owner[nodes]
            for j in np.unique(prev[prev >= 0]):
                parent[find(int(j))] = find(i)
            owner[nodes] = i
    roots: dict[int, int] = {}
    for i, b in enumerate(raw.blocks):
        b.body = roots.setdefault(find(i), len(roots))


def _nodal(ds, raw: RawMesh, n_nodes: int, chosen: int | None) -> None:
    nvar = _dim(ds, "num_nod_var", 0)
    names = _names(ds, "name_nod_var", nvar)
    if nvar == 0 or chosen is None:
        return
    old = "vals_nod_var" in ds.variables

    def over_time(i: int) -> Callable[[], np.ndarray]:
        def load() -> np.ndarray:
            if old:
                v = ds.variables["vals_nod_var"]
                if v.ndim != 3 or v.shape[1] != nvar or v.shape[2] != n_nodes:
                    raise InputFileError(f"{raw.path}: vals_nod_var has shape {v.shape}")
                return np.asarray(v[:, i, :], float)
            v = ds.variables.get(f"vals_nod_var{i + 1}")
            if v is None:
                raise InputFileError(f"{raw.path}: nodal variable {names[i]!r} has no values")
            if v.ndim != 2 or v.shape[1] != n_nodes:
                raise InputFileError(
                    f"{raw.path}: nodal variable {names[i]!r} has shape {v.shape}, "
                    f"expected (steps, {n_nodes})"
                )
            return np.asarray(v[:], float)

        return load

    def at_step(i: int) -> Callable[[], np.ndarray]:
        def load() -> np.ndarray:
            if old:
                v = ds.variables["vals_nod_var"]
                if v.ndim != 3 or v.shape[1] != nvar or v.shape[2] != n_nodes or v.shape[0] <= chosen:
                    raise InputFileError(f"{raw.path}: vals_nod_var has shape {v.shape}")
                return np.asarray(v[chosen, i, :], float)
            v = ds.variables.get(f"vals_nod_var{i + 1}")
            if v is None:
                raise InputFileError(f"{raw.path}: nodal variable {names[i]!r} has no values")
            if v.ndim != 2 or v.shape[1] != n_nodes or v.shape[0] <= chosen:
                raise InputFileError(
                    f"{raw.path}: nodal variable {names[i]!r} has shape {v.shape}, "
                    f"expected (steps, {n_nodes})"
                )
            return np.asarray(v[chosen, :], float)

        return load

    index = {}
    for i, name in enumerate(names):
        if name and name not in index:
            index[name] = i
            raw.point_data.add(name, at_step(i))
            raw.ncomp[name] = 1
    for base, comps in vector_groups(list(index)).items():

        def vec(comps=comps) -> np.ndarray:
            cols = [np.asarray(raw.point_data[c], float) for c in comps]
            out = fresh_array((len(cols[0]), len(cols)), float)
            for k, c in enumerate(cols):
                out[:, k] = c
            return out

        raw.point_data.add(base, vec)
        raw.components[base] = comps
        raw.ncomp[base] = len(comps)

    def step_values(name: str) -> np.ndarray:
        return over_time(index[name])()

    raw.step_values = step_values


def _side_sets(ds, n_elem: int) -> list[SideSet]:
    nss = _dim(ds, "num_side_sets", 0)
    names = _names(ds, "ss_names", nss)
    ids = _ids(ds, "ss_prop1", nss)
    out = []
    for k in range(nss):
        m = _dim(ds, f"num_side_ss{k + 1}", 0)
        if m == 0:
            continue
        el = _read(ds, f"elem_ss{k + 1}", (m,), dtype=np.int64) - 1
        sd = _read(ds, f"side_ss{k + 1}", (m,), dtype=np.int64) - 1
        if el.size and (el.min() < 0 or el.max() >= n_elem):
            raise ValueError(f"side set {ids[k]} names element {int(el.max()) + 1} of {n_elem}")
        if sd.size and (sd.min() < 0 or sd.max() > 5):
            raise ValueError(f"side set {ids[k]} names side {int(sd.max()) + 1}")
        label = f"side set {ids[k]}" + (f" '{names[k]}'" if names[k] else "")
        out.append(SideSet(label, names[k], ids[k], el, sd))
    return out


def _globals(ds, chosen: int | None) -> dict[str, float]:
    n = _dim(ds, "num_glo_var", 0)
    if n == 0 or chosen is None or "vals_glo_var" not in ds.variables:
        return {}
    names = _names(ds, "name_glo_var", n)
    v = ds.variables["vals_glo_var"]
    if v.ndim != 2 or v.shape[1] != n or v.shape[0] <= chosen:
        raise ValueError(f"vals_glo_var has shape {v.shape}")
    vals = np.asarray(v[chosen, :], float)
    return {name: float(x) for name, x in zip(names, vals, strict=True) if name}
