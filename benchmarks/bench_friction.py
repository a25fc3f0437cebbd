"""Speed and accuracy of the exact friction integrals (fepost.friction.exact).

Times ``friction_resultants`` for 1,000 random kinematic points (half with the
instantaneous centre of rotation inside the patch, half outside, a few pure
sliding and pure spin) on the default friction grid, before and after in one
run: the numpy node sums (``backend="numpy"``, the implementation before the
compiled one) and the compiled node sums (``backend="numba"``,
`fepost.friction.nodesums`), medians of alternating runs; and compares both with
a fine grid. Errors are relative to the natural scales: |ΔF|/(fN) for Fx, Fy and
|ΔM_z|/M0 with M0 = f∬σ r dA, the pure-spin torque; ``numpy-numba`` is the
largest difference between the two paths on the same grid (round-off).

A second table times what ``fepost coefficients`` spends on friction, the build of the
generalised model of one map (fit grid 32 x 24 and check grid 32 x 33 of exact values,
`fepost.friction.build.build_model`), with the turned sums of `fepost.friction.turns`
and with every point summed directly (the code before), alternating, and gives the
largest difference of the two paths' exact values on the check grid (round-off).

Run: ``.venv/bin/python benchmarks/bench_friction.py [--points 1000] [--nr 32 --nphi 64] [--threads 1]``
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from fepost.analytic import pressure_function
from fepost.friction import build, nodesums, turns
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import FRICTION_NPHI, FRICTION_NR, PressureQuadrature, edge_grid
from fepost.polar import PolarMap

RADIUS = 0.1  # m


def kinematics(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random (vx, vy, wz): ICR at distance ~U(0, 2)·R in a random direction."""
    wz = rng.choice([-1.0, 1.0], n) * rng.uniform(0.5, 20.0, n)  # rad/s
    dist = RADIUS * np.concatenate([rng.uniform(0.0, 1.0, n // 2), rng.uniform(1.0, 3.0, n - n // 2)])
    ang = rng.uniform(0.0, 2.0 * np.pi, n)
    p0x, p0y = dist * np.cos(ang), dist * np.sin(ang)
    vx, vy = wz * p0y, -wz * p0x  # p0 = (−vy/ω, vx/ω)
    wz[:10] = 0.0  # pure sliding
    vx[10:20] = vy[10:20] = 0.0  # pure spin about the origin
    return vx, vy, wz


def quadrature(profile: str, nr: int, nphi: int, k_x: float) -> PressureQuadrature:
    fn = pressure_function(profile, RADIUS, peak=2e5, k_x=k_x)
    return PressureQuadrature.from_polar(PolarMap.from_function(fn, RADIUS, edge_grid(nr, nphi)))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1000)
    parser.add_argument("--nr", type=int, default=FRICTION_NR)
    parser.add_argument("--nphi", type=int, default=FRICTION_NPHI)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--threads", type=int, default=None, help="worker threads (default: CPU count)")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    vx, vy, wz = kinematics(args.points, rng)
    law = FrictionLaw(f=0.8)
    backends = ("numpy", "numba") if nodesums.AVAILABLE else ("numpy",)
    load = os.getloadavg()[0]
    print(
        f"{args.points} kinematic points, grid {args.nr}x{args.nphi} (sine radial rule), "
        f"reference grid 256x512; threads {args.threads or os.cpu_count()}; medians of {args.runs}"
    )
    if not nodesums.AVAILABLE:
        print("(numba not installed: numpy node sums only; pip install fepost[fast])")
    head = "".join(f"{'s, ' + b:>14}{'cpu s':>8}" for b in backends)
    cols = f"{'speed-up':>10}{'max |dF|/fN':>13}{'max |dM|/M0':>13}{'numpy-numba':>13}{'inside':>8}"
    print(f"{'map':<16}{head}{cols}")
    for profile, k_x in (
        ("hertz", 0.0),
        ("hertz", 0.13),
        ("tire", 0.0),
        ("uniform", 0.0),
        ("paraboloid", 0.0),
    ):
        quad = quadrature(profile, args.nr, args.nphi, k_x)
        fine = quadrature(profile, 256, 512, k_x)
        times: dict[str, list[float]] = {b: [] for b in backends}
        cpu: dict[str, list[float]] = {b: [] for b in backends}
        res = {}
        for b in backends:
            friction_resultants(quad, vx[:8], vy[:8], wz[:8], law, backend=b)  # warm up (numba: compile)
        for _ in range(args.runs):
            for b in backends:
                t0, c0 = time.perf_counter(), time.process_time()
                res[b] = friction_resultants(quad, vx, vy, wz, law, backend=b, threads=args.threads)
                times[b].append(time.perf_counter() - t0)
                cpu[b].append(time.process_time() - c0)
        ref = friction_resultants(fine, vx, vy, wz, law)
        fn = law.f * fine.load
        m0 = law.f * float(fine.sigma @ (np.hypot(fine.x, fine.y) * fine.dA))
        last = res[backends[-1]]
        dF = max(np.max(np.abs(last.Fx - ref.Fx)), np.max(np.abs(last.Fy - ref.Fy))) / fn
        dM = np.max(np.abs(last.Mz - ref.Mz)) / m0
        med = {b: float(np.median(t)) for b, t in times.items()}
        up = med["numpy"] / med[backends[-1]]
        same = 0.0
        if len(backends) == 2:
            a, c = res["numpy"], res["numba"]
            same = max(
                float(np.max(np.abs(a.Fx - c.Fx))) / fn,
                float(np.max(np.abs(a.Fy - c.Fy))) / fn,
                float(np.max(np.abs(a.Mz - c.Mz))) / m0,
            )
        inside = np.count_nonzero(np.hypot(vx, vy) < np.abs(wz) * RADIUS)
        cells = "".join(f"{med[b]:>14.3f}{float(np.median(cpu[b])):>8.3f}" for b in backends)
        name = f"{profile} k={k_x:g}"
        print(f"{name:<16}{cells}{up:>10.1f}{dF:>13.2e}{dM:>13.2e}{same:>13.1e}{inside:>8d}")
    print(f"load average before/after: {load:.2f} / {os.getloadavg()[0]:.2f} ({os.cpu_count()} CPUs)")
    print()
    model_builds(args)


def model_builds(args: argparse.Namespace) -> None:
    """Model builds with the turned sums and with direct sums, alternating (second table)."""
    load = os.getloadavg()[0]
    law = FrictionLaw(f=0.3)
    layout = turns.polar_layout
    print(f"model build, order (4, 8): grid {args.nr}x{args.nphi}; medians of {args.runs} alternating runs")
    print(f"{'map':<16}{'turned s':>10}{'direct s':>10}{'speed-up':>10}{'turned-direct':>15}")
    for profile, k_x in (("hertz", 0.0), ("hertz", 0.13), ("tire", 0.0)):
        quad = quadrature(profile, args.nr, args.nphi, k_x)
        times: dict[str, list[float]] = {"turned": [], "direct": []}
        for _ in range(args.runs):
            for name in ("turned", "direct"):
                turns.polar_layout = layout if name == "turned" else (lambda q, n: None)
                t0 = time.perf_counter()
                build.build_model(quad, law, order=(4, 8))
                times[name].append(time.perf_counter() - t0)
        turns.polar_layout = layout
        nodes, _ = np.polynomial.legendre.leggauss(build.CHECK_GRID[1])
        vx, vy, u, _, _ = build.sphere_nodes(build.CHECK_GRID[0], 0.5 * (nodes + 1.0))
        wz = u / quad.radius
        a = friction_resultants(quad, vx, vy, wz, law, turns=build.CHECK_GRID[0])
        b = friction_resultants(quad, vx, vy, wz, law)
        m0 = law.f * float(quad.sigma @ (np.hypot(quad.x, quad.y) * quad.dA))
        diff = max(
            float(np.max(np.hypot(a.Fx - b.Fx, a.Fy - b.Fy))) / (law.f * quad.load),
            float(np.max(np.abs(a.Mz - b.Mz))) / m0,
        )
        t, d = float(np.median(times["turned"])), float(np.median(times["direct"]))
        print(f"{profile + f' k={k_x:g}':<16}{t:>10.3f}{d:>10.3f}{d / t:>10.1f}{diff:>15.1e}")
    print(f"load average before/after: {load:.2f} / {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
