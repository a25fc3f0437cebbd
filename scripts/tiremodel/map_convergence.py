"""Mesh convergence of static maps on what ``fepost coefficients`` reports.

``python -m scripts.tiremodel.map_convergence COARSE.vtu FINE.vtu [--tol 0.02]`` runs
``fepost coefficients --json`` on both maps and prints, for N, the centre of pressure
(x, y), R = r_max, a, m, b, b1 and the peak contact pressure (the largest nodal CPRESS of
the map), the two values, the change from the coarse to the fine map (relative; the centre
in mm of its shift, against ``tol`` times R), and whether it is within ``tol``. Exit status
1 if any is not (0 with ``--exit-zero``).

R is r_max, the smallest circle about the centre that holds the support of the FE field
(THEORY section 1; fepost.patch): the farthest node of a face with a loaded node. Those faces
carry load out to their unloaded nodes (the field is linear on them), so R lies one element
beyond the farthest loaded node, and the contact's edge lies between the two: R moves with
the element size there, and a and m (which carry R) move with it, as R^-2 and R^2. The row
``r_loaded`` is the farthest loaded node itself (pressure above fepost's default threshold,
deformed coordinates, about the same centre): the edge's other bound. The rows ``a R^2`` and
``m / R^2`` are the coefficients without R (THEORY: "aR^2, m/R^2, k_x/R do not" change with R);
``area`` is the loaded area.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from fepost.patch import DEFAULT_THRESHOLD

QUANTITIES = ("N", "R", "a", "m", "b", "b1")
DERIVED = ("r_loaded", "a R^2", "m / R^2", "area")


def loaded_edge(mesh, centre) -> float:
    """The farthest node of a rig map (a meshio mesh with ``CPRESS`` and ``displacement``) whose
    pressure is above fepost's default threshold, from ``centre`` in the road plane (deformed, m)."""
    p = mesh.point_data["CPRESS"]
    xy = (mesh.points + mesh.point_data["displacement"])[:, :2] - np.asarray(centre[:2])
    return float(np.hypot(*xy[p > DEFAULT_THRESHOLD * p.max()].T).max())


def coefficients(path: Path) -> dict:
    """``fepost coefficients --json`` of one static map, with its peak CPRESS (Pa) added."""
    import meshio

    with tempfile.TemporaryDirectory(prefix="conv-") as tmp:
        out = Path(tmp) / "c.json"
        cmd = [sys.executable, "-m", "fepost", "coefficients", str(path), "--json", str(out)]
        subprocess.run(cmd, check=True, capture_output=True)
        c = json.loads(out.read_text())
    mesh = meshio.read(path)
    c["peak_pressure"] = float(mesh.point_data["CPRESS"].max())
    c["r_loaded"] = loaded_edge(mesh, c["patch"]["centre"])
    r = float(c["R"])
    c["a R^2"] = float(c["a"]) * r**2
    c["m / R^2"] = float(c["m"]) / r**2
    c["area"] = float(c["patch"]["area"])
    return c


def rows(coarse: dict, fine: dict, tol: float) -> list[tuple[str, float, float, float, bool]]:
    """(name, coarse, fine, change, within tol) for each quantity."""
    out = []
    for k in (*QUANTITIES, *DERIVED, "peak_pressure"):
        a, b = float(coarse[k]), float(fine[k])
        change = b / a - 1.0
        out.append((k, a, b, change, abs(change) <= tol))
    r = float(fine["R"])
    for i, axis in enumerate("xy"):
        # in mm to 1e-4 mm (a centre on the symmetry line is 0 to round-off, 1e-17 m)
        a, b = (round(1e3 * float(c["patch"]["centre"][i]), 4) + 0.0 for c in (coarse, fine))
        out.append((f"centre {axis} (mm)", a, b, (b - a) / (1e3 * r) + 0.0, abs(b - a) <= tol * 1e3 * r))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m scripts.tiremodel.map_convergence", description=__doc__)
    ap.add_argument("coarse", type=Path)
    ap.add_argument("fine", type=Path)
    ap.add_argument("--tol", type=float, default=0.02, help="relative tolerance (default 0.02)")
    ap.add_argument("--exit-zero", action="store_true", help="exit 0 even where a quantity is not within tol")
    args = ap.parse_args(argv)
    table = rows(coefficients(args.coarse), coefficients(args.fine), args.tol)
    print(f"{'quantity':<16} {'coarse':>12} {'fine':>12} {'change':>9}  within {args.tol:g}")
    for name, a, b, change, ok in table:
        print(f"{name:<16} {a:12.6g} {b:12.6g} {100 * change:+8.2f}%  {'yes' if ok else 'NO'}")
    print("(centre: change = shift / R)")
    return 0 if args.exit_zero or all(r[4] for r in table) else 1


if __name__ == "__main__":
    sys.exit(main())
