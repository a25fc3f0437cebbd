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
  that have a contact spring only). A node listed twice with the same values
  is read once; with different values, or two CONTACT (or DISP) blocks of one
  increment that differ, the file is refused (which one is right?);
* when no step is asked for and the last increment holds no CONTACT block (a
  last step without contact output, as in CalculiX's ``contact10`` example),
  the last increment that holds one is read, with a note; an asked-for step
  without one is refused, naming the steps that have contact output, and so
  is a file cut off (no closing ``9999`` line) before its last step's contact output;
* ``DISP`` (``*NODE FILE`` / ``*NODE OUTPUT`` with ``U``) as the displacement,
  and the other nodal blocks of the increment under their frd names.

The contact surface is recovered from the elements: the elements touching a
node with a non-zero ``CONTACT`` record are handed on (nodes compacted), and
`fepost.reader.surface` takes their boundary faces that touch non-zero
pressure, keeps one side where both bodies carry pressure, and the patch step
drops the steep side faces at the rim. Faces keep their mid-side nodes
(``quad8``, ``tri6``). Why not "the faces whose nodes all carry a record":
CalculiX writes node-to-surface contact only at the slave nodes whose spring
is active, so the faces at the rim of the contact, half open, have nodes
without a record; that rule lost 23 % of the load of the sample tire model
(`scripts/tiremodel`), this one matches its reaction to 2e-4. A model with
only surface elements lying in z = 0 is a 2-D model.

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
from .cells import SPECS
from .exodus import choose_step
from .frdparse import FrdFile, ResultBlock, block_values, open_frd, scan
from .raw import Block, RawMesh
from .suffixes import FRD_SUFFIXES

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


def _nodal(frd: FrdFile, nodes: _Nodes, block: ResultBlock, keep: np.ndarray, where: str) -> np.ndarray:
    """The block's values at the nodes ``keep`` (NaN where it has no record; ``DISP`` must cover them)."""
    ids, vals = _records(frd, block, where)
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
        if not frd.complete:
            raise _truncated(frd, path, "before any results")
        raise FieldError(f"{path}: the file holds no results; {NO_CONTACT}")
    notes: list[str] = []
    if not _blocks_at(frd, incs[chosen][0]).get("CONTACT"):
        chosen = _contact_step(frd, path, incs, chosen, explicit=step is not None)
        notes.append(
            f"step {len(incs) - 1} (t = {incs[-1][1]:g}), the last, holds no contact output: read step "
            f"{chosen} (t = {incs[chosen][1]:g}), the last with a CONTACT block; choose another with --step"
        )
        warnings.warn(f"{path}: {notes[-1]}", ReaderWarning, stacklevel=3)
    kode = incs[chosen][0]
    where = f"step {chosen} (t = {incs[chosen][1]:g})"
    named = _blocks_at(frd, kode)
    here = {name: _one(frd, blocks, where) for name, blocks in named.items()}
    contact = here["CONTACT"]
    if "CPRESS" not in contact.components:
        raise FieldError(
            f"{path}: the CONTACT block has no CPRESS component ({', '.join(contact.components)})"
        )
    nodes = _Nodes(path, frd.node_ids)
    n = len(frd.node_ids)
    conn = {
        t: nodes.rows(c, f"an element of frd type {t} ({CANONICAL[t]})") for t, c in frd.elem_nodes.items()
    }
    cids, cvals = _records(frd, contact, where)
    rows = nodes.rows(cids, "the CONTACT block")
    written = np.zeros(n, bool)
    written[rows] = True
    contact_values = np.zeros((n, len(contact.components)))
    contact_values[rows] = cvals
    solid = [t for t in conn if SPECS[CANONICAL[t]].dim == 3]
    keep, blocks = _surface(path, conn, contact_values, written)
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
    raw.notes += notes
    raw.point_data.add("CONTACT", contact_values[keep])
    raw.components["CONTACT"] = contact.components
    raw.ncomp["CONTACT"] = len(contact.components)
    for name, b in here.items():
        if name == "CONTACT" or not b.components:
            continue

        def load(b=b) -> np.ndarray:
            return _nodal(frd, nodes, b, keep, where)

        raw.point_data.add(name, load)
        raw.components[name] = b.components
        raw.ncomp[name] = len(b.components)
    return raw


def _surface(
    path: Path, conn: dict[int, np.ndarray], contact: np.ndarray, written: np.ndarray
) -> tuple[np.ndarray, list[Block]]:
    """(nodes kept, element blocks): the elements touching a node with non-zero contact output."""
    hot = np.any(contact != 0.0, axis=1)  # NaN counts: its faces must meet the NaN checks
    chosen = {t: c[hot[c].any(axis=1)] for t, c in conn.items()}
    chosen = {t: c for t, c in chosen.items() if len(c)}
    if not chosen:  # no contact at this increment: the pipeline says so, naming the step
        return np.arange(len(contact)), _element_blocks(conn, conn)
    keep = np.unique(np.concatenate([c.ravel() for c in chosen.values()]))
    node_to_surface = not written[keep].all()
    if node_to_surface and any(t in (4, 10) for t in chosen):
        warnings.warn(
            f"{path}: node-to-surface contact on quadratic hexahedra: CalculiX's nodal CPRESS on 8-node "
            "faces does not integrate to the contact force (its tributary areas are not the shape-function "
            "integrals: tens of percent off in a test); prefer surface-to-surface contact or linear elements",
            ReaderWarning,
            stacklevel=3,
        )
    remap = np.full(len(contact), -1, np.int64)
    remap[keep] = np.arange(len(keep))
    return keep, _element_blocks({t: remap[c] for t, c in chosen.items()}, conn)


def _blocks_at(frd: FrdFile, kode: int) -> dict[str, list[ResultBlock]]:
    """The result blocks of one increment by name, in file order."""
    out: dict[str, list[ResultBlock]] = {}
    for b in frd.blocks:
        if b.kode == kode:
            out.setdefault(b.name, []).append(b)
    return out


def _one(frd: FrdFile, blocks: list[ResultBlock], where: str) -> ResultBlock:
    """The block of a name at one increment; several are refused unless they hold the same records."""
    first = blocks[0]
    if len(blocks) > 1 and first.name in _CHECKED_TWICE:
        ids, vals = block_values(frd, first)
        for other in blocks[1:]:
            ids2, vals2 = block_values(frd, other)
            if not (np.array_equal(ids, ids2) and np.array_equal(vals, vals2, equal_nan=True)):
                raise InputFileError(
                    f"{frd.path}: {where} holds {len(blocks)} {first.name} blocks with different values "
                    "(corrupt file, or two runs written into one file?); fepost cannot tell which to read"
                )
    return first


#: Blocks whose repetition at one increment is checked (the ones the field is made of).
_CHECKED_TWICE = ("CONTACT", "DISP")


def _records(frd: FrdFile, block: ResultBlock, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(node ids, values) of a block, a node's repeated records dropped where they are equal and
    refused where they differ (which one holds the node's values?)."""
    ids, vals = block_values(frd, block)
    if len(ids) < 2:
        return ids, vals
    order = np.argsort(ids, kind="stable")
    same = ids[order[1:]] == ids[order[:-1]]
    if not same.any():
        return ids, vals
    first, second = order[:-1][same], order[1:][same]
    differ = np.any((vals[first] != vals[second]) & ~(np.isnan(vals[first]) & np.isnan(vals[second])), axis=1)
    if differ.any():
        k = int(np.flatnonzero(differ)[0])
        node = int(ids[first[k]])
        raise InputFileError(
            f"{frd.path}: result block {block.name} at {where} holds node {node} twice, with different "
            f"values ({_shown(block, vals[first[k]])} and {_shown(block, vals[second[k]])}); "
            "fepost cannot tell which to read (corrupt file?)"
        )
    keep = np.ones(len(ids), bool)
    keep[second] = False
    return ids[keep], vals[keep]


def _shown(block: ResultBlock, row: np.ndarray) -> str:
    if "CPRESS" in block.components:
        return f"CPRESS {row[block.components.index('CPRESS')]:g}"
    return ", ".join(f"{v:g}" for v in row[:3])


def _contact_step(
    frd: FrdFile, path: Path, incs: list[tuple[int, float]], chosen: int, explicit: bool
) -> int:
    """The step to read when step ``chosen`` holds no CONTACT block: the last that holds one when
    no step was asked for; else (or in a file cut off while that step was written) refused."""
    with_contact = {b.kode for b in frd.blocks if b.name == "CONTACT"}
    if not with_contact:
        if not frd.complete:  # cut off in its first step, or in a step header line (1PSTEP, 100C)
            last = len(incs) - 1
            where = f"in step {last} (t = {incs[last][1]:g}), before its contact output"
            if last:
                where += f"; its complete step(s) 0-{last - 1} hold no contact output either: {NO_CONTACT}"
            raise _truncated(frd, path, where)
        raise FieldError(f"{path}: {NO_CONTACT}")
    listed = [k for k, (kd, _) in enumerate(incs) if kd in with_contact]
    shown = ", ".join(f"{k} (t = {incs[k][1]:g})" for k in listed[-10:])
    more = f"{len(listed) - 10} more and " if len(listed) > 10 else ""
    if not frd.complete and chosen == len(incs) - 1:
        raise InputFileError(
            f"{path}: truncated .frd file: it ends at byte {len(frd.data)} without CalculiX's closing 9999 "
            f"line, in step {chosen} (t = {incs[chosen][1]:g}), before its contact output (cut off while "
            f"written?); contact output is complete at step(s) {more}{shown}: choose one with --step"
        )
    if explicit:
        raise FieldError(
            f"{path}: no CONTACT block at step {chosen} (t = {incs[chosen][1]:g}); contact output is at "
            f"step(s) {more}{shown}: choose one with --step"
        )
    return listed[-1]


def _truncated(frd: FrdFile, path: Path, where: str) -> InputFileError:
    """The error of a file cut off while CalculiX wrote it (no closing 9999 line)."""
    return InputFileError(
        f"{path}: truncated .frd file: it ends at byte {len(frd.data)} without CalculiX's closing 9999 "
        f"line (cut off while written?), {where}"
    )


def _element_blocks(chosen: dict[int, np.ndarray], conn: dict[int, np.ndarray]) -> list[Block]:
    blocks, first = [], 0
    for t, c in chosen.items():
        canon = CANONICAL[t]
        what = f"{len(c)}" if len(c) == len(conn[t]) else f"{len(c)} of {len(conn[t])} touching the contact"
        blocks.append(Block(f"{canon.upper()} elements ({what})", canon, c, first, 0))
        first += len(c)
    return blocks


__all__ = ["FRD_SUFFIXES", "NO_CONTACT", "read_frd", "read_steps"]
