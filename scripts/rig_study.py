"""The friction model against the FE with friction: misfit of four predictions over the rig runs.

    python scripts/rig_study.py [--rig meshes/rig] [--out out/rig]
    python scripts/rig_study.py --rig meshes/rig-aircraft          # -> out/rig-aircraft
    python scripts/rig_study.py --rig meshes/rig-aircraft --update # -> docs/rig/aircraft (tracked)
    python scripts/rig_study.py --rig meshes/rig-tire360 --no-extension [--runs NAME ...]
    python scripts/rig_study.py --rig meshes/rig-tire360/xfine --longer DIR ... [--out DIR]

Writes into ``out/<rig folder name>`` (or ``--out``); only ``--update`` rewrites the
tracked copies the documentation shows (``docs/rig/`` for ``meshes/rig``,
``docs/rig/aircraft/`` for ``meshes/rig-aircraft``). Each step prints a progress line
on stderr with its time.

Reads the slide/spin runs of ``meshes/rig/`` (``fepost.rig``: forces of the road
on the tire from CalculiX's reactions) and compares them with

(a) the paper's closed forms with the static map's coefficients,
(b) the exact Coulomb integrals over the static map,
(c) the exact Coulomb integrals over each run's own (deformed, end-of-slide)
    pressure map, placed in the static patch's frame,
(d) fepost's generalised model built from the static map,

all through ``fepost.friction.predict``, and the extension

(e) the exact integrals over the static map shifted by load transfer
    (``fepost.rig.extension``), h identified from the runs' own maps and the
    shear-traction force per load: on all runs, and held out (h from the
    other sliding directions' runs; the table's cross-validated row and the
    ``*_shift`` columns of ``misfit.csv``).

The predictions
over a static map carry the static load; the FE load changes a little during
the slide (the rim is held at its height), so (a), (b), (d) and (e) are scaled by
N_run / N_static (the Coulomb forces are proportional to the load at a fixed
pressure shape). Misfits are in units of f N (forces) and f N R (torque),
N the run's load, R the static patch radius. Writes ``misfit.csv`` (per run),
``table.txt`` (RMS and max per model, the identified law), figures
``rig_<direction>.png``, the shifts against the forces ``rig_shift.png`` and the
forces against the sliding path, ``rig_history.png``.

``--runs`` takes only the named runs (the runs two rigs share, set side by side);
``--longer DIR ...`` puts the runs found in those folders (longer paths, smaller increments:
solved from the same base, which their ``static.json`` must name) in place of the rig's
runs of the same names (a later folder's in place of an earlier one's), so the study reads
each run at its steadiest solve;
``--no-extension`` stops after (a)-(d) and the decomposition, for a programme whose
held-out folds cannot identify (e) yet (a fold with no force along x or y).

Two more tables in ``table.txt``: the steady state (how much each of Fx, Fy (in f N) and
N (relative) moves over the last 20 % of each run's path, judged as
``scripts/tiremodel/steadiness`` does; |F| and Mz beside) and the load-transfer heights found in
four ways (``heights``): from the runs' maps (the centre-of-pressure shifts, as
(e)), and by least squares on the forces that the shifted static map should
reproduce, three targets in turn: the static map moved by each run's own
measured shift (a rigid move, so the shape change is left out), the exact
integrals over the run's own map (c) (rigid slip, so the compliance is left
out), and the FE reactions (as ``fepost diagnose`` fits them). The steps
between the rows say which part of the FE's behaviour each h absorbs.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

MODELS = {
    "paper": "(a) paper's closed forms",
    "exact": "(b) exact integrals, static map",
    "own": "(c) exact integrals, run's own map",
    "model": "(d) generalised model",
}

#: The load-transfer extension (``fepost.rig.extension``), after the decomposition row.
EXTENSION = {
    "fit": "(e) static map shifted by load transfer, h from all runs' maps",
    "shift": "(e) the same, cross-validated (h from the other directions' maps)",
    "lo": "(e) sensitivity: h_x, h_y both at the lower 95% interval ends",
    "hi": "(e) sensitivity: h_x, h_y both at the upper 95% interval ends",
    "only_y": "(e) sensitivity: h_x = 0 (lateral transfer only)",
    "only_x": "(e) sensitivity: h_y = 0 (longitudinal transfer only)",
}


def _runs(rig: Path) -> list[Path]:
    """The slide/spin runs of the folder (``d<direction>_*``, ``spin_*``; not other runs beside them)."""
    out = []
    for side in sorted([*rig.glob("d[0-9][0-9][0-9]_*.json"), *rig.glob("spin_*.json")]):
        data = json.loads(side.read_text())
        if "kinematics" in data:
            out.append(side.with_suffix(".vtu"))
    return out


def replace_runs(rig: Path, runs: list[Path], longer: list[Path]) -> tuple[list[Path], list[str]]:
    """``runs`` with each run found in a ``longer`` folder in place of the rig's of the same name,
    and a line per replaced run (name, folder, path). Every folder's ``static.json`` must name the
    rig's base deck (the runs restart from the same static solution) and hold only runs of the
    rig; a run found in several folders is taken from the last of them, one left out of ``runs``
    stays out."""
    from fepost.errors import ArgumentError

    def base_of(folder: Path) -> str | None:
        try:
            return json.loads((folder / "static.json").read_text()).get("base_deck_sha256")
        except (OSError, ValueError) as err:
            raise ArgumentError(f"--longer: {folder}: no readable static.json ({err})") from err

    own = base_of(rig)
    names = {p.stem: i for i, p in enumerate(runs)}
    known = {p.stem for p in _runs(rig)}
    out, taken = list(runs), {}
    for folder in longer:
        if own is None or base_of(folder) != own:
            raise ArgumentError(f"--longer: {folder}: its static.json names another base than {rig}'s")
        for run in _runs(folder):
            if run.stem not in known:
                raise ArgumentError(f"--longer: {folder}: run {run.stem} is not one of the runs of {rig}")
            if run.stem in names:  # a run of the rig left out of ``runs`` stays out
                out[names[run.stem]] = taken[run.stem] = run
    lines = []
    for name, run in sorted(taken.items(), key=lambda item: names[item[0]]):
        model = json.loads(run.with_suffix(".json").read_text())["model"]
        lines.append(f"{name}: {run.parent} ({model['slide_path']:.2f} m, {model['slide_steps']} steps)")
    return out, lines


def predictions(rig: Path, runs: list[Path], friction: float, tick=None):
    """FE table, static analysis, a dict model -> (n, 3) predicted (Fx, Fy, Mz) and the runs' maps;
    ``tick()`` is called after each run's own map (the progress line's dots)."""
    from fepost.analysis import analyse
    from fepost.friction.exact import friction_resultants
    from fepost.friction.law import FrictionLaw
    from fepost.friction.predict import predict
    from fepost.friction.quadrature import PressureQuadrature
    from fepost.rig import rig_table

    law = FrictionLaw(f=friction)
    table = rig_table(runs)
    vx = np.array([r.vx for r in table.runs])
    vy = np.array([r.vy for r in table.runs])
    wz = np.array([r.wz for r in table.runs])
    static = analyse(rig / "static.vtu", friction=friction)
    p = predict(vx, vy, wz, pmap=static.static_map, coefficients=static.coefficients, law=law)
    n_static = static.coefficients.N
    scale = np.array([r.reaction.N for r in table.runs]) / n_static
    out = {}
    for key, res in (("paper", p.paper), ("exact", p.exact), ("model", p.generalised)):
        out[key] = np.column_stack([res.Fx, res.Fy, res.Mz]) * scale[:, None]
    own, shifts = [], []
    c0 = np.array(static.static_moments.centroid)
    for i, run in enumerate(runs):
        # each run's own map at its own load (the aircraft tire's load changes by up to 13 %
        # during a slide); only its pressure is used here, not the pair's k_x
        a = analyse(rig / "static.vtu", run, friction=friction, allow_load_mismatch=True)
        q = friction_resultants(PressureQuadrature.from_polar(a.rolling_map), vx[i], vy[i], wz[i], law)
        own.append([float(q.Fx[()]), float(q.Fy[()]), float(q.Mz[()])])
        shifts.append(np.array(a.rolling_moments.centroid) - c0)
        if tick is not None:
            tick()
    out["own"] = np.array(own)
    return table, static, out, np.array(shifts)


def misfit_table(table, static, preds, friction: float) -> tuple[list[dict], list[dict]]:
    """Per-run rows and the summary (RMS, max) per model, in f N and f N R."""
    fe = np.array([[r.reaction.Fx, r.reaction.Fy, r.reaction.Mz] for r in table.runs])
    n = np.array([r.reaction.N for r in table.runs])
    R = static.coefficients.R
    unit = np.column_stack([friction * n, friction * n, friction * n * R])
    rows = []
    for i, r in enumerate(table.runs):
        row = {
            "run": Path(r.source).stem,
            "vx": r.vx,
            "vy": r.vy,
            "wz": r.wz,
            "spin_ratio": abs(r.wz) * R / np.hypot(r.vx, r.vy) if (r.vx, r.vy) != (0.0, 0.0) else np.inf,
            "Fx_fe": fe[i, 0] / unit[i, 0],
            "Fy_fe": fe[i, 1] / unit[i, 1],
            "Mz_fe": fe[i, 2] / unit[i, 2],
        }
        for key, p in preds.items():
            if key in EXTENSION and key != "shift":
                continue  # per run: only the held-out extension
            for j, q in enumerate(("Fx", "Fy", "Mz")):
                row[f"{q}_{key}"] = p[i, j] / unit[i, j]
        rows.append(row)
    summary = []
    for key in MODELS:
        d = (preds[key] - fe) / unit
        df = np.hypot(d[:, 0], d[:, 1])
        summary.append(
            {
                "model": MODELS[key],
                "rms_F": float(np.sqrt(np.mean(df**2))),
                "max_F": float(df.max()),
                "rms_Mz": float(np.sqrt(np.mean(d[:, 2] ** 2))),
                "max_Mz": float(np.abs(d[:, 2]).max()),
            }
        )
    # the decomposition: (b) - (c) isolates the pressure redistribution, (c) - FE the compliance
    pairs = [("(b) - (c): pressure redistribution", "exact", "own")]
    pairs += [(label, key, None) for key, label in EXTENSION.items() if key in preds]
    for label, a, b in pairs:
        d = (preds[a] - (fe if b is None else preds[b])) / unit
        df = np.hypot(d[:, 0], d[:, 1])
        summary.append(
            {
                "model": label,
                "rms_F": float(np.sqrt(np.mean(df**2))),
                "max_F": float(df.max()),
                "rms_Mz": float(np.sqrt(np.mean(d[:, 2] ** 2))),
                "max_Mz": float(np.abs(d[:, 2]).max()),
            }
        )
    return rows, summary


def extension(table, static, shifts, friction: float) -> tuple[dict, object]:
    """The load-transfer extension: (n, 3) predictions (all runs' h; cross-validated) and the law.

    The law is identified from each run's centre-of-pressure shift (its own map against
    the static map) and its friction force per load from the integral of the export's
    shear traction (not the reactions the predictions are checked against). Held-out
    groups: the sliding directions and the pure-spin runs.
    """
    from dataclasses import replace

    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature
    from fepost.rig.extension import cross_validate, identify_shift, predict_shifted

    law = FrictionLaw(f=friction)
    vx, vy, wz = (np.array([getattr(r, k) for r in table.runs]) for k in ("vx", "vy", "wz"))
    force = np.array([[r.shear.Fx / r.shear.N, r.shear.Fy / r.shear.N] for r in table.runs])
    groups = [Path(r.source).stem.split("_")[0] for r in table.runs]
    quad = PressureQuadrature.from_polar(static.static_map)
    shift_law = identify_shift(shifts, force)
    scale = np.array([r.reaction.N for r in table.runs])[:, None] / static.coefficients.N
    fit = predict_shifted(quad, vx, vy, wz, law=shift_law, friction=law).resultants
    cv = cross_validate(quad, vx, vy, wz, shifts=shifts, forces=force, groups=groups, friction=law)
    out = {
        "fit": np.column_stack([fit.Fx, fit.Fy, fit.Mz]) * scale,
        "shift": np.column_stack([cv.Fx, cv.Fy, cv.Mz]) * scale,
    }
    lx, ly = shift_law.interval_x, shift_law.interval_y
    for key, hx, hy in (
        ("lo", lx[0], ly[0]),
        ("hi", lx[1], ly[1]),
        ("only_y", 0.0, shift_law.h_y),
        ("only_x", shift_law.h_x, 0.0),
    ):
        other = replace(shift_law, h_x=hx, h_y=hy)
        r = predict_shifted(quad, vx, vy, wz, law=other, friction=law).resultants
        out[key] = np.column_stack([r.Fx, r.Fy, r.Mz]) * scale
    return out, shift_law


def write_outputs(out: Path, rows, summary, static, n_runs: int) -> None:
    out.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0])
    lines = [",".join(keys)]
    for row in rows:
        lines.append(",".join(row[k] if isinstance(row[k], str) else f"{row[k]:.6g}" for k in keys))
    (out / "misfit.csv").write_text("\n".join(lines) + "\n")
    c = static.coefficients
    md = [
        f"Misfit over {n_runs} rig runs (forces in f N, torque in f N R; N the run's load, "
        f"R = {c.R:.4g} m the static patch radius; f = {c.f}).",
        "",
        "| prediction | RMS \\|dF\\| / fN | max \\|dF\\| / fN | RMS dMz / fNR | max \\|dMz\\| / fNR |",
        "|---|---|---|---|---|",
    ]
    for s in summary:
        md.append(
            f"| {s['model']} | {s['rms_F']:.4f} | {s['max_F']:.4f} | {s['rms_Mz']:.4f} | {s['max_Mz']:.4f} |"
        )
    (out / "table.txt").write_text("\n".join(md) + "\n")


def law_lines(law) -> list[str]:
    """Markdown: the identified load-transfer law with its intervals."""
    pct = f"{law.level:.0%}"
    return [
        "",
        f"(e) load transfer identified from the {law.n} runs' own maps (centre-of-pressure shift "
        "against the friction force per load from the shear-traction integral; least squares "
        f"through the origin, {pct} intervals):",
        "",
        f"| axis | h / mm | {pct} interval / mm | RMS shift / mm | RMS unexplained / mm |",
        "|---|---|---|---|---|",
        f"| x | {law.h_x * 1e3:.2f} | {law.interval_x[0] * 1e3:.2f} .. {law.interval_x[1] * 1e3:.2f} | "
        f"{law.scatter_x * 1e3:.3f} | {law.residual_x * 1e3:.3f} |",
        f"| y | {law.h_y * 1e3:.2f} | {law.interval_y[0] * 1e3:.2f} .. {law.interval_y[1] * 1e3:.2f} | "
        f"{law.scatter_y * 1e3:.3f} | {law.residual_y * 1e3:.3f} |",
    ]


def convergence(rig: Path, static, friction: float) -> list[str]:
    """Markdown rows: the same run on a finer mesh (``fine/``; the whole tire's finest mesh:
    ``xfine/``) or a smaller increment (``inc05/``)."""
    from fepost.rig import read_run

    R = static.coefficients.R
    lines = []
    for sub, what in (("fine", "finer mesh"), ("xfine", "finer mesh"), ("inc05", "half the increment")):
        for side in sorted((rig / sub).glob("*.json")):
            if "kinematics" not in json.loads(side.read_text()):
                continue
            base = rig / side.with_suffix(".vtu").name
            if not base.exists():
                continue
            a = read_run(base, shear=False).reaction
            b = read_run(side.with_suffix(".vtu"), shear=False).reaction
            ua, ub = friction * a.N, friction * b.N  # each in its own f N
            pa = np.array([a.Fx / ua, a.Fy / ua, a.Mz / (ua * R)])
            pb = np.array([b.Fx / ub, b.Fy / ub, b.Mz / (ub * R)])
            df = float(np.hypot(*(pb[:2] - pa[:2])))
            # rounded first, + 0.0: a force of -1e-16 fN prints as 0.0000, not -0.0000
            va, vb = (", ".join(f"{round(float(v), 4) + 0.0:.4f}" for v in p) for p in (pa, pb))
            lines.append(
                f"| {side.stem} | {what} | {va} | {vb} | {df:.4f} | {abs(pb[2] - pa[2]):.4f} | "
                f"{b.N / a.N - 1:+.2%} |"
            )
    return lines


def figures(out: Path, rows) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dirs: dict[int, list[dict]] = {}
    for r in rows:
        if r["vx"] == r["vy"] == 0.0:
            d = -1  # pure spin: on every direction's plot
        else:
            d = int(round(np.degrees(np.arctan2(r["vy"], r["vx"]))))
        dirs.setdefault(d, []).append(r)
    spin = dirs.pop(-1, [])
    styles = {
        "fe": ("k", "o"),
        "paper": ("C0", "s"),
        "exact": ("C1", "^"),
        "own": ("C2", "v"),
        "model": ("C3", "x"),
        "shift": ("C4", "d"),
    }
    for d, rs in sorted(dirs.items()):
        rs = rs + spin
        ang = np.array([np.degrees(np.arctan(r["spin_ratio"])) * np.sign(r["wz"] or 1.0) for r in rs])
        order = np.argsort(ang)
        fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
        c, s_ = np.cos(np.radians(d)), np.sin(np.radians(d))
        for key, (col, mk) in styles.items():
            if f"Fx_{key}" not in rs[0]:
                continue  # a model the study did not compute (--no-extension)
            fx = np.array([r[f"Fx_{key}"] for r in rs])
            fy = np.array([r[f"Fy_{key}"] for r in rs])
            m = np.array([r[f"Mz_{key}"] for r in rs])
            label = "FE (CalculiX)" if key == "fe" else {**MODELS, **EXTENSION}[key]
            # along and across the sliding direction d (across: +90 degrees from it)
            along, across = fx * c + fy * s_, -fx * s_ + fy * c
            for a, y in zip(ax, (along, across, m), strict=True):
                a.plot(ang[order], y[order], marker=mk, color=col, lw=0.8, label=label)
        ax[0].set_ylabel("F along v / fN")
        ax[1].set_ylabel("F across v (+90 deg) / fN")
        ax[2].set_ylabel("Mz / fNR")
        for a in ax:
            a.set_xlabel("spin angle atan(wz R / |v|), deg (sign of wz)")
            a.grid(alpha=0.3)
        ax[0].legend(fontsize=7)
        fig.suptitle(f"sliding direction {d} deg")
        fig.tight_layout()
        fig.savefig(out / f"rig_{d:03d}.png", dpi=80)
        plt.close(fig)


def shift_figure(out: Path, table, shifts, law) -> None:
    """Each run's centre-of-pressure shift against its friction force per load, with the law."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    force = np.array([[r.shear.Fx / r.shear.N, r.shear.Fy / r.shear.N] for r in table.runs])
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    for j, (q, h, ci) in enumerate((("x", law.h_x, law.interval_x), ("y", law.h_y, law.interval_y))):
        g = np.linspace(force[:, j].min(), force[:, j].max(), 2)
        ax[j].plot(force[:, j], shifts[:, j] * 1e3, "ko", ms=4, label="runs' own maps")
        ax[j].plot(g, h * g * 1e3, "C4", label=f"h_{q} = {h * 1e3:.1f} mm")
        ax[j].fill_between(g, ci[0] * g * 1e3, ci[1] * g * 1e3, color="C4", alpha=0.25, lw=0)
        ax[j].set_xlabel(f"F{q} / N (shear-traction integral)")
        ax[j].set_ylabel(f"d{q}, centre of pressure shift, mm")
        ax[j].grid(alpha=0.3)
        ax[j].legend(fontsize=7)
    fig.suptitle(f"load transfer identified from the {law.n} runs' maps")
    fig.tight_layout()
    fig.savefig(out / "rig_shift.png", dpi=80)
    plt.close(fig)


def history_figure(rig: Path, out: Path, runs: list[Path], friction: float) -> None:
    """Forces against the sliding path (the steady state): |F| / fN and Mz / fN R_ref per increment."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    for run in runs:
        side = json.loads(run.with_suffix(".json").read_text())
        h = side["history"]
        fn = friction * np.array(h["Fz"])
        path = np.array(h["path"]) * 1e3
        ax[0].plot(path, np.hypot(h["Fx"], h["Fy"]) / fn, lw=0.7)
        ax[1].plot(path, np.array(h["Mz"]) / (fn * side["model"]["r_ref"]), lw=0.7)
    ax[0].set_ylabel("|F| / fN")
    ax[1].set_ylabel("Mz / fN R_ref")
    for a in ax:
        a.set_xlabel("reference sliding path, mm")
        a.grid(alpha=0.3)
    fig.suptitle(f"all {len(runs)} runs, per increment")
    fig.tight_layout()
    fig.savefig(out / "rig_history.png", dpi=80)
    plt.close(fig)


def steady_state(runs: list[Path], friction: float, share: float = 0.2) -> list[tuple[str, object, float]]:
    """(run, its `scripts.tiremodel.steadiness.Motion` over the last ``share`` of the path (Fx, Fy
    in f N, N relative, |F| in f N), the largest change of Mz / (f N R_ref) there)."""
    from scripts.tiremodel.steadiness import tail_motion

    out = []
    for run in runs:
        side = json.loads(run.with_suffix(".json").read_text())
        h = side["history"]
        path = np.array(h["path"])
        tail = path >= (1.0 - share) * path[-1] - 1e-12
        fn = friction * np.array(h["Fz"])[tail]
        m = np.array(h["Mz"])[tail] / (fn * side["model"]["r_ref"])
        out.append((run.stem, tail_motion(h, friction, share), float(np.ptp(m))))
    return out


def steady_lines(rows: list[tuple[str, object, float]]) -> list[str]:
    """The steady-state table: every force component and N judged (``steadiness.TOL``), |F| beside."""
    from scripts.tiremodel.steadiness import TOL

    moving = [r for r, mo, _ in rows if not mo.steady()]
    return [
        "",
        f"Steady state: {len(rows) - len(moving)} of {len(rows)} runs move by less than {TOL} over the "
        "last 20 % of the path in each of Fx, Fy (in fN) and N (relative); not steady: "
        f"{', '.join(moving) if moving else 'none'}.",
        "",
        "| run | Fx / fN | Fy / fN | N / N | \\|F\\| / fN | Mz / fN R_ref | steady |",
        "|---|---|---|---|---|---|---|",
        *(
            f"| {r} | {mo.fx:.4f} | {mo.fy:.4f} | {mo.n:.4f} | {mo.f_abs:.4f} | {dm:.4f} | "
            f"{'yes' if mo.steady() else 'no'} |"
            for r, mo, dm in rows
        ),
    ]


def _shifted_forces(quad, kin, h, scale, friction: float) -> np.ndarray:
    """(n, 3) Fx, Fy, Mz of the static map shifted by the law with heights ``h`` (m), at each run's load."""
    from fepost.friction.law import FrictionLaw
    from fepost.rig.extension import ShiftLaw, predict_shifted

    hx, hy = float(h[0]), float(h[1])
    law = ShiftLaw(hx, hy, 0.0, 0.0, (hx, hx), (hy, hy), 0.0, 0.0, 0.0, 0.0, len(scale))
    r = predict_shifted(quad, *kin, law=law, friction=FrictionLaw(f=friction)).resultants
    return np.column_stack([r.Fx, r.Fy, r.Mz]) * scale[:, None]


def _fit_heights(quad, kin, target, scale, R: float, friction: float) -> tuple[float, float]:
    """(h_x, h_y) (m) that make the shifted static map reproduce ``target`` (n, 3) best.

    Least squares on (Fx, Fy) / fN and Mz / fNR, each row in its own load
    (``scale`` = N_run / N_static), f fixed: the residuals ``fepost diagnose``
    weighs, without its noise model and its free f.
    """
    from scipy.optimize import least_squares

    n0 = float(np.sum(quad.sigma * quad.dA))
    unit = np.array([1.0, 1.0, 1.0 / R]) / (friction * n0 * scale[:, None])

    def residual(h):
        return ((_shifted_forces(quad, kin, h, scale, friction) - target) * unit).ravel()

    sol = least_squares(residual, x0=np.array([0.01, 0.01]), bounds=([-0.5, -0.5], [0.5, 0.5]), x_scale=0.01)
    return float(sol.x[0]), float(sol.x[1])


def heights(table, static, preds, shifts, shift_law, friction: float, diagnosis: Path | None) -> list[str]:
    """Markdown: the load-transfer heights from the maps and from three force targets (module docstring).

    Each row also says what its h does with the other data: the RMS force and
    torque misfit against the FE (in-sample) and the RMS error of the
    centre-of-pressure shift h F / N against the runs' own maps.
    """
    from fepost.friction.law import FrictionLaw
    from fepost.friction.quadrature import PressureQuadrature
    from fepost.rig.extension import shifted_resultants

    quad = PressureQuadrature.from_polar(static.static_map)
    kin = tuple(np.array([getattr(r, k) for r in table.runs]) for k in ("vx", "vy", "wz"))
    n_run = np.array([r.reaction.N for r in table.runs])
    scale = n_run / static.coefficients.N
    moved = shifted_resultants(quad, *kin, dx=shifts[:, 0], dy=shifts[:, 1], law=FrictionLaw(f=friction))
    fe = np.array([[r.reaction.Fx, r.reaction.Fy, r.reaction.Mz] for r in table.runs])
    force = np.array([[r.shear.Fx / r.shear.N, r.shear.Fy / r.shear.N] for r in table.runs])
    R = static.coefficients.R
    rows = [("the runs' maps: centre-of-pressure shift against F / N (as (e))", shift_law.h_x, shift_law.h_y)]
    for label, target in (
        (
            "forces of the static map moved by each run's own shift (rigid: no shape change)",
            np.column_stack([moved.Fx, moved.Fy, moved.Mz]) * scale[:, None],
        ),
        ("forces of (c), the run's own map (shape change, rigid slip: no compliance)", preds["own"]),
        ("forces of the FE (solver's reactions: shape change and compliance)", fe),
    ):
        hx, hy = _fit_heights(quad, kin, target, scale, R, friction)
        rows.append((label, hx, hy))
    if diagnosis is not None and diagnosis.exists():
        values = json.loads(diagnosis.read_text()).get("parameters", {})
        if "h_x" in values and "h_y" in values:
            rows.append(
                (
                    "`fepost diagnose` on the FE reactions (f free, its noise model)",
                    float(values["h_x"]["value"]),
                    float(values["h_y"]["value"]),
                )
            )
    lines = []
    for label, hx, hy in rows:
        d = (_shifted_forces(quad, kin, (hx, hy), scale, friction) - fe) / (friction * n_run[:, None])
        rms_f = float(np.sqrt(np.mean(d[:, 0] ** 2 + d[:, 1] ** 2)))
        rms_m = float(np.sqrt(np.mean((d[:, 2] / R) ** 2)))
        err = shifts - force * np.array([hx, hy])
        rms_d = float(np.sqrt(np.mean(np.sum(err**2, axis=1))))
        lines.append(
            f"| {label} | {hx * 1e3:.1f} | {hy * 1e3:.1f} | {rms_f:.4f} | {rms_m:.4f} | {rms_d * 1e3:.2f} |"
        )
    return [
        "",
        "Load-transfer heights found in different ways (h / mm), and what each does: RMS misfit of the "
        "shifted static map against the FE forces (in-sample; fN, fNR) and RMS error of the "
        "centre-of-pressure shift h F / N against the runs' maps (mm):",
        "",
        "| from | h_x | h_y | RMS \\|dF\\| / fN | RMS dMz / fNR | RMS shift error / mm |",
        "|---|---|---|---|---|---|",
        *lines,
    ]


#: The tracked folder each rig folder's study is kept in (rewritten only with --update).
TRACKED = {
    "rig": REPO / "docs" / "rig",
    "rig-aircraft": REPO / "docs" / "rig" / "aircraft",
    "rig-tire360": REPO / "docs" / "rig" / "tire360",
}


class _Progress:
    """``rig_study: [k/n] step ... done in t s`` lines on stderr, one per step."""

    def __init__(self, total: int) -> None:
        self.total, self.k = total, 0

    def __call__(self, name: str, func, *args):
        import time

        self.k += 1
        print(f"rig_study: [{self.k}/{self.total}] {name} ...", end="", file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        try:
            value = func(*args)
        except BaseException:
            print(" failed", file=sys.stderr, flush=True)
            raise
        print(f" done in {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
        return value

    @staticmethod
    def tick() -> None:
        """One dot on the current step's line (one unit of its work done)."""
        print(".", end="", file=sys.stderr, flush=True)


def output_folder(rig: Path, out: Path | None, update: bool) -> Path:
    """Where the study writes: ``--out``, the tracked folder with ``--update``, else
    ``out/<rig folder name>`` in the working folder."""
    if update:
        if out is not None:
            raise SystemExit("rig_study: --update writes the tracked folder; give either --out or --update")
        tracked = TRACKED.get(rig.resolve().name)
        if tracked is None or rig.resolve() != (REPO / "meshes" / rig.resolve().name).resolve():
            known = ", ".join(f"meshes/{k}" for k in TRACKED)
            raise SystemExit(f"rig_study: --update: {rig} has no tracked study (only {known})")
        return tracked
    return out if out is not None else Path("out") / rig.resolve().name


def main(argv=None) -> int:
    """The command line (module docstring); fepost's errors end it with one line and status 2."""
    from fepost.errors import FepostError

    try:
        return _main(argv)
    except FepostError as err:
        print(f"rig_study: {err}", file=sys.stderr)
        return 2


def _main(argv) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rig", type=Path, default=REPO / "meshes" / "rig")
    ap.add_argument("--out", type=Path, default=None, help="output folder (default out/<rig folder name>)")
    ap.add_argument(
        "--update",
        action="store_true",
        help="rewrite the tracked copy the documentation shows (docs/rig/...)",
    )
    ap.add_argument("--friction", type=float, default=0.3)
    ap.add_argument(
        "--diagnosis", type=Path, default=None, help="a `fepost diagnose` diagnosis.json to compare h with"
    )
    ap.add_argument(
        "--runs",
        nargs="+",
        default=None,
        metavar="NAME",
        help="only these runs of the folder (e.g. the runs two rigs share, to set them side by side)",
    )
    ap.add_argument(
        "--longer",
        nargs="+",
        type=Path,
        default=[],
        metavar="DIR",
        help="folders of the same runs solved longer or with smaller increments from the same base: "
        "each replaces the rig's run of its name (a later folder's an earlier one's)",
    )
    ap.add_argument(
        "--no-extension",
        action="store_true",
        help="(a)-(d) and the decomposition only: no load-transfer extension (e) and no heights "
        "(for a programme whose held-out folds cannot identify (e) yet)",
    )
    args = ap.parse_args(argv)
    out = output_folder(args.rig, args.out, args.update)
    runs = _runs(args.rig)
    if not runs:
        print(f"rig_study: no rig runs in {args.rig}", file=sys.stderr)
        return 2
    if args.runs is not None:
        names = {p.stem: p for p in runs}
        unknown = [n for n in args.runs if n not in names]
        if unknown:
            print(f"rig_study: --runs: no run {', '.join(unknown)} in {args.rig}", file=sys.stderr)
            return 2
        runs = [names[n] for n in dict.fromkeys(args.runs)]
    runs, replaced = replace_runs(args.rig, runs, args.longer)
    step = _Progress(5 if args.no_extension else 8)
    table, static, preds, shifts = step(
        f"predictions (a)-(d) over {len(runs)} runs, a dot per run's own map",
        predictions,
        args.rig,
        runs,
        args.friction,
        step.tick,
    )
    shift_law = None
    if not args.no_extension:
        ext, shift_law = step(
            "load-transfer extension (e), held out by direction",
            extension,
            table,
            static,
            shifts,
            args.friction,
        )
        preds.update(ext)
    rows, summary = misfit_table(table, static, preds, args.friction)
    write_outputs(out, rows, summary, static, len(runs))
    with open(out / "table.txt", "a") as fh:
        if replaced:
            fh.write(f"\n{len(replaced)} runs from other folders (path, slide steps):\n")
            fh.write("".join(f"- {line}\n" for line in replaced))
        if shift_law is None:
            fh.write("\n(e) and the load-transfer heights not computed (--no-extension).\n")
        else:
            fh.write("\n".join(law_lines(shift_law)) + "\n")
    conv = step(
        "convergence (finer mesh, smaller increments, longer slides)",
        convergence,
        args.rig,
        static,
        args.friction,
    )
    if conv:
        head = [
            "",
            "Convergence (Fx, Fy in fN, Mz in fNR, each run in its own N; R as above):",
            "",
            "| run | repeated with | programme | repeat | \\|dF\\| / fN | \\|dMz\\| / fNR | N change |",
            "|---|---|---|---|---|---|---|",
        ]
        with open(out / "table.txt", "a") as fh:
            fh.write("\n".join(head + conv) + "\n")
    steady = step("steady state over the last 20 % of each path", steady_state, runs, args.friction)
    found = []
    if shift_law is not None:
        found = step(
            "load-transfer heights, four ways",
            heights,
            table,
            static,
            preds,
            shifts,
            shift_law,
            args.friction,
            args.diagnosis,
        )
    with open(out / "table.txt", "a") as fh:
        fh.write("\n".join(steady_lines(steady)) + "\n")
        fh.write("".join(f"{line}\n" for line in found))
    step("figures per sliding direction", figures, out, rows)
    if shift_law is not None:
        step("figure of the shifts", shift_figure, out, table, shifts, shift_law)
    step("figure of the histories", history_figure, args.rig, out, runs, args.friction)
    print((out / "table.txt").read_text())
    print(f"rig_study: wrote {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
