"""Write Exodus II files for the tests, with netCDF4 and nothing of fepost.

The layout follows the Exodus II specification as MOOSE writes it (netCDF
64-bit offset, ``connect<k>`` with ``elem_type``, ``vals_nod_var<k>``,
``vals_elem_var<i>eb<k>``, ``elem_ss<k>``/``side_ss<k>``, ``vals_glo_var``).
"""

from __future__ import annotations

from pathlib import Path

import netCDF4
import numpy as np

LEN = 33


def _names(ds, var: str, dim: str, names: list[str]) -> None:
    v = ds.createVariable(var, "S1", (dim, "len_name"))
    arr = np.zeros((len(names), LEN), "S1")
    for i, n in enumerate(names):
        b = n.encode()[: LEN - 1]
        arr[i, : len(b)] = np.frombuffer(b, "S1")
    v[:] = arr


def _ids_and_names(ds, prefix: str, dim: str, count: int, names) -> None:
    """Status (all active), IDs 1..count and names of ``count`` blocks or sets (``prefix`` eb, ss)."""
    ds.createVariable(f"{prefix}_status", "i4", (dim,))[:] = np.ones(count, np.int32)
    prop = ds.createVariable(f"{prefix}_prop1", "i4", (dim,))
    prop.setncattr("name", "ID")
    prop[:] = np.arange(1, count + 1, dtype=np.int32)
    _names(ds, f"{prefix}_names", dim, names or [""] * count)


def write(
    path: str | Path,
    points: np.ndarray,
    blocks: list[tuple[str, np.ndarray]],
    nodal: dict[str, np.ndarray] | None = None,
    times=(0.0,),
    elemental: dict[str, list[np.ndarray]] | None = None,
    globals_: dict[str, np.ndarray] | None = None,
    side_sets: list[tuple[np.ndarray, np.ndarray]] | None = None,
    side_set_names: list[str] | None = None,
    node_sets: list[np.ndarray] | None = None,
    block_names: list[str] | None = None,
    num_dim: int | None = None,
    fmt: str = "NETCDF3_64BIT_OFFSET",
) -> Path:
    """Write an Exodus II file.

    ``points`` (n, d); ``blocks`` [(elem_type, (m, k) 0-based connectivity)];
    ``nodal`` {name: (steps, n)}; ``elemental`` {name: [per block (steps, m)]};
    ``globals_`` {name: (steps,)}; ``side_sets`` [(0-based global elements,
    0-based sides)]; ``node_sets`` [0-based nodes].
    """
    path = Path(path)
    points = np.asarray(points, float)
    nd = num_dim or points.shape[1]
    times = np.asarray(times, float)
    ds = netCDF4.Dataset(str(path), "w", format=fmt)
    try:
        ds.title = "fepost test file"
        ds.api_version = np.float32(8.0)
        ds.version = np.float32(2.0)
        ds.floating_point_word_size = np.int32(8)
        ds.file_size = np.int32(1)
        ds.createDimension("len_string", LEN)
        ds.createDimension("len_line", 81)
        ds.createDimension("four", 4)
        ds.createDimension("len_name", LEN)
        ds.createDimension("time_step", None)
        ds.createDimension("num_dim", nd)
        ds.createDimension("num_nodes", len(points))
        ds.createDimension("num_elem", sum(len(c) for _, c in blocks))
        ds.createDimension("num_el_blk", len(blocks))
        t = ds.createVariable("time_whole", "f8", ("time_step",))
        t[:] = times
        for k, c in enumerate("xyz"[:nd]):
            ds.createVariable(f"coord{c}", "f8", ("num_nodes",))[:] = points[:, k]
        _names(ds, "coor_names", "num_dim", list("xyz"[:nd]))
        _ids_and_names(ds, "eb", "num_el_blk", len(blocks), block_names)
        for k, (etype, conn) in enumerate(blocks):
            conn = np.asarray(conn, np.int64)
            ds.createDimension(f"num_el_in_blk{k + 1}", len(conn))
            ds.createDimension(f"num_nod_per_el{k + 1}", conn.shape[1])
            v = ds.createVariable(
                f"connect{k + 1}", "i4", (f"num_el_in_blk{k + 1}", f"num_nod_per_el{k + 1}")
            )
            v.elem_type = etype
            v[:] = conn + 1
        if nodal:
            ds.createDimension("num_nod_var", len(nodal))
            _names(ds, "name_nod_var", "num_nod_var", list(nodal))
            for i, vals in enumerate(nodal.values()):
                v = ds.createVariable(f"vals_nod_var{i + 1}", "f8", ("time_step", "num_nodes"))
                v[:] = np.asarray(vals, float).reshape(len(times), len(points))
        if elemental:
            ds.createDimension("num_elem_var", len(elemental))
            _names(ds, "name_elem_var", "num_elem_var", list(elemental))
            tab = ds.createVariable("elem_var_tab", "i4", ("num_el_blk", "num_elem_var"))
            tab[:] = np.ones((len(blocks), len(elemental)), np.int32)
            for i, per_block in enumerate(elemental.values()):
                for k, vals in enumerate(per_block):
                    v = ds.createVariable(
                        f"vals_elem_var{i + 1}eb{k + 1}", "f8", ("time_step", f"num_el_in_blk{k + 1}")
                    )
                    v[:] = np.asarray(vals, float).reshape(len(times), -1)
        if globals_:
            ds.createDimension("num_glo_var", len(globals_))
            _names(ds, "name_glo_var", "num_glo_var", list(globals_))
            v = ds.createVariable("vals_glo_var", "f8", ("time_step", "num_glo_var"))
            v[:] = np.column_stack([np.asarray(g, float).reshape(len(times)) for g in globals_.values()])
        if side_sets:
            ds.createDimension("num_side_sets", len(side_sets))
            _ids_and_names(ds, "ss", "num_side_sets", len(side_sets), side_set_names)
            for k, (el, sd) in enumerate(side_sets):
                ds.createDimension(f"num_side_ss{k + 1}", len(el))
                ds.createVariable(f"elem_ss{k + 1}", "i4", (f"num_side_ss{k + 1}",))[:] = np.asarray(el) + 1
                ds.createVariable(f"side_ss{k + 1}", "i4", (f"num_side_ss{k + 1}",))[:] = np.asarray(sd) + 1
        if node_sets:
            ds.createDimension("num_node_sets", len(node_sets))
            for k, nodes in enumerate(node_sets):
                ds.createDimension(f"num_nod_ns{k + 1}", len(nodes))
                ds.createVariable(f"node_ns{k + 1}", "i4", (f"num_nod_ns{k + 1}",))[:] = np.asarray(nodes) + 1
    finally:
        ds.close()
    return path


def hex_grid(nx: int, ny: int, nz: int, size=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0)):
    """A structured block of HEX8 elements (Exodus node order): points (n, 3), connectivity (m, 8)."""
    xs = np.linspace(0, size[0], nx + 1) + origin[0]
    ys = np.linspace(0, size[1], ny + 1) + origin[1]
    zs = np.linspace(0, size[2], nz + 1) + origin[2]
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    idx = np.arange(len(pts)).reshape(nx + 1, ny + 1, nz + 1)
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    conn = np.column_stack(
        [
            idx[i, j, k],
            idx[i + 1, j, k],
            idx[i + 1, j + 1, k],
            idx[i, j + 1, k],
            idx[i, j, k + 1],
            idx[i + 1, j, k + 1],
            idx[i + 1, j + 1, k + 1],
            idx[i, j + 1, k + 1],
        ]
    )
    return pts, conn
