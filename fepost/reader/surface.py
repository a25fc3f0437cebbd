"""The surface that carries the contact pressure: element faces of one body.

Rules (why each: see ``docs/reading.md``):

* The surface is made of **element faces**: the cells themselves for shell or
  surface meshes, the boundary faces of volume elements otherwise. Exodus side
  sets are never added as faces (they repeat faces the blocks already have);
  node sets are never used.
* **Nodes are never merged**: two bodies in contact have nodes at the same
  positions, and merging them mixes their faces.
* For volume meshes with nodal pressure only the elements touching a node with
  non-zero (or NaN) pressure are looked at: the faces away from the contact
  carry nothing, and a large model's boundary is not extracted.
* **Bodies**: those elements split into connected parts (elements sharing a
  node). Parts whose faces carry pressure at the same place are the two sides
  of one contact: the one with more loaded nodes (the finer mesh, which
  resolves the pressure better; on a tie the larger load) is kept, and the
  note says which and the other's load. Loaded parts apart from each other are all kept:
  the patch step decides whether they are one patch, fragments or several patches.
* ``surface=NAME`` restricts the faces to an Exodus side set (by name or id) or
  to an element block (by name or id): the way to pick one contact surface
  when a model has several.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..components import item_parts
from ..errors import FieldError
from .cells import FACE_TYPES, SPECS, Faces, boundary_faces, pack_key, side_faces
from .raw import RawMesh

#: Share of one part's loaded nodes that must lie near the other's for "both sides of one contact".
OVERLAP_SHARE = 0.5


@dataclass
class Surface:
    """Faces by type, their element values (cell data), and what was chosen."""

    conn: dict[str, np.ndarray]
    values: dict[str, np.ndarray] | None  # per face, for cell data
    body: str
    notes: list[str] = field(default_factory=list)


def _faces_of(
    blocks: list[tuple[str, np.ndarray]], values: list[np.ndarray] | None
) -> tuple[Faces, dict | None]:
    faces = boundary_faces(blocks)
    if values is None:
        return faces, None
    allv = np.concatenate(values) if values else np.empty(0)
    return faces, {t: allv[faces.cell[t]] for t in faces.conn}


def _named_surface(
    raw: RawMesh, name: str, cell_values: list[np.ndarray] | None
) -> tuple[dict[str, np.ndarray], dict | None, str]:
    key = name.strip().lower()
    for ss in raw.side_sets:
        if key in (ss.name.lower(), str(ss.id)):
            conn: dict[str, list] = {}
            vals: dict[str, list] = {}
            for bi, b in enumerate(raw.blocks):
                m = len(b.conn)
                sel = (ss.elements >= b.first_cell) & (ss.elements < b.first_cell + m)
                if not sel.any() or SPECS[b.cell_type].dim < 2:
                    continue
                rows = ss.elements[sel] - b.first_cell
                sides = ss.sides[sel]
                for ftype, nodes, idx in side_faces(b.cell_type, b.conn[rows], sides):
                    conn.setdefault(ftype, []).append(nodes)
                    if cell_values is not None:
                        vals.setdefault(ftype, []).append(cell_values[bi][rows[idx]])
            return (
                {t: np.concatenate(v) for t, v in conn.items()},
                {t: np.concatenate(v) for t, v in vals.items()} if cell_values is not None else None,
                ss.label,
            )
    for bi, b in enumerate(raw.blocks):
        ident = b.label.lower()
        if key == ident or ident.startswith(f"element block {key} ") or f"'{key}'" in ident:
            faces, fvals = _faces_of(
                [(b.cell_type, b.conn)], None if cell_values is None else [cell_values[bi]]
            )
            return faces.conn, fvals, b.label
    sets = ", ".join(f"{s.id}" + (f" '{s.name}'" if s.name else "") for s in raw.side_sets) or "none"
    blocks = ", ".join(b.label for b in raw.blocks) or "none"
    raise FieldError(
        f"{raw.path}: no side set or element block {name!r}; side sets: {sets}; blocks: {blocks}"
    )


def loaded_surfaces(
    raw: RawMesh, point_values: np.ndarray | None, cell_values: list[np.ndarray] | None
) -> list[str]:
    """Labels of the side sets and element blocks whose faces carry positive pressure.

    For the refusal of a ``--surface`` that carries none: it names where the pressure is.
    """
    out = []
    keys = [ss.name or str(ss.id) for ss in raw.side_sets]
    keys += [str(b.label) for b in raw.blocks if SPECS[b.cell_type].dim >= 2 and len(b.conn)]
    for key in keys:
        conn, vals, label = _named_surface(raw, key, cell_values)
        if point_values is not None:
            peaks = [np.nanmax(point_values[c]) for c in conn.values() if len(c)]
        else:
            peaks = [np.nanmax(v) for v in (vals or {}).values() if len(v)]
        if peaks and max(peaks) > 0 and label not in out:
            out.append(label)
    return out


def select_surface(
    raw: RawMesh,
    location: str,
    point_values: np.ndarray | None,
    cell_values: list[np.ndarray] | None,
    surface: str | None = None,
) -> Surface:
    """The faces carrying the pressure (``point_values`` per node, or ``cell_values`` per block)."""
    if surface is not None:
        conn, vals, label = _named_surface(raw, surface, cell_values)
        return Surface(conn, vals, label, [f"surface: {label} (chosen with --surface)"])
    volume = any(SPECS[b.cell_type].dim == 3 for b in raw.blocks)
    if not volume or location != "point":
        blocks = [(b.cell_type, b.conn) for b in raw.blocks]
        faces, vals = _faces_of(blocks, cell_values)
        labels = sorted({b.label for b in raw.blocks if SPECS[b.cell_type].dim >= 2})
        surf = Surface(faces.conn, vals, " + ".join(labels) if len(labels) <= 3 else f"{len(labels)} blocks")
        if len({b.body for b in raw.blocks}) > 1:
            _choose_parts(raw, surf, faces, point_values, cell_values, [b.body for b in raw.blocks])
        return surf
    assert point_values is not None
    nonzero = ~(point_values == 0.0)  # NaN counts: its faces must be seen by the NaN checks
    cand_blocks: list[tuple[str, np.ndarray]] = []
    owners: list[int] = []
    for bi, b in enumerate(raw.blocks):
        if SPECS[b.cell_type].dim < 2 or len(b.conn) == 0:
            continue
        touch = nonzero[b.conn].any(axis=1)
        if touch.any():
            cand_blocks.append((b.cell_type, b.conn[touch]))
            owners.append(bi)
    if not cand_blocks:
        return Surface({}, None, "no element touches a node with non-zero pressure")
    faces = boundary_faces(cand_blocks)
    # drop faces with no non-zero node: interior faces seen from one side only, or plain unloaded ones
    for t in list(faces.conn):
        keep = nonzero[faces.conn[t]].any(axis=1)
        faces.conn[t] = faces.conn[t][keep]
        faces.cell[t] = faces.cell[t][keep]
        if not len(faces.conn[t]):
            del faces.conn[t], faces.cell[t]
    part = _parts(cand_blocks, len(raw.points))
    block_of_cell = np.concatenate(
        [np.full(len(c), o) for (_, c), o in zip(cand_blocks, owners, strict=True)]
    )
    labels = [raw.blocks[o].label for o in owners]
    surf = Surface(faces.conn, None, " + ".join(sorted(set(labels))))
    _choose_parts(raw, surf, faces, point_values, None, part, block_of_cell=block_of_cell)
    note = _side_set_note(raw, surf, point_values)
    if note:
        surf.notes.append(note)
    return surf


def _keys(conn: dict[str, np.ndarray]) -> np.ndarray:
    """One void-typed key per face from its sorted corners (comparable across face types)."""
    parts = [pack_key(c[:, : (3 if t.startswith("tri") else 4)]) for t, c in conn.items() if len(c)]
    if not parts:
        return np.empty(0, np.dtype((np.void, 32)))
    keys = np.concatenate(parts)
    return keys.view(np.dtype((np.void, keys.dtype.itemsize * 4))).ravel()


def _side_set_note(raw: RawMesh, surf: Surface, point_values: np.ndarray) -> str:
    """Name the side set that holds the loaded faces, when one does (Exodus files have them)."""
    if not raw.side_sets or not surf.conn:
        return ""
    # faces loaded at every node: the contact surface itself (the faces at its rim may be sides)
    loaded = {t: c[np.nan_to_num(point_values[c], nan=0.0).min(axis=1) > 0] for t, c in surf.conn.items()}
    keys = _keys(loaded)
    if keys.size == 0:
        return ""
    best, best_share = None, 0.0
    for ss in raw.side_sets:
        conn: dict[str, list] = {}
        for b in raw.blocks:
            m = len(b.conn)
            sel = (ss.elements >= b.first_cell) & (ss.elements < b.first_cell + m)
            if sel.any() and SPECS[b.cell_type].dim >= 2:
                rows = b.conn[ss.elements[sel] - b.first_cell]
                for ftype, nodes, _ in side_faces(b.cell_type, rows, ss.sides[sel]):
                    conn.setdefault(ftype, []).append(nodes)
        share = float(np.isin(keys, _keys({t: np.concatenate(v) for t, v in conn.items()})).mean())
        if share > best_share:
            best, best_share = ss, share
    if best is None or best_share < 0.9:
        return ""
    return f"the loaded faces lie on {best.label} ({best_share:.0%} of them)"


def _parts(cand_blocks: list[tuple[str, np.ndarray]], n_points: int) -> np.ndarray:
    """Connected part of each candidate element (elements sharing a node are connected)."""
    conns = [c for _, c in cand_blocks]
    nodes = np.concatenate([c.ravel() for c in conns])
    elem = np.concatenate([np.repeat(np.arange(len(c)), c.shape[1]) for c in conns])
    offsets = np.cumsum([0] + [len(c) for c in conns])[:-1]
    elem = elem + np.repeat(offsets, [c.size for c in conns])
    return item_parts(elem, nodes, sum(len(c) for c in conns))[1]


def _choose_parts(
    raw: RawMesh,
    surf: Surface,
    faces: Faces,
    point_values: np.ndarray | None,
    cell_values: list[np.ndarray] | None,
    part_of_cell,
    block_of_cell: np.ndarray | None = None,
) -> None:
    """Keep one side where two loaded parts overlap (both sides of one contact)."""
    part_of_cell = np.asarray(part_of_cell)
    if block_of_cell is None:
        # one entry per block: expand to one per element (cells of the blocks in order)
        sizes = [len(b.conn) for b in raw.blocks]
        block_of_cell = np.repeat(np.arange(len(raw.blocks)), sizes)
        part_of_cell = np.repeat(part_of_cell, sizes)
    parts: dict[int, dict] = {}
    for t, conn in faces.conn.items():
        pc = part_of_cell[faces.cell[t]]
        if point_values is not None:
            v = point_values[conn]
            loaded = np.nan_to_num(v, nan=0.0).max(axis=1) > 0
        else:
            fv = surf.values[t] if surf.values is not None else np.zeros(len(conn))
            loaded = np.nan_to_num(fv, nan=0.0) > 0
        for p in np.unique(pc[loaded]):
            sel = loaded & (pc == p)
            d = parts.setdefault(int(p), {"nodes": [], "load": 0.0, "blocks": set()})
            hot_nodes = conn[sel].ravel()
            if point_values is not None:
                hot_nodes = hot_nodes[np.nan_to_num(point_values[hot_nodes], nan=0.0) > 0]
            d["nodes"].append(hot_nodes)
            d["blocks"].update(int(b) for b in np.unique(block_of_cell[faces.cell[t][sel]]))
            d["load"] += _rough_load(raw.points, conn[sel], t, point_values, surf, sel)
    if len(parts) < 2:
        if len(parts) == 1:
            (p,) = parts
            blocks = parts[p]["blocks"]
            surf.body = " + ".join(raw.blocks[b].label for b in sorted(blocks))
            if len({raw.blocks[b].body for b in range(len(raw.blocks))}) > 1 or len(raw.blocks) > 1:
                surf.notes.append(f"loaded faces from {surf.body}")
        return
    for d in parts.values():
        d["hot"] = len(np.unique(np.concatenate(d["nodes"]))) if d["nodes"] else 0
    keys = sorted(parts, key=lambda p: (-parts[p]["hot"], -parts[p]["load"]))
    pts = raw.points
    from scipy.spatial import cKDTree

    drop: set[int] = set()
    for i, a in enumerate(keys):
        if a in drop:
            continue
        na = np.unique(np.concatenate(parts[a]["nodes"]))
        tree = cKDTree(pts[na])
        h = _edge(pts, na)
        for b in keys[i + 1 :]:
            if b in drop:
                continue
            nb = np.unique(np.concatenate(parts[b]["nodes"]))
            tol = max(h, _edge(pts, nb))
            d, _ = tree.query(pts[nb], distance_upper_bound=tol)
            if np.mean(np.isfinite(d)) >= OVERLAP_SHARE:
                drop.add(b)
    if not drop:
        names = [_part_label(raw, parts[p]["blocks"]) for p in keys]
        surf.body = " + ".join(dict.fromkeys(names))
        return
    kept = [p for p in keys if p not in drop]
    keep_cells = np.isin(part_of_cell, kept)
    for t in list(faces.conn):
        sel = keep_cells[faces.cell[t]]
        surf.conn[t] = faces.conn[t][sel]
        if surf.values is not None:
            surf.values[t] = surf.values[t][sel]
        if not len(surf.conn[t]):
            del surf.conn[t]
            if surf.values is not None:
                del surf.values[t]
    chosen = " + ".join(dict.fromkeys(_part_label(raw, parts[p]["blocks"]) for p in kept))
    others = "; ".join(
        f"{_part_label(raw, parts[p]['blocks'])} (~{parts[p]['load']:.4g})" for p in sorted(drop)
    )
    surf.body = chosen
    surf.notes.append(
        f"both sides of the contact carry pressure: loaded faces taken from {chosen} "
        f"(~{sum(parts[p]['load'] for p in kept):.4g} in file units), not from {others}"
    )


def _part_label(raw: RawMesh, blocks: set[int]) -> str:
    return " + ".join(raw.blocks[b].label for b in sorted(blocks))


def _edge(pts: np.ndarray, nodes: np.ndarray) -> float:
    """A length of the order of the mesh size around ``nodes``: √(bounding-box area / node count)."""
    p = pts[nodes]
    ext = np.sort(p.max(axis=0) - p.min(axis=0))[::-1]
    area = max(ext[0] * ext[1], ext[0] ** 2 * 1e-6, 1e-300)
    return float(2.0 * np.sqrt(area / max(len(nodes), 1)))


def _rough_load(points, conn, ftype, point_values, surf, sel) -> float:
    """Load of faces from their corner triangle(s), for ranking the sides of a contact."""
    nc = 3 if ftype.startswith("tri") else 4
    c = conn[:, :nc]
    p = points[c]
    if nc == 3:
        area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    else:
        area = 0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1)
    if point_values is not None:
        mean = np.nan_to_num(point_values[c], nan=0.0).mean(axis=1)
    else:
        mean = np.nan_to_num(surf.values[ftype][sel], nan=0.0)
    return float(np.sum(area * mean))


__all__ = ["FACE_TYPES", "Surface", "loaded_surfaces", "select_surface"]
