"""Rig runs against the static map's friction model, with and without load transfer.

``compare_runs(analysis, runs)`` reads the runs (``rig_table``), places each
run's own pressure map in the static patch's frame (``fepost.analysis.analyse``
with the run as the second map) for its centre-of-pressure shift, identifies
the load-transfer law from those shifts and the runs' shear-traction force per
load (``fepost.rig.extension``), and predicts every run by

- ``static``: the exact Coulomb integrals over the static map, and
- ``shifted``: the same over the static map shifted by the law (fixed point),

both scaled to the run's load (the Coulomb forces are proportional to the load
at a fixed pressure shape). The law is identified on all the runs given: the
held-out measure is ``fepost.rig.extension.cross_validate`` (the rig study,
``scripts/rig_study.py``). Misfits are in f N and f N R (R the static radius).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .._arrays import frozen
from ..errors import DataError
from .extension import ShiftLaw, identify_shift, predict_shifted
from .table import RigTable, rig_table


@dataclass(frozen=True)
class RigComparison:
    """Per-run forces in units of f N (``fe``, ``static``, ``shifted``: (n, 3) arrays
    Fx/fN, Fy/fN, Mz/fNR), the runs' ``shifts`` (n, 2) (m), the ``law`` and ``names``."""

    names: tuple[str, ...]
    kinematics: np.ndarray
    fe: np.ndarray
    static: np.ndarray
    shifted: np.ndarray
    shifts: np.ndarray
    law: ShiftLaw
    radius: float
    friction: float

    def __post_init__(self) -> None:
        for name in ("kinematics", "fe", "static", "shifted", "shifts"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def misfit(self, which: str) -> dict[str, float]:
        """RMS and max of |dF| / fN and |dMz| / fNR of ``which`` (``static`` or ``shifted``)."""
        d = getattr(self, which) - self.fe
        df = np.hypot(d[:, 0], d[:, 1])
        return {
            "rms_F": float(np.sqrt(np.mean(df**2))),
            "max_F": float(df.max()),
            "rms_Mz": float(np.sqrt(np.mean(d[:, 2] ** 2))),
            "max_Mz": float(np.abs(d[:, 2]).max()),
        }

    def to_dict(self) -> dict:
        return {
            "names": list(self.names),
            "kinematics": self.kinematics.tolist(),
            "fe": self.fe.tolist(),
            "static": self.static.tolist(),
            "shifted": self.shifted.tolist(),
            "shifts": self.shifts.tolist(),
            "law": self.law.to_dict(),
            "radius": self.radius,
            "friction": self.friction,
            "misfit": {k: self.misfit(k) for k in ("static", "shifted")},
        }


def _shear_per_load(table: RigTable) -> np.ndarray:
    out = []
    for r in table.runs:
        if r.shear is None or not r.shear.N > 0.0:
            raise DataError(
                f"{r.source}: the export has no shear traction to identify the load transfer from"
            )
        out.append([r.shear.Fx / r.shear.N, r.shear.Fy / r.shear.N])
    return np.array(out)


def compare_runs(analysis, runs, *, options=None) -> RigComparison:
    """Compare the rig ``runs`` (paths) with the static map of ``analysis`` (module docstring).

    ``options``: the `fepost.options.AnalysisOptions` to read the runs' maps with
    (default: those of ``analysis``).
    """
    from ..analysis import analyse
    from ..friction.exact import friction_resultants
    from ..friction.law import FrictionLaw
    from ..friction.quadrature import PressureQuadrature

    table = rig_table(list(runs))
    c = analysis.coefficients
    law = FrictionLaw(f=c.f)
    kin = np.array([[r.vx, r.vy, r.wz] for r in table.runs])
    n = np.array([r.reaction.N for r in table.runs])
    unit = np.column_stack([c.f * n, c.f * n, c.f * n * c.R])
    fe = np.array([[r.reaction.Fx, r.reaction.Fy, r.reaction.Mz] for r in table.runs]) / unit
    # a run's load is not the static map's (the rim is held at its height: sliding across the
    # aircraft tire lowers it by 13 %); each run is compared in its own load (``unit``), so the
    # run's map is placed as a rolling partner without the pair's 3 % load check
    opts = replace(options if options is not None else analysis.options, allow_load_mismatch=True)
    c0 = np.array(analysis.static_moments.centroid)
    shifts = []
    for r in table.runs:
        own = analyse(analysis.static_field, r.source, friction=c.f, options=opts).rolling_moments
        if own is None:  # analyse always places the second map; kept for the type checker
            raise DataError(f"{r.source}: no pressure map of the run")
        shifts.append(np.array(own.centroid) - c0)
    shift_law = identify_shift(np.array(shifts), _shear_per_load(table))
    quad = PressureQuadrature.from_polar(analysis.static_map)
    per_load = unit / (n[:, None] / c.N)  # the predictions carry the static load
    b = friction_resultants(quad, kin[:, 0], kin[:, 1], kin[:, 2], law)
    e = predict_shifted(quad, kin[:, 0], kin[:, 1], kin[:, 2], law=shift_law, friction=law).resultants
    return RigComparison(
        names=tuple(Path(r.source).stem for r in table.runs),
        kinematics=kin,
        fe=fe,
        static=np.column_stack([b.Fx, b.Fy, b.Mz]) / per_load,
        shifted=np.column_stack([e.Fx, e.Fy, e.Mz]) / per_load,
        shifts=np.array(shifts),
        law=shift_law,
        radius=float(c.R),
        friction=float(c.f),
    )
