"""CalculiX ``.frd`` result files read directly, ASCII and binary.

What is read (the records: `fepost.reader.frdparse`):

* the nodes and the elements (``C3D8``/``C3D8R``/``C3D8I`` as frd type 1,
  ``C3D6`` 2, ``C3D4`` 3, ``C3D20``/``C3D20R`` 4, ``C3D15`` 5, ``C3D10`` 6,
  surface elements 7–10, beams 11–12 passed over). CalculiX writes the
  quadratic types with the Exodus II node order (corners, bottom edges,
  vertical edges, top edges), so they keep every node here;
* every **increment** (all blocks with one increment counter) is a time
  step, the last by default (``step`` picks one, 0-based, negative from the end);
* at that increment the ``CONTACT`` block (``*CONTACT FILE`` / ``*CONTACT
  OUTPUT`` with ``CSTR``): one nodal array ``CONTACT`` with the named
  components ``COPEN CSLIP1 CSLIP2 CPRESS CSHEAR1 CSHEAR2``; the pressure is
  its ``CPRESS`` component, the others stay available; nodes without a
  record hold zero (CalculiX writes node-to-surface contact at the slave nodes
  that have a contact spring only). A node listed twice keeps its last record;
* ``DISP`` (``*NODE FILE`` / ``*NODE OUTPUT`` with ``U``) as the displacement,
  and the other nodal blocks of the increment under their frd names.

The contact surface: the boundary faces of the elements whose nodes **all**
carry a ``CONTACT`` record (the slave faces of node-to-surface contact; on
quadratic faces all mid-side nodes: CalculiX gives no contact spring to a
node without tributary area, such as the corners of a 6-node triangle, whose
shape function integrates to zero, and those corners hold zero). When
the block covers every node of the mesh (surface-to-surface contact writes all
nodes, zeros away from the slave surface) the elements are handed on and the
faces touching non-zero pressure are found as for any volume mesh
(`fepost.reader.surface`). Faces keep their mid-side nodes (``quad8``,
``tri6``). A model with only surface elements lying in z = 0 is a 2-D model.

Why fepost parses the file itself and not with ccx2paraview (the only
maintained Python reader): it reads ASCII files only, keeps its node numbering
in a module-level dictionary, builds VTK objects for every block of every
increment, drops the mid-side nodes of ``C3D15`` and stops a corrupt file with
a ``SyntaxError``. The format is a handful of fixed-width records, parsed here
with numpy and every declared size checked before use.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..errors import FieldError, InputFileError, ReaderWarning
from .cells import SPECS, boundary_faces
from .exodus import choose_step
from .frdparse import FrdFile, ResultBlock, block_values, open_frd, scan
from .raw import Block, RawMesh

FRD_SUFFIXES = (".frd",)
#: frd element type → canonical type of `fepost.reader.cells` (node orders agree).
CANONICAL = {
    1: "hex8",
    2: "wedge6",
    3: "tet4",
    4: "hex20",
    5: "wedge15",
    6: "tet10",
    7: "tri3",
    8: "tri6",
    9: "quad4",
    10: "quad8",
    11: "line2",
    12: "line3",
}
#: What to put in the deck when the file has no contact output.
NO_CONTACT = (
    "no contact output (no CONTACT block): ask CalculiX for it with *CONTACT FILE (ASCII .frd) "
    "or *CONTACT OUTPUT (binary .frd) and the output variable CSTR (CDIS adds COPEN and the slips)"
)


def _increments(frd: FrdFile) -> list[tuple[int, float]]:
    """(increment counter, time) of every increment, in file order."""
    seen: dict[int, float] = {}
    for b in frd.blocks:
        seen.setdefault(b.kode, b.time)
    return list(seen.items())


def _release(data) -> None:
    """Unmap the file; while an error's traceback still holds a view of it, the collector unmaps it later."""
    try:
        data.close()
    except BufferError:
        pass


def read_steps(path: Path) -> tuple[float, ...]:
    """The time of every increment stored in an ``.frd`` file."""
    data = open_frd(path)
    try:
        return tuple(t for _, t in _increments(scan(path, data)))
    finally:
        _release(data)


def read_frd(path: Path, step: int | None) -> RawMesh:
    """Read an ``.frd`` file into a `fepost.reader.raw.RawMesh` at ``step`` (default: last)."""
    data = open_frd(path)
    try:
        frd = scan(path, data)
        raw = _assemble(frd, path, step)
    except (ValueError, IndexError, OverflowError) as exc:
        _release(data)
        raise InputFileError(f"{path}: corrupt .frd file ({exc})") from None
    except BaseException:
        _release(data)
        raise
    raw.closer = lambda: _release(data)
    return raw


class _Nodes:
    """Node numbers → row of the node block."""

    def __init__(self, path: Path, ids: np.ndarray):
        self.path = path
        self.order = np.argsort(ids, kind="stable")
        self.sorted = ids[self.order]
        if len(ids) > 1 and np.any(self.sorted[1:] == self.sorted[:-1]):
            dup = int(self.sorted[1:][self.sorted[1:] == self.sorted[:-1]][0])
            raise InputFileError(f"{path}: corrupt .frd file (node {dup} is defined twice)")

    def rows(self, ids: np.ndarray, what: str) -> np.ndarray:
        if not len(self.sorted):
            if len(ids):
                raise InputFileError(
                    f"{self.path}: {what} refers to node {int(ids.ravel()[0])}; the file has no nodes"
                )
            return np.asarray(ids, np.int64)
        pos = np.clip(np.searchsorted(self.sorted, ids), 0, len(self.sorted) - 1)
        bad = self.sorted[pos] != ids
        if np.any(bad):
            raise InputFileError(
                f"{self.path}: {what} refers to node {int(np.asarray(ids)[bad].ravel()[0])}, "
                "which the node block lacks (corrupt or inconsistent file)"
            )
        return self.order[pos]


def _nodal(frd: FrdFile, nodes: _Nodes, block: ResultBlock, keep: np.ndarray) -> np.ndarray:
    """The block's values at the nodes ``keep`` (NaN where it has no record; ``DISP`` must cover them)."""
    ids, vals = block_values(frd, block)
    out = np.full((len(frd.node_ids), vals.shape[1]), np.nan)
    written = np.zeros(len(frd.node_ids), bool)
    rows = nodes.rows(ids, f"result block {block.name}")
    out[rows] = vals
    written[rows] = True
    missing = int(np.count_nonzero(~written[keep]))
    if missing and block.name == "DISP":
        raise FieldError(
            f"{frd.path}: the DISP block has no values at {missing} of the {len(keep)} nodes read "
            "(written for a node set that leaves them out?); "
            "--displacement none reads the undeformed coordinates"
        )
    return out[keep]


def _assemble(frd: FrdFile, path: Path, step: int | None) -> RawMesh:
    incs = _increments(frd)
    chosen = choose_step(path, step, len(incs))
    if chosen is None:
        raise FieldError(f"{path}: the file holds no results; {NO_CONTACT}")
    kode = incs[chosen][0]
    here: dict[str, ResultBlock] = {}
    for b in frd.blocks:
        if b.kode == kode:
            here.setdefault(b.name, b)
    contact = here.get("CONTACT")
    if contact is None:
        _refuse_step(frd, path, incs, chosen)
    assert contact is not None
    if "CPRESS" not in contact.components:
        raise FieldError(
            f"{path}: the CONTACT block has no CPRESS component ({', '.join(contact.components)})"
        )
    nodes = _Nodes(path, frd.node_ids)
    n = len(frd.node_ids)
    conn = {
        t: nodes.rows(c, f"an element of frd type {t} ({CANONICAL[t]})") for t, c in frd.elem_nodes.items()
    }
    cids, cvals = block_values(frd, contact)
    rows = nodes.rows(cids, "the CONTACT block")
    carried = np.zeros(n, bool)
    carried[rows] = True
    contact_values = np.zeros((n, len(contact.components)))
    contact_values[rows] = cvals
    solid = [t for t in conn if SPECS[CANONICAL[t]].dim == 3]
    keep, blocks = _surface(path, conn, carried, n)
    points = frd.coords[keep]
    if not np.all(np.isfinite(points)):
        bad = int(np.sum(~np.isfinite(points).all(axis=1)))
        raise InputFileError(f"{path}: {bad} node coordinates are NaN or infinite")
    dim = 3 if solid or not len(points) or np.any(points[:, 2] != 0.0) else 2
    raw = RawMesh(
        path=str(path),
        format=f"CalculiX .frd ({'binary' if frd.binary else 'ASCII'})",
        points=points,
        blocks=blocks,
        dim=dim if blocks else 3,
        steps=tuple(t for _, t in incs),
        step=chosen,
    )
    raw.point_data.add("CONTACT", contact_values[keep])
    raw.components["CONTACT"] = contact.components
    raw.ncomp["CONTACT"] = len(contact.components)
    for name, b in here.items():
        if name == "CONTACT" or not b.components:
            continue

        def load(b=b) -> np.ndarray:
            return _nodal(frd, nodes, b, keep)

        raw.point_data.add(name, load)
        raw.components[name] = b.components
        raw.ncomp[name] = len(b.components)
    return raw


def _surface(
    path: Path, conn: dict[int, np.ndarray], carried: np.ndarray, n: int
) -> tuple[np.ndarray, list[Block]]:
    """(nodes kept, blocks): the contact faces when the CONTACT block picks them out, else the elements."""
    used = np.zeros(n, bool)
    for c in conn.values():
        used[c.ravel()] = True
    faces = [] if carried[used].all() else _contact_faces(conn, carried, n)
    if not faces:  # every node written (surface-to-surface): faces found from the pressure downstream
        return np.arange(n), _element_blocks(conn)
    if any(ftype in ("quad8", "quad9") for ftype, _, _ in faces):
        warnings.warn(
            f"{path}: node-to-surface contact on quadratic hexahedra: CalculiX's nodal CPRESS on 8-node "
            "faces does not integrate to the contact force (its tributary areas are not the shape-function "
            "integrals: tens of percent off in a test); prefer surface-to-surface contact or linear elements",
            ReaderWarning,
            stacklevel=3,
        )
    keep = np.unique(np.concatenate([f.ravel() for _, _, f in faces]))
    remap = np.full(n, -1, np.int64)
    remap[keep] = np.arange(len(keep))
    return keep, _face_blocks(faces, remap)


def _refuse_step(frd: FrdFile, path: Path, incs: list[tuple[int, float]], chosen: int) -> None:
    with_contact = {b.kode for b in frd.blocks if b.name == "CONTACT"}
    if not with_contact:
        raise FieldError(f"{path}: {NO_CONTACT}")
    listed = [f"{k} (t = {t:g})" for k, (kd, t) in enumerate(incs) if kd in with_contact]
    more = f" and {len(listed) - 10} more" if len(listed) > 10 else ""
    raise FieldError(
        f"{path}: no CONTACT block at step {chosen} (t = {incs[chosen][1]:g}); contact output is at "
        f"step(s) {', '.join(listed[:10])}{more}: choose one with --step"
    )


def _bodies(conn: dict[int, np.ndarray], n: int) -> np.ndarray:
    """Connected part (elements sharing nodes) of every node (a node of no element is a part alone)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    a = np.concatenate([np.repeat(c[:, 0], c.shape[1]) for c in conn.values()]) if conn else np.empty(0, int)
    b = np.concatenate([c.ravel() for c in conn.values()]) if conn else np.empty(0, int)
    g = coo_matrix((np.ones(len(a), np.int8), (a, b)), shape=(n, n))
    _, labels = connected_components(g, directed=False)
    return labels


def _contact_faces(
    conn: dict[int, np.ndarray], carried: np.ndarray, n: int
) -> list[tuple[str, int, np.ndarray]]:
    """(face type, body, (m, k) node rows) of the boundary faces whose nodes all carry contact output."""
    cand = []
    for t, c in conn.items():
        if SPECS[CANONICAL[t]].dim < 2:
            continue
        touch = carried[c].any(axis=1)
        if touch.any():
            cand.append((CANONICAL[t], c[touch]))
    if not cand:
        return []
    faces = boundary_faces(cand)
    body = _bodies(conn, n)
    out = []
    for ftype, f in faces.conn.items():
        corners = 3 if ftype.startswith("tri") else 4
        rule = f[:, corners:] if f.shape[1] > corners else f  # quadratic faces: their mid-side nodes
        f = f[carried[rule].all(axis=1)]
        for k in np.unique(body[f[:, 0]]) if len(f) else ():
            out.append((ftype, int(k), f[body[f[:, 0]] == k]))
    return out


def _face_blocks(faces: list[tuple[str, int, np.ndarray]], remap: np.ndarray) -> list[Block]:
    order = {k: i for i, k in enumerate(dict.fromkeys(k for _, k, _ in faces))}
    blocks, first = [], 0
    for ftype, k, f in faces:
        label = f"contact faces of body {order[k] + 1} ({ftype.upper()}, {len(f)} faces with CONTACT output)"
        blocks.append(Block(label, ftype, remap[f], first, order[k]))
        first += len(f)
    return blocks


def _element_blocks(conn: dict[int, np.ndarray]) -> list[Block]:
    blocks, first = [], 0
    for t, c in conn.items():
        canon = CANONICAL[t]
        blocks.append(Block(f"{canon.upper()} elements ({len(c)})", canon, c, first, 0))
        first += len(c)
    return blocks


__all__ = ["FRD_SUFFIXES", "NO_CONTACT", "read_frd", "read_steps"]
