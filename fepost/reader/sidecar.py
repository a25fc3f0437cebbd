"""The optional sidecar ``<stem>.json`` beside an FE export, read and validated.

A sidecar is a JSON object whose keys describe the run (``reaction_z``: the
solver's total normal reaction, in the model's force unit; ``inflation_pressure``;
``deflection``; …). It is checked before use: an object at the top, at most
`MAX_BYTES`, no ``NaN``/``Infinity`` literals, and every key fepost reads
(`NUMBER_KEYS`) either absent, null, a finite number (not a boolean) or,
for a file with time steps, a list of finite numbers, one per step:
`at_step` then takes the value of the step read, so what the rest of
fepost sees is always one number per key.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import InputFileError
from ..jsonobject import read_json_object

#: Largest sidecar accepted, bytes.
MAX_BYTES = 1 << 20
#: Keys fepost reads as numbers.
NUMBER_KEYS = ("reaction_z", "inflation_pressure", "deflection", "friction", "cpress_integral", "load")


def read_sidecar(path: Path) -> dict | None:
    """The validated sidecar of ``path`` (``<stem>.json``), or None when there is none.

    Raises
    ------
    InputFileError
        Unreadable, too large, not a JSON object, or a number key that is not a finite number.
    """
    side = path.with_suffix(".json")
    if side == path or not side.is_file():
        return None
    try:
        data = read_json_object(side, "sidecar JSON", MAX_BYTES)
    except FileNotFoundError:  # removed since the check above
        return None
    for key in NUMBER_KEYS:
        v = data.get(key)
        if v is None:
            continue
        if isinstance(v, list):
            if not v or not all(_finite(x) for x in v):
                raise InputFileError(
                    f"{side}: sidecar key {key!r} must be a finite number or a non-empty list of them "
                    f"(one per time step), got {v!r}"
                )
        elif not _finite(v):
            raise InputFileError(f"{side}: sidecar key {key!r} must be a finite number, got {v!r}")
    return data


def _finite(v) -> bool:
    return not isinstance(v, bool) and isinstance(v, int | float) and math.isfinite(v)


def at_step(data: dict | None, path: Path, step: int | None, n_steps: int) -> dict | None:
    """``data`` (a validated sidecar of ``path``) with each per-step list replaced by the
    value of time step ``step`` of ``n_steps`` (``step`` None: a file without steps).

    Raises
    ------
    InputFileError
        A list whose length is not the file's number of time steps.
    """
    if data is None or not any(isinstance(data.get(k), list) for k in NUMBER_KEYS):
        return data
    out = dict(data)
    for key in NUMBER_KEYS:
        v = data.get(key)
        if isinstance(v, list):
            if step is None or len(v) != n_steps:
                raise InputFileError(
                    f"{path.with_suffix('.json')}: {key!r} lists {len(v)} values but {path} has "
                    f"{n_steps or 'no'} time steps"
                )
            out[key] = v[step]
    return out
