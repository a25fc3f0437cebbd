"""The resultants of a rig run: friction force and torque on the tire, and the load.

Its own module so that the run's reader (``fepost.rig.run``) and the
shear-traction integral (``fepost.rig.surface``) share it without importing
each other.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Resultants:
    """Friction force (N) of the road on the tire and torque about the static patch origin (N m)."""

    Fx: float
    Fy: float
    Mz: float
    N: float

    def to_dict(self) -> dict:
        return {"Fx": self.Fx, "Fy": self.Fy, "Mz": self.Mz, "N": self.N}
