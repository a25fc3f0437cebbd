"""Accuracy and speed of the generalised friction model against the paper's closed forms.

For each reference map (uniform and Hertz ellipses, a tire-like rounded
rectangle with shoulders, an asymmetric rolling-like map) at aspects 1.0, 1.25,
1.5, 2.0, 2.5 and 3.0, and for the CalculiX samples in ``meshes/``, prints the
largest error over the whole kinematic sphere (sliding direction 0–180° in 5°
steps, 65 points uniform in t = (2/π)·atan ε from pure spin to pure sliding,
both spin signs) of

* ``paper``: the closed forms (1.8) with the map's F0, M0, a, m (and k_x),
* ``base``: the generalised model's base potential alone (its tensors, no fit),
* ``model``: the generalised model (base + the fitted correction),

as |ΔF|/F0 and |ΔM_z|/M0 against the exact Coulomb integrals, then the
evaluation speed (median of several alternating runs on 10⁶ random points) of
the closed forms and of the base, the default model and a 204-number model, each
by numpy and by the compiled kernel (`fepost.friction.kernel`, when numba is
installed). The machine may be shared: the load average is printed, and the
ratios (to the closed forms, numpy to kernel) are the stable figures. Run on one
core for the one-core figures:

``taskset -c 0 .venv/bin/python benchmarks/bench_model.py --speed-only``

Run: ``.venv/bin/python benchmarks/bench_model.py [--order K L] [--n-beta 37 --n-t 65]``
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from fepost.friction import kernel
from fepost.friction.accuracy import rolling_shift
from fepost.friction.build import build_model
from fepost.friction.closed_form import paper_coefficients, paper_model
from fepost.friction.law import FrictionLaw
from fepost.friction.quadrature import PressureQuadrature
from fepost.friction.reference_maps import asymmetric, ellipse_quad, tire_like
from fepost.friction.sphere import error_map
from fepost.friction.tensors import map_tensors

F = 0.3
LOAD = os.getloadavg()
ASPECTS = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0)
FAMILIES = {
    "uniform ellipse": lambda a: ellipse_quad("uniform", a),
    "Hertz ellipse": lambda a: ellipse_quad("hertz", a),
    "tire-like": lambda a: tire_like(a),
    "asymmetric rolling-like": lambda a: asymmetric(a),
}
MESHES = Path(__file__).resolve().parents[1] / "meshes"


def row(name, quad, paper, order, n_beta, n_t, radius=None, scales=None):
    law = FrictionLaw(f=F)
    t0 = time.perf_counter()
    model = build_model(quad, law, radius=radius, order=order, check=order == "auto")
    build = time.perf_counter() - t0
    F0, M0 = scales if scales is not None else (model.F0, model.M0)
    em = error_map(
        quad,
        {"paper": paper, "base": model.without_correction(), "model": model},
        law=law,
        F0=F0,
        M0=M0,
        R=model.R,
        n_beta=n_beta,
        n_t=n_t,
    )
    cells = [em.worst(k) for k in ("paper", "base", "model")]
    vals = " | ".join(f"{c['force']:.3f} | {c['torque']:.3f}" for c in cells)
    K, L = model.order
    print(f"| {name} | {vals} | {(2 * K + 1) * L} | {build:.2f} |", flush=True)
    return model


def reference_rows(order, n_beta, n_t):
    for family, make in FAMILIES.items():
        for aspect in ASPECTS:
            quad = make(aspect)
            k_x = rolling_shift(quad, quad.radius) if family.startswith("asym") else 0.0
            p = paper_coefficients(map_tensors(quad), F, k_x=k_x)
            row(f"{family}, aspect {aspect:g}", quad, paper_model(**p), order, n_beta, n_t)


def sample_rows(order, n_beta, n_t):
    from fepost.analysis import analyse

    static = MESHES / "static.vtu"
    if not static.is_file():
        print(f"(samples skipped: {static} not found)")
        return None
    model = None
    for case, rolling in (("static", None), ("rolling", MESHES / "rolling.vtu"), ("heavy", None)):
        src = MESHES / f"{case if case != 'rolling' else 'static'}.vtu"
        an = analyse(src, rolling, friction=F)
        c = an.coefficients
        pmap = an.rolling_map if rolling is not None else an.static_map
        quad = PressureQuadrature.from_polar(pmap)
        paper = paper_model(c.F0, c.M0, c.a, c.m, c.k_x or 0.0, c.R)
        aspect = an.static_patch.aspect
        m = row(
            f"CalculiX {case} (aspect {aspect:.2f})",
            quad,
            paper,
            order,
            n_beta,
            n_t,
            radius=c.R,
            scales=(c.F0, c.M0),
        )
        model = model or m
    return model


def speed(model, runs: int = 7, n: int = 1_000_000) -> None:
    """Evaluations per second on one thread: medians of ``runs`` alternating runs, by
    wall clock and by the process's CPU time (the second is less sensitive to other
    jobs on a shared machine, not to a busy sibling hyperthread)."""
    rng = np.random.default_rng(0)
    vx, vy = rng.normal(size=(2, n))
    wz = rng.normal(size=n) * 10.0
    reused = (np.empty(n), np.empty(n), np.empty(n))
    paper = paper_model(model.F0, model.M0, 1.0, 8.0, 0.1, model.R)
    big = build_model(ellipse_quad("uniform", 3.0), FrictionLaw(f=F), order=(8, 12), check=False)
    K, L = model.order
    cands = {"paper closed forms": paper}
    for label, m in (
        ("base", model.without_correction()),
        (f"model ({(2 * K + 1) * L} numbers)", model),
        ("model (204 numbers)", big),
    ):
        cands[f"{label}, numpy"] = lambda a, b, c, m=m: m.evaluate(a, b, c, backend="numpy")
        if kernel.AVAILABLE:
            m.evaluate(vx[:8192], vy[:8192], wz[:8192], backend="numba")  # compile (or load the cache)
            cands[f"{label}, numba kernel"] = lambda a, b, c, m=m: m.evaluate(a, b, c, backend="numba")
            if label != "base":  # as a simulation loop calls it: its output arrays reused
                cands[f"{label}, numba kernel, out="] = lambda a, b, c, m=m: m.evaluate(
                    a, b, c, backend="numba", out=reused
                )
    times: dict[str, list[float]] = {k: [] for k in cands}
    cpu: dict[str, list[float]] = {k: [] for k in cands}
    for _ in range(runs):
        for k, fn in cands.items():
            t0, c0 = time.perf_counter(), time.process_time()
            fn(vx, vy, wz)
            times[k].append(time.perf_counter() - t0)
            cpu[k].append(time.process_time() - c0)
    ref = float(np.median(times["paper closed forms"]))
    print(f"\nload average before/after: {LOAD[0]:.2f} / {os.getloadavg()[0]:.2f} ({os.cpu_count()} CPUs)")
    if not kernel.AVAILABLE:
        print("(numba not installed: no kernel rows; pip install fepost[fast])")
    print("| evaluator | median s per 10^6 points | evaluations/s (wall) | evaluations/s (CPU) ", end="")
    print("| time / closed forms |")
    print("|---|---|---|---|---|")
    for k, ts in times.items():
        med = float(np.median(ts))
        print(f"| {k} | {med:.3f} | {n / med:.3g} | {n / float(np.median(cpu[k])):.3g} | {med / ref:.2f} |")
    for label in ("base", f"model ({(2 * K + 1) * L} numbers)", "model (204 numbers)"):
        if kernel.AVAILABLE:
            r = float(np.median(times[f"{label}, numpy"]) / np.median(times[f"{label}, numba kernel"]))
            print(f"kernel speed-up, {label}: {r:.1f}x")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--order", type=int, nargs=2, metavar=("K", "L"), help="fixed correction order (default: auto)"
    )
    parser.add_argument("--n-beta", type=int, default=37)
    parser.add_argument("--n-t", type=int, default=65)
    parser.add_argument("--no-samples", action="store_true")
    parser.add_argument("--speed-only", action="store_true")
    args = parser.parse_args(argv)
    order = "auto" if args.order is None else tuple(args.order)
    print(f"generalised model order {order} ('auto': 72 correction numbers, more where needed); f = {F}")
    print("max over the sphere of |dF|/F0 and |dMz|/M0 (both spin signs)\n")
    print("| map | paper F | paper M | base F | base M | model F | model M | numbers | build s |")
    print("|---|---|---|---|---|---|---|---|---|")
    model = None
    if not args.speed_only:
        reference_rows(order, args.n_beta, args.n_t)
        if not args.no_samples:
            model = sample_rows(order, args.n_beta, args.n_t)
    if model is None or model.order != (4, 8):
        model = build_model(ellipse_quad("hertz", 2.0), FrictionLaw(f=F), order=(4, 8))
    speed(model)


if __name__ == "__main__":
    main()
