"""The FE model as a friction test rig: slide/spin runs -> measured friction data.

A rig run is an FE export of a tire slid and spun on a rigid road with
Coulomb friction (``scripts/tiremodel`` writes them into ``meshes/rig/``) with a
sidecar holding the kinematics and the solver's reactions on the road. This
package turns runs into the measured-data CSV of ``fepost diagnose``:

>>> from fepost.rig import rig_table                     # doctest: +SKIP
>>> table = rig_table(["meshes/rig/d000_slide.vtu"])     # doctest: +SKIP
>>> text = table.to_csv()                                # doctest: +SKIP

- ``read_run(path)`` -> ``RigRun``: kinematics (vx, vy, wz), ``reaction``
  (``Resultants`` Fx, Fy, Mz, N of the road on the tire, Mz about the static
  patch origin, from the solver's reactions) and ``shear`` (the same from the
  integral of the export's shear traction, None when the export has none);
- ``rig_table(paths)`` -> ``RigTable`` (``to_csv()``, ``rows()``,
  ``max_shear_difference()``);
- ``fepost.rig.extension``: the load-transfer extension of the friction model
  (``identify_shift``, ``predict_shifted``, ``cross_validate``), identified from
  the runs' own pressure maps;
- ``compare_runs(analysis, runs)`` -> ``RigComparison``: the runs against the
  static map's exact integrals with and without load transfer.

Frames and signs are those of the measured data: x rolling direction, y
lateral, z the road normal; (vx, vy) the sliding velocity of the static patch
origin relative to the road, wz the spin; pure sliding with vx > 0 gives
Fx = -f N.
"""

from .compare import RigComparison, compare_runs
from .extension import ShiftLaw, cross_validate, identify_shift, predict_shifted, shifted_resultants
from .run import Resultants, RigRun, reaction_resultants, read_run
from .table import COLUMNS, RigTable, rig_table

__all__ = [
    "COLUMNS",
    "Resultants",
    "RigComparison",
    "RigRun",
    "RigTable",
    "ShiftLaw",
    "compare_runs",
    "cross_validate",
    "identify_shift",
    "predict_shifted",
    "reaction_resultants",
    "read_run",
    "rig_table",
    "shifted_resultants",
]
