"""The sample FE exports the report uses when it is given no inputs.

The one place that names them: ``fepost report`` without inputs, ``make demo``
and the documentation's examples all go through `sample_inputs`. They are
the aircraft main-gear tire of ``meshes/aircraft/`` (46×17R20 size class,
1.38 MPa) at its rated load, static and rolling; ``meshes/README.md`` describes
the model. The small stand-in tire (``meshes/static.vtu``, ``rolling.vtu``,
``heavy.*``) stays for the tests, which name it explicitly.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ArgumentError

#: Sample static and rolling maps, relative to the repository's ``meshes/`` folder:
#: the aircraft tire at its rated load (100 %).
SAMPLE_STATIC = "aircraft/static_100.vtu"
SAMPLE_ROLLING: str | None = "aircraft/rolling_100.vtu"


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
