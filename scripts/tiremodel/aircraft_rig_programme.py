"""The slide/spin programme on the aircraft tire: which runs, in which order, and the driver.

Runs (named as the small tire's, ``rig_programme.run_name``): sliding
directions 0, 45 and 90 degrees, spin angles a (|v| = S cos a,
|wz| R_ref = S sin a) of 0 (pure sliding), 20, 40, 60, 75 and 90 (pure spin)
degrees, both spin signs. Order, most informative first (a session that ends
early still has a programme): pure spin and one pure slide per direction;
then the spin angles 40, 60, 20, 75 in turn, each at 0 and 90 degrees with
positive spin and at 45 degrees with both signs; last the negative spins at
0 and 90 degrees and the negative pure spin, which are the mirror images of
positive ones (the tire and its sector are symmetric about x = 0 and y = 0):
a check of the rig, not new data.

The driver (``run_programme``) is resumable: a run whose ``.vtu``,
``.dat.txt`` and sidecar exist in the output folder and whose sidecar holds
the sha256 of the deck it would solve now is skipped; anything else (a run
never started, half-written, or with a changed deck) is solved again. Each
run is a task on Dask (the sweep's ``Cluster``: a local cluster of one-thread
workers by default, ``scheduler`` for an existing one; the work folder must
then be visible to the workers); the client writes every finished run's
files at once (the sidecar last) and prints its progress.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from . import rig_deck as rd
from .aircraft_rig_deck import AIRCRAFT, incompatible_mask, plain_element, tire_for
from .aircraft_rig_mesh import build_rig_mesh
from .rig_programme import run_name

SPIN_ANGLES = (40.0, 60.0, 20.0, 75.0)
DIRECTIONS = (0.0, 45.0, 90.0)
RUN_FILES = (".vtu", ".dat.txt", ".json")  # written in this order: the sidecar marks a finished run


@dataclass(frozen=True)
class RunSpec:
    name: str
    direction: float  # deg
    angle: float  # spin angle, deg (0 pure sliding, 90 pure spin)
    sign: int  # sign of wz


def programme() -> list[RunSpec]:
    """Every run of the programme, in solving order (see the module docstring)."""
    runs = [(0.0, 90.0, 1), (0.0, 0.0, 1), (45.0, 0.0, 1), (90.0, 0.0, 1)]
    for a in SPIN_ANGLES:
        runs += [(45.0, a, 1), (45.0, a, -1), (0.0, a, 1), (90.0, a, 1)]
    runs.append((0.0, 90.0, -1))
    for a in SPIN_ANGLES:
        runs += [(0.0, a, -1), (90.0, a, -1)]
    return [RunSpec(run_name(d, a, s), d, a, s) for d, a, s in runs]


@dataclass(frozen=True)
class Setup:
    """What every task needs: the mesh, the work folder, the largest increment of the slide and
    the reference path S of the slide (`AIRCRAFT.slide_path` unless a longer one is asked for)."""

    mesh_kind: str
    work: str
    inc: float
    path: float = AIRCRAFT.slide_path
    friction: float | None = None  # Coulomb coefficient of base and slides (None: the tire's 0.3)

    @property
    def tire(self) -> rd.RigTire:
        """The mesh's rig tire (``tire_for``, with this set-up's friction) and reference path (the
        base does not depend on the path)."""
        return dataclasses.replace(tire_for(self.mesh_kind, self.friction), slide_path=self.path)


@functools.lru_cache(maxsize=4)
def _mesh(kind: str):
    return build_rig_mesh(kind)


def base_task(setup: Setup, mesh):
    """Inflation pre-run and base run, reused from the work folder: (rim travel, clearance, Base).

    The mesh comes from the client (gmsh meshes only in a main thread, Dask runs tasks in others).
    """
    from .rig_run import inflation_rim_travel, solve_base
    from .solve import find_ccx

    exe, work = find_ccx(), Path(setup.work)
    rim_travel, clearance, _ = inflation_rim_travel(mesh, work, exe, setup.tire)
    return rim_travel, clearance, solve_base(mesh, rim_travel, work / "base", exe, setup.tire)


def run_deck_sha256(setup: Setup, spec: RunSpec, rim_travel: float, base_sha: str) -> str:
    """The sha256 the run's sidecar records (its slide deck and the base deck's sha256)."""
    with tempfile.TemporaryDirectory(prefix="arig-deck-") as tmp:
        inp = Path(tmp) / f"{spec.name}.inp"
        kin = rd.kinematics(spec.direction, spec.angle, spec.sign, setup.tire)
        rd.write_slide_deck(inp, _mesh(setup.mesh_kind), kin, rim_travel, (0.0, 0.0), setup.inc, setup.tire)
        return hashlib.sha256(inp.read_bytes() + base_sha.encode()).hexdigest()


def is_done(out: Path, name: str, sha: str) -> bool:
    """A run is finished when all its files exist and its sidecar names this deck."""
    if not all((out / f"{name}{s}").is_file() for s in RUN_FILES):
        return False
    try:
        return json.loads((out / f"{name}.json").read_text()).get("deck_sha256") == sha
    except (OSError, ValueError):
        return False


def run_task(setup: Setup, spec: RunSpec, info: dict, mesh) -> dict[str, bytes]:
    """Solve one run (reusing a finished solve in the work folder) and export it: {file name: bytes}."""
    from .rig_export import write_run
    from .rig_run import inflation_rim_travel, solve_base, solve_run
    from .solve import find_ccx

    exe, work = find_ccx(), Path(setup.work)
    rim_travel, _, _ = inflation_rim_travel(mesh, work, exe, setup.tire)
    base = solve_base(mesh, rim_travel, work / "base", exe, setup.tire)
    kin = rd.kinematics(spec.direction, spec.angle, spec.sign, setup.tire)
    res = solve_run(mesh, base, spec.name, kin, rim_travel, work / spec.name, exe, setup.inc, setup.tire)
    extra = {"direction_deg": spec.direction, "spin_angle_deg": spec.angle, "spin_sign": spec.sign}
    with tempfile.TemporaryDirectory(prefix="arig-export-") as tmp:
        write_run(mesh, res, Path(tmp), {**info, **extra}, tire=setup.tire)
        return {f"{spec.name}{s}": (Path(tmp) / f"{spec.name}{s}").read_bytes() for s in RUN_FILES}


def save_files(out: Path, files: dict[str, bytes]) -> None:
    """Write the files atomically in their given order (the sidecar last)."""
    out.mkdir(parents=True, exist_ok=True)
    for name, data in files.items():
        part = out / f"{name}.part"
        part.write_bytes(data)
        os.replace(part, out / name)


def _log(msg: str) -> None:
    print(f"rig-aircraft: {msg}", file=sys.stderr, flush=True)


def drive(
    specs: list[RunSpec],
    shas: dict[str, str],
    out: Path,
    submit: Callable[[RunSpec], object],
    completed: Callable[[list], Iterable[tuple[object, object]]],
    log: Callable[[str], None] = _log,
) -> dict[str, dict]:
    """Skip the finished runs, submit the others in order, save each result as it arrives.

    ``submit(spec)`` returns a handle whose result is the run's files
    (``run_task``); ``completed(handles)`` yields (handle, result or exception)
    as they finish. Returns {run name: sidecar} of the runs solved now; a
    failed run is reported and the others go on (raises at the end if any failed).
    """
    todo = [s for s in specs if not is_done(out, s.name, shas[s.name])]
    skipped = len(specs) - len(todo)
    if skipped:
        log(f"{skipped} of {len(specs)} runs already finished in {out}; skipped")
    handles = {}
    for s in todo:
        h = submit(s)
        handles[id(h)] = (s, h)
    done, failed = {}, []
    t0 = time.perf_counter()
    for h, result in completed([h for _, h in handles.values()]):
        spec = handles[id(h)][0]
        if isinstance(result, BaseException):
            failed.append(spec.name)
            log(f"{spec.name}: FAILED: {type(result).__name__}: {result}")
            continue
        save_files(out, result)
        side = json.loads(result[f"{spec.name}.json"])
        done[spec.name] = side
        f = side["reaction"]["force"]
        log(
            f"[{skipped + len(done)}/{len(specs)}] {spec.name}: F = ({f[0]:.0f}, {f[1]:.0f}, {f[2]:.0f}) N, "
            f"Mz = {side['history']['Mz'][-1]:.0f} N m, solve {side['runtime_s']:.0f} s"
            f"{_cpu(side.get('cpu_s'))} (programme {time.perf_counter() - t0:.0f} s); {_steadiness(side)}"
        )
    if failed:
        raise RuntimeError(f"{len(failed)} run(s) failed: {', '.join(failed)}")
    return done


def _cpu(seconds: float | None) -> str:
    """The solver's CPU time as ``, CPU 783 s`` ("solve" is its wall time); empty where unmeasured."""
    return "" if seconds is None else f", CPU {seconds:.0f} s"


def _steadiness(side: dict) -> str:
    """The run's steadiness over the last fifth of its path (``steadiness``), in words."""
    from .steadiness import tail_motion

    try:
        m = tail_motion(side["history"], float(side["friction"]))
    except (KeyError, ValueError) as exc:
        return f"steadiness not judged ({exc})"
    verdict = "steady" if m.steady() else "NOT steady"
    return f"{verdict}: last fifth moves Fx {m.fx:.4f}, Fy {m.fy:.4f} fN, N {m.n:.4f} N"


def model_info(mesh, setup: Setup, rim_travel: float, clearance: float, solver: str) -> dict:
    """The provenance block every sidecar of the programme carries."""
    from . import aircraft_deck as ad
    from .aircraft_export import model_description

    hexes = mesh.hexes.shape[0]
    incompatible = int(incompatible_mask(mesh).sum())
    info = {
        "solver": solver,
        "mesh": {
            "name": f"aircraft-{setup.mesh_kind}",
            "tire_nodes": int(mesh.nodes.shape[0]),
            "tire_elements": int(hexes),
            "element_type": f"C3D8I ({incompatible}), {plain_element(mesh)} ({hexes - incompatible})",
            "contact_faces": int(mesh.contact_quads.shape[0]),
            "sector_deg": round(mesh.info["sector_deg"], 6),
            "n_crown": mesh.params.n_crown,
            "n_shoulder": mesh.params.n_shoulder,
            "n_side": mesh.params.n_side,
            "layer_deg": mesh.params.first_deg,
            "fine_deg": mesh.params.fine_deg,
            "full_section": True,
        },
        "model": {
            **model_description(mesh),
            "rim": "rigid: the bead nodes prescribed (inflation, vertical travel, the rig's rigid motion)",
            "deflection": setup.tire.deflection,
            "rim_travel_z": round(rim_travel, 9),
            "inflated_clearance": round(clearance, 9),
            "inflation_pressure": ad.PRESSURE,
            "rated_load": ad.RATED_LOAD,
            "road": "rigid body (*RIGID BODY), held at its reference and rotation nodes; the rim moves",
            "slide_path": setup.path,
            "r_ref": setup.tire.r_ref,
            "max_increment": setup.inc,
            "slide_steps": rd.substeps(setup.inc),
            "convergence": _convergence(setup.tire),
        },
    }
    if mesh.info.get("whole_tire"):
        info["mesh"]["whole_tire"] = True
        info["mesh"]["n_rubber"] = mesh.params.n_rubber
        info["model"]["rim"] = (
            "rigid: the bead nodes prescribed (inflation, vertical travel, the rig's rigid motion); "
            "the whole 360-degree tire, no cut faces"
        )
    if setup.friction is not None:
        info["model"]["friction"] = setup.friction
    return info


def _criteria(controls: tuple[str, ...]) -> str:
    """The field controls of ``controls``, in words."""
    field = [ln for i, ln in enumerate(controls[1:], 1) if controls[i - 1].endswith("FIELD")]
    if field:
        r, c = (v.strip() for v in field[0].split(",")[:2])
        return f"CalculiX field controls {r} (force residual), {c} (displacement correction)"
    return "CalculiX's default field controls: 0.005 (force residual), 0.01 (displacement correction)"


def _convergence(tire: rd.RigTire) -> str:
    """The convergence criteria of the tire's steps, in words (base and slides apart if they differ)."""
    if tire.slide_controls is None or tire.slide_controls == tire.controls:
        return _criteria(tire.controls)
    return f"base: {_criteria(tire.controls)}; slides: {_criteria(tire.slide_controls)}"


def select_runs(only: list[str] | None) -> list[RunSpec]:
    """The runs to solve, in solving order: the programme's (``only`` None or empty), else the runs
    named in ``only`` in the order given (a user who lists runs says which matter first; repeats
    once). "static" names the base and its static map, always solved and written, and no run."""
    specs = programme()
    if not only:
        return specs
    unknown = sorted(set(only) - {s.name for s in specs} - {"static"})
    if unknown:
        raise ValueError(f"--only: unknown run(s) {', '.join(unknown)}")
    by_name = {s.name: s for s in specs}
    return [by_name[name] for name in dict.fromkeys(only) if name in by_name]


def run_programme(
    out: Path,
    work: Path,
    *,
    mesh_kind: str = "rig",
    inc: float = 0.1,
    path: float = AIRCRAFT.slide_path,
    friction: float | None = None,
    only: list[str] | None = None,
    workers: int | None = 2,
    scheduler: str | None = None,
) -> dict[str, dict]:
    """Solve (or skip, when finished) and export the runs ``only``, in that order (default: the whole
    programme, in its order)."""
    import dask

    from fepost.sweep.engine import Cluster

    from .rig_export import write_static
    from .rig_run import check_on_road
    from .solve import ccx_version, find_ccx

    exe = find_ccx()
    setup = Setup(mesh_kind, str(work.resolve()), inc, path, friction)
    specs = select_runs(only)
    mesh = _mesh(mesh_kind)
    _log(f"mesh aircraft-{mesh_kind}: {mesh.nodes.shape[0]} nodes, {mesh.hexes.shape[0]} hexahedra")
    # tasks wait on the scheduler until a worker is free, so they start in the programme's order
    # (assigned to workers at once, a busy worker's queue would hold back its early runs)
    dask.config.set({"distributed.scheduler.worker-saturation": 1.0})
    with Cluster(workers=None if scheduler else workers, scheduler=scheduler) as cluster:
        client = cluster.client
        t0 = time.perf_counter()
        shared = client.scatter(mesh, broadcast=True)
        rim_travel, clearance, base = client.submit(base_task, setup, shared, pure=False).result()
        _log(
            f"base (inflation + {setup.tire.deflection * 1e3:.1f} mm): "
            f"load {base.static_load[2] / 1e3:.1f} kN, "
            f"{(base.static_cpress > 0).sum()} loaded nodes, solve {base.runtime_s:.0f} s"
            f"{_cpu(base.cpu_s)} (this call {time.perf_counter() - t0:.0f} s)"
        )
        check_on_road(
            mesh,
            base,
            setup.tire.road(),
            {s.name: rd.kinematics(s.direction, s.angle, s.sign, setup.tire) for s in specs},
            setup.path,
            _log,
        )
        info = model_info(mesh, setup, rim_travel, clearance, ccx_version(exe))
        static = out / "static.json"
        if not static.exists() or json.loads(static.read_text()).get("base_deck_sha256") != base.deck_sha256:
            write_static(mesh, base, out, {**info, "base_deck_sha256": base.deck_sha256}, tire=setup.tire)
        shas = {s.name: run_deck_sha256(setup, s, rim_travel, base.deck_sha256) for s in specs}
        n = len(specs)

        def submit(spec: RunSpec):
            # earlier runs first: a higher priority for each earlier place in the order
            return client.submit(
                run_task, setup, spec, info, shared, pure=False, priority=n - specs.index(spec)
            )

        return drive(specs, shas, out, submit, cluster.as_completed)
