"""Where a stalled CalculiX run's residual sits: the nodes, or the C3D8I elements, it keeps naming.

CalculiX prints ``largest residual force= F in node N and dof D`` after every iteration. When an
increment will not converge, the same few N come back; some are beyond the deck's node numbers.
CalculiX numbers the nodes it adds on from the deck's largest node number: first, as it reads a
``*RIGID BODY`` card, one for each node of the body (each node's rigid-body equations) and two
more; then, once the whole model is read, three for each C3D8I element (its incompatible modes),
taking the elements in the order of their numbers. A run restarted from such a model
(``*RESTART, READ``) counts the same nodes less those two per rigid body, and its modes are
again the last nodes (CalculiX 2.20, measured on a tiny deck and its restart:
``tests/test_tiremodel_residuals.py``). A residual on those last nodes is an element's, not a
node's. This script undoes that numbering and says where each named node or element is (its
reference coordinates, or its element's centroid, and the element sets that hold it).

With ``--frd RUN.frd`` (one log) each named element's shape is checked too: the smallest of its
eight corner volumes (the Jacobian at a corner, det of the three edges leaving it) over the same
corner's in the reference mesh, at the last increment the run stored (not the "best solution"
CalculiX writes with the residuals when it gives up: that increment holds the residual forces,
``FORC``, which ccx2paraview names ``RF``).

    python -m scripts.tiremodel.residuals BASE.inp RUN.log [RUN.log ...] [--restart] [--last 400]
        [--top 4] [--frd RUN.frd [--worst ELSET] [--at TIME]]

``--worst ELSET`` lists the most distorted elements of a set (e.g. ETREAD) at the stored
increment nearest ``--at`` (default the last), with or without a log.

``BASE.inp`` is the deck that defines the mesh (a restarted run's log goes with its base deck).

Why the deck is read here and not by meshio: meshio's Abaqus reader gives every hexahedron one
cell type (C3D8I and C3D8 alike), numbers the nodes from zero and skips ``*RIGID BODY``; the
mapping needs the deck's own node and element numbers, each element's type and the rigid
bodies' node sets. Only ``*NODE``, ``*ELEMENT``, ``*NSET``, ``*ELSET`` and ``*RIGID BODY`` are read.
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import re
import sys
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

_RESIDUAL = re.compile(r"largest residual force=\s*\S+ in node (\d+) and dof (\d+)")
#: extra nodes CalculiX adds to each C3D8I element (its three incompatible modes) ...
EXTRA_PER_C3D8I = 3
#: ... and to each rigid body besides one per node of the body (CalculiX 2.20; not in a restart)
EXTRA_PER_RIGID_BODY = 2


@dataclass(frozen=True)
class Mesh:
    """The nodes, the elements (type and nodes) and the element sets of a CalculiX deck, numbered
    as in the run of the deck itself or (``restart``) of a run restarted from it."""

    nodes: dict[int, np.ndarray]
    elements: dict[int, tuple[str, tuple[int, ...]]]
    elsets: dict[str, frozenset[int]]
    #: the rigid bodies' nodes other than their reference and rotation nodes, and the bodies
    rigid_body_nodes: int = 0
    rigid_bodies: int = 0
    restart: bool = False

    @property
    def rigid_nodes(self) -> int:
        """Nodes CalculiX adds for the rigid bodies (numbered before the incompatible modes)."""
        return self.rigid_body_nodes + (0 if self.restart else EXTRA_PER_RIGID_BODY * self.rigid_bodies)

    @cached_property
    def incompatible(self) -> tuple[int, ...]:
        """The C3D8I elements, in the order CalculiX gives them their modes (their numbers)."""
        return tuple(sorted(e for e, (etype, _) in self.elements.items() if etype == "C3D8I"))

    @property
    def modes_from(self) -> int:
        """The number of the first incompatible-mode node CalculiX adds."""
        return max(self.nodes) + self.rigid_nodes + 1

    @property
    def total_nodes(self) -> int:
        """The node count CalculiX prints (``nodes:``) for this deck."""
        return self.modes_from - 1 + EXTRA_PER_C3D8I * len(self.incompatible)

    def extra_owner(self, node: int) -> int | None:
        """The C3D8I element whose incompatible mode is ``node`` (None: any other node)."""
        if node < self.modes_from:
            return None
        k = (node - self.modes_from) // EXTRA_PER_C3D8I
        if k >= len(self.incompatible):
            raise ValueError(f"node {node} is beyond the deck's nodes and its C3D8I elements' modes")
        return self.incompatible[k]

    def centroid(self, element: int) -> np.ndarray:
        """The mean of the element's nodes (reference coordinates, m)."""
        return np.mean([self.nodes[n] for n in self.elements[element][1]], axis=0)

    def corner_volume(self, element: int, displacement: dict[int, np.ndarray]) -> float | None:
        """The hexahedron's smallest corner volume over its reference's (`corner_volume_ratio`)
        under ``displacement``; None where a corner has no displacement."""
        corners = self.elements[element][1][:8]
        if any(n not in displacement for n in corners):
            return None
        reference = np.array([self.nodes[n] for n in corners])
        return corner_volume_ratio(reference, reference + np.array([displacement[n] for n in corners]))

    def place(self, node: int) -> tuple[str, int]:
        """("node", N) for a node of the deck, ("element", E) for a C3D8I element's mode."""
        owner = self.extra_owner(node)
        return ("node", node) if owner is None else ("element", owner)

    def where(self, node: int) -> str:
        """One phrase: what ``node`` is and where (reference coordinates, m); an incompatible
        mode is named by its element."""
        owner = self.extra_owner(node)
        if owner is None:
            if node not in self.nodes:
                return f"node {node} (one CalculiX adds for a rigid body)"
            x = self.nodes[node]
            what = f"node {node}"
            sets = ""
        else:
            x = self.centroid(owner)
            what = f"{self.elements[owner][0]} element {owner} (incompatible modes)"
            names = sorted(name for name, members in self.elsets.items() if owner in members)
            sets = f" in {', '.join(names)}" if names else ""
        return f"{what}{sets} at {_point(x)}"


def _point(x: np.ndarray) -> str:
    """A point (m) as the script prints it: (+x.xxx, +y.yyy, +z.zzz)."""
    return f"({x[0]:+.3f}, {x[1]:+.3f}, {x[2]:+.3f})"


def _cards(lines: list[str]):
    """(keyword line, its data lines) for every card of the deck."""
    k = 0
    while k < len(lines):
        if lines[k].startswith("*") and not lines[k].startswith("**"):
            j = k + 1
            while j < len(lines) and not lines[j].startswith("*"):
                j += 1
            yield lines[k], [s for s in lines[k + 1 : j] if s.strip()]
            k = j
        else:
            k += 1


def _option(card: str, name: str) -> str | None:
    m = re.search(rf"{name}\s*=\s*([^,\s]+)", card, re.IGNORECASE)
    return m.group(1) if m else None


def read_mesh(deck: Path, restart: bool = False) -> Mesh:
    """The mesh of a CalculiX deck (``*NODE``, ``*ELEMENT``, ``*ELSET`` cards; no ``*INCLUDE``),
    numbered as in the run of the deck itself or, with ``restart``, of a run restarted from it."""
    try:
        lines = deck.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{deck}: cannot read the deck ({exc})") from exc
    nodes: dict[int, np.ndarray] = {}
    elements: dict[int, tuple[str, tuple[int, ...]]] = {}
    elsets: dict[str, set[int]] = collections.defaultdict(set)
    nsets: dict[str, set[int]] = collections.defaultdict(set)
    bodies: list[tuple[str, set[int]]] = []
    for card, data in _cards(lines):
        key = card.split(",")[0].strip().upper()
        if key == "*NODE":
            for row in data:
                p = row.split(",")
                nodes[int(p[0])] = np.array([float(v) for v in p[1:4]])
        elif key == "*ELEMENT":
            etype = (_option(card, "TYPE") or "").upper()
            values = [int(v) for row in data for v in row.split(",") if v.strip()]
            per = {"C3D8": 8, "C3D8I": 8, "C3D8R": 8, "C3D20": 20, "C3D20R": 20}.get(etype)
            if per is None:
                continue
            for k in range(0, len(values), per + 1):
                elements[values[k]] = (etype, tuple(values[k + 1 : k + 1 + per]))
            name = _option(card, "ELSET")
            if name:
                elsets[name.upper()].update(values[0 :: per + 1])
        elif key in ("*ELSET", "*NSET") and "GENERATE" not in card.upper():
            name = (_option(card, key[1:]) or "").upper()
            members = (int(v) for row in data for v in row.split(",") if v.strip().isdigit())
            (elsets if key == "*ELSET" else nsets)[name].update(members)
        elif key == "*RIGID BODY":
            name = _option(card, "NSET")
            if name is None:
                raise ValueError(f"{deck}: a *RIGID BODY without NSET= (only node sets are counted)")
            compact = card.upper().replace(" ", "")
            own = {int(v) for v in re.findall(r"(?:REFNODE|ROTNODE)=(\d+)", compact)}
            bodies.append((name.upper(), own))
    if not nodes:
        raise ValueError(f"{deck}: no *NODE card")
    missing = [name for name, _ in bodies if name not in nsets]
    if missing:
        raise ValueError(f"{deck}: the rigid body's node set {missing[0]} is not defined")
    dependent = sum(len(nsets[name] - own) for name, own in bodies)
    return Mesh(
        nodes, elements, {k: frozenset(v) for k, v in elsets.items()}, dependent, len(bodies), restart
    )


#: for each corner of a hexahedron (CalculiX order), the three corners its edges go to,
#: ordered so that the reference element's corner determinants are positive
_CORNERS = (
    (0, 1, 3, 4),
    (1, 2, 0, 5),
    (2, 3, 1, 6),
    (3, 0, 2, 7),
    (4, 7, 5, 0),
    (5, 4, 6, 1),
    (6, 5, 7, 2),
    (7, 6, 4, 3),
)


def corner_volume_ratio(reference: np.ndarray, current: np.ndarray) -> float:
    """The smallest corner volume of a hexahedron, (8, 3) corners, over its reference's."""
    corner, ends = np.array(_CORNERS)[:, :1], np.array(_CORNERS)[:, 1:]
    now = np.linalg.det(current[ends] - current[corner])  # (8, 3, 3): each corner's three edges
    ref = np.linalg.det(reference[ends] - reference[corner])
    return float(np.min(now / ref))


def stored_displacements(frd: Path, at: float | None = None) -> tuple[float, dict[int, np.ndarray]]:
    """(time, {node: displacement}) of the last increment ``frd`` stored as a solution, or of
    the one whose total time is nearest ``at``."""
    from .frd import read_frd

    try:
        res = read_frd(frd, every=True)
    except (OSError, ValueError, KeyError, IndexError) as exc:
        raise ValueError(f"{frd}: cannot read the results ({exc})") from exc
    # ccx2paraview names CalculiX's DISP block U and its FORC block RF
    solutions = [(t, blocks) for t, blocks in res.every if "U" in blocks and "RF" not in blocks]
    if not solutions:
        raise ValueError(f"{frd}: no stored displacement")
    t, blocks = solutions[-1] if at is None else min(solutions, key=lambda tb: abs(tb[0] - at))
    u = blocks["U"][1]
    return t, {int(n): u[k, :3] for k, n in enumerate(res.node_ids)}


def most_distorted(mesh: Mesh, displacement: dict[int, np.ndarray], elset: str) -> list[tuple[float, int]]:
    """(smallest corner volume over the reference's, element) of the hexahedra of ``elset``
    whose corners all have a displacement, most distorted first."""
    members = mesh.elsets.get(elset.upper())
    if not members:
        raise ValueError(f"no element set {elset} in the deck")
    ratios = ((mesh.corner_volume(e, displacement), e) for e in sorted(members) if e in mesh.elements)
    out = sorted((r, e) for r, e in ratios if r is not None)
    if not out:
        raise ValueError(f"the results hold no displacement of element set {elset}")
    return out


def named_nodes(log: Path, last: int) -> list[int]:
    """The node named as the largest residual in each of the last ``last`` iterations."""
    try:
        hits = _RESIDUAL.findall(log.read_text(errors="replace"))
    except OSError as exc:
        raise ValueError(f"{log}: cannot read the log ({exc})") from exc
    return [int(n) for n, _ in hits[-last:]]


def places(mesh: Mesh, named: list[int]) -> list[tuple[int, int]]:
    """(times named, a node standing for the place), most named first: a C3D8I element's three
    modes count as one place."""
    counts: collections.Counter = collections.Counter()
    stand_in: dict[tuple[str, int], int] = {}
    for node in named:
        key = mesh.place(node)
        counts[key] += 1
        stand_in.setdefault(key, node)
    return [(n, stand_in[key]) for key, n in counts.most_common()]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m scripts.tiremodel.residuals", description=__doc__.splitlines()[0]
    )
    ap.add_argument("deck", type=Path, help="the deck that defines the mesh (a restart's base deck)")
    ap.add_argument("logs", type=Path, nargs="*", help="CalculiX's printed output of the runs")
    ap.add_argument("--last", type=int, default=400, help="iterations looked at, from the end (default 400)")
    ap.add_argument("--top", type=int, default=4, help="places listed per log (default 4)")
    ap.add_argument("--frd", type=Path, help="the run's results: the named elements' corner volumes")
    ap.add_argument("--restart", action="store_true", help="the logs are of runs restarted from the deck")
    ap.add_argument("--worst", metavar="ELSET", help="with --frd: the most distorted elements of this set")
    ap.add_argument("--at", type=float, help="with --frd: the stored increment nearest this total time")
    args = ap.parse_args(argv)
    if args.last < 1 or args.top < 1:
        print("residuals: --last and --top must be positive", file=sys.stderr)
        return 2
    if args.frd is not None and len(args.logs) > 1:
        print("residuals: --frd goes with one log", file=sys.stderr)
        return 2
    if (args.worst or args.at is not None) and args.frd is None:
        print("residuals: --worst and --at need --frd", file=sys.stderr)
        return 2
    if not args.logs and not args.worst:
        print("residuals: give a log, or --frd with --worst ELSET", file=sys.stderr)
        return 2
    try:
        mesh = read_mesh(args.deck, restart=args.restart)
        shape = stored_displacements(args.frd, args.at) if args.frd is not None else None
        if args.worst and shape is not None:
            print(f"{args.frd} at t = {shape[0]:.6g}: the most distorted elements of {args.worst.upper()}")
            for ratio, e in most_distorted(mesh, shape[1], args.worst)[: args.top]:
                print(
                    f"  {mesh.elements[e][0]} element {e} at {_point(mesh.centroid(e))}: "
                    f"smallest corner volume {ratio:.2f} of the reference"
                )
        for log in args.logs:
            named = named_nodes(log, args.last)
            if not named:
                print(f"{log}: no residual line")
                continue
            stated = re.search(r"nodes:\s*(\d+)", log.read_text(errors="replace"))
            if stated and int(stated.group(1)) != mesh.total_nodes:
                other = dataclasses.replace(mesh, restart=not mesh.restart).total_nodes
                hint = (
                    f"a {'run of the deck itself' if args.restart else 'restarted run'}? "
                    f"({'without' if args.restart else 'with'} --restart)"
                    if int(stated.group(1)) == other
                    else "not this log's deck"
                )
                raise ValueError(
                    f"{log}: CalculiX counted {stated.group(1)} nodes, the deck {args.deck} gives "
                    f"{mesh.total_nodes}: {hint}"
                )
            print(f"{log}: {len(named)} iterations")
            for n, node in places(mesh, named)[: args.top]:
                print(f"  {n:4d}x  {mesh.where(node)}{_shape(mesh, node, shape)}")
    except ValueError as exc:
        print(f"residuals: {exc}", file=sys.stderr)
        return 2
    return 0


def _shape(mesh: Mesh, node: int, shape: tuple[float, dict[int, np.ndarray]] | None) -> str:
    """The named element's shape (``; smallest corner volume 0.44 of the reference at t = ...``);
    empty for a node of the deck or without results."""
    owner = mesh.extra_owner(node)
    if shape is None or owner is None:
        return ""
    t, u = shape
    ratio = mesh.corner_volume(owner, u)
    if ratio is None:
        raise ValueError(f"the results hold no displacement of element {owner}'s corners")
    return f"; smallest corner volume {ratio:.2f} of the reference at t = {t:.6g}"


if __name__ == "__main__":
    raise SystemExit(main())
