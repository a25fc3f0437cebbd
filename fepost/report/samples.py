"""The sample FE exports the report uses when it is given no inputs.

The one place that names them: ``fepost report`` without inputs, ``make demo``
and the documentation's examples all go through `sample_inputs`. They are
the aircraft main-gear tire (46×17R20 size class, 1.38 MPa) at its rated load:
the static map ``meshes/aircraft/static_100.vtu`` and the rolled map
``meshes/rig-aircraft/roll_free.vtu``, the same tire really rolled (rim turned
about the axle while the axle travelled 0.75 m, free rolling) on the rolling
runs' own, coarser mesh. ``meshes/aircraft/rolling_100.vtu`` is not the rolling
partner any more: it is a sliding stand-in (the rim slid 30 mm along x without
turning), whose k_x is the shift of a sliding patch; it stays the rolling map of
the load sweep, labelled as such. ``meshes/README.md`` and ``docs/rolling.md``
describe the models. The small stand-in tire (``meshes/static.vtu``,
``rolling.vtu``, ``heavy.*``) stays for the tests, which name it explicitly.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ArgumentError

#: Sample static and rolling maps, relative to the repository's ``meshes/`` folder:
#: the aircraft tire at its rated load (100 %), static, and rolled freely.
SAMPLE_STATIC = "aircraft/static_100.vtu"
SAMPLE_ROLLING: str | None = "rig-aircraft/roll_free.vtu"


def meshes_folder() -> Path:
    """The ``meshes/`` folder shipped beside the package (``<repository>/meshes``)."""
    return Path(__file__).resolve().parents[2] / "meshes"


def sample_inputs() -> tuple[Path, Path | None]:
    """(static, rolling) sample paths; a one-line `ArgumentError` when one is missing."""
    paths: list[Path | None] = []
    for name in (SAMPLE_STATIC, SAMPLE_ROLLING):
        if name is None:
            paths.append(None)
            continue
        p = meshes_folder() / name
        if not p.is_file():
            raise ArgumentError(f"{p}: sample mesh not found (give the FE exports explicitly)")
        paths.append(p)
    static = paths[0]
    assert static is not None  # SAMPLE_STATIC is a name
    return static, paths[1]
