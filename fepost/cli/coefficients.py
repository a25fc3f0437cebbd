"""``fepost coefficients STATIC [--rolling ROLLING] [--field NAME] [--friction F] [--json PATH]``."""

from __future__ import annotations

import argparse
import os
from typing import TYPE_CHECKING

from ._common import add_friction_option, add_input_options, analysis_options

if TYPE_CHECKING:
    from ..analysis import Analysis


def add_parser(sub) -> None:
    p = sub.add_parser(
        "coefficients",
        help="patch, circularity and friction-model coefficients of an FE contact map",
        description=(
            "Compute the contact patch and its frame, the paper's coefficients and the generalised "
            "friction model of the map. Definitions: docs/theory.md; the model: docs/model.md."
        ),
    )
    p.add_argument(
        "static",
        metavar="STATIC",
        help="static contact map (.vtu .vtk .vtp .pvtu .vts .e .xdmf .frd ...: see docs/formats.md)",
    )
    p.add_argument("--rolling", metavar="ROLLING", help="rolling contact map at the same deflection")
    add_friction_option(p)
    p.add_argument("--json", metavar="PATH", help="write the coefficients as JSON (- for standard output)")
    add_input_options(p)
    p.set_defaults(func=run)


def _pct(x: float) -> str:
    """A signed percentage without a negative zero."""
    return f"{(x if abs(x) >= 5e-5 else 0.0):+.2%}"


def _rolling_load(a: Analysis) -> str:
    """The rolling map's load beside the static one, and whether a mismatch was allowed."""
    from ..analysis import LOAD_TOL

    rp, c = a.rolling_patch, a.coefficients
    assert rp is not None and c.N_rolling is not None
    ratio = rp.N_fe / a.static_patch.N_fe
    text = f"{c.N_rolling:.6g} N  (N_fe {rp.N_fe:.6g} N, {_pct(ratio - 1)} vs the static N_fe"
    if abs(ratio - 1) > LOAD_TOL:
        return text + f"; beyond {LOAD_TOL:.0%}, ALLOWED by --allow-load-mismatch)"
    allowed = ", --allow-load-mismatch given" if a.load_mismatch_allowed else ""
    return text + f"; within {LOAD_TOL:.0%}{allowed})"


def format_analysis(a: Analysis) -> str:
    """A readable table of the patch and the coefficients."""
    c, p = a.coefficients, a.static_patch
    rows = [
        ("static map", f"{a.static_field.source}  [{a.static_field.field}, {p.location} data]"),
        ("normal load N (polar)", f"{c.N:.6g} N"),
        ("normal load N_fe (FE faces)", f"{p.N_fe:.6g} N  (differs by {c.N / p.N_fe - 1:+.2e})"),
    ]
    from ..analysis import reaction_candidates
    from ..reader.units import describe

    for name, value in reaction_candidates(a.static_field, p.frame.axes[2]).items():
        rel = f"  (N_fe/|reaction| - 1 = {_pct(p.N_fe / abs(value) - 1)})" if value else ""
        rows.append((f"solver {name}", f"{value:.6g} N{rel}"))
    f = a.static_field
    if f.step is not None:
        rows.append(("time step", f"{f.step} of steps 0-{len(f.steps) - 1}  (t = {f.time:g} s)"))
    if f.body:
        rows.append(("faces from", f.body))
    rows.append(("units", describe(f.units)))
    o = p.frame.origin
    rows += [
        ("patch centre (global)", f"({o[0]:.5g}, {o[1]:.5g}, {o[2]:.5g}) m"),
        ("patch normal", "(" + ", ".join(f"{v:.4f}" for v in p.frame.axes[2]) + ")"),
        ("R = r_max", f"{c.R:.6g} m"),
        ("r_equiv", f"{p.r_equiv:.6g} m"),
        ("ellipse semi-axes", f"{p.ellipse_axes[0]:.5g} x {p.ellipse_axes[1]:.5g} m, aspect {p.aspect:.4f}"),
        ("load outside r_equiv", f"{p.load_outside:.2%}"),
        (
            "circular",
            f"{'yes' if p.circular else 'NO'}  (aspect {p.aspect:.3f}, r_max/r_equiv "
            f"{p.r_max / p.r_equiv:.3f}; circular needs {p.to_dict()['circular_rule']})",
        ),
        ("A0..A3", ", ".join(f"{v:.6g}" for v in c.A) + " Pa"),
        ("f", f"{c.f:g}"),
        ("F0", f"{c.F0:.6g} N"),
        ("M0", f"{c.M0:.6g} N m"),
        ("a", f"{c.a:.6g}   (aR^2 = {c.a * c.R**2:.6g} m^2)"),
        ("m", f"{c.m:.6g}   (m/R^2 = {c.m / c.R**2:.6g} 1/m^2)"),
        ("b = m/4", f"{c.b:.6g}"),
        ("b1 = M0/2", f"{c.b1:.6g} N m"),
    ]
    if c.k_x is not None and a.rolling_field is not None:
        rows += [
            ("rolling map", f"{a.rolling_field.source}"),
            ("rolling normal load N", _rolling_load(a)),
            ("x_c (rolling CoP shift)", f"{c.x_c:.6g} m"),
            ("k_x", f"{c.k_x:.6g}"),
        ]
    rows += a.model_summary.lines()  # generalised model (fepost.friction.summary)
    g = a.grid
    rows.append(("polar grid", f"{g.rule}, {g.shape[0]} x {g.shape[1]} (r x phi)"))
    width = max(len(k) for k, _ in rows)
    lines = [f"{k:<{width}}  {v}" for k, v in rows]
    lines += [f"note: {n}" for n in p.notes]
    return "\n".join(lines)


#: Most heap (bytes) faulted in while the files are read (`warm_heap`): part of what the patch step
#: and the resampling of a million-node map allocate, as much as keeps the process tree's peak
#: memory below a bare read's (64 MB took it to 1.09 x); never more than the map's file size.
WARM_HEAP = 32 << 20
#: glibc's ``mallopt`` parameters (malloc.h).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def warm_heap(nbytes: int) -> None:
    """Fault in ``nbytes`` of heap now, for the pipeline to reuse later (glibc only).

    The command's process is idle while its reading child reads. The arrays of the patch
    step and the resampling (tens of MB) would otherwise each be mapped afresh and fault
    page by page, one fault per 4 kB, on the critical path after the read; and returned to
    the system when freed, only to fault again in the next step. Here malloc keeps
    allocations of up to 1 GB in its heap and keeps freed memory there, and a zeroed block
    of ``nbytes``, freed at once, leaves that many pages mapped. Elsewhere (no glibc), nothing
    is done. On the 1.08 M-node surface map (benchmarks/bench_read.py) the patch step's page
    faults drop from about 8500 to 3300 with 32 MB, and the whole process takes 0.92 x the
    time."""
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (AttributeError, OSError):  # not glibc: no mallopt
        return
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    if mallopt(_M_MMAP_THRESHOLD, 1 << 30) and mallopt(_M_TRIM_THRESHOLD, 2**31 - 1):
        bytearray(nbytes)  # zeroed, so every page is touched, then freed into the heap


def _size(path: str) -> int:
    try:
        return os.stat(path).st_size
    except (OSError, ValueError):  # the reader says what is wrong with the file
        return 0


def run(args: argparse.Namespace) -> int:
    from ..reader import start_reading
    from . import WHOLE_PROCESS

    options = analysis_options(args)
    # the files are read in their children while the pipeline's modules are imported
    pending = [start_reading(args.static, **options.reading())]
    try:
        if args.rolling:
            pending.append(start_reading(args.rolling, **options.reading()))
        from ..analysis import analyse
        from ..output import write_json_atomic  # imported while the files are read (10-30 ms)

        if WHOLE_PROCESS:  # not in a program that calls `main`: its malloc keeps its own ways
            warm_heap(min(WARM_HEAP, _size(args.static)))
        result = analyse(*pending, friction=args.friction, options=options)
    finally:
        for p in pending:
            p.cancel()
    from ._common import summary_stream

    print(format_analysis(result), file=summary_stream(args.json))
    if args.json:
        write_json_atomic(args.json, result.to_dict())
    return 0
