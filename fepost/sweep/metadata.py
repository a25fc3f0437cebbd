"""Case metadata from a sidecar ``<case>.json`` beside an FE export.

Solvers do not store the load case in the mesh file, so a sweep reads it from
``<stem>.json`` next to the export (the file the reader also takes the
solver's reaction from). Recognised keys, SI units:

====================== ========================================= ======
column                 sidecar key(s)                             unit
====================== ========================================= ======
``case``               ``case`` (text)                            —
``load``               ``load``, else ``reaction_z``              N
``deflection``         ``deflection``                             m
``inflation_pressure`` ``inflation_pressure``                     Pa
====================== ========================================= ======

A number applies to every time step of the file; a list of numbers gives one
value per time step (its length must equal the number of steps). Other keys
are ignored.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

from ..errors import InputFileError

#: Numeric metadata columns and the sidecar keys they are read from, first found wins.
NUMERIC_KEYS: dict[str, tuple[str, ...]] = {
    "load": ("load", "reaction_z"),
    "deflection": ("deflection",),
    "inflation_pressure": ("inflation_pressure",),
}
#: Every metadata column, in table order.
COLUMNS = ("case", *NUMERIC_KEYS)


def sidecar_path(path: str | Path) -> Path:
    return Path(path).with_suffix(".json")


def read_sidecar(path: str | Path) -> dict | None:
    """The parsed sidecar of the export ``path``, or None when there is none.

    Raises
    ------
    InputFileError
        The sidecar exists but is not a JSON object.
    """
    side = sidecar_path(path)
    if not side.is_file():
        return None
    try:
        data = json.loads(side.read_text())
    except (OSError, ValueError) as exc:
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise InputFileError(f"{side}: unreadable sidecar JSON ({first})") from None
    if not isinstance(data, dict):
        raise InputFileError(f"{side}: the sidecar must be a JSON object, got {type(data).__name__}")
    return data


def _number(side: Path, key: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputFileError(f"{side}: {key!r} must be a finite number, got {value!r}")
    return float(value)


def case_metadata(path: str | Path, step: int | None, n_steps: int | None | Callable[[], int | None]) -> dict:
    """The metadata columns of one row: file ``path`` at time ``step`` of ``n_steps``.

    Missing keys (or no sidecar) give None. ``step`` and ``n_steps`` matter only
    for per-step lists; ``n_steps`` may be a function, called only then.

    Raises
    ------
    InputFileError
        Unreadable sidecar, a non-numeric value, or a per-step list whose length
        is not the number of time steps.
    """
    row: dict = dict.fromkeys(COLUMNS)
    data = read_sidecar(path)
    if data is None:
        return row
    side = sidecar_path(path)
    if data.get("case") is not None:
        row["case"] = str(data["case"])
    for column, keys in NUMERIC_KEYS.items():
        key = next((k for k in keys if data.get(k) is not None), None)
        if key is None:
            continue
        value = data[key]
        if isinstance(value, list):
            if callable(n_steps):
                n_steps = n_steps()
            if n_steps is None or len(value) != n_steps or step is None:
                raise InputFileError(
                    f"{side}: {key!r} lists {len(value)} values but {path} has {n_steps or 'no'} time steps"
                )
            value = value[step]
        row[column] = _number(side, key, value)
    return row
