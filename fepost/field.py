"""The FE contact field: what a reader hands to the patch step."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Literal

import numpy as np

from ._arrays import adopted, frozen

#: Face types besides linear triangles, in the order their face values follow the triangles'.
OTHER_FACE_TYPES = ("tri6", "tri7", "quad4", "quad8", "quad9")


@dataclass(frozen=True)
class ContactField:
    """A contact-pressure field on the element faces of an FE surface, SI units.

    Attributes
    ----------
    source : str
        The file it was read from (or a description).
    points : (n, 3) float array, m
        Node coordinates (deformed when a displacement array was applied).
    triangles : (m, 3) int array
        Linear triangular faces.
    values : float array, Pa
        Contact pressure, per node (``location == "point"``, shape (n,)) or per
        face (``"cell"``: the triangles' values, then those of `faces` in
        the order of `OTHER_FACE_TYPES`).
    field : str
        Name of the array the pressure came from (``NAME:COMPONENT`` for a component).
    step, time : int | None, float | None
        The time step read (Exodus series) and its time value, s.
    reaction_z : float | None
        The solver's total normal reaction, N, from a sidecar ``<stem>.json``.
    arrays : tuple[str, ...]
        Every array name found in the file (for messages and reports).
    sidecar : dict | None
        The validated sidecar.
    faces : mapping face type → (m, k) int array
        Faces of other types: ``quad4`` (bilinear), ``tri6``, ``tri7``, ``quad8``,
        ``quad9`` (quadratic), nodes in the order of `fepost.reader.cells`.
    reactions : mapping name → float, N
        The solver's reaction and contact-force values stored in the file at this
        step (Exodus global variables whose names say reaction or force).
    steps : tuple[float, ...]
        The time of every step of the file (empty for single-state files), s.
    body : str
        Which element block(s) or piece(s) the faces were taken from.
    units : UnitSystem | None
        The unit system the file was read in (None: SI assumed, not given).
    notes : tuple[str, ...]
        What the reader chose or assumed (shown beside the results).
    format : str
        The file format read.
    displacement : str | None
        The nodal displacement array added to the coordinates (None: none was).
    """

    source: str
    points: np.ndarray
    triangles: np.ndarray
    values: np.ndarray
    location: Literal["point", "cell"]
    field: str
    step: int | None = None
    time: float | None = None
    reaction_z: float | None = None
    arrays: tuple[str, ...] = ()
    sidecar: dict | None = None
    faces: Mapping[str, np.ndarray] = dataclasses.field(default_factory=dict)
    reactions: Mapping[str, float] = dataclasses.field(default_factory=dict)
    steps: tuple[float, ...] = ()
    body: str = ""
    units: Any = None
    notes: tuple[str, ...] = ()
    format: str = ""
    displacement: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", frozen(self.points))
        tri = self.triangles
        if np.ndim(tri) != 2:  # an empty list: no triangles (a reshaped view would not be shared)
            tri = np.reshape(np.asarray(tri, np.int64), (-1, 3))
        object.__setattr__(self, "triangles", frozen(tri, dtype=np.int64))
        object.__setattr__(self, "values", frozen(self.values))
        faces = {t: frozen(self.faces[t], dtype=np.int64) for t in OTHER_FACE_TYPES if t in self.faces}
        unknown = set(self.faces) - set(OTHER_FACE_TYPES)
        if unknown:
            raise ValueError(f"ContactField: unknown face types {sorted(unknown)}")
        object.__setattr__(self, "faces", MappingProxyType({t: f for t, f in faces.items() if len(f)}))
        object.__setattr__(self, "reactions", MappingProxyType(dict(self.reactions)))
        object.__setattr__(self, "notes", tuple(self.notes))

    def __reduce__(self):
        # plain containers across processes (the reading child sends fields to the caller)
        state = {f: getattr(self, f) for f in self.__dataclass_fields__}
        state["faces"] = dict(self.faces)
        state["reactions"] = dict(self.reactions)
        return (_restore, (state,))

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_faces(self) -> int:
        """Number of element faces (triangles and the other face types)."""
        return int(self.triangles.shape[0]) + sum(len(f) for f in self.faces.values())

    def face_groups(self) -> Iterator[tuple[str, np.ndarray, slice]]:
        """(face type, connectivity, slice of `values` for face data) of every non-empty group."""
        start = 0
        groups = [("tri3", self.triangles)] + [
            (t, self.faces[t]) for t in OTHER_FACE_TYPES if t in self.faces
        ]
        for t, conn in groups:
            n = len(conn)
            if n:
                yield t, conn, slice(start, start + n)
            start += n


def _restore(state: dict) -> ContactField:
    """Rebuild an unpickled field; its arrays are new and held by nobody else: shared, not copied."""
    for key in ("points", "triangles", "values"):
        a = state[key]
        if isinstance(a, np.ndarray):
            state[key] = adopted(a)
    state["faces"] = {t: adopted(a) for t, a in state["faces"].items()}
    return ContactField(**state)
