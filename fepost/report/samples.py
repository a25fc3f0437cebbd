"""The sample FE exports the report uses when it is given no inputs.

The one place that names them: ``fepost report`` without inputs, ``make demo``
and the documentation's examples all go through :func:`sample_inputs`.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ArgumentError

#: Sample static and rolling maps, in the repository's ``meshes/`` folder.
SAMPLE_STATIC = "static.vtu"
SAMPLE_ROLLING: str | None = "rolling.vtu"


def meshes_folder() -> Path:
    """The ``meshes/`` folder shipped beside the package (``<repository>/meshes``)."""
    return Path(__file__).resolve().parents[2] / "meshes"


def sample_inputs() -> tuple[Path, Path | None]:
    """(static, rolling) sample paths; a one-line :class:`ArgumentError` when one is missing."""
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
