"""What a rolling map is, read from its sidecar: a rolled map, a sliding stand-in, or unstated.

A "rolling" map is whatever the user pairs with the static map; its k_x is the
centre-of-pressure shift of that map, so what the map is decides what k_x means:

* a sidecar with ``kind: "rolling run"`` (``meshes/rig-aircraft/roll_*.json``): the
  rim turned about the axle while the axle travelled, with ``longitudinal_slip``,
  ``rim_rotation_deg`` and ``axle_travel_m`` — a **rolled map**;
* a sidecar with a ``rolling_standin`` block (``meshes/aircraft/rolling_100.json``,
  ``meshes/rolling.json``): the rim slid along x without turning — a **sliding
  stand-in**, whose k_x is the shift of a sliding patch, not of rolling;
* anything else (no sidecar, or one that says neither): the kind is not stated
  (a sidecar ``kind`` of another value is quoted).

`rolling_label` turns a sidecar into the words the report and ``fepost table1``
print; `own_mesh_static` finds the static map solved on the rolled map's own mesh
(the same run before it rolled), the like-for-like partner for k_x.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: Sidecar ``kind`` of a rolled map and of a static map.
ROLLING_RUN = "rolling run"
STATIC_MAP = "static map"
#: Sidecar key of a sliding stand-in.
STANDIN_KEY = "rolling_standin"


@dataclass(frozen=True)
class RollingLabel:
    """What a rolling map is: ``kind`` ("rolled", "standin" or "unstated"), ``text`` (the
    full label, once per place the report shows the map or k_x) and ``short`` (for a
    figure title)."""

    kind: str
    text: str
    short: str


def _number(side: Mapping[str, Any], key: str) -> float | None:
    v = side.get(key)
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        return None
    return float(v)


def _motion(slip: float | None) -> str:
    if slip is None:
        return "rolling"
    if slip == 0:
        return "free rolling"
    return "braking" if slip < 0 else "driving"


def _rolled(side: Mapping[str, Any]) -> RollingLabel:
    slip = _number(side, "longitudinal_slip")
    turned, travel = _number(side, "rim_rotation_deg"), _number(side, "axle_travel_m")
    motion = _motion(slip)
    parts = [f"quasi-static {motion}"]
    if slip is not None:
        parts.append(f"slip κ = {slip:.3f}")
    if turned is not None and travel is not None:
        parts.append(f"rim turned {turned:.1f}° over {travel:g} m of axle travel")
    elif turned is not None:
        parts.append(f"rim turned {turned:.1f}°")
    short = f"rolled map, {motion}" + ("" if slip in (None, 0) else f" κ = {slip:.3f}")
    return RollingLabel("rolled", f"rolled map ({', '.join(parts)})", short)


def rolling_label(sidecar: Mapping[str, Any] | None) -> RollingLabel:
    """The label of a rolling map with this (validated) sidecar, None for no sidecar."""
    side = sidecar or {}
    if side.get("kind") == ROLLING_RUN:
        return _rolled(side)
    if STANDIN_KEY in side:
        return RollingLabel(
            "standin",
            "sliding stand-in (the rim slid along x, no rotation): its k_x is the shift of a "
            "sliding patch, not of rolling",
            "sliding stand-in",
        )
    kind = side.get("kind")
    if isinstance(kind, str) and kind:
        return RollingLabel("unstated", f"rolling map (its sidecar's kind: {kind})", "rolling map")
    return RollingLabel("unstated", "rolling map (kind not stated)", "rolling map")


def rolling_kind(path: str | Path) -> str:
    """The short label (`RollingLabel.short`) of the rolling map ``path``, from its sidecar
    (an unreadable sidecar: the kind is not stated)."""
    from ..errors import InputFileError
    from ..reader.sidecar import read_sidecar

    try:
        side = read_sidecar(Path(path))
    except InputFileError:
        side = None
    return rolling_label(side).short


def kind_of_rolling_maps(paths) -> str | None:
    """The short label (`RollingLabel.short`) the rolling maps ``paths`` share, "rolling maps
    of several kinds" when they differ, None without any (a static-only sweep)."""
    kinds = {rolling_kind(p) for p in {str(p) for p in paths if p}}
    if not kinds:
        return None
    return kinds.pop() if len(kinds) == 1 else "rolling maps of several kinds"


def own_mesh_static(rolling: str | Path, sidecar: Mapping[str, Any] | None) -> Path | None:
    """The static map solved on the rolled map's own mesh, or None.

    For a rolled map (``kind: "rolling run"``), the one ``.vtu`` beside it whose
    sidecar says ``kind: "static map"`` and describes the same ``mesh``
    (``meshes/rig-aircraft/roll_static.vtu`` for ``roll_*.vtu``); None for any other
    map, or when there is none or more than one.
    """
    from ..errors import InputFileError
    from ..reader.sidecar import read_sidecar

    side = sidecar or {}
    if side.get("kind") != ROLLING_RUN or not side.get("mesh"):
        return None
    here = Path(rolling)
    found = []
    for p in sorted(here.parent.glob("*.vtu")):
        if p.resolve() == here.resolve():
            continue
        try:
            other = read_sidecar(p)
        except InputFileError:
            continue  # a broken neighbour is not a partner
        if other and other.get("kind") == STATIC_MAP and other.get("mesh") == side["mesh"]:
            found.append(p)
    return found[0] if len(found) == 1 else None


@dataclass(frozen=True)
class OwnMeshKx:
    """k_x of the rolled map with its own-mesh static partner (`own_mesh_static`)."""

    static: Path
    k_x: float


def own_mesh_k_x(analysis, *, friction: float, options=None) -> OwnMeshKx | None:
    """k_x of ``analysis``'s rolled map paired with its own-mesh static map, or None.

    None when the rolling map is not a rolled map, has no such partner, or the
    partner is the analysis's static map already; the pair is analysed with the
    same friction and reading options as ``analysis``.
    """
    from ..analysis import analyse

    rf = analysis.rolling_field
    if rf is None or not isinstance(rf.source, str | Path):
        return None
    partner = own_mesh_static(rf.source, rf.sidecar)
    source = analysis.static_field.source
    if partner is None or (isinstance(source, str | Path) and Path(source).resolve() == partner.resolve()):
        return None
    k_x = analyse(partner, rf, friction=friction, options=options).coefficients.k_x  # rf: read already
    return None if k_x is None else OwnMeshKx(partner, float(k_x))
