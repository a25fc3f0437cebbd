"""What a format reader hands on: nodes, element blocks, arrays, side sets, time.

A `RawMesh` is the file's content in canonical form (Exodus node
ordering, 0-based indices, SI not yet applied), before any choice is made
about which surface carries the contact. Arrays may be loaded lazily
(Exodus variables are read only when asked for).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field

import numpy as np


class LazyArrays(Mapping):
    """A read-once mapping name → array; values may be given as loaders (callables)."""

    def __init__(self, items: dict[str, np.ndarray | Callable[[], np.ndarray]] | None = None):
        self._items: dict[str, np.ndarray | Callable[[], np.ndarray]] = dict(items or {})

    def __getitem__(self, key: str) -> np.ndarray:
        value = self._items[key]
        if callable(value):
            value = value()
            self._items[key] = value
        return value

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def add(self, key: str, value: np.ndarray | Callable[[], np.ndarray]) -> None:
        self._items[key] = value


@dataclass
class Block:
    """One group of elements of a single canonical type.

    ``conn`` (m, k) 0-based node indices; ``label`` says where it came from
    (``element block 2 (id 2)``, ``cells of piece 1``); ``body`` is the index of
    the file-level piece it belongs to (Exodus: blocks that share nodes form
    one body; VTK: pieces of a multi-block file); ``first_cell`` the global
    index of its first element (Exodus side sets count elements over all
    blocks); ``cell_data`` its element arrays.
    """

    label: str
    cell_type: str
    conn: np.ndarray
    first_cell: int = 0
    body: int = 0
    cell_data: LazyArrays = field(default_factory=LazyArrays)


@dataclass
class SideSet:
    """An Exodus side set: global 0-based element indices and 0-based side numbers."""

    label: str
    name: str
    id: int
    elements: np.ndarray
    sides: np.ndarray


@dataclass
class RawMesh:
    """The content of an FE export in canonical form.

    ``points`` (n, 3) as written (2-D models get z = 0 and ``dim`` 2);
    ``point_data`` nodal arrays, (n,) or (n, c); ``components`` the names of
    the components of vector arrays where the file gives them; ``steps`` the
    time values of every step (empty for single-state files), ``step`` the one
    read; ``globals`` global variables at that step.
    """

    path: str
    format: str
    points: np.ndarray
    blocks: list[Block]
    point_data: LazyArrays = field(default_factory=LazyArrays)
    components: dict[str, tuple[str, ...]] = field(default_factory=dict)
    dim: int = 3
    side_sets: list[SideSet] = field(default_factory=list)
    steps: tuple[float, ...] = ()
    step: int | None = None
    globals: dict[str, float] = field(default_factory=dict)
    skipped: dict[str, int] = field(default_factory=dict)  # element types not read → count
    step_values: Callable[[str], np.ndarray] | None = None  # nodal variable over all steps (Exodus)
    ncomp: dict[str, int] = field(default_factory=dict)  # components of lazily loaded point arrays
    closer: Callable[[], None] | None = None
    connectivity_size: int = 0  # VTK files: node references of all cells as read
    notes: list[str] = field(default_factory=list)  # what the format reader did, for the result's notes
    #: Only the elements of one side set were read (Exodus ``surface=``): ``blocks`` hold those
    #: elements alone, numbered in file order, and ``side_sets`` count over them.
    partial: bool = False

    def close(self) -> None:
        """Release the file (lazy arrays cannot be loaded afterwards)."""
        if self.closer is not None:
            closer, self.closer = self.closer, None
            closer()

    @property
    def time(self) -> float | None:
        return None if self.step is None or not self.steps else float(self.steps[self.step])


def defer_point_arrays(raw: RawMesh, order, deferred: dict) -> None:
    """Give ``raw`` the point arrays of ``order`` (names, in file order) that were not
    decoded as loaders: ``deferred`` maps such a name to (loader, component count,
    component names); the others are ``raw``'s own. Their component counts go into
    ``raw.ncomp``, so that choosing among the arrays never loads them."""
    data = LazyArrays()
    for name in order:
        if name in deferred:
            loader, ncomp, names = deferred[name]
            data.add(name, loader)
            raw.ncomp[name] = ncomp
            if names:
                raw.components.setdefault(name, names)
        else:
            data.add(name, raw.point_data[name])
    raw.point_data = data
