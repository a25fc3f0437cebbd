"""Real pushes of a block that slides and spins: fepost's models, limit surfaces and diagnosis.

    python scripts/real_study.py [--out out/real] [--no-fe] [--no-diagnose]
    python scripts/real_study.py --update        # also rewrites docs/real/ (tracked)

Reads the five hardboard logs of ``../shared/real/planar-sliding`` (Zhou et al., ICRA
2016; no other log is read) and, per layout:

1. ``fepost pushes`` (the pushes CSV) and ``fepost map`` (the support's pressure map;
   for the flat base also ``--fe``, the base on an elastic board solved by CalculiX);
2. predicts every push with fepost's models at f = 1 through ``fepost.friction.predict``
   (exact integrals, the paper's closed forms, the generalised model) and, as an
   independent check of the exact integrals, by plain sums over point contacts (three
   legs with their statics loads; the flat base on a 1 mm grid);
3. splits the pushes at random (seed `SPLIT_SEED`) into a training share `TRAIN_SHARE`
   and a held-out rest; fits the friction coefficient of each physical model on the
   training pushes (least squares on Fx, Fy, Mz/ρ; 95 % interval from push-clustered
   residuals, Student t) and the limit surfaces (ellipsoid, 6 coefficients; convex
   quartic, 15) on the same pushes; reports held-out errors: force |ΔF| (N), torque |ΔM|
   (N·mm) and the angle between the wrenches (F, M/ρ);
4. across layouts: f (physics) or the surface fitted on the four other layouts'
   pushes, the fifth predicted;
5. the paper's Table 1 procedure on the pushes (``fepost.identify.fit_table1``: F∥ over
   ψ = ωR/|v|, M_C and F⊥ over υ = |v|/(ωR)) beside the values of each map;
6. ``fepost.diagnose`` on each log (on the map's own grid, nominal f = 0.28, the
   authors' value) and the five pooled (sums of the per-log ΔBIC of each cause, each
   log with its own parameters: the layouts have five different maps);
7. physics beyond the vocabulary, each against plain Coulomb with one f by BIC (one
   common noise level on the scaled channels) and by held-out errors: the finite turn
   within a push (the twist from the SE(2) logarithm of the start-to-end motion: no
   parameter), friction that differs from leg to leg (three coefficients), the
   finger's height tilting the block (loads move between the legs, d = −h F/N: f, h),
   and for the flat base the FE map on an elastic board and a base loaded at its
   edges (σ ∝ exp(−d/λ), d the distance to the edge: f, λ).

Writes ``results.json``, ``tables.md`` and the figures into ``--out`` (default
``out/real``); ``--update`` copies them into ``docs/real/`` (the tables as ``tables.txt``).
Should ``fepost.diagnose`` stop on a log (its ``load_transfer`` fixed point once diverged on
the close legs), that log's diagnosis is run without that cause and says so
(``failed_with_every_cause``); on the five hardboard logs none stops.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from scripts.realstudy.diagnosis import diagnose_layout, plain, pooled_diagnosis  # noqa: E402
from scripts.realstudy.figures import figure_curves, figure_diagnosis, figure_errors, figure_surfaces  # noqa: E402
from scripts.realstudy.fits import (  # noqa: E402
    SCALE,
    across_layouts,
    fit_level,
    fit_surface,
    held_out,
    split,
    table1_rows,
)
from scripts.realstudy.layouts import (  # noqa: E402
    LAYOUTS,
    NOMINAL_F,
    PHYSICS,
    RHO,
    SHARED,
    SPLIT_SEED,
    TRAIN_SHARE,
    Layout,
    finite_turn,
    load_layout,
    log,
    point_wrench,
    prepare,
    statics_loads,
)
from scripts.realstudy.physics import extras, fit_edge  # noqa: E402
from scripts.realstudy.tables import (  # noqa: E402
    table_across,
    table_diagnosis,
    table_extras,
    table_friction,
    table_held_out,
    table_pooled,
    table_table1,
)

#: What tests/test_real_study.py reaches through this script.
__all__ = ["finite_turn", "fit_level", "main", "point_wrench", "statics_loads"]


def fitted_models(lay: Layout, train: np.ndarray) -> dict:
    """f per physical model and the two surfaces, fitted on the training pushes (for the figures)."""
    out = {
        "f": {k: fit_level(lay.pred[k][train], lay.W[train])["f"] for k in PHYSICS},
        "surface": {
            k: fit_surface(lay.kin[train], lay.W[train], d) for k, d in (("ellipsoid", 2), ("quartic", 4))
        },
    }
    if "base" in lay.body:
        lam, f, _ = fit_edge(lay, train)
        out["edge"] = (lam, f)
    return out


def study(args, t0: float) -> dict:
    layouts = []
    for name in args.layouts:
        paths = prepare(name, args.out, fe=args.fe)
        layouts.append(load_layout(name, paths))
        log(f"{name}: {layouts[-1].n} pushes, map {layouts[-1].grid}", t0)
    held, fits, checks, t1, ex = {}, {}, {}, {}, {}
    for lay in layouts:
        train, test = split(lay.n)
        held[lay.name] = held_out(lay, train, test)
        fits[lay.name] = fitted_models(lay, train)
        P, Q = lay.pred["exact"], lay.pred["points"]
        checks[lay.name] = float(np.sqrt(np.mean(np.sum(((P - Q) * SCALE) ** 2, axis=1))) / lay.N)
        t1[lay.name] = table1_rows(lay, fit_level(P, lay.W)["f"])
        ex[lay.name] = extras(lay, train, test)
        log(f"{lay.name}: held-out errors, Table 1, extra physics", t0)
    across = across_layouts(layouts) if len(layouts) > 1 else {}
    log("across layouts", t0)
    per_log = {}
    if args.diagnose:
        for lay in layouts:
            per_log[lay.name] = diagnose_layout(lay)
            log(f"{lay.name}: diagnosis {per_log[lay.name]['causes']}", t0)
    pooled = pooled_diagnosis(per_log) if per_log else {}
    figs = args.out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    figure_curves(layouts, fits, figs / "real_curves.png")
    figure_surfaces(layouts, fits, figs / "real_surfaces.png")
    if across:
        figure_errors(held, across, figs / "real_errors.png")
    if per_log:
        figure_diagnosis(per_log, pooled, figs / "real_diagnosis.png")
    log("figures", t0)
    return {
        "layouts": list(args.layouts), "rho_m": RHO, "nominal_f": NOMINAL_F, "split_seed": SPLIT_SEED,
        "train_share": TRAIN_SHARE, "held_out": held, "exact_vs_point_sums": checks, "table1": t1,
        "across_layouts": across, "extras": ex, "diagnosis": per_log, "pooled": pooled,
    }  # fmt: skip


def write_tables(res: dict, path: Path) -> None:
    parts = [
        (
            "Friction coefficient on the training pushes (95 %)",
            table_friction(res["held_out"], res["exact_vs_point_sums"]),
        ),
        ("Held-out errors per log", table_held_out(res["held_out"])),
        ("Across layouts", table_across(res["across_layouts"]) if res["across_layouts"] else []),
        ("Table 1 on the pushes", table_table1(res["table1"])),
        ("Diagnosis per log", table_diagnosis(res["diagnosis"]) if res["diagnosis"] else []),
        ("Pooled diagnosis", table_pooled(res["pooled"]) if res["pooled"] else []),
        ("Physics beyond the vocabulary", table_extras(res["extras"])),
    ]
    text = "\n".join(f"### {title}\n\n" + "\n".join(lines) + "\n" for title, lines in parts if lines)
    path.write_text(text)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=REPO / "out" / "real")
    ap.add_argument("--update", action="store_true", help="also copy the results into docs/real/ (tracked)")
    ap.add_argument("--no-fe", dest="fe", action="store_false", help="skip the CalculiX map of the flat base")
    ap.add_argument("--no-diagnose", dest="diagnose", action="store_false")
    ap.add_argument("--layouts", nargs="+", default=list(LAYOUTS), choices=LAYOUTS)
    args = ap.parse_args(argv)
    if not SHARED.is_dir():
        print(
            f"real_study: {SHARED} not found (the planar-sliding logs live beside the clone)", file=sys.stderr
        )
        return 2
    t0 = time.time()
    args.out.mkdir(parents=True, exist_ok=True)
    res = study(args, t0)
    (args.out / "results.json").write_text(json.dumps(plain(res), indent=1, allow_nan=True) + "\n")
    write_tables(res, args.out / "tables.md")
    if args.update:
        docs = REPO / "docs" / "real"
        docs.mkdir(parents=True, exist_ok=True)
        for src in (*(args.out / "figures").glob("real_*.png"), args.out / "results.json"):
            shutil.copy2(src, docs / src.name)
        # the tables as text, not as a page of the site (the page docs/real.md shows them)
        shutil.copy2(args.out / "tables.md", docs / "tables.txt")
    log(f"done: {args.out}", t0)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
