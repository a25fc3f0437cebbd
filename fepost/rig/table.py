"""Rig runs -> the measured-data CSV that ``fepost diagnose --measured`` reads.

Columns: ``vx``, ``vy``, ``wz``, ``Fx``, ``Fy``, ``Mz``, ``N`` (the measured-data
CSV of the interface), then ``source`` (the run as given) and, as an
independent check of the solver's reactions, ``Fx_shear``, ``Fy_shear``,
``Mz_shear``, ``N_shear`` (integrals of the export's shear traction and contact
pressure; empty when the export has no shear traction). Readers of measured
data ignore the extra columns.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import ArgumentError
from .run import RigRun, not_a_run, read_run

COLUMNS = ("vx", "vy", "wz", "Fx", "Fy", "Mz", "N", "source", "Fx_shear", "Fy_shear", "Mz_shear", "N_shear")


@dataclass(frozen=True)
class RigTable:
    """The rows of the rig CSV, one per run, in the order given; ``skipped``: (path, why) of
    the exports given that are no slide/spin runs (a static reference map caught by a glob)."""

    runs: tuple[RigRun, ...]
    skipped: tuple[tuple[str, str], ...] = ()

    def rows(self) -> list[dict]:
        out = []
        for r in self.runs:
            row = {"vx": r.vx, "vy": r.vy, "wz": r.wz, **r.reaction.to_dict(), "source": r.source}
            for k in ("Fx", "Fy", "Mz", "N"):
                row[f"{k}_shear"] = "" if r.shear is None else getattr(r.shear, k)
            out.append(row)
        return out

    def to_csv(self) -> str:
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
        w.writeheader()
        for row in self.rows():
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
        return buf.getvalue()

    def max_shear_difference(self) -> dict[str, float]:
        """Largest |reaction - shear integral| over the runs with shear: Fx, Fy and |F| in N, Mz in N m."""
        dif = {"F": 0.0, "Mz": 0.0}
        for r in self.runs:
            if r.shear is None:
                continue
            d = ((r.reaction.Fx - r.shear.Fx) ** 2 + (r.reaction.Fy - r.shear.Fy) ** 2) ** 0.5
            dif["F"] = max(dif["F"], d)
            dif["Mz"] = max(dif["Mz"], abs(r.reaction.Mz - r.shear.Mz))
        return dif

    def to_dict(self) -> dict:
        return {
            "runs": [r.to_dict() for r in self.runs],
            "skipped": [{"source": p, "reason": why} for p, why in self.skipped],
        }


def rig_table(paths: Sequence, *, shear: bool = True) -> RigTable:
    """Read every rig run of ``paths`` (see ``fepost.rig.run``) into a table; an export whose
    sidecar holds neither kinematics nor a reaction (`not_a_run`) is skipped and listed in
    ``skipped``. `ArgumentError` when no path is a run."""
    if not paths:
        raise ArgumentError("no rig runs given")
    reasons = [not_a_run(p) for p in paths]
    skipped = tuple((str(p), why) for p, why in zip(paths, reasons, strict=True) if why is not None)
    runs = [p for p, why in zip(paths, reasons, strict=True) if why is None]
    if not runs:
        path, why = skipped[0]
        raise ArgumentError(f"no slide/spin run among the {len(paths)} exports given: {path}: {why}")
    return RigTable(runs=tuple(read_run(p, shear=shear) for p in runs), skipped=skipped)
