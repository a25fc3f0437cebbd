"""The FE contact field: what a reader hands to the patch step."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ._arrays import frozen


@dataclass(frozen=True)
class ContactField:
    """A contact-pressure field on a triangulated FE surface.

    Attributes
    ----------
    source : str
        The file it was read from (or a description).
    points : (n, 3) float array, m
        Node coordinates (deformed when a displacement array was applied).
    triangles : (m, 3) int array
        Surface faces, triangulated (quads split into two triangles).
    values : float array, Pa
        Contact pressure, per node (``location == "point"``, shape (n,)) or per
        face (``"cell"``, shape (m,)).
    field : str
        Name of the array the pressure came from.
    step, time : int | None, float | None
        The time step read (Exodus series) and its time value.
    reaction_z : float | None
        The solver's total normal reaction, N, from a sidecar ``<stem>.json``.
    arrays : tuple[str, ...]
        Every array name found in the file (for messages and reports).
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

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", frozen(self.points))
        object.__setattr__(self, "triangles", frozen(self.triangles, dtype=np.int64))
        object.__setattr__(self, "values", frozen(self.values))

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_faces(self) -> int:
        return int(self.triangles.shape[0])
