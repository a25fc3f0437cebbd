"""The headline numbers the documentation quotes, computed in one place.

    python scripts/headline_numbers.py

docs/numbers.md shows what this prints, and the documentation tests run it and compare
(``tests/test_doc_examples.py``), so a page that quotes one of these numbers can point
there instead of stating its own. Three families of numbers:

* the paper's closed forms against the exact Coulomb integrals: the largest |ΔF|/F0 and
  |ΔMz|/M0 over the kinematic sphere on the error-map grid (`fepost.friction.summary.
  ACCURACY_GRID`, the grid of every accuracy fepost states), on reference maps (circular,
  and ellipses up to aspect 3) and on the sample tire's FE maps;
* k_x of free rolling: the half sector's rolled map ``meshes/rig-aircraft/roll_free.vtu`` (driven
  through a spring 2.4 % fast) with each static map it can be paired with, the whole tire's
  ``meshes/rig-tire360/roll/roll_ref.vtu`` (its rim turned at the free-rolling radius found from
  the driven runs) with its own static map, and the sliding stand-in for comparison;
* R = r_max of the same tire at its rated load on each of its meshes, with what
  makes them differ (the outermost loaded node of a coarser mesh lies further out).

Reads only the repository's sample meshes; writes nothing.
"""

from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

F = 0.3
ASPECTS = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0)
#: The sample tire's meshes at its rated load: file, what the mesh is.
MESHES = (
    ("aircraft/static_100.vtu", "fine static mesh (the demo's static map, the load sweep)"),
    ("rig-aircraft/roll_static.vtu", "rolling runs' mesh, before rolling"),
    ("rig-aircraft/static.vtu", "slide/spin rig mesh"),
    ("rig-tire360/static.vtu", "whole tire on the rig (whole-fine)"),
    ("rig-tire360/roll/roll_static.vtu", "whole tire's rolling mesh, before rolling"),
)
#: The whole tire driven at its free-rolling radius, and its partner before rolling.
WHOLE_ROLLED = "rig-tire360/roll/roll_ref.vtu"
WHOLE_STATIC = "rig-tire360/roll/roll_static.vtu"
ROLLED = "rig-aircraft/roll_free.vtu"
STAND_IN = "aircraft/rolling_100.vtu"


def _paper_error(quad, k_x: float = 0.0) -> tuple[float, float]:
    """(largest |ΔF|/F0, largest |ΔMz|/M0) of the closed forms with the map's own coefficients."""
    from fepost.friction.closed_form import paper_coefficients, paper_model
    from fepost.friction.law import FrictionLaw
    from fepost.friction.sphere import error_map
    from fepost.friction.summary import ACCURACY_GRID
    from fepost.friction.tensors import map_tensors

    p = paper_coefficients(map_tensors(quad), F, k_x=k_x)
    law = FrictionLaw(f=F)
    em = error_map(
        quad, {"paper": paper_model(**p)}, law=law, F0=p["F0"], M0=p["M0"], R=p["radius"], **ACCURACY_GRID
    )
    worst = em.worst("paper")
    return worst["force"], worst["torque"]


def reference_lines() -> list[str]:
    from fepost.friction.accuracy import rolling_shift
    from fepost.friction.reference_maps import asymmetric, ellipse_quad, tire_like

    families = {
        "uniform": lambda a: ellipse_quad("uniform", a, nr=32, nphi=64),
        "Hertz": lambda a: ellipse_quad("hertz", a, nr=32, nphi=64),
        "tire-like": tire_like,
        "asymmetric rolling-like": asymmetric,
    }
    lines = ["closed forms against the exact integrals, reference maps (largest |ΔF|/F0, |ΔMz|/M0):"]
    circular, every = [], []
    for name, make in families.items():
        errs = []
        for aspect in ASPECTS:
            quad = make(aspect)
            k_x = rolling_shift(quad, quad.radius) if name.startswith("asym") else 0.0
            errs.append(_paper_error(quad, k_x))
        circular.append(errs[0])
        every += errs
        lines.append(
            f"  {name:24s} aspect 1: {errs[0][0]:.3f}, {errs[0][1]:.3f}; aspects 1-3: "
            f"{min(e[0] for e in errs):.3f}-{max(e[0] for e in errs):.3f}, "
            f"{min(e[1] for e in errs):.3f}-{max(e[1] for e in errs):.3f}"
        )
    for label, errs in (("circular (aspect 1)", circular), ("aspects 1-3", every)):
        lines.append(
            f"  range, {label:20s} force {min(e[0] for e in errs):.3f}-{max(e[0] for e in errs):.3f}, "
            f"torque {min(e[1] for e in errs):.3f}-{max(e[1] for e in errs):.3f}"
        )
    return lines


def sample_lines() -> list[str]:
    import fepost

    meshes = REPO / "meshes"
    lines = ["", "the sample aircraft tire at its rated load, by mesh:"]
    lines.append(
        "  mesh                               N (N)    R = r_max (m)  r_equiv (m)  aspect  "
        "closed forms' error"
    )
    for name, what in MESHES:
        a = fepost.analyse(meshes / name, friction=F)
        c, p = a.coefficients, a.static_patch
        worst = a.model_summary.static_errors.worst("paper")
        lines.append(
            f"  {name:34s} {c.N:7.0f}  {c.R:.4f}         {p.r_equiv:.4f}       {p.aspect:.3f}   "
            f"{worst['force']:.3f}, {worst['torque']:.3f}   ({what})"
        )
    lines += [
        "",
        "k_x of free rolling:",
        f"  the half sector's {ROLLED} (driven through a spring 2.4 % fast, 0.75 m of axle travel):",
    ]
    demo = None
    for name, _ in MESHES[:2]:
        a = fepost.analyse(meshes / name, meshes / ROLLED, friction=F)
        demo = demo or a
        lines.append(f"    with the static map {name:34s} k_x = {a.coefficients.k_x:.4f}")
    whole = fepost.analyse(meshes / WHOLE_STATIC, meshes / WHOLE_ROLLED, friction=F)
    lines += [
        f"  the whole tire's {WHOLE_ROLLED} (driven at the free-rolling radius, torque-free, 0.8 m):",
        f"    with the static map {WHOLE_STATIC:34s} k_x = {whole.coefficients.k_x:.4f}",
    ]
    a = fepost.analyse(meshes / MESHES[0][0], meshes / STAND_IN, friction=F)
    lines.append(f"  sliding stand-in {STAND_IN} (not rolling)  k_x = {a.coefficients.k_x:.4f}")
    worst = demo.model_summary.rolling_errors.worst("paper")
    lines.append(
        f"  closed forms' error on the rolled map (with the demo's k_x): {worst['force']:.3f}, "
        f"{worst['torque']:.3f}"
    )
    return lines


def main() -> int:
    print("\n".join([*reference_lines(), *sample_lines()]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
