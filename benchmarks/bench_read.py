"""Benchmark: whole-process ``fepost coefficients F`` against a bare ``pyvista.read(F)`` process.

Three files of about a million nodes each, built once into ``--dir`` (reused when present):

* ``surface.vtu``: the 1.08 M-node triangulated Hertz patch of ``bench_coefficients.py``
  (zlib-compressed inline arrays, as meshio writes them; one point array);
* ``solver.vtu``: a hexahedral volume (250 x 250 x 16 cells, 1.07 M nodes) whose bottom face
  carries a Hertz pressure, with the displacement and 12 extra point arrays as a solver
  writes them (4 tensors, 4 vectors, 4 scalars; VTK's XML writer through pyvista's
  ``save``: zlib, inline base64);
* ``series.e``: the same volume as Exodus II (netCDF 64-bit offset, 8-byte words) with 50 time
  steps and 10 nodal variables (contact pressure, displacement and velocity components,
  temperature, von Mises, hydrostatic), and side set 1 'ground' naming the bottom sides of the
  bottom layer (62 500 of the 10⁶ elements). ``exodus`` times ``fepost coefficients`` on it as it
  is, ``exodus-ground`` with ``--surface ground`` (only that side set's elements are read).

For each file, ``--pairs`` alternating pairs of whole processes are timed (the order
flips every pair, so a change of machine load hits both sides alike): medians and
their ratio are printed side by side, with the load average before and after. Peak
memory is sampled every 10 ms as the summed resident set of the process and all its
descendants (fepost reads in a forked child); shared copy-on-write pages are counted
once per process, so fepost's figure is an upper bound.

    .venv/bin/python benchmarks/bench_read.py --dir /tmp/fepost-bench [--pairs 7]
        [--files surface,solver,exodus]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

SHAPE = (250, 250, 16)  # hexahedra along x, y, z: 251 * 251 * 17 = 1.07 M nodes
SIZE = (0.5, 0.5, 0.1)  # m
RADIUS, PEAK = 0.15, 1.0e6  # Hertz patch on the bottom face (m, Pa)
STEPS, NODAL = 50, 10


def _grid_points() -> np.ndarray:
    axes = [
        np.linspace(-s / 2, s / 2, n + 1) if k < 2 else np.linspace(0, s, n + 1)
        for k, (s, n) in enumerate(zip(SIZE, SHAPE, strict=True))
    ]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    # x fastest, as VTK's structured point order
    return np.column_stack([x.ravel(order="F"), y.ravel(order="F"), z.ravel(order="F")])


def _hexes() -> np.ndarray:
    nx, ny, nz = SHAPE
    px, py = nx + 1, ny + 1
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    base = (i + px * (j + py * k)).ravel(order="F")
    corners = [0, 1, 1 + px, px]
    bottom = [base + c for c in corners]
    top = [b + px * py for b in bottom]
    return np.column_stack(bottom + top).astype(np.int64)


def _hertz(points: np.ndarray) -> np.ndarray:
    r2 = points[:, 0] ** 2 + points[:, 1] ** 2
    p = PEAK * np.sqrt(np.clip(1.0 - r2 / RADIUS**2, 0.0, None))
    return np.where(np.isclose(points[:, 2], 0.0), p, 0.0)


def _smooth(points: np.ndarray, k: int) -> np.ndarray:
    x, y, z = points.T
    return np.cos(7.0 * x + k) * np.sin(5.0 * y - 0.3 * k) * (1.0 + z * (k + 1))


def write_solver_vtu(path: Path) -> None:
    import pyvista as pv

    pts = _grid_points()
    hexes = _hexes()
    cells = np.column_stack([np.full(len(hexes), 8), hexes]).ravel()
    grid = pv.UnstructuredGrid(cells, np.full(len(hexes), pv.CellType.HEXAHEDRON, np.uint8), pts)
    grid.point_data["CPRESS"] = _hertz(pts)
    u = np.zeros_like(pts)
    u[:, 2] = -1e-4 * (1.0 + pts[:, 2])
    grid.point_data["U"] = u
    k = 0
    for name, ncomp in (
        ("S", 6),
        ("E", 6),
        ("PE", 6),
        ("ME", 6),
        ("V", 3),
        ("A", 3),
        ("RF", 3),
        ("NT", 3),
        ("T", 1),
        ("SEQV", 1),
        ("PEEQ", 1),
        ("ENER", 1),
    ):
        cols = [_smooth(pts, k + c) for c in range(ncomp)]
        k += ncomp
        grid.point_data[name] = cols[0] if ncomp == 1 else np.column_stack(cols)
    grid.save(path)


def nodal_values(pts: np.ndarray, p: np.ndarray, i: int, scale: float) -> np.ndarray:
    """Nodal variable ``i`` of the Exodus series at load factor ``scale``: pressure, displacement
    (small: 0.1 mm), then smooth fields."""
    if i == 0:
        return p * scale
    if i in (1, 2, 3):
        return -1e-4 * scale * (1.0 + pts[:, 2]) * (1.0 if i == 3 else 0.01 * _smooth(pts, i))
    return scale * _smooth(pts, i)


def write_exodus(path: Path) -> None:
    import netCDF4

    pts = _grid_points()
    hexes = _hexes()
    names = [
        "contact_pressure",
        "disp_x",
        "disp_y",
        "disp_z",
        "vel_x",
        "vel_y",
        "vel_z",
        "temperature",
        "vonmises",
        "hydrostatic",
    ][:NODAL]
    ds = netCDF4.Dataset(str(path), "w", format="NETCDF3_64BIT_OFFSET")
    try:
        ds.title = "fepost benchmark"
        ds.api_version = np.float32(8.0)
        ds.version = np.float32(2.0)
        ds.floating_point_word_size = np.int32(8)
        ds.file_size = np.int32(1)
        for dim, n in (
            ("len_string", 33),
            ("len_line", 81),
            ("four", 4),
            ("len_name", 33),
            ("time_step", None),
            ("num_dim", 3),
            ("num_nodes", len(pts)),
            ("num_elem", len(hexes)),
            ("num_el_blk", 1),
            ("num_el_in_blk1", len(hexes)),
            ("num_nod_per_el1", 8),
            ("num_nod_var", len(names)),
        ):
            ds.createDimension(dim, n)

        def text(var: str, dim: str, items: list[str]) -> None:
            v = ds.createVariable(var, "S1", (dim, "len_name"))
            arr = np.zeros((len(items), 33), "S1")
            for i, s in enumerate(items):
                arr[i, : len(s)] = np.frombuffer(s.encode(), "S1")
            v[:] = arr

        for k, c in enumerate("xyz"):
            ds.createVariable(f"coord{c}", "f8", ("num_nodes",))[:] = pts[:, k]
        text("coor_names", "num_dim", list("xyz"))
        ds.createVariable("eb_status", "i4", ("num_el_blk",))[:] = [1]
        prop = ds.createVariable("eb_prop1", "i4", ("num_el_blk",))
        prop.setncattr("name", "ID")
        prop[:] = [1]
        text("eb_names", "num_el_blk", ["tire"])
        conn = ds.createVariable("connect1", "i4", ("num_el_in_blk1", "num_nod_per_el1"))
        conn.elem_type = "HEX8"
        conn[:] = (hexes + 1).astype(np.int32)
        # side set 1 'ground': the bottom side (Exodus side 5) of the bottom layer's elements
        ground = np.arange(SHAPE[0] * SHAPE[1])  # the layer k = 0 comes first (i, then j, fastest)
        ds.createDimension("num_side_sets", 1)
        ds.createDimension("num_side_ss1", len(ground))
        ds.createVariable("ss_status", "i4", ("num_side_sets",))[:] = [1]
        ss_prop = ds.createVariable("ss_prop1", "i4", ("num_side_sets",))
        ss_prop.setncattr("name", "ID")
        ss_prop[:] = [1]
        text("ss_names", "num_side_sets", ["ground"])
        ds.createVariable("elem_ss1", "i4", ("num_side_ss1",))[:] = ground + 1
        ds.createVariable("side_ss1", "i4", ("num_side_ss1",))[:] = np.full(len(ground), 5)
        text("name_nod_var", "num_nod_var", names)
        t = ds.createVariable("time_whole", "f8", ("time_step",))
        var = [
            ds.createVariable(f"vals_nod_var{i + 1}", "f8", ("time_step", "num_nodes"))
            for i in range(len(names))
        ]
        p = _hertz(pts)
        for s in range(STEPS):
            t[s] = (s + 1) / STEPS
            for i, v in enumerate(var):
                v[s, :] = nodal_values(pts, p, i, (s + 1) / STEPS)
    finally:
        ds.close()


def write_surface_vtu(path: Path) -> None:
    from fepost.synthetic import write_map

    rings = int(60 * (1_000_000 / 24_000) ** 0.5)  # as bench_coefficients.py: 1.08 M nodes
    write_map(path, "hertz", radius=RADIUS, peak=PEAK, n_rings=rings)


BUILDERS = {
    "surface": ("surface.vtu", write_surface_vtu),
    "solver": ("solver.vtu", write_solver_vtu),
    "exodus": ("series.e", write_exodus),
    "exodus-ground": ("series.e", write_exodus),
}
#: fepost's further options per file kind
OPTIONS = {"exodus-ground": ["--surface", "ground"]}


def _current(path: Path) -> bool:
    """False for a benchmark file written before its present layout (then it is written again)."""
    if path.suffix != ".e":
        return True
    import netCDF4

    with netCDF4.Dataset(str(path)) as ds:
        return "num_side_sets" in ds.dimensions


def _tree_rss(pid: int) -> int:
    """Resident bytes of ``pid`` and its descendants (0 once gone)."""
    total, stack, page = 0, [pid], os.sysconf("SC_PAGE_SIZE")
    while stack:
        p = stack.pop()
        try:
            with open(f"/proc/{p}/statm", "rb") as fh:
                total += int(fh.read().split()[1]) * page
            with open(f"/proc/{p}/task/{p}/children", "rb") as fh:
                stack += [int(c) for c in fh.read().split()]
        except (OSError, ValueError):
            continue
    return total


def run(
    argv: list[str], pythonpath: str | None = None, cwd: Path | None = None
) -> tuple[float, float, float]:
    """Wall time (s) of a whole process, its sampled peak tree RSS (MB) and the CPU time (s, user
    + system) of it and the children it waited for (the reading child): on a machine shared with
    other work the CPU time moves much less than the wall time."""
    import resource

    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    peak = [0]
    t = time.perf_counter()
    # run from a neutral folder: with ``-m`` the working directory comes first on sys.path and
    # would decide which checkout's fepost is imported, whatever PYTHONPATH says
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, cwd=cwd)
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            peak[0] = max(peak[0], _tree_rss(proc.pid))
            done.wait(0.01)

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    _, err = proc.communicate()
    dt = time.perf_counter() - t
    done.set()
    th.join()
    if proc.returncode:
        raise SystemExit(f"{' '.join(argv)} failed ({proc.returncode}): {err.decode()[-500:]}")
    now = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = now.ru_utime + now.ru_stime - used.ru_utime - used.ru_stime
    return dt, peak[0] / 2**20, cpu


BREAKDOWN = r"""
import sys, time
t0 = time.perf_counter()
T = {}
def lap(name):
    global t0
    t = time.perf_counter(); T[name] = t - t0; t0 = t
from pathlib import Path
path = Path(sys.argv[1])
from fepost.cli import coefficients as cli
lap("parent: import fepost.cli")
from fepost.reader import isolate
from fepost.reader.contact import read_here
lap("parent: import fepost.reader")
def timed_read(p):
    s = {}
    t = time.perf_counter()
    if p.suffix == ".e":
        import netCDF4  # noqa: F401
    s["child: import netCDF4 (Exodus; VTK XML files need no library)"] = time.perf_counter() - t
    t = time.perf_counter()
    f = read_here(p, surface=sys.argv[2] if len(sys.argv) > 2 else None)
    s["child: read_here (check, select, read, arrays, surface)"] = time.perf_counter() - t
    return f, s, time.time()
pending = isolate.start(timed_read, path, what=str(path), nbytes=path.stat().st_size)
lap("parent: fork the reading child")
from fepost.analysis import _warm_up
from fepost.patch import build_patch
from fepost.resample import resample
from fepost.moments import moments
from fepost.polar import PolarGrid
from fepost.coefficients import coefficients_from_moments
from fepost.refine import refined_map
_warm_up()
lap("parent: import the pipeline (child reads meanwhile)")
from fepost.cli.coefficients import WARM_HEAP, warm_heap
warm_heap(min(WARM_HEAP, path.stat().st_size))
lap("parent: fault in the heap (child reads meanwhile)")
sf, child, sent = pending.result()
got = time.time()
lap("parent: wait for the child's answer")
from threadpoolctl import threadpool_limits
with threadpool_limits(limits=1, user_api="blas"):
    sp = build_patch(sf)
    lap("parent: patch")
    sm = resample(sp, PolarGrid.make(), radius=sp.r_max)
    lap("parent: resample")
    smo = moments(sm)
    sm, smo = refined_map(sp, sm, smo)
    lap("parent: moments, refinement check (fepost.refine)")
    coef = coefficients_from_moments(smo, None, friction=0.3)
    lap("parent: coefficients")
from fepost.analysis import Analysis
text = cli.format_analysis(Analysis(sf, sp, sm, smo, coef, None, None, None, None))
lap("parent: format the output (generalised model summary)")
for k, v in child.items():
    print(f"  {k:<58} {v:6.2f} s")
print(f"  {'transfer child -> parent (child sent .. parent has it)':<58} {got - sent:6.2f} s")
for k, v in T.items():
    print(f"  {k:<58} {v:6.2f} s")
print(f"  {'parent total after interpreter start':<58} {sum(T.values()):6.2f} s")
"""


def breakdown(path: Path, surface: str | None = None) -> None:
    """Where the time of one ``fepost coefficients``-like process goes (one run, stage by stage)."""
    t = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    start = time.perf_counter() - t
    print(f"breakdown of {path.name} (load {load()}):")
    print(f"  {'interpreter start (python -c pass)':<58} {start:6.2f} s")
    subprocess.run([sys.executable, "-c", BREAKDOWN, str(path), *([surface] if surface else [])], check=True)


def load() -> str:
    return ", ".join(f"{v:.1f}" for v in os.getloadavg())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", type=Path, required=True, help="folder of the generated files (reused)")
    ap.add_argument("--pairs", type=int, default=7)
    ap.add_argument("--files", default="surface,solver,exodus,exodus-ground")
    ap.add_argument("--breakdown", action="store_true", help="also time the stages of one run per file")
    ap.add_argument("--baseline", type=Path, help="another checkout whose fepost is timed in the same rounds")
    args = ap.parse_args()
    args.dir.mkdir(parents=True, exist_ok=True)
    import compileall

    import fepost

    compileall.compile_dir(Path(fepost.__file__).parent, quiet=2)  # as an installed package has it
    rows = []
    for key in args.files.split(","):
        name, build = BUILDERS[key]
        path = args.dir / name
        if not path.is_file() or not _current(path):
            t = time.perf_counter()
            build(path)
            print(
                f"wrote {path}: {path.stat().st_size / 1e6:.0f} MB in {time.perf_counter() - t:.0f} s",
                flush=True,
            )
        if args.breakdown:
            breakdown(path, "ground" if key == "exodus-ground" else None)
        bare = [sys.executable, "-c", f"import pyvista; pyvista.read({str(path)!r})"]
        ours = [sys.executable, "-m", "fepost", "coefficients", str(path), *OPTIONS.get(key, [])]
        before = load()
        tb, to, mb, mo, tbase, cb, co = [], [], [], [], [], [], []
        here = str(Path(__file__).resolve().parents[1])
        sides = [("bare", bare, None), ("ours", ours, here)]
        if args.baseline:
            sides.append(("base", ours, str(args.baseline)))
        for k in range(args.pairs):
            # the order rotates every round: bare, ours(, base); ours(, base), bare; ...
            for label, argv, pythonpath in sides[k % len(sides) :] + sides[: k % len(sides)]:
                dt, peak, cpu = run(argv, pythonpath, args.dir)
                if label == "bare":
                    tb.append(dt)
                    mb.append(peak)
                    cb.append(cpu)
                elif label == "ours":
                    to.append(dt)
                    mo.append(peak)
                    co.append(cpu)
                else:
                    tbase.append(dt)
        rows.append((key, tb, to, mb, mo, before, load(), cb, co))
        r = rows[-1]
        print(
            f"{key}: bare {statistics.median(tb):.2f} s, fepost {statistics.median(to):.2f} s, "
            f"ratio {statistics.median(to) / statistics.median(tb):.2f}; load {before} -> {r[6]}",
            flush=True,
        )
        if tbase:
            mbase = statistics.median(tbase)
            print(
                f"{key}: baseline {args.baseline} fepost {mbase:.2f} s, "
                f"ratio to bare {mbase / statistics.median(tb):.2f}; "
                f"this checkout / baseline {statistics.median(to) / mbase:.2f}",
                flush=True,
            )
    print()
    print(
        f"{'file':<13} {'bare read s':>12} {'fepost s':>9} {'ratio':>6} {'pair ratios':>24} "
        f"{'bare MB':>8} {'fepost MB':>9} {'mem ratio':>9} {'bare CPU':>8} {'fepost CPU':>10}"
        "  load before -> after"
    )
    for key, tb, to, mb, mo, before, after, cb, co in rows:
        pr = sorted(o / b for o, b in zip(to, tb, strict=True))
        print(
            f"{key:<13} {statistics.median(tb):12.2f} {statistics.median(to):9.2f} "
            f"{statistics.median(to) / statistics.median(tb):6.2f} {pr[0]:>11.2f} .. {pr[-1]:<10.2f} "
            f"{max(mb):8.0f} {max(mo):9.0f} {max(mo) / max(mb):9.2f} {statistics.median(cb):8.2f} "
            f"{statistics.median(co):10.2f}  {before} -> {after}"
        )
    print(
        f"medians of {args.pairs} alternating pairs (CPU: user + system s of the process tree); "
        "targets: surface <= 0.5, solver <= 0.17; "
        "exodus, exodus-ground <= 0.5; memory <= 1.0"
    )


if __name__ == "__main__":
    main()
