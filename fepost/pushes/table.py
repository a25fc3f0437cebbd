"""The pushes of one or more logs as the measured-data CSV (the contract's "pushes CSV").

One row per push that gives a wrench: ``vx, vy, wz`` the block's displacement over the
push in its frame at the start of the push (m, m, rad: a direction of the twist, the
pushes being quasi-static), ``Fx, Fy, Mz`` the support's friction wrench on the block (N,
N·m, block frame, torque about the body's ``reference_point``), ``N`` the weight
(mass × gravity), ``time`` the push's number in its log, ``push`` the same number and
``source`` the log. The row order is the logs' order, then the pushes'.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..body import Body
from .checks import LogChecks, check_log
from .log import read_log
from .wrench import LeftOut, Push, Settings, form_push, log_format, patch_radius

#: The CSV's columns, in order.
COLUMNS = ("vx", "vy", "wz", "Fx", "Fy", "Mz", "N", "time", "push", "source")


@dataclass(frozen=True)
class PushTable:
    """The pushes of a set of logs, with the checks of each log.

    Attributes
    ----------
    body : Body
    pushes : tuple of Push
        The pushes that give a wrench, in order.
    left_out : tuple of LeftOut
    checks : tuple of LogChecks
        One per log.
    """

    body: Body
    pushes: tuple[Push, ...]
    left_out: tuple[LeftOut, ...]
    checks: tuple[LogChecks, ...]

    def to_csv(self) -> str:
        """The measured-data CSV text (module docstring)."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(COLUMNS)
        weight = self.body.weight
        for p in self.pushes:
            dx, dy, dth = p.displacement
            fx, fy, mz = p.wrench
            numbers = (dx, dy, dth, fx, fy, mz, weight)
            writer.writerow([*(f"{float(x):.10g}" for x in numbers), p.index, p.index, p.log])
        return buf.getvalue()

    def lines(self) -> list[str]:
        """The console summary of every log."""
        out: list[str] = []
        for c in self.checks:
            out += c.lines()
        return out


def read_pushes(logs: Sequence, body: Body, settings: Settings | None = None) -> PushTable:
    """Read the planar-push ``logs`` of ``body`` and form every push's wrench and twist.

    Parameters
    ----------
    logs : sequence of str or Path
        The logs, in order.
    body : Body
        The pushed block, with its ``log`` block.
    settings : Settings, optional
        The thresholds of `fepost.pushes.wrench.form_push` (default `Settings()`).

    Returns
    -------
    PushTable

    Raises
    ------
    DataError
        A log is damaged or truncated (one line naming the push and the line), or the body has no
        ``log`` block.
    InputFileError
        A log is missing or unreadable.
    """
    log_format(body)
    settings = settings or Settings()
    radius = patch_radius(body)
    pushes: list[Push] = []
    left: list[LeftOut] = []
    checks = []
    for log in logs:
        results = _log_pushes(log, body, settings)
        pushes += [r for r in results if isinstance(r, Push)]
        left += [r for r in results if isinstance(r, LeftOut)]
        checks.append(check_log(str(log), results, weight=body.weight, radius=radius))
    return PushTable(body=body, pushes=tuple(pushes), left_out=tuple(left), checks=tuple(checks))


def _log_pushes(log, body: Body, settings: Settings) -> list[Push | LeftOut]:
    """One log's pushes; those whose own zero is loaded are formed again with the log's median zero."""
    raws = list(read_log(log))
    results = [form_push(raw, body, settings) for raw in raws]
    zeros = np.array([r.zero for r in results if isinstance(r, Push)])
    if len(zeros) == 0:
        return results
    median = np.median(zeros, axis=0)
    for k, r in enumerate(results):
        if isinstance(r, Push) and np.hypot(*(r.zero - median)) > settings.zero_tolerance:
            results[k] = form_push(raws[k], body, settings, zero=median)
    return results
