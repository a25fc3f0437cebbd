"""Pushes of a rigid block, read from a robot rig's logs: the friction wrench and twist of each.

`read_log` streams a planar-push log (`fepost.pushes.log`); `form_push` turns one
push into the support's friction wrench and the block's displacement
(`fepost.pushes.wrench`, where the module docstring says how and why);
`read_pushes` does both for a list of logs and runs the rig engineer's checks
(`fepost.pushes.checks`); `PushTable.to_csv` writes the measured-data CSV
(`fepost.pushes.table`).
"""

from __future__ import annotations

from .checks import LogChecks, check_log
from .log import RawPush, read_log
from .table import COLUMNS, PushTable, read_pushes
from .wrench import LeftOut, Push, Settings, form_push

__all__ = [
    "COLUMNS",
    "LeftOut",
    "LogChecks",
    "Push",
    "PushTable",
    "RawPush",
    "Settings",
    "check_log",
    "form_push",
    "read_log",
    "read_pushes",
]
