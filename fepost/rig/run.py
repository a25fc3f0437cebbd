"""One slide/spin rig run: its sidecar read and checked, its resultants on the tire.

A rig run is an FE export (``<run>.vtu`` or any other mesh) with a sidecar
``<run>.json`` next to it. The sidecar keys read here:

``kinematics``  {``vx``, ``vy``, ``wz``}: sliding velocity of the static patch
                origin relative to the road and spin of the tire relative to
                the road (the measured-data convention, THEORY section 3)
``origin``      [x, y] or [x, y, z]: the static patch origin (m)
``reaction``    the solver's reactions at the end of the run, on the rigid
                road's constraint: ``force`` [3] (N) at the reference node,
                ``moment`` [3] (N m) about the reference node's current
                position ``ref_position`` + ``ref_displacement`` (m)
``tire_motion`` optional {``rotation_z``, ``origin_position``}: when the tire
                (not the road) was moved, the angle (rad) by which the tire's
                frame is turned against the road's at the end of the run and
                where the static patch origin then is (m, road's frame); the
                reactions are in the road's frame. Default: no rotation, the
                origin where it was.
``units``       optional; when present it must name SI (m, N, Pa)

Signs. The solver's reaction at the road's constraint is the force the support
exerts on the road; the road is in equilibrium between the support and the
tire, so this reaction equals the force of the road on the tire, which is what
the measured data hold. The force is turned into the tire's frame,
F_tire = Rot(-rotation_z) F, and the moment is transferred from the reference
node to the moved origin o: Mz(o) = Mz(ref) + (r_ref - o) x F (Mz is the same
in both frames).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DataError, InputFileError
from .resultants import Resultants


@dataclass(frozen=True)
class RigRun:
    """A rig run: kinematics, the solver's resultants and, if the export has it, the shear check."""

    source: str
    vx: float
    vy: float
    wz: float
    reaction: Resultants
    shear: Resultants | None
    origin: tuple[float, float]

    def to_dict(self) -> dict:
        return {
            "source": self.source,
            "vx": self.vx,
            "vy": self.vy,
            "wz": self.wz,
            "reaction": self.reaction.to_dict(),
            "shear": None if self.shear is None else self.shear.to_dict(),
            "origin": list(self.origin),
        }


def sidecar_path(run: Path) -> Path:
    return run.with_suffix(".json")


def _load(run: Path) -> dict:
    if not run.is_file():
        raise InputFileError(f"{run}: rig run not found")
    side = sidecar_path(run)
    if not side.is_file():
        raise InputFileError(f"{run}: sidecar {side.name} not found (a rig run needs <run>.json)")
    try:
        data = json.loads(side.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataError(f"{side}: not valid JSON ({exc})") from None
    if not isinstance(data, dict):
        raise DataError(f"{side}: expected a JSON object")
    return data


def not_a_run(path) -> str | None:
    """Why the export ``path`` is no slide/spin run although its sidecar reads (a sidecar with
    neither ``kinematics`` nor ``reaction``: the static reference map of a rig folder; or a
    rolling run's, ``kind: "rolling run"`` without ``kinematics``), or None when it is one or
    its sidecar is faulty (`read_run` then says how)."""
    run = Path(path)
    try:
        data = _load(run)
    except (InputFileError, DataError):
        return None
    side = sidecar_path(run).name
    if "kinematics" not in data and data.get("kind") == "rolling run":
        return f"its sidecar {side} is a rolling run: not a slide/spin run (read it as a --rolling partner)"
    if "kinematics" in data or "reaction" in data:
        return None
    what = f" (case {data['case']!r})" if isinstance(data.get("case"), str) else ""
    return f"its sidecar {side}{what} has no kinematics and no reaction: not a slide/spin run"


def _number(side: Path, where: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise DataError(f"{side}: {where} must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise DataError(f"{side}: {where} is not finite ({value!r})")
    return x


def _vector(side: Path, block: dict, key: str, where: str, sizes=(3,)) -> list[float]:
    if key not in block:
        raise DataError(f"{side}: missing key {where}.{key}")
    vals = block[key]
    if not isinstance(vals, list) or len(vals) not in sizes:
        raise DataError(f"{side}: {where}.{key} must be a list of {' or '.join(map(str, sizes))} numbers")
    return [_number(side, f"{where}.{key}[{i}]", v) for i, v in enumerate(vals)]


def _block(side: Path, data: dict, key: str) -> dict:
    if key not in data:
        raise DataError(f"{side}: missing key {key!r}")
    if not isinstance(data[key], dict):
        raise DataError(f"{side}: {key!r} must be a JSON object")
    return data[key]


def _check_units(side: Path, data: dict) -> None:
    units = data.get("units")
    if units is None:
        return
    if not isinstance(units, str) or not units.strip().upper().startswith("SI"):
        raise DataError(f"{side}: units {units!r} not supported (the rig sidecar must be in SI: m, N, Pa)")


def reaction_resultants(force, moment, ref, origin, rotation: float = 0.0) -> Resultants:
    """Road-on-tire resultants from the solver's reaction at the road's reference node.

    ``force``, ``moment``: the reaction (N, N m) at the reference node, which sits
    at ``ref`` (m, current position), in the road's frame; ``origin``: the static
    patch origin (m, road's frame, where it is at the end of the run);
    ``rotation``: angle (rad) of the tire's frame against the road's.
    """
    fx, fy, fz = (float(v) for v in force)
    dx, dy = float(ref[0]) - float(origin[0]), float(ref[1]) - float(origin[1])
    c, s = math.cos(rotation), math.sin(rotation)
    return Resultants(Fx=c * fx + s * fy, Fy=-s * fx + c * fy, Mz=float(moment[2]) + dx * fy - dy * fx, N=fz)


def read_run(path, *, shear: bool = True) -> RigRun:
    """Read one rig run (module docstring); ``shear``: also integrate the export's shear traction."""
    run = Path(path)
    data = _load(run)
    side = sidecar_path(run)
    _check_units(side, data)
    kin = _block(side, data, "kinematics")
    vx, vy, wz = (_number(side, f"kinematics.{k}", kin.get(k, "missing")) for k in ("vx", "vy", "wz"))
    if vx == vy == wz == 0.0:
        raise DataError(f"{side}: kinematics all zero (no sliding, no spin)")
    if "origin" not in data:
        raise DataError(f"{side}: missing key 'origin' (the static patch origin)")
    o = _vector(side, data, "origin", "sidecar", sizes=(2, 3))
    rec = _block(side, data, "reaction")
    force = _vector(side, rec, "force", "reaction")
    moment = _vector(side, rec, "moment", "reaction")
    ref = np.add(
        _vector(side, rec, "ref_position", "reaction"), _vector(side, rec, "ref_displacement", "reaction")
    )
    rotation, moved = 0.0, o[:2]
    if "tire_motion" in data:
        mot = _block(side, data, "tire_motion")
        rotation = _number(side, "tire_motion.rotation_z", mot.get("rotation_z", "missing"))
        moved = _vector(side, mot, "origin_position", "tire_motion", sizes=(2, 3))
    res = reaction_resultants(force, moment, ref, moved, rotation)
    if not res.N > 0.0:
        raise DataError(f"{side}: reaction.force z = {res.N:g} N; the road must push the tire up (N > 0)")
    sh = None
    if shear:
        from .surface import shear_resultants

        sh = shear_resultants(run, (o[0], o[1]))
    return RigRun(source=str(path), vx=vx, vy=vy, wz=wz, reaction=res, shear=sh, origin=(o[0], o[1]))
