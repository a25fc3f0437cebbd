"""Convergence study behind the default polar grid (README, "Accuracy").

For FE maps the polar quadrature integrates the FE interpolant, so its error is
measured against the exact integral over the FE faces (N_fe) and, for the
moments, against a 512 x 1024 Gauss grid. Prints one row per grid size.

    .venv/bin/python benchmarks/bench_grid.py [--mesh meshes/static.vtu]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from fepost.coefficients import coefficients_from_moments
from fepost.moments import moments
from fepost.patch import build_patch
from fepost.polar import PolarGrid
from fepost.reader import read_contact
from fepost.resample import resample
from fepost.synthetic import write_map


def study(path: Path) -> None:
    patch = build_patch(read_contact(path))
    ref_grid = PolarGrid.make(512, 1024)
    ref = coefficients_from_moments(moments(resample(patch, ref_grid, radius=patch.r_max)))
    print(f"\n{path.name}: {len(patch.xy):,} nodes, N_fe = {patch.N_fe:.6g} N, R = {patch.r_max:.4g} m")
    print(
        f"{'rule':>9} {'nr x nphi':>10} {'N/N_fe-1':>10} {'M0 err':>9} "
        f"{'a err':>9} {'m err':>9} {'time s':>7}"
    )
    for rule in ("trapezoid", "gauss"):
        for nr in (16, 32, 64, 128, 256):
            g = PolarGrid.make(nr + (rule == "trapezoid"), 2 * nr, rule)
            t = time.perf_counter()
            c = coefficients_from_moments(moments(resample(patch, g, radius=patch.r_max)))
            dt = time.perf_counter() - t
            e = [abs(getattr(c, k) / getattr(ref, k) - 1) for k in ("M0", "a", "m")]
            print(
                f"{rule:>9} {nr:>4} x {2 * nr:<4} {c.N / patch.N_fe - 1:>+10.1e} "
                f"{e[0]:>9.1e} {e[1]:>9.1e} {e[2]:>9.1e} {dt:>7.3f}"
            )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", type=Path, action="append", help="FE export(s) to study")
    args = ap.parse_args()
    meshes = args.mesh or []
    with tempfile.TemporaryDirectory() as tmp:
        if not meshes:
            meshes = [write_map(Path(tmp) / "hertz.vtu", "hertz", radius=0.1, n_rings=60)]
            sample = Path(__file__).resolve().parents[1] / "meshes" / "static.vtu"
            if sample.is_file():
                meshes.append(sample)
        for m in meshes:
            study(Path(m))
    np.set_printoptions()


if __name__ == "__main__":
    main()
