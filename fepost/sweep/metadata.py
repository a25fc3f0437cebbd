"""Case metadata from a sidecar ``<case>.json`` beside an FE export.

Solvers do not store the load case in the mesh file, so a sweep takes it from
``<stem>.json`` next to the export: the sidecar the reader already reads,
validates, converts with the model's units (``--units``) and resolves at the
time step read (`fepost.reader.sidecar`; a per-step list gives the value
of that step). Recognised keys, SI units:

====================== ========================================= ======
column                 sidecar key(s)                             unit
====================== ========================================= ======
``case``               ``case`` (text)                            —
``load``               ``load``, else ``reaction_z``              N
``deflection``         ``deflection``                             m
``inflation_pressure`` ``inflation_pressure``                     Pa
====================== ========================================= ======

Other keys are ignored.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

#: Numeric metadata columns and the sidecar keys they are read from, first found wins.
NUMERIC_KEYS: dict[str, tuple[str, ...]] = {
    "load": ("load", "reaction_z"),
    "deflection": ("deflection",),
    "inflation_pressure": ("inflation_pressure",),
}
#: Every metadata column, in table order.
COLUMNS = ("case", *NUMERIC_KEYS)


def sidecar_path(path: str | Path) -> Path:
    """The sidecar of the export ``path`` (whether it exists or not)."""
    return Path(path).with_suffix(".json")


def case_metadata(sidecar: Mapping | None) -> dict:
    """The metadata columns of one row from the sidecar the reader resolved for it
    (`fepost.field.ContactField.sidecar`); missing keys (or no sidecar) give None."""
    row: dict = dict.fromkeys(COLUMNS)
    if not sidecar:
        return row
    if sidecar.get("case") is not None:
        row["case"] = str(sidecar["case"])
    for column, keys in NUMERIC_KEYS.items():
        value = next((sidecar[k] for k in keys if sidecar.get(k) is not None), None)
        if value is not None:
            row[column] = float(value)
    return row
