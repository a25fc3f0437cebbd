"""Bring the committed rolling runs' sidecars up to the current exporter, without solving again.

``python -m scripts.tiremodel.roll_refresh [--folder DIR] [--out DIR] [--update]``

The sidecars ``meshes/rig-aircraft/roll_*.json`` were written before the exporter's
fix of b87383b; the CalculiX results they came from are gone, so they cannot simply
be exported again. What can be brought up to date, and how:

- **Labels.** ``description`` (``RunSpec.description``), ``imposed``, the slip
  definition (``SLIP_DEFINITION``) and the blocks that ``common_keys`` writes
  (``model`` with the contact slaves' arc, ``mesh``, notes) are taken from the
  current programme and exporter themselves. They apply to the committed runs
  because the current programme writes, for each run, the very deck whose sha256
  the sidecar holds (checked; a mismatch stops the refresh).
- **Centre of pressure at the end of the roll.** The committed ``roll_<run>.vtu``
  holds the end-of-roll fields; the half model's state is rebuilt from it (checked
  by mirroring it back to the same file) and the exporter's ``centre_of_pressure``
  integrates p(xi) x(xi) exactly over the faces projected on the road. The old
  value (the interpolated nodal products p x) is recomputed as well: it must
  reproduce the committed number to rounding, which shows which rule wrote it.
  The new ``centre_of_pressure_x_m`` is the exact centre, ``samples[-1]``'s shift
  is it minus ``static_centre_of_pressure_x_m``.
- **Static centre.** Exact where the run's static state is a committed map
  (``roll_free``: ``roll_static.vtu`` is that run's state, same load to rounding);
  the slip runs' own static states were not exported, so their static centre
  stays the old rule's (on ``roll_static.vtu`` that rule is off by 0.0025 mm).
- **Earlier samples.** Their fields are gone: their shifts stay the old rule's,
  re-referred to the (possibly new) static centre, and ``centre_of_pressure_note``
  says so, with the old rule's end-of-roll value and its bias on this run, so
  that the series can be read on one rule.

A second, independent computation checks each end-of-roll centre: fepost's
``analyse`` of the map as the rolling partner of ``roll_static.vtu`` (its polar
resampling); the refresh stops if the two differ by more than ``FEPOST_TOL``.

Without ``--update`` the refreshed sidecars go to ``--out`` (default
``out/tiremodel/rig-aircraft-refresh``) and the changed keys are listed; with
``--update`` the committed ones are rewritten (each atomically, only if changed).
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from . import aircraft_roll_programme as prog
from .aircraft_export import mirror_surface
from .aircraft_geometry import AircraftMesh
from .aircraft_roll_run import RollState
from .rig_export import write_text

REPO = Path(__file__).resolve().parents[2]
FOLDER = REPO / "meshes" / "rig-aircraft"
OUT = REPO / "out" / "tiremodel" / "rig-aircraft-refresh"
#: m: fepost's polar resampling against the exact face integral (measured: 0.0064 mm at most, roll_drive04)
FEPOST_TOL = 2e-5
#: relative: identities (the same integral of the same field, the same rule on the same numbers)
SAME = 1e-9
SCRIPT = "scripts/tiremodel/roll_refresh.py"


class RefreshError(ValueError):
    """A committed file is not what the refresh can vouch for (one line: file and problem)."""


def state_from_map(mesh: AircraftMesh, vtu: Path, side: dict) -> RollState:
    """The half model's state behind an exported map, from the map itself.

    Parameters
    ----------
    mesh : AircraftMesh
        The rolling mesh the runs were solved on.
    vtu : Path
        ``roll_<run>.vtu``: the mirrored outer surface, ``CPRESS`` and ``displacement``.
    side : dict
        Its sidecar (forces, travel and turn of the state).

    Returns
    -------
    RollState
        Displacement and CPRESS at the surface nodes (zero elsewhere: the exporter
        reads the surface only), forces and travel from the sidecar. Mirroring it
        again gives the file back exactly, else RefreshError.
    """
    import meshio

    m = meshio.read(vtu)
    used = np.unique(mesh.outer_quads)
    n = used.size
    if m.points.shape[0] < n or not np.allclose(m.points[:n], mesh.nodes[used], rtol=0, atol=1e-9):
        raise RefreshError(f"{vtu}: its points are not the rolling mesh's surface nodes")
    disp = np.zeros_like(mesh.nodes)
    cp = np.zeros(mesh.nodes.shape[0])
    disp[used] = m.point_data["displacement"][:n]
    cp[used] = m.point_data["CPRESS"][:n]
    force = side["reaction"]["force"] if "reaction" in side else [0.0, 0.0, side["reaction_z"]]
    state = RollState(
        name=vtu.stem,
        time=float("nan"),
        displacement=disp,
        cpress=cp,
        road_force=np.asarray(force, float),
        rotation=np.radians(side.get("rim_rotation_deg", 0.0)),
        axle_travel=side.get("axle_travel_m", 0.0),
        road_z=side["rim_travel_z"],
        axle_torque=side.get("axle_torque_Nm", 0.0),
    )
    pts, quads, cp2, disp2 = mirror_surface(mesh, state)
    same = (
        np.array_equal(quads, m.cells_dict["quad"])
        and np.allclose(pts, m.points, rtol=0, atol=1e-9)
        and np.array_equal(cp2, m.point_data["CPRESS"])
        and np.array_equal(disp2, m.point_data["displacement"])
    )
    if not same:
        raise RefreshError(f"{vtu}: the state rebuilt from it does not export back to it")
    return state


def centres(mesh: AircraftMesh, state: RollState) -> tuple[float, float, float]:
    """(N, exact x, old-rule x) of the CPRESS centre on the faces projected on the road (m).

    The exact centre is the exporter's own ``centre_of_pressure`` (p(xi) x(xi), 2 x 2 Gauss);
    the old rule, the bilinear interpolation of the nodal products p x, is the exporter's
    integral of the field ``p * x`` (what the export before b87383b integrated).
    """
    from .aircraft_roll_export import centre_of_pressure, projected_integral

    n, x = centre_of_pressure(mesh, state)
    pts, quads, cp, disp = mirror_surface(mesh, state)
    deformed = pts + disp
    return n, x, projected_integral(deformed, quads, cp * deformed[:, 0]) / n


def current_common(mesh: AircraftMesh, side: dict, state: RollState) -> dict:
    """The keys the current exporter's ``common_keys`` writes for this state.

    The run's provenance (solver, run time, deck hash, road elements) is the sidecar's;
    the figures are the exporter's ``write_map`` of the rebuilt state (into a scratch folder).
    """
    from .aircraft_roll_export import common_keys, write_map

    result = SimpleNamespace(
        solver=side["solver"],
        runtime_s=side["runtime_s"],
        deck_sha256=side["deck_sha256"],
        deck_info={"road_elements": side["mesh"]["road_elements"]},
    )
    with tempfile.TemporaryDirectory() as tmp:
        figures = write_map(mesh, state, Path(tmp), "map")
    return common_keys(mesh, result, state, figures)


def numbers_agree(old, new, where: str) -> str | None:
    """Where two JSON values differ in a number (or in shape), None if only their texts differ."""
    if isinstance(old, dict) and isinstance(new, dict):
        if old.keys() != new.keys():
            return f"{where}: keys {sorted(set(old) ^ set(new))}"
        return next((w for k in old if (w := numbers_agree(old[k], new[k], f"{where}.{k}"))), None)
    if isinstance(old, list) and isinstance(new, list):
        if len(old) != len(new):
            return f"{where}: length"
        return next(
            (
                w
                for i, (a, b) in enumerate(zip(old, new, strict=True))
                if (w := numbers_agree(a, b, f"{where}[{i}]"))
            ),
            None,
        )
    if isinstance(old, str) and isinstance(new, str):
        return None
    if isinstance(old, bool) or old is None or isinstance(old, str):
        return None if old == new else f"{where}: {old!r} -> {new!r}"
    if isinstance(old, (int, float)) and isinstance(new, (int, float)):
        return None if np.isclose(old, new, rtol=SAME, atol=0) else f"{where}: {old!r} -> {new!r}"
    return f"{where}: {type(old).__name__} -> {type(new).__name__}"


def check_deck(mesh: AircraftMesh, spec: prog.RunSpec, plan, side: dict, path: Path) -> None:
    """The current programme writes the deck the sidecar's run solved (its sha256), else RefreshError."""
    from .aircraft_roll_run import deck_text, sha256_text

    with tempfile.TemporaryDirectory() as tmp:
        sha = sha256_text(deck_text(mesh, plan, Path(tmp) / "deck.inp")[0])
    if sha != side["deck_sha256"]:
        raise RefreshError(
            f"{path}: the current programme writes another deck for {spec.name} (sha256 {sha[:12]}, "
            f"sidecar {side['deck_sha256'][:12]}): its labels would not describe this run"
        )


def refresh_common(mesh: AircraftMesh, side: dict, state: RollState, path: Path) -> dict:
    """The sidecar with the common keys as the current exporter writes them (numbers unchanged)."""
    common = current_common(mesh, side, state)
    old = {k: side[k] for k in common}
    if (where := numbers_agree(old, common, path.name)) is not None:
        raise RefreshError(f"{path}: the rebuilt state does not give the sidecar's numbers ({where})")
    return {k: common.get(k, v) for k, v in side.items()}


def fepost_shift(static_vtu: Path, vtu: Path) -> float:
    """fepost's x_c (m): the rolled map's centre shift against ``static_vtu``, from its polar grid."""
    from fepost import analyse

    return float(analyse(static_vtu, vtu).coefficients.x_c)


def _centre_note(side: dict, ends: dict, static_exact: bool) -> dict:
    """The ``centre_of_pressure_note`` block: which rule gave which number, and the measured bias."""
    static = (
        "exact, from roll_static.vtu (this run's static state: the same load to rounding)"
        if static_exact
        else "the old rule (interpolated nodal products p x): this run's static state was not "
        "exported (roll_static.vtu is the free run's, 0.13 % more load), so it cannot be "
        "recomputed; on roll_static.vtu that rule is off by "
        f"{1e3 * ends['static_bias']:+.4f} mm"
    )
    return {
        "rule": "centre_of_pressure_shift_m = x of the CPRESS centre on the deformed faces projected "
        "on the road minus static_centre_of_pressure_x_m (axle frame, m)",
        "end_of_roll": f"exact integral of p(xi) x(xi) over {side['case']}.vtu's faces (2 x 2 Gauss): "
        "centre_of_pressure_x_m and the last sample",
        "earlier_samples": "x by the old rule, the bilinear interpolation of the nodal products "
        "p x (not the product of the bilinear p and x fields), minus static_centre_of_pressure_x_m: "
        "their fields were not kept, so x cannot be recomputed and the rule's bias there is not "
        "known; at the end of this roll the rule gave end_of_roll_shift_old_rule_m, off by "
        "end_of_roll_bias_old_rule_m (over the committed runs: "
        f"{1e3 * ends['bias_range'][0]:+.2f} to {1e3 * ends['bias_range'][1]:+.2f} mm)",
        "static_centre": static,
        "end_of_roll_shift_old_rule_m": ends["old_shift"],
        "end_of_roll_bias_old_rule_m": ends["bias"],
        "end_of_roll_shift_against_roll_static_m": ends["against_partner"],
        "against_roll_static_note": "the exact end-of-roll centre minus roll_static.vtu's exact "
        "centre: what fepost's x_c measures (it pairs this map with roll_static.vtu, the free "
        "run's static state)",
        "refreshed_by": f"{SCRIPT} (labels from the current exporter; no new solve)",
    }


def refresh_rolling(
    mesh: AircraftMesh, side: dict, path: Path, partner: dict, bias_range: tuple[float, float]
) -> tuple[dict, dict]:
    """The refreshed sidecar of one rolling run and its centre figures (m).

    ``partner``: the static map's figures (``n``, ``x`` exact, ``old`` rule, ``vtu``);
    ``bias_range``: the old rule's end-of-roll bias over all the committed runs (m).
    """
    from .aircraft_roll_export import SLIP_DEFINITION, _imposed

    spec = next((s for s in prog.programme() if s.name == side["case"]), None)
    if spec is None:
        raise RefreshError(f"{path}: {side['case']!r} is not a run of the rolling programme")
    radius = None if spec.slip is None else side["effective_rolling_radius_m"]
    plan = spec.plan(radius, prog.AIRCRAFT)
    check_deck(mesh, spec, plan, side, path)
    vtu = path.with_suffix(".vtu")
    state = state_from_map(mesh, vtu, side)
    n, x, old = centres(mesh, state)
    if not np.isclose(n, side["cpress_integral_projected"], rtol=SAME, atol=0):
        raise RefreshError(f"{path}: the map's load is not the sidecar's: another state")
    fe = fepost_shift(partner["vtu"], vtu)
    if abs(fe - (x - partner["x"])) > FEPOST_TOL:
        raise RefreshError(
            f"{vtu}: fepost's x_c {1e3 * fe:+.4f} mm against the exact {1e3 * (x - partner['x']):+.4f} mm"
        )
    new = refresh_common(mesh, side, state, path)
    new["description"] = spec.description(prog.AIRCRAFT)
    new["imposed"] = _imposed(plan)
    new["longitudinal_slip_definition"] = SLIP_DEFINITION
    x0_now = side["static_centre_of_pressure_x_m"]
    shift_now = side["samples"][-1]["centre_of_pressure_shift_m"]
    if "centre_of_pressure_note" not in side and np.isclose(x - x0_now, shift_now, rtol=SAME, atol=1e-12):
        # written by the exporter since b87383b: its centres are exact already, only labels to do
        figures = {"old": shift_now, "exact": shift_now, "partner": x - partner["x"], "fepost": fe}
        return new, figures
    static_exact = bool(np.isclose(side["static_cpress_integral"], partner["n"], rtol=SAME, atol=0))
    old_shift = old_rule_end(side, old, partner, static_exact, path)
    x0 = partner["x"] if static_exact else x0_now
    new["static_centre_of_pressure_x_m"] = x0
    samples = copy.deepcopy(side["samples"])
    for s in samples[:-1]:
        s["centre_of_pressure_shift_m"] += x0_now - x0
    samples[-1]["centre_of_pressure_shift_m"] = x - x0
    new["samples"] = samples
    ends = {
        "old_shift": old_shift,
        "bias": old - x,
        "static_bias": partner["old"] - partner["x"],
        "against_partner": x - partner["x"],
        "bias_range": bias_range,
    }
    new = _with_centre_keys(new, x, _centre_note(side, ends, static_exact))
    figures = {"old": ends["old_shift"], "exact": x - x0, "partner": x - partner["x"], "fepost": fe}
    return new, figures


def old_rule_end(side: dict, old: float, partner: dict, static_exact: bool, path: Path) -> float:
    """The end-of-roll shift (m) the old rule wrote, checked against that rule on the map.

    ``old``: the old rule's centre of the committed map. The static centre that rule
    subtracted is the sidecar's, or for a run whose static state is ``roll_static.vtu``
    that map's by the same rule. A sidecar refreshed before keeps the old shift in its
    ``centre_of_pressure_note`` (so refreshing twice changes nothing).
    """
    prior = side.get("centre_of_pressure_note")
    shift = (
        prior["end_of_roll_shift_old_rule_m"] if prior else side["samples"][-1]["centre_of_pressure_shift_m"]
    )
    x0_old = partner["old"] if static_exact else side["static_centre_of_pressure_x_m"]
    if (
        static_exact
        and not prior
        and not np.isclose(partner["old"], side["static_centre_of_pressure_x_m"], rtol=SAME)
    ):
        raise RefreshError(f"{path}: the static centre is not the old rule on roll_static.vtu")
    if not np.isclose(old - x0_old, shift, rtol=SAME, atol=1e-12):
        raise RefreshError(f"{path}: the old end-of-roll shift is not the old rule on this map")
    return shift


def _with_centre_keys(side: dict, x: float, note: dict) -> dict:
    """``centre_of_pressure_x_m`` after the static centre's keys, the note after ``samples_note``."""
    out: dict = {}
    for k, v in side.items():
        if k in ("centre_of_pressure_x_m", "centre_of_pressure_note"):
            continue
        out[k] = v
        if k == "static_cpress_integral":
            out["centre_of_pressure_x_m"] = x
        if k == "samples_note":
            out["samples_note"] = (
                "the written times along the roll; centre-of-pressure shift: see centre_of_pressure_note "
                "(the last sample exact, the earlier ones by the old rule); steady when it stops changing"
            )
            out["centre_of_pressure_note"] = note
    return out


def refreshed(folder: Path) -> tuple[dict[Path, dict], dict[str, dict]]:
    """Every refreshed sidecar of ``folder`` (path -> content) and the centre figures per run."""
    from .aircraft_roll_mesh import build_roll_mesh

    static_json = folder / f"{prog.STATIC_NAME}.json"
    runs = sorted(p for p in folder.glob("roll_*.json") if p != static_json)
    if not static_json.is_file() or not runs:
        raise RefreshError(f"{folder}: no {static_json.name} or no rolling run's sidecar")
    mesh = build_roll_mesh(prog.AIRCRAFT.mesh)
    static_side = _read(static_json)
    if static_side["mesh"]["model_nodes"] != mesh.nodes.shape[0]:
        raise RefreshError(f"{static_json}: not the rolling programme's mesh")
    state = state_from_map(mesh, static_json.with_suffix(".vtu"), static_side)
    n0, x0, old0 = centres(mesh, state)
    partner = {"n": n0, "x": x0, "old": old0, "vtu": static_json.with_suffix(".vtu")}
    out = {static_json: refresh_common(mesh, static_side, state, static_json)}
    sides = {path: _read(path) for path in runs}
    biases = [end_bias(mesh, path, side) for path, side in sides.items()]
    figures = {}
    for path, side in sides.items():
        out[path], figures[path.stem] = refresh_rolling(mesh, side, path, partner, (min(biases), max(biases)))
    return out, figures


def end_bias(mesh: AircraftMesh, path: Path, side: dict) -> float:
    """The old rule's bias (m) on the end-of-roll centre of one run's committed map."""
    _, x, old = centres(mesh, state_from_map(mesh, path.with_suffix(".vtu"), side))
    return old - x


def _read(path: Path) -> dict:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise RefreshError(f"{path}: not readable as JSON ({exc})") from None


def changed_keys(old, new, where: str = "") -> list[str]:
    """Dotted paths of the leaves (or keys) that differ."""
    if isinstance(old, dict) and isinstance(new, dict):
        keys = list(old) + [k for k in new if k not in old]
        return [w for k in keys for w in changed_keys(old.get(k), new.get(k), f"{where}.{k}".lstrip("."))]
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [
            w
            for i, (a, b) in enumerate(zip(old, new, strict=True))
            for w in changed_keys(a, b, f"{where}[{i}]")
        ]
    return [] if old == new else [where]


def write_json(path: Path, data: dict) -> None:
    """Atomically (`rig_export.write_text`), in the exporter's layout: indent 2, newline."""
    write_text(path, json.dumps(data, indent=2) + "\n")


def table(figures: dict[str, dict]) -> str:
    """The end-of-roll centre shifts (mm): old sidecar, exact, exact against roll_static, fepost."""
    lines = [
        "run            old rule   exact (own static)   exact vs roll_static   fepost x_c   fepost - exact",
    ]
    for name, f in figures.items():
        lines.append(
            f"{name:<14} {1e3 * f['old']:+9.4f} {1e3 * f['exact']:+20.4f} {1e3 * f['partner']:+22.4f} "
            f"{1e3 * f['fepost']:+12.4f} {1e3 * (f['fepost'] - f['partner']):+15.4f}"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m scripts.tiremodel.roll_refresh", description=__doc__.split("\n")[0]
    )
    parser.add_argument(
        "--folder", type=Path, default=FOLDER, help="the committed runs (default meshes/rig-aircraft)"
    )
    parser.add_argument("--out", type=Path, default=OUT, help="where to write without --update")
    parser.add_argument("--update", action="store_true", help="rewrite the sidecars in --folder")
    args = parser.parse_args(argv)
    try:
        new, figures = refreshed(args.folder)
    except (RefreshError, OSError) as exc:
        print(f"roll_refresh: error: {exc}", file=sys.stderr)
        return 2
    except KeyError as exc:
        print(f"roll_refresh: error: a sidecar in {args.folder} lacks the key {exc}", file=sys.stderr)
        return 2
    target = args.folder if args.update else args.out
    target.mkdir(parents=True, exist_ok=True)
    for path, data in new.items():
        keys = changed_keys(_read(path), data)
        print(f"{path.name}: {len(keys)} changed: {', '.join(keys) if keys else '-'}")
        if keys or not args.update:
            write_json(target / path.name, data)
    print()
    print(table(figures))
    print(f"\nwritten to {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
