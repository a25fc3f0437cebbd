"""Check the rubber elements: does a nearly incompressible Neo-Hooke C3D8I lock?

A cantilever of the tread rubber (Neo-Hooke, shear modulus G, bulk modulus K)
with one element through half its depth (as coarse as the tire's tread) is
loaded by a small tip force; its tip deflection is compared with Timoshenko's
beam (E = 9KG/(3K+G), shear coefficient 5/6). Volumetric or shear locking shows
as a deflection far below the beam's. Cases: C3D8I, C3D8 and C3D8R (reduced
integration with CalculiX's hourglass control, the whole tire's band on ``whole-fine-r``),
K/G = 100 (the tire model) and 1000.

Run: ``python -m scripts.tiremodel check-elements`` (a few seconds per case).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from .frd import read_frd
from .solve import ModelError, find_ccx, run_ccx

LENGTH, DEPTH, WIDTH = 0.20, 0.02, 0.02  # m
NX, NY, NZ = 20, 2, 2
SHEAR = 1.5e6  # Pa, tread rubber
TIP_FORCE = 0.05  # N, small: the linear range of the hyperelastic law


def _deck(path: Path, etype: str, bulk: float) -> int:
    xs = np.linspace(0, LENGTH, NX + 1)
    ys = np.linspace(0, WIDTH, NY + 1)
    zs = np.linspace(0, DEPTH, NZ + 1)

    def nid(i, j, k):
        return 1 + i + (NX + 1) * (j + (NY + 1) * k)

    lines = ["*NODE, NSET=NALL"]
    for k, z in enumerate(zs):
        for j, y in enumerate(ys):
            for i, x in enumerate(xs):
                lines.append(f"{nid(i, j, k)}, {x:.9e}, {y:.9e}, {z:.9e}")
    lines.append(f"*ELEMENT, TYPE={etype}, ELSET=EALL")
    e = 0
    for k in range(NZ):
        for j in range(NY):
            for i in range(NX):
                e += 1
                n = [
                    nid(i, j, k),
                    nid(i + 1, j, k),
                    nid(i + 1, j + 1, k),
                    nid(i, j + 1, k),
                    nid(i, j, k + 1),
                    nid(i + 1, j, k + 1),
                    nid(i + 1, j + 1, k + 1),
                    nid(i, j + 1, k + 1),
                ]
                lines.append(f"{e}, " + ", ".join(map(str, n)))
    fixed = [nid(0, j, k) for j in range(NY + 1) for k in range(NZ + 1)]
    tip = [nid(NX, j, k) for j in range(NY + 1) for k in range(NZ + 1)]
    lines += ["*NSET, NSET=FIX", ", ".join(map(str, fixed)), "*NSET, NSET=TIP", ", ".join(map(str, tip))]
    lines += [
        "*MATERIAL, NAME=RUBBER",
        "*HYPERELASTIC, NEO HOOKE",
        f"{SHEAR / 2:.6e}, {2.0 / bulk:.6e}",
        "*SOLID SECTION, ELSET=EALL, MATERIAL=RUBBER",
        "*BOUNDARY",
        "FIX, 1, 3",
        "*STEP, NLGEOM",
        "*STATIC",
        "1.0, 1.0",
        "*CLOAD",
    ]
    lines += [f"{n}, 3, {-TIP_FORCE / len(tip):.9e}" for n in tip]
    lines += ["*NODE FILE", "U", "*END STEP"]
    path.write_text("\n".join(lines) + "\n")
    return nid(NX, NY // 2, NZ // 2)


def timoshenko_tip(bulk: float) -> float:
    """Tip deflection (m) of the Timoshenko cantilever for the same load."""
    e_mod = 9.0 * bulk * SHEAR / (3.0 * bulk + SHEAR)
    inertia = WIDTH * DEPTH**3 / 12.0
    area = WIDTH * DEPTH
    return TIP_FORCE * LENGTH**3 / (3 * e_mod * inertia) + TIP_FORCE * LENGTH / (5.0 / 6.0 * SHEAR * area)


def check(etype: str, bulk_ratio: float) -> tuple[float, float]:
    """(FE tip deflection, Timoshenko tip deflection), m."""
    exe = find_ccx()
    bulk = bulk_ratio * SHEAR
    with tempfile.TemporaryDirectory(prefix="tiremodel-check-") as tmp:
        inp = Path(tmp) / "beam.inp"
        node = _deck(inp, etype, bulk)
        try:
            run_ccx(exe, inp, threads=1, timeout=600, niceness=10)
        except ModelError as exc:
            raise ModelError(f"ccx beam check ({etype}, K/G = {bulk_ratio:g}) failed: {exc}") from exc
        res = read_frd(inp.with_suffix(".frd"))
        _, u = res.field(max(res.last), "U")
        row = int(np.flatnonzero(res.node_ids == node)[0])
        return float(-u[row, 2]), timoshenko_tip(bulk)


def main() -> int:
    print("element  K/G    FE tip (mm)  Timoshenko (mm)  ratio")
    for etype in ("C3D8I", "C3D8", "C3D8R"):
        for ratio in (100.0, 1000.0):
            fe, beam = check(etype, ratio)
            print(f"{etype:7s} {ratio:6.0f}   {1e3 * fe:10.4f}   {1e3 * beam:14.4f}   {fe / beam:5.3f}")
    return 0
