"""A `BodyMap` written as an FE-style export: ``MAP.vtu`` and its sidecar ``MAP.json``.

The ``.vtu`` holds the triangles in the map frame at z = 0 and the nodal
array ``pressure`` (Pa), which fepost finds by name. The sidecar
(`fepost.reader.sidecar`) holds ``reaction_z`` (the support's total normal
reaction, N: the weight by statics, or CalculiX's reaction for a board
model), ``separate_patches`` for point supports, and the map's description
(body, frame, loads, profile, board, polar grid). Both files are written
through temporaries and renamed only when both are complete
(`fepost.output.atomic_path`): an error or an interruption leaves neither
half-written, and an existing map as it was.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..output import atomic_path, to_json
from .maps import BodyMap

#: The map's file type.
SUFFIX = ".vtu"
#: The name of the pressure array in the ``.vtu``.
PRESSURE_ARRAY = "pressure"


def sidecar_path(path: str | Path) -> Path:
    """The sidecar of a map: ``MAP.json`` beside ``MAP.vtu``."""
    return Path(path).with_suffix(".json")


def check_map_path(path: str | Path) -> Path:
    """``path`` as a map's output: a ``.vtu`` file in an existing folder (`OutputError` otherwise)."""
    p = Path(path)
    if str(path) == "-":
        raise OutputError("-: a map is two files (MAP.vtu and its sidecar MAP.json), not standard output")
    if p.suffix.lower() != SUFFIX:
        raise OutputError(f"{path}: a map is written as a .vtu file (with its sidecar .json beside it)")
    if p.is_dir():
        raise OutputError(f"{path}: is a folder, not a file")
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"{path}: folder {folder} does not exist")
    return p


def sidecar(bmap: BodyMap) -> dict:
    """The sidecar's content: the map's `BodyMap.info` with its load and centre of pressure."""
    out = dict(bmap.info)
    out["map_load"] = bmap.load
    out["centre_of_pressure"] = list(bmap.centre_of_pressure)
    out["peak_pressure"] = bmap.peak()
    out["mean_pressure"] = bmap.mean_pressure()
    return out


def write_map(bmap: BodyMap, path: str | Path) -> tuple[Path, Path]:
    """Write ``bmap`` to ``path`` (``.vtu``) and its sidecar (module docstring).

    Returns
    -------
    (Path, Path)
        The map and its sidecar.

    Raises
    ------
    OutputError
        Not a ``.vtu`` name, a missing folder, or a file that cannot be written.
    """
    import meshio

    p = check_map_path(path)
    side = sidecar_path(p)
    points = np.column_stack([bmap.xy, np.zeros(len(bmap.xy))])
    mesh = meshio.Mesh(
        points, [("triangle", np.asarray(bmap.triangles))], point_data={PRESSURE_ARRAY: bmap.pressure}
    )
    text = to_json(sidecar(bmap)) + "\n"
    with atomic_path(p) as tmp_map, atomic_path(side) as tmp_side:
        try:
            mesh.write(tmp_map, file_format="vtu")
            tmp_side.write_text(text, encoding="utf-8")
        except OSError as exc:
            raise OutputError(f"{path}: cannot write ({exc.strerror or exc})") from None
    return p, side
