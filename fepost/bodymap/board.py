"""A flat base pressed by its weight on an elastic board, solved by CalculiX (``fepost map --fe``).

The model
---------
* **The block** is rigid (CalculiX ``*RIGID BODY``): one layer of elements
  over the base polygon, loaded by its weight m g at the centre of mass; it may
  sink and tilt, not slide or turn (its in-plane motion is held, which the
  frictionless contact could not resist). Statics then puts the centre of
  pressure at the centre of mass.
* **The board** is an elastic layer (isotropic, linear) of thickness t on a
  rigid table: its bottom is held vertically and is free to slide
  (frictionless), with in-plane rigid motion removed at two nodes. It covers the
  base polygon's bounding box and a margin of `MARGIN_THICKNESSES` × t around it,
  beyond which a thin layer's deflection has died out.
* **The contact** is frictionless node-to-surface penalty contact, the block's
  base the slave, the board's top the master; the penalty slope is
  `PENALTY_LAYERS` × E/t, so the contact's own give is 1 % of the layer's.
  The base is the slave because CalculiX writes CPRESS at the slave's nodes,
  each standing for its share of the slave's faces: with the board as the slave
  the loaded faces reached half an element beyond the base's edge (11 % of the
  load outside the base on 5 mm elements), with the base they are the base.

A rigid flat punch on an elastic layer carries more pressure at its edges than
inside (singular at the corner of a half-space; over about a thickness from the
edge on a thin layer), with the same load and centre of pressure as a uniform
pressure: that shape is the point of the model. On a mesh the edge peak is
bounded by the element size near the edge (`EDGE_SIZE`).

The board's properties come from the body file's ``board`` object when it has
one (``youngs_modulus`` Pa, ``poisson_ratio``, ``thickness`` m), else the
hardboard defaults `HARDBOARD`: E = 4 GPa (tempered hardboard, 3-5 GPa),
ν = 0.3, t = 3.2 mm (1/8 in sheet).

Mesh: gmsh (the optional ``model`` dependency) meshes the bounding box with the
polygon embedded, fine at the polygon's edges; the quadrangles are extruded
through the layer here (hexahedra, wedges where gmsh left a triangle).
The solve runs in a temporary folder that is removed afterwards; nothing is
cached. The map is the contact pressure (CPRESS) on the block's base as
CalculiX writes it, read by `fepost.reader.read_contact`, scaled to carry the
solver's total vertical reaction at the table (which equals m g to the solver's
precision): the nodal CPRESS interpolated linearly over the base's faces
carries 0.4-0.6 % more than the reaction (measured: factor 0.9957 on
the default model of the planar-sliding block, 0.9940 on a coarse one); the
factor is recorded (``cpress_scale``). A flat punch's pressure is singular at
its edge, so the peak depends on the mesh: on the default model of the block
(1.5 mm at the edges) the nodes on the edge carry 2.19 × the uniform pressure
on average, a corner node 9.1 ×, the 2 mm strip along the edges 1.51 × (11 %
of the load), the inside 0.94-0.97 ×; the element size at the edge stands for
the rounding of a real edge.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..body import Body
from ..errors import ArgumentError, DataError, InputFileError
from .maps import BodyMap, common_info
from .mesh import linear_load, triangle_areas

#: The hardboard defaults (module docstring).
HARDBOARD = {"youngs_modulus": 4.0e9, "poisson_ratio": 0.3, "thickness": 0.0032}
#: The board's margin around the base's bounding box, in board thicknesses.
MARGIN_THICKNESSES = 4.0
#: Penalty slope of the contact, in units of the layer's stiffness E/t per area.
PENALTY_LAYERS = 100.0
#: Element size at the base polygon's edges and far from them, m; layers through the board.
EDGE_SIZE = 0.0015
FAR_SIZE = 0.006
LAYERS = 3
#: Longest a solve may take, s.
TIMEOUT = 600


@dataclass(frozen=True)
class Board:
    """The elastic board: Young's modulus (Pa), Poisson's ratio, thickness (m)."""

    youngs_modulus: float
    poisson_ratio: float
    thickness: float

    @classmethod
    def of(cls, body: Body) -> Board:
        """The body file's ``board`` object over the `HARDBOARD` defaults (checked)."""
        given = body.extra.get("board", {})
        if not isinstance(given, dict):
            raise DataError(f"{body.path}: key 'board' must be an object, got {given!r}")
        unknown = sorted(set(given) - set(HARDBOARD))
        if unknown:
            raise DataError(f"{body.path}: key 'board.{unknown[0]}' is unknown ({', '.join(HARDBOARD)})")
        vals = {}
        for key, default in HARDBOARD.items():
            v = given.get(key, default)
            if isinstance(v, bool) or not isinstance(v, int | float) or not np.isfinite(v):
                raise DataError(f"{body.path}: key 'board.{key}' must be a finite number, got {v!r}")
            vals[key] = float(v)
        if vals["youngs_modulus"] <= 0 or vals["thickness"] <= 0:
            raise DataError(f"{body.path}: the board's youngs_modulus and thickness must be positive")
        if not -1.0 < vals["poisson_ratio"] < 0.5:
            raise DataError(f"{body.path}: key 'board.poisson_ratio' must lie in (-1, 0.5)")
        return cls(**vals)


@dataclass(frozen=True)
class Mesh2D:
    """The plane mesh: nodes (n, 2), quads (q, 4) and triangles (t, 3), counter-clockwise,
    and for each element whether it lies in the base polygon."""

    xy: np.ndarray
    quads: np.ndarray
    tris: np.ndarray
    quad_in: np.ndarray
    tri_in: np.ndarray


def plane_mesh(polygon: np.ndarray, *, margin: float, edge: float, far: float) -> Mesh2D:
    """Mesh the polygon's bounding box grown by ``margin`` with gmsh, the polygon embedded."""
    try:
        import gmsh
    except ImportError:
        raise ArgumentError("fepost map --fe needs gmsh (pip install 'fepost[model]')") from None
    lo, hi = polygon.min(axis=0) - margin, polygon.max(axis=0) + margin
    gmsh.initialize(readConfigFiles=False, interruptible=False)  # the CLI keeps its signal handlers
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("board")
        geo = gmsh.model.geo
        box = [
            geo.addPoint(x, y, 0.0)
            for x, y in ((lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1]))
        ]
        poly = [geo.addPoint(float(x), float(y), 0.0) for x, y in polygon]
        box_lines = [geo.addLine(box[i], box[(i + 1) % 4]) for i in range(4)]
        poly_lines = [geo.addLine(poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly))]
        outer, inner = geo.addCurveLoop(box_lines), geo.addCurveLoop(poly_lines)
        s_in = geo.addPlaneSurface([inner])
        s_out = geo.addPlaneSurface([outer, inner])
        geo.synchronize()
        dist = gmsh.model.mesh.field.add("Distance")
        gmsh.model.mesh.field.setNumbers(dist, "CurvesList", poly_lines)
        gmsh.model.mesh.field.setNumber(dist, "Sampling", 200)
        thr = gmsh.model.mesh.field.add("Threshold")
        for name, value in (("InField", dist), ("SizeMin", edge), ("SizeMax", far)):
            gmsh.model.mesh.field.setNumber(thr, name, value)
        gmsh.model.mesh.field.setNumber(thr, "DistMin", 0.5 * edge)
        gmsh.model.mesh.field.setNumber(thr, "DistMax", 6.0 * far)
        gmsh.model.mesh.field.setAsBackgroundMesh(thr)
        for name, value in (
            ("Mesh.MeshSizeExtendFromBoundary", 0),
            ("Mesh.MeshSizeFromPoints", 0),
            ("Mesh.MeshSizeFromCurvature", 0),
            ("Mesh.RecombineAll", 1),
            ("Mesh.Algorithm", 8),
        ):
            gmsh.option.setNumber(name, value)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        xy = np.asarray(coords, float).reshape(-1, 3)[:, :2]
        index = {int(t): i for i, t in enumerate(tags)}
        parts = {}
        for s in (s_in, s_out):
            types, _, nodes = gmsh.model.mesh.getElements(2, s)
            for t, conn in zip(types, nodes, strict=True):
                k = 3 if t == 2 else 4
                arr = np.array([index[int(n)] for n in conn], dtype=np.int64).reshape(-1, k)
                parts[(s == s_in, k)] = arr
    finally:
        gmsh.finalize()
    return _oriented(xy, parts)


def _oriented(xy: np.ndarray, parts: dict) -> Mesh2D:
    quads: list = []
    tris: list = []
    quad_in: list = []
    tri_in: list = []
    for (inside, k), conn in parts.items():
        flip = triangle_areas(xy, conn) < 0  # the first three corners' turn
        conn = np.where(flip[:, None], conn[:, ::-1], conn)
        (quads if k == 4 else tris).append(conn)
        (quad_in if k == 4 else tri_in).append(np.full(len(conn), inside))
    cat = lambda parts_, k: np.vstack(parts_) if parts_ else np.zeros((0, k), np.int64)  # noqa: E731
    flags = lambda parts_: np.concatenate(parts_) if parts_ else np.zeros(0, bool)  # noqa: E731
    return Mesh2D(xy, cat(quads, 4), cat(tris, 3), flags(quad_in), flags(tri_in))


@dataclass(frozen=True)
class Solid:
    """The extruded model: nodes (n, 3); board and block elements as (type, connectivity) lists."""

    nodes: np.ndarray
    board: list
    block: list
    bottom: np.ndarray  # board nodes on the table (0-based)
    n_top: int  # elements in the board's top layer


def extrude(m: Mesh2D, *, thickness: float, layers: int, block_height: float) -> Solid:
    """The board (``layers`` element layers from z = −``thickness`` to 0) and the block (one layer
    from 0 to ``block_height`` over the polygon's elements, nodes of its own)."""
    n = len(m.xy)
    zs = np.linspace(-thickness, 0.0, layers + 1)
    planes = [np.column_stack([m.xy, np.full(n, z)]) for z in zs]
    used = np.unique(np.concatenate([m.quads[m.quad_in].ravel(), m.tris[m.tri_in].ravel()]))
    block_of = np.full(n, -1, np.int64)
    block_of[used] = np.arange(used.size)
    base = (layers + 1) * n
    block_nodes = [np.column_stack([m.xy[used], np.full(used.size, z)]) for z in (0.0, block_height)]
    nodes = np.vstack(planes + block_nodes)
    board = []
    for k in range(layers):
        lo, up = k * n, (k + 1) * n
        board.append(("C3D8", np.hstack([m.quads + lo, m.quads + up])))
        board.append(("C3D6", np.hstack([m.tris + lo, m.tris + up])))
    b0, b1 = base, base + used.size
    q, t = block_of[m.quads[m.quad_in]], block_of[m.tris[m.tri_in]]
    block = [("C3D8", np.hstack([q + b0, q + b1])), ("C3D6", np.hstack([t + b0, t + b1]))]
    keep = lambda groups: [g for g in groups if len(g[1])]  # noqa: E731
    return Solid(nodes, keep(board), keep(block), np.arange(n), len(m.quads) + len(m.tris))


def _lines(values, per: int = 10) -> list[str]:
    vals = [str(int(v)) for v in values]
    return [", ".join(vals[i : i + per]) for i in range(0, len(vals), per)]


def deck(solid: Solid, *, board: Board, weight: float, com, penalty: float) -> str:
    """The CalculiX input deck (1-based numbering; the rigid body's two extra nodes last)."""
    nn = len(solid.nodes)
    ref, rot = nn + 1, nn + 2
    out = ["*HEADING", "fepost map --fe: a rigid flat base on an elastic board", "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {x:.12e}, {y:.12e}, {z:.12e}" for i, (x, y, z) in enumerate(solid.nodes)]
    out += [f"{ref}, {com[0]:.12e}, {com[1]:.12e}, 0.0", f"{rot}, {com[0]:.12e}, {com[1]:.12e}, 0.0"]
    number = 1
    for elset, groups in (("BOARD", solid.board), ("BLOCK", solid.block)):
        for etype, conn in groups:
            out.append(f"*ELEMENT, TYPE={etype}, ELSET={elset}")
            out += [f"{number + i}, " + ", ".join(str(int(v) + 1) for v in row) for i, row in enumerate(conn)]
            number += len(conn)
    n_board = sum(len(c) for _, c in solid.board)
    # the board's elements go layer by layer: the top layer's are the last n_top
    faces = {
        "SBOARD": [f"{e}, S2" for e in range(n_board - solid.n_top + 1, n_board + 1)],
        "SBLOCK": [f"{e}, S1" for e in range(n_board + 1, number)],
    }
    out += ["*NSET, NSET=BOTTOM", *_lines(solid.bottom + 1)]
    out += ["*NSET, NSET=REF", str(ref), "*NSET, NSET=ROT", str(rot)]
    for name, rows in faces.items():
        out += [f"*SURFACE, NAME={name}, TYPE=ELEMENT", *rows]
    out += [
        "*MATERIAL, NAME=BOARDMAT",
        "*ELASTIC",
        f"{board.youngs_modulus:.6e}, {board.poisson_ratio:.6g}",
        "*MATERIAL, NAME=BLOCKMAT",
        "*ELASTIC",
        "2.1e11, 0.3",
        "*SOLID SECTION, ELSET=BOARD, MATERIAL=BOARDMAT",
        "*SOLID SECTION, ELSET=BLOCK, MATERIAL=BLOCKMAT",
        f"*RIGID BODY, ELSET=BLOCK, REF NODE={ref}, ROT NODE={rot}",
        "*SURFACE INTERACTION, NAME=SI",
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
        f"{penalty:.6e}",
        "*CONTACT PAIR, INTERACTION=SI, TYPE=NODE TO SURFACE",
        "SBLOCK, SBOARD",
        "*BOUNDARY",
        "BOTTOM, 3, 3",
        f"{solid.bottom[0] + 1}, 1, 2",
        f"{_second_fix(solid) + 1}, 2, 2",
        "REF, 1, 2",
        "ROT, 3, 3",
        "*STEP",
        "*STATIC",
        "1.0, 1.0",
        "*CLOAD",
        f"REF, 3, {-weight:.12e}",
        "*NODE PRINT, NSET=BOTTOM, TOTALS=ONLY",
        "RF",
        "*CONTACT FILE",
        "CSTR",
        "*END STEP",
    ]
    return "\n".join(out) + "\n"


def _second_fix(solid: Solid) -> int:
    """A bottom node far from the first along x: holding its y stops the board turning."""
    xy = solid.nodes[solid.bottom, :2]
    return int(solid.bottom[int(np.argmax(np.hypot(*(xy - xy[0]).T)))])


def solve(deck_text: str, folder: Path, *, timeout: float = TIMEOUT) -> tuple[Path, float]:
    """Run CalculiX on ``deck_text`` in ``folder``: the ``.frd`` and the table's total vertical
    reaction (N)."""
    ccx = shutil.which("ccx")
    if ccx is None:
        raise ArgumentError("fepost map --fe needs the CalculiX solver 'ccx' on PATH")
    (folder / "board.inp").write_text(deck_text)
    env = {**os.environ, "OMP_NUM_THREADS": os.environ.get("OMP_NUM_THREADS", "1")}
    try:
        run = subprocess.run(
            [ccx, "-i", "board"], cwd=folder, capture_output=True, text=True, timeout=timeout, env=env
        )
    except subprocess.TimeoutExpired:
        raise InputFileError(f"CalculiX did not finish the board model within {timeout:g} s") from None
    frd, dat = folder / "board.frd", folder / "board.dat"
    text = dat.read_text(errors="replace") if dat.is_file() else ""
    if run.returncode != 0 or not frd.is_file() or "total force" not in text:
        tail = " ".join((run.stdout + run.stderr).split()[-30:])
        raise InputFileError(f"CalculiX failed on the board model (exit {run.returncode}): ...{tail}")
    return frd, _total_reaction(text)


_TOTAL = re.compile(
    r"total force \(fx,fy,fz\) for set BOTTOM.*?\n\s*\n?\s*(\S+)\s+(\S+)\s+(\S+)", re.S | re.I
)


def _total_reaction(dat: str) -> float:
    """The last total vertical reaction of node set BOTTOM in a CalculiX ``.dat`` (N)."""
    found = _TOTAL.findall(dat)
    if not found:
        raise InputFileError("CalculiX's .dat holds no total reaction of the board's bottom")
    return float(found[-1][2])


def board_map(
    body: Body,
    *,
    edge: float | None = None,
    far: float | None = None,
    layers: int | None = None,
    timeout: float | None = None,
) -> BodyMap:
    """The base's contact pressure on an elastic board, solved by CalculiX (module docstring).

    Parameters
    ----------
    body : Body
        A body on a flat base (`fepost.body.load_body`).
    edge, far : float, optional
        Element sizes (m) at the base's edges and away from them (default `EDGE_SIZE`, `FAR_SIZE`).
    layers : int, optional
        Element layers through the board's thickness (default `LAYERS`).
    timeout : float, optional
        Longest the solve may take (s; default `TIMEOUT`).

    Returns
    -------
    BodyMap
        Kind ``"board"``: the CPRESS CalculiX writes on the board's top, map frame;
        ``info["reaction_z"]`` is the solver's total vertical reaction at the table.
    """
    from ..reader import read_contact

    if body.base is None:
        raise ArgumentError(
            f"{body.path}: --fe models a flat base on an elastic board; this body has point supports"
        )
    board = Board.of(body)
    t = board.thickness
    edge = EDGE_SIZE if edge is None else edge
    far = FAR_SIZE if far is None else far
    layers = LAYERS if layers is None else layers
    timeout = TIMEOUT if timeout is None else timeout
    poly = np.asarray(body.base, float) - np.asarray(body.reference_point, float)
    com = np.asarray(body.centre_of_mass, float) - np.asarray(body.reference_point, float)
    plane = plane_mesh(poly, margin=MARGIN_THICKNESSES * t, edge=edge, far=far)
    solid = extrude(plane, thickness=t, layers=layers, block_height=max(t, edge))
    penalty = PENALTY_LAYERS * board.youngs_modulus / t
    text = deck(solid, board=board, weight=body.weight, com=com, penalty=penalty)
    folder = Path(tempfile.mkdtemp(prefix="fepost-board-"))
    try:
        frd, reaction = solve(text, folder, timeout=timeout)
        fld = read_contact(frd, displacement=None)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    xy, tri, raw = _map_faces(fld)
    raw_load, _ = linear_load(xy, tri, raw)
    p = raw * (reaction / raw_load)  # the load the solver's reaction says (module docstring)
    load, first = linear_load(xy, tri, p)
    info = common_info(body, "flat base on an elastic board (CalculiX)")
    info.update(
        reaction_z=reaction,
        reaction_source="CalculiX: total vertical reaction of the table under the board",
        board={**board.__dict__, "penalty_slope": penalty, "margin": MARGIN_THICKNESSES * t},
        mesh={"edge_size": edge, "far_size": far, "layers": layers, "nodes": int(len(solid.nodes))},
        uniform_pressure=body.weight / body.base_area(),
        cpress_scale=reaction / raw_load,
    )
    return BodyMap("board", xy, tri, p, load, (float(first[0] / load), float(first[1] / load)), info)


def _map_faces(fld) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The loaded faces of the read field as triangles (quads split along a diagonal), in the plane."""
    if fld.location != "point":
        raise InputFileError(f"{fld.source}: expected nodal contact pressure from CalculiX")
    tris = [np.asarray(fld.triangles)]
    quads = np.asarray(fld.faces.get("quad4", np.zeros((0, 4), np.int64)))
    tris += [quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]
    tri = np.vstack(tris)
    p = np.clip(np.asarray(fld.values, float), 0.0, None)
    z = np.asarray(fld.points)[:, 2]
    flat = np.all(
        np.abs(z[tri]) <= 1e-9 * np.ptp(np.asarray(fld.points)[:, :2]), axis=1
    )  # the base, not its sides
    keep = flat & np.any(p[tri] > 0, axis=1)
    tri = tri[keep]
    used = np.unique(tri)
    remap = np.full(len(fld.points), -1, np.int64)
    remap[used] = np.arange(used.size)
    return np.asarray(fld.points)[used, :2], remap[tri], p[used]
