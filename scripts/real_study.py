"""Real pushes of a block that slides and spins: fepost's models, limit surfaces and diagnosis.

    python scripts/real_study.py [--out out/real] [--no-fe] [--no-diagnose]
    python scripts/real_study.py --update        # also rewrites docs/real/ (tracked)

Reads the five hardboard logs of ``../shared/real/planar-sliding`` (Zhou et al., ICRA
2016; the plywood logs are held out and never read) and, per layout:

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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import optimize, stats

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

SHARED = REPO.parent / "shared" / "real" / "planar-sliding"
#: The hardboard layouts (folder names of the upstream logs); the plywood logs are held out.
LAYOUTS = (
    "10_130_10_10_10_130",
    "10_90_10_10_30_130",
    "30_63.33_43.33_30_43.33_63.33",
    "30_90_30_30_30_90",
    "patch",
)
SHORT = {
    "10_130_10_10_10_130": "legs wide",
    "10_90_10_10_30_130": "legs skew",
    "30_63.33_43.33_30_43.33_63.33": "legs close",
    "30_90_30_30_30_90": "legs mid",
    "patch": "flat base",
}
#: Length (m) that makes torques force-like: the flat base's polar radius of gyration about
#: its centroid, √((0.15² + 0.15²)/18) = 0.05 m.
RHO = 0.05
#: The authors' friction coefficient on hardboard: the nominal f of the diagnosis.
NOMINAL_F = 0.28
TRAIN_SHARE = 0.7
SPLIT_SEED = 38
#: Edge decay lengths (m) scanned for the edge-loaded base.
EDGE_LENGTHS = tuple(float(v) for v in np.geomspace(0.001, 0.04, 17))
#: Grid step (m) of the flat base's point sums.
BASE_STEP = 0.001

PHYSICS = ("exact", "paper", "model")
SURFACES = ("ellipsoid", "quartic")
NAMES = {
    "exact": "exact integrals",
    "paper": "paper's closed forms",
    "model": "generalised model",
    "ellipsoid": "ellipsoid (6)",
    "quartic": "convex quartic (15)",
    "points": "point sums (check)",
    "turn": "exact, finite turn",
    "fe": "exact, FE map (--fe)",
    "edge": "base loaded at its edges (2)",
}


def log(msg: str, t0: float) -> None:
    print(f"[{time.time() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)


@dataclass
class Layout:
    """One layout's pushes, its map's predictions at f = 1 and the analysis behind them."""

    name: str
    body: dict
    kin: np.ndarray  # (n, 3) vx, vy (m), wz (rad): the displacement over each push
    W: np.ndarray  # (n, 3) measured friction wrench Fx, Fy (N), Mz (N·m)
    N: float
    R: float
    coefficients: object
    pmap: object
    grid: tuple[int, int]
    pred: dict = field(default_factory=dict)  # model -> (n, 3) at f = 1

    @property
    def n(self) -> int:
        return self.W.shape[0]


# -- inputs -------------------------------------------------------------------------------


def run_cli(argv: list[str]) -> None:
    from fepost.cli import main

    status = main(argv)
    if status != 0:
        raise SystemExit(f"fepost {' '.join(argv)} failed with status {status}")


def prepare(name: str, out: Path, *, fe: bool) -> dict:
    """Run ``fepost pushes`` and ``fepost map`` (and ``map --fe`` for the base) into ``out/name``."""
    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    body = SHARED / "bodies" / f"{name}.json"
    logf = SHARED / f"hardboard_{name}.txt"
    paths = {"body": body, "log": logf, "csv": folder / "pushes.csv", "map": folder / "map.vtu"}
    if not paths["csv"].is_file():
        run_cli(["pushes", str(logf), "--body", str(body), "--out", str(paths["csv"])])
    if not paths["map"].is_file():
        run_cli(["map", str(body), "--out", str(paths["map"])])
    if fe and "base" in json.loads(body.read_text()):
        paths["fe"] = folder / "map_fe.vtu"
        if not paths["fe"].is_file():
            run_cli(["map", str(body), "--out", str(paths["fe"]), "--fe"])
    return paths


def analysed(map_path: Path):
    """The map analysed at f = 1 on the grid its sidecar recommends."""
    import fepost

    side = json.loads(map_path.with_suffix(".json").read_text())
    nr, nphi = int(side["grid"]["nr"]), int(side["grid"]["nphi"])
    return fepost.analyse(str(map_path), friction=1.0, nr=nr, nphi=nphi), (nr, nphi)


def predict_map(an, kin: np.ndarray) -> dict:
    """Exact, paper and generalised wrenches (f = 1) of an analysis at the kinematics ``kin``."""
    return predict_on(an.static_map, an.coefficients, kin)


def predict_on(pmap, coefficients, kin: np.ndarray) -> dict:
    from fepost.friction.law import FrictionLaw
    from fepost.friction.predict import predict

    p = predict(kin[:, 0], kin[:, 1], kin[:, 2], pmap=pmap, coefficients=coefficients, law=FrictionLaw(f=1.0))
    out = {}
    for key, res in (("exact", p.exact), ("paper", p.paper), ("model", p.generalised)):
        out[key] = np.column_stack([res.Fx, res.Fy, res.Mz])
    return out


def load_layout(name: str, paths: dict) -> Layout:
    from fepost.diagnose import read_measured

    d = read_measured(str(paths["csv"]))
    kin = np.column_stack([d.vx, d.vy, d.wz])
    W = np.column_stack([d.Fx, d.Fy, d.Mz])
    body = json.loads(Path(paths["body"]).read_text())
    an, grid = analysed(paths["map"])
    N = float(body["mass"] * body["gravity"])
    lay = Layout(name, body, kin, W, N, an.coefficients.R, an.coefficients, an.static_map, grid)
    lay.pred.update(predict_map(an, kin))
    lay.pred["turn"] = turned_prediction(an, kin)
    pts, wts = support_points(body)
    lay.pred["points"] = point_wrench(pts, wts, kin)
    if "fe" in paths:
        fe, _ = analysed(paths["fe"])
        lay.pred["fe"] = predict_map(fe, kin)["exact"]
    return lay


# -- physics by point sums (independent of fepost's quadrature) ---------------------------------


def finite_turn(kin: np.ndarray) -> np.ndarray:
    """The constant twist (v, ω) that carries the start pose to the end pose: the SE(2) logarithm.

    The CSV's (vx, vy) is the displacement in the start frame and wz the turn θ; a constant
    body twist moves the point by V(θ) v, V = [[sin θ/θ, −(1 − cos θ)/θ], [(1 − cos θ)/θ, sin θ/θ]].
    """
    th = kin[:, 2]
    small = np.abs(th) < 1e-9
    t = np.where(small, 1.0, th)
    s = np.where(small, 1.0, np.sin(t) / t)
    c = np.where(small, 0.0, (1.0 - np.cos(t)) / t)
    det = s * s + c * c
    vx = (s * kin[:, 0] + c * kin[:, 1]) / det
    vy = (-c * kin[:, 0] + s * kin[:, 1]) / det
    return np.column_stack([vx, vy, th])


def turned_prediction(an, kin: np.ndarray) -> np.ndarray:
    """Exact wrenches (f = 1) for the finite turn: the physics in the mid-push body frame.

    The pushes CSV gives the chord of the path and the mean force both in the start frame,
    where each lies Δθ/2 off its direction in the mid-push frame. The body's map acts in its
    own frame, so the constant twist (`finite_turn`, in the mid-push frame to first order in Δθ)
    is predicted there and its force turned back by +Δθ/2 into the start frame (Mz unchanged).
    """
    P = predict_map(an, finite_turn(kin))["exact"]
    half = 0.5 * kin[:, 2]
    c, s = np.cos(half), np.sin(half)
    return np.column_stack([c * P[:, 0] - s * P[:, 1], s * P[:, 0] + c * P[:, 1], P[:, 2]])


def triangle_grid(poly: np.ndarray, step: float) -> np.ndarray:
    """Cell centres of a square grid of ``step`` (m) inside the polygon (the right-triangle base)."""
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    xs = np.arange(lo[0] + step / 2, hi[0], step)
    ys = np.arange(lo[1] + step / 2, hi[1], step)
    X, Y = np.meshgrid(xs, ys)
    P = np.column_stack([X.ravel(), Y.ravel()])
    from matplotlib.path import Path as MplPath

    return P[MplPath(poly).contains_points(P)]


def edge_distance(poly: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Distance (m) of each point to the polygon's boundary."""
    d = np.full(len(P), np.inf)
    for a, b in zip(poly, np.roll(poly, -1, axis=0), strict=True):
        ab = b - a
        t = np.clip(((P - a) @ ab) / (ab @ ab), 0.0, 1.0)
        d = np.minimum(d, np.linalg.norm(P - (a + t[:, None] * ab), axis=1))
    return d


def statics_loads(points: np.ndarray, centre: np.ndarray, N: float) -> np.ndarray:
    """Normal loads of three supports carrying N with their centre of pressure at ``centre``."""
    A = np.vstack([np.ones(3), points.T])
    return np.linalg.solve(A, N * np.array([1.0, centre[0], centre[1]]))


def support_points(body: dict) -> tuple[np.ndarray, np.ndarray]:
    """Contact points (m, about the reference point) and their loads (N) by statics or a uniform base."""
    ref = np.array(body["reference_point"], float)
    N = float(body["mass"] * body["gravity"])
    com = np.array(body["centre_of_mass"], float) - ref
    if "supports" in body:
        pts = np.array(body["supports"], float) - ref
        return pts, statics_loads(pts, com, N)
    pts = triangle_grid(np.array(body["base"], float), BASE_STEP) - ref
    return pts, np.full(len(pts), N / len(pts))


def point_wrench(points: np.ndarray, loads, kin: np.ndarray) -> np.ndarray:
    """Coulomb friction (f = 1) of point contacts: F = −Σ N_i ŵ_i, M = Σ p_i × F_i (N, N·m).

    ``loads``: (m,) or per push (n, m).
    """
    wx = kin[:, 0, None] - kin[:, 2, None] * points[None, :, 1]
    wy = kin[:, 1, None] + kin[:, 2, None] * points[None, :, 0]
    speed = np.hypot(wx, wy)
    speed = np.where(speed > 0, speed, 1.0)
    Fx, Fy = -loads * wx / speed, -loads * wy / speed
    Mz = points[None, :, 0] * Fy - points[None, :, 1] * Fx
    return np.column_stack([Fx.sum(1), Fy.sum(1), Mz.sum(1)])


# -- fits and scores -------------------------------------------------------------------------

SCALE = np.array([1.0, 1.0, 1.0 / RHO])


def fit_level(P: np.ndarray, W: np.ndarray) -> dict:
    """f of W ≈ f P by least squares on (Fx, Fy, Mz/ρ), with a push-clustered 95 % interval."""
    a, b = P * SCALE, W * SCALE
    den = float(np.sum(a * a))
    f = float(np.sum(a * b) / den)
    e = b - f * a
    score = np.sum(a * e, axis=1)  # each push's contribution to the normal equation
    n = len(P)
    se = float(np.sqrt(np.sum(score**2) * n / (n - 1)) / den)
    t = float(stats.t.ppf(0.975, n - 1))
    return {"f": f, "ci95": [f - t * se, f + t * se], "se": se}


def scores(P: np.ndarray, W: np.ndarray) -> dict:
    """Force, torque and wrench-direction errors of predictions P against measurements W."""
    from fepost.limitsurface import wrench_errors

    err = wrench_errors(P, W, RHO)
    F = np.hypot(W[:, 0], W[:, 1])
    rms_f = float(np.sqrt(np.mean(err["force"] ** 2)))
    rms_m = float(np.sqrt(np.mean(err["torque"] ** 2)))
    return {
        "force_rms_N": rms_f,
        "force_rel": rms_f / float(np.sqrt(np.mean(F**2))),
        "torque_rms_Nmm": 1000.0 * rms_m,
        "torque_rel": rms_m / float(np.sqrt(np.mean(W[:, 2] ** 2))),
        "angle_deg": float(np.degrees(np.mean(err["angle"]))),
        "n": len(W),
    }


def gaussian_bic(W: np.ndarray, P: np.ndarray, k: int) -> float:
    """BIC of predictions P (k fitted parameters) with one noise level on (Fx, Fy, Mz/ρ)."""
    r = ((W - P) * SCALE).ravel()
    n = r.size
    return float(n * np.log(np.sum(r * r) / n) + k * np.log(n))


def split(n: int, seed: int = SPLIT_SEED) -> tuple[np.ndarray, np.ndarray]:
    order = np.random.default_rng(seed).permutation(n)
    k = round(TRAIN_SHARE * n)
    return np.sort(order[:k]), np.sort(order[k:])


def fit_surface(kin: np.ndarray, W: np.ndarray, degree: int):
    from fepost.limitsurface import fit_limit_surface

    return fit_limit_surface(W, kin, degree=degree, rho=RHO)


def held_out(lay: Layout, train: np.ndarray, test: np.ndarray) -> dict:
    """Per model: f (or the surface) fitted on ``train``, scores on ``test``."""
    out = {}
    for key in (*PHYSICS, "points", "turn", *(("fe",) if "fe" in lay.pred else ())):
        P = lay.pred[key]
        lev = fit_level(P[train], lay.W[train])
        out[key] = {"fit": lev, "test": scores(lev["f"] * P[test], lay.W[test])}
    for degree, key in ((2, "ellipsoid"), (4, "quartic")):
        surf = fit_surface(lay.kin[train], lay.W[train], degree)
        out[key] = {
            "fit": {"n_params": surf.n_params, "convexity": surf.convexity, **surf.loss},
            "test": scores(surf.wrench(lay.kin[test]), lay.W[test]),
        }
    return out


def across_layouts(layouts: list[Layout]) -> dict:
    """Fit on four layouts, predict the fifth: exact integrals (one f) against the surfaces."""
    out = {}
    for k, lay in enumerate(layouts):
        rest = [x for j, x in enumerate(layouts) if j != k]
        P = np.vstack([x.pred["exact"] for x in rest])
        W = np.vstack([x.W for x in rest])
        K = np.vstack([x.kin for x in rest])
        lev = fit_level(P, W)
        row = {"exact": {"f": lev["f"], "test": scores(lev["f"] * lay.pred["exact"], lay.W)}}
        for degree, key in ((2, "ellipsoid"), (4, "quartic")):
            surf = fit_surface(K, W, degree)
            row[key] = {"test": scores(surf.wrench(lay.kin), lay.W)}
        out[lay.name] = row
    return out


# -- the paper's Table 1 on the pushes --------------------------------------------------------


def table1_curves(lay: Layout):
    """The three test curves of the paper from the pushes (ψ = ωR/|v|, υ = |v|/(ωR)).

    F∥ = −F·v̂ (N) over ψ; M_C = −M sgn ω (N·m) and F⊥ = −F·(ẑ × v̂) sgn ω (N) over υ
    (``fepost.identify.TestCurves``); pushes without spin or without slide sit on one curve only.
    """
    from fepost.identify import TestCurves

    t = lay.kin  # the chord and the mean force, both in the start frame (the pushes CSV)
    v = np.hypot(t[:, 0], t[:, 1])
    u = np.abs(t[:, 2]) * lay.R
    vhat = t[:, :2] / np.where(v > 0, v, 1.0)[:, None]
    sgn = np.sign(t[:, 2])
    fpar = -(lay.W[:, 0] * vhat[:, 0] + lay.W[:, 1] * vhat[:, 1])
    fperp = -(-lay.W[:, 0] * vhat[:, 1] + lay.W[:, 1] * vhat[:, 0]) * sgn
    spin = u > 0
    return TestCurves(
        psi=u / v, f_parallel=fpar, upsilon=v[spin] / u[spin], torque=-lay.W[spin, 2] * sgn[spin],
        f_perp=fperp[spin], R=lay.R, source="data",
    )  # fmt: skip


def table1_rows(lay: Layout, f_exact: float) -> dict:
    """F0, M0, a, m (and k_x) identified from the pushes, beside the map's values at f = f_exact."""
    from fepost.identify import fit_table1

    fit = fit_table1(table1_curves(lay), lay.N, profile=False)
    c = lay.coefficients
    theory = {"F0": f_exact * c.F0, "M0": f_exact * c.M0, "a": c.a, "m": c.m, "k_x": 0.0}
    rows = {}
    for name in ("F0", "M0", "a", "m", "k_x"):
        lo, hi = fit.interval(name)
        rows[name] = {"fitted": fit.value(name), "ci95": [float(lo), float(hi)], "map": theory[name]}
    rows["f"] = {"fitted": fit.f, "ci95": list(fit.f_ci95), "map": f_exact}
    return rows


# -- diagnosis ----------------------------------------------------------------------------------


def diagnose_layout(lay: Layout) -> dict:
    """``fepost.diagnose`` on the layout's pushes, the map on its own grid, nominal f = `NOMINAL_F`."""
    from fepost.diagnose import diagnose
    from fepost.diagnose.measured import MeasuredData
    from fepost.diagnose.simulation import simulation_from_maps

    sim = simulation_from_maps(lay.pmap, friction=NOMINAL_F, nr=lay.grid[0], nphi=lay.grid[1])
    data = MeasuredData(
        vx=lay.kin[:, 0], vy=lay.kin[:, 1], wz=lay.kin[:, 2], Fx=lay.W[:, 0], Fy=lay.W[:, 1],
        Mz=lay.W[:, 2], N=None, roll=np.zeros(lay.n, int), source=lay.name,
        time=np.arange(1.0, lay.n + 1.0),
    )  # fmt: skip
    failed = None
    try:
        d = diagnose(sim, data, friction=NOMINAL_F)
    except (ArithmeticError, ValueError) as exc:  # fepost's errors subclass ValueError
        failed = f"{type(exc).__name__}: {exc}"
        d = _diagnose_without(sim, data, "load_transfer")
    return {
        "failed_with_every_cause": failed,
        "cause": d.cause,
        "causes": list(d.causes),
        "parameters": {
            k: {"value": v.value, "ci95": list(v.ci95), "unit": v.unit} for k, v in d.parameters.items()
        },
        "gain": {k: d.gain[k] for k in ("rmse_before", "rmse_after", "delta_bic")},
        "lack_of_fit": {"detected": bool(d.lack_of_fit["detected"]), "message": d.lack_of_fit["message"]},
        "candidates": [
            {k: v for k, v in _plain(c.to_dict()).items() if k in CANDIDATE_KEYS} for c in d.candidates
        ],
        "outliers": list(d.outliers),
    }


CANDIDATE_KEYS = ("name", "delta_bic", "admissible", "cv_rmse", "reasons", "parameters", "n_params")


def _diagnose_without(sim, data, cause: str):
    """The diagnosis with one cause left out of the vocabulary (after that cause's fit failed)."""
    from unittest import mock

    from fepost.diagnose import causes, diagnose, pairs, pipeline

    def build(pred):
        return {k: v for k, v in causes.build_candidates(pred).items() if k != cause}

    kept = tuple(e for e in causes.EXTENSIONS if e != cause)
    with mock.patch.object(pipeline, "build_candidates", build), mock.patch.object(pairs, "EXTENSIONS", kept):
        return diagnose(sim, data, friction=NOMINAL_F)


def _plain(obj):
    """JSON-ready copy of a diagnosis value (numpy scalars and arrays to Python)."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if hasattr(obj, "to_dict"):
        return _plain(obj.to_dict())
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def pooled_diagnosis(per_log: dict) -> dict:
    """Each cause's ΔBIC summed over the logs (each log with its own parameters) and its spread."""
    names = sorted({c["name"] for d in per_log.values() for c in d["candidates"]})
    rows = []
    for name in names:
        got = {k: next((c for c in d["candidates"] if c["name"] == name), None) for k, d in per_log.items()}
        vals = [c["delta_bic"] for c in got.values() if c is not None]
        rows.append({
            "name": name, "delta_bic_sum": float(np.sum(vals)), "logs": len(vals),
            "admissible_in": [k for k, c in got.items() if c is not None and c["admissible"]],
            "per_log": {k: (None if c is None else c["delta_bic"]) for k, c in got.items()},
        })  # fmt: skip
    rows.sort(key=lambda r: r["delta_bic_sum"])
    return {"candidates": rows, "best": rows[0]["name"] if rows else None}


# -- physics beyond the vocabulary ---------------------------------------------------------------


def leg_friction(lay: Layout, pts: np.ndarray, loads: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """One friction coefficient per leg by linear least squares on the pushes ``idx``."""
    cols = np.stack([point_wrench(pts[i : i + 1], loads[i : i + 1], lay.kin[idx]) for i in range(3)], axis=2)
    A = (cols * SCALE[None, :, None]).reshape(-1, 3)
    mu, *_ = np.linalg.lstsq(A, (lay.W[idx] * SCALE).ravel(), rcond=None)
    return mu


def tilted(pts: np.ndarray, com: np.ndarray, N: float, kin: np.ndarray, f: float, h: float) -> np.ndarray:
    """Friction of three legs whose loads follow the centre of pressure d = −h F/N (fixed point)."""
    F = f * point_wrench(pts, statics_loads(pts, com, N), kin)
    for _ in range(30):
        loads = np.array([statics_loads(pts, com - h * F[i, :2] / N, N) for i in range(len(kin))])
        new = f * point_wrench(pts, loads, kin)
        if np.max(np.abs(new - F)) < 1e-12 * N:
            break
        F = new
    return F


def fit_tilt(lay: Layout, pts, com, idx) -> tuple[float, float]:
    def resid(p):
        return ((tilted(pts, com, lay.N, lay.kin[idx], p[0], p[1]) - lay.W[idx]) * SCALE).ravel()

    res = optimize.least_squares(resid, [0.3, 0.0], bounds=([0.01, -0.2], [2.0, 0.2]))
    return float(res.x[0]), float(res.x[1])


def edge_loaded(lay: Layout, lam: float, kin: np.ndarray | None = None) -> np.ndarray:
    """Coulomb friction (f = 1) of the base with σ ∝ exp(−d/λ), d the distance to its edge,
    at the pushes' kinematics or at ``kin``."""
    poly = np.array(lay.body["base"], float)
    P = triangle_grid(poly, BASE_STEP)
    w = np.exp(-edge_distance(poly, P) / lam)
    ref = np.array(lay.body["reference_point"], float)
    # the same centre of pressure as the uniform base (the centroid): the weights are symmetric
    # only for a symmetric polygon, so the small first moment left is removed by a plane
    w = _same_centre(P - ref, w, np.array(lay.body["centre_of_mass"], float) - ref)
    return point_wrench(P - ref, lay.N * w / w.sum(), lay.kin if kin is None else kin)


def _same_centre(P: np.ndarray, w: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Weights w (1 + a·(p − c)) with a chosen so that their centre is ``centre``."""
    d = P - centre
    A = (w[:, None, None] * d[:, :, None] * d[:, None, :]).sum(0)
    a = np.linalg.solve(A, -(w[:, None] * d).sum(0))
    return w * (1.0 + d @ a)


def fit_edge(lay: Layout, idx: np.ndarray) -> tuple[float, float, dict]:
    """λ by a scan of `EDGE_LENGTHS` with f fitted at each; returns (λ, f, the f = 1 predictions)."""
    best = None
    cache = {}
    for lam in EDGE_LENGTHS:
        P = cache[lam] = edge_loaded(lay, lam)
        f = fit_level(P[idx], lay.W[idx])["f"]
        r = float(np.sum(((lay.W[idx] - f * P[idx]) * SCALE) ** 2))
        if best is None or r < best[0]:
            best = (r, lam, f)
    assert best is not None
    return best[1], best[2], cache


def extras(lay: Layout, train: np.ndarray, test: np.ndarray) -> dict:
    """The physics beyond the vocabulary: BIC (fitted on all pushes) and held-out scores."""
    every = np.arange(lay.n)
    rows = {}
    base = fit_level(lay.pred["exact"][every], lay.W)["f"]
    rows["coulomb"] = {"k": 1, "bic": gaussian_bic(lay.W, base * lay.pred["exact"], 1)}
    ftr = fit_level(lay.pred["exact"][train], lay.W[train])["f"]
    rows["coulomb"]["test"] = scores(ftr * lay.pred["exact"][test], lay.W[test])
    f_all = fit_level(lay.pred["turn"], lay.W)["f"]
    f_tr = fit_level(lay.pred["turn"][train], lay.W[train])["f"]
    rows["finite_turn"] = {
        "k": 1, "bic": gaussian_bic(lay.W, f_all * lay.pred["turn"], 1),
        "test": scores(f_tr * lay.pred["turn"][test], lay.W[test]),
    }  # fmt: skip
    if "supports" in lay.body:
        rows.update(_leg_extras(lay, train, test))
    else:
        rows.update(_base_extras(lay, train, test))
    for r in rows.values():
        r["delta_bic"] = r["bic"] - rows["coulomb"]["bic"]
    return rows


def _leg_extras(lay: Layout, train, test) -> dict:
    pts, loads = support_points(lay.body)
    every = np.arange(lay.n)
    out = {}
    mu_all, mu_tr = leg_friction(lay, pts, loads, every), leg_friction(lay, pts, loads, train)

    def legs(mu, idx):
        return sum(m * point_wrench(pts[i : i + 1], loads[i : i + 1], lay.kin[idx]) for i, m in enumerate(mu))

    out["leg_friction"] = {
        "k": 3, "mu": mu_all.tolist(), "bic": gaussian_bic(lay.W, legs(mu_all, every), 3),
        "test": scores(legs(mu_tr, test), lay.W[test]),
    }  # fmt: skip
    ref = np.array(lay.body["reference_point"], float)
    com = np.array(lay.body["centre_of_mass"], float) - ref
    f_all, h_all = fit_tilt(lay, pts, com, every)
    f_tr, h_tr = fit_tilt(lay, pts, com, train)
    out["finger_tilt"] = {
        "k": 2, "f": f_all, "h_m": h_all,
        "bic": gaussian_bic(lay.W, tilted(pts, com, lay.N, lay.kin, f_all, h_all), 2),
        "test": scores(tilted(pts, com, lay.N, lay.kin[test], f_tr, h_tr), lay.W[test]),
    }  # fmt: skip
    return out


def _bic_at_best_f(lay: Layout, P: np.ndarray) -> float:
    return gaussian_bic(lay.W, fit_level(P, lay.W)["f"] * P, 2)


def _base_extras(lay: Layout, train, test) -> dict:
    out = {}
    if "fe" in lay.pred:
        P = lay.pred["fe"]
        f_all, f_tr = fit_level(P, lay.W)["f"], fit_level(P[train], lay.W[train])["f"]
        out["fe_map"] = {
            "k": 1, "bic": gaussian_bic(lay.W, f_all * P, 1), "test": scores(f_tr * P[test], lay.W[test]),
        }  # fmt: skip
    lam_all, f_all, cache = fit_edge(lay, np.arange(lay.n))
    lam_tr, f_tr, _ = fit_edge(lay, train)
    out["edge_loaded"] = {
        "k": 2, "lambda_m": lam_all, "f": f_all, "lambda_train_m": lam_tr,
        "bic": gaussian_bic(lay.W, f_all * cache[lam_all], 2),
        "test": scores(f_tr * cache[lam_tr][test], lay.W[test]),
        "curve": {f"{lam:.4g}": _bic_at_best_f(lay, P) for lam, P in cache.items()},
    }  # fmt: skip
    return out


# -- figures ----------------------------------------------------------------------------------


def _psi(lay: Layout) -> np.ndarray:
    v = np.hypot(lay.kin[:, 0], lay.kin[:, 1])
    return np.abs(lay.kin[:, 2]) * lay.R / np.where(v > 0, v, np.nan)


def figure_curves(layouts: list[Layout], fits: dict, path: Path) -> None:
    """Measured against predicted |F|/N and |M|/(N R) over ψ = ωR/|v| (the paper's Figures 4–6)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(layouts), figsize=(3.2 * len(layouts), 6.0), sharex=True)
    axes = np.atleast_2d(axes).reshape(2, len(layouts))
    style = {
        "exact": ("tab:blue", "o"), "paper": ("tab:green", "^"), "ellipsoid": ("tab:orange", "s"),
        "quartic": ("tab:purple", "D"), "edge": ("tab:red", "v"),
    }  # fmt: skip
    for j, lay in enumerate(layouts):
        psi = _psi(lay)
        preds = {k: fits[lay.name]["f"][k] * lay.pred[k] for k in ("exact", "paper")}
        preds.update({k: fits[lay.name]["surface"][k].wrench(lay.kin) for k in SURFACES})
        if "edge" in fits[lay.name]:
            lam, f = fits[lay.name]["edge"]
            preds["edge"] = f * edge_loaded(lay, lam)
        for i, (quantity, unit) in enumerate(((_force, lay.N), (_torque, lay.N * lay.R))):
            ax = axes[i, j]
            for key, P in preds.items():
                color, marker = style[key]
                ax.plot(psi, quantity(P) / unit, marker, ms=3.5, mfc="none", color=color, label=NAMES[key])
            ax.plot(psi, quantity(lay.W) / unit, "k.", ms=5, label="measured")
            ax.set_xscale("log")
            ax.grid(alpha=0.3)
            if j == 0:
                ax.set_ylabel("|F| / N" if i == 0 else "|M| / (N R)")
            if i == 1:
                ax.set_xlabel("ψ = |ω| R / |v|")
        axes[0, j].set_title(f"{SHORT[lay.name]} (R = {1000 * lay.R:.0f} mm)", fontsize=10)
    axes[0, 0].legend(fontsize=7, loc="lower left")
    fig.suptitle("Hardboard pushes: measured and predicted (f and surfaces fitted on 70 % of each log)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _force(W: np.ndarray) -> np.ndarray:
    return np.hypot(W[:, 0], W[:, 1])


def _torque(W: np.ndarray) -> np.ndarray:
    return np.abs(W[:, 2])


SLICE_COLOURS = (
    ("exact", "tab:blue"),
    ("ellipsoid", "tab:orange"),
    ("quartic", "tab:purple"),
    ("edge", "tab:red"),
)


def figure_surfaces(layouts: list[Layout], fits: dict, path: Path) -> None:
    """Slices of the limit surfaces (twists in the planes vy = 0 and vx = 0), pushes near them."""
    import matplotlib.pyplot as plt

    chosen = [x for x in layouts if x.name in ("patch", "30_90_30_30_30_90")]
    fig, axes = plt.subplots(len(chosen), 2, figsize=(9.0, 4.2 * len(chosen)), squeeze=False)
    th = np.linspace(0.0, 2.0 * np.pi, 181)
    for i, lay in enumerate(chosen):
        for j, (c, label) in enumerate(((0, "F_x"), (1, "F_y"))):
            ax = axes[i, j]
            t = np.zeros((th.size, 3))
            t[:, c] = np.cos(th)
            t[:, 2] = np.sin(th) / RHO
            curves = {
                "exact": fits[lay.name]["f"]["exact"] * predict_on(lay.pmap, lay.coefficients, t)["exact"]
            }
            curves.update({k: fits[lay.name]["surface"][k].wrench(t) for k in SURFACES})
            if "edge" in fits[lay.name]:
                lam, f = fits[lay.name]["edge"]
                curves["edge"] = f * edge_loaded(lay, lam, t)
            for key, color in SLICE_COLOURS:
                if key not in curves:
                    continue
                W = curves[key]
                ax.plot(W[:, c], W[:, 2] / RHO, "-", color=color, label=NAMES[key])
            tw = np.column_stack([lay.kin[:, 0], lay.kin[:, 1], lay.kin[:, 2] * RHO])
            off = np.degrees(np.arcsin(np.abs(tw[:, 1 - c]) / np.linalg.norm(tw, axis=1)))
            near = off < 25.0
            ax.plot(lay.W[near, c], lay.W[near, 2] / RHO, "k.", label="pushes within 25° of the slice")
            ax.set_xlabel(f"{label} (N)")
            ax.set_ylabel("M_z / ρ (N), ρ = 50 mm")
            ax.set_title(f"{SHORT[lay.name]}: twists with v_{'yx'[c]} = 0", fontsize=10)
            ax.set_aspect("equal")
            ax.grid(alpha=0.3)
        axes[i, 0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


BAR_COLOURS = {
    "exact": "tab:blue", "paper": "tab:green", "model": "tab:cyan", "ellipsoid": "tab:orange",
    "quartic": "tab:purple",
}  # fmt: skip


def figure_errors(held: dict, across: dict, path: Path) -> None:
    """Held-out force and torque errors per model and layout, within a log and across layouts."""
    import matplotlib.pyplot as plt

    keys = ("exact", "paper", "model", "ellipsoid", "quartic")
    names = list(held)
    fig, axes = plt.subplots(1, 3, figsize=(14.0, 4.0))
    x = np.arange(len(names))
    width = 0.8 / len(keys)
    for ax, metric, title in (
        (axes[0], "force_rel", "held-out |ΔF| / |F| (RMS), within each log"),
        (axes[1], "torque_rel", "held-out |ΔM| / |M| (RMS), within each log"),
    ):
        for k, key in enumerate(keys):
            vals = [held[n][key]["test"][metric] for n in names]
            ax.bar(x + k * width, vals, width, label=NAMES[key], color=BAR_COLOURS[key])
        ax.set_title(title, fontsize=10)
    for k, key in enumerate(("exact", "ellipsoid", "quartic")):
        vals = [across[n][key]["test"]["force_rel"] for n in names]
        axes[2].bar(x + k * 0.27, vals, 0.27, label=NAMES[key], color=BAR_COLOURS[key])
    axes[2].set_title("|ΔF| / |F| (RMS), fitted on the other four layouts", fontsize=10)
    for ax in axes:
        ax.set_xticks(x + 0.3, [SHORT[n] for n in names], rotation=20, fontsize=8)
        ax.grid(axis="y", alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_diagnosis(per_log: dict, pooled: dict, path: Path) -> None:
    """ΔBIC of every cause against the simulation per log and summed (pooled); chosen causes boxed."""
    import matplotlib.pyplot as plt

    causes = [r["name"] for r in pooled["candidates"]]
    logs = list(per_log)
    M = np.array(
        [
            [r["per_log"][g] if r["per_log"][g] is not None else np.nan for g in logs]
            for r in pooled["candidates"]
        ]
    )
    M = np.column_stack([M, [r["delta_bic_sum"] for r in pooled["candidates"]]])
    fig, ax = plt.subplots(figsize=(9.0, 0.45 * len(causes) + 1.6))
    shown = np.sign(M) * np.log10(1.0 + np.abs(M))
    lim = np.nanmax(np.abs(shown))
    ax.imshow(shown, cmap="RdBu_r", vmin=-lim, vmax=lim, aspect="auto")
    for i in range(M.shape[0]):
        for j in range(M.shape[1]):
            if np.isfinite(M[i, j]):
                ax.text(j, i, f"{M[i, j]:.0f}", ha="center", va="center", fontsize=7)
    for j, g in enumerate(logs):
        primary = per_log[g]["cause"]
        if primary in causes:
            i = causes.index(primary)
            ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=2.0, ec="k"))
    ax.set_xticks(range(len(logs) + 1), [SHORT[g] for g in logs] + ["pooled (sum)"], fontsize=8)
    ax.set_yticks(range(len(causes)), causes, fontsize=8)
    ax.set_title("ΔBIC of each cause against the simulation (blue: supported; boxed: named)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# -- tables ------------------------------------------------------------------------------------


def _ci(v: float, ci, fmt: str = ".3f") -> str:
    return f"{v:{fmt}} ({ci[0]:{fmt}} – {ci[1]:{fmt}})"


def table_friction(held: dict, checks: dict) -> list[str]:
    lines = [
        "| layout | exact integrals | paper's closed forms | generalised model | point sums (check) "
        "| exact vs point sums (RMS, of N) |",
        "|---|---|---|---|---|---|",
    ]
    for name, h in held.items():
        cells = [_ci(h[k]["fit"]["f"], h[k]["fit"]["ci95"]) for k in ("exact", "paper", "model", "points")]
        lines.append(f"| {SHORT[name]} | " + " | ".join(cells) + f" | {checks[name]:.1%} |")
    return lines


def table_held_out(held: dict) -> list[str]:
    lines = [
        "| layout | model | parameters | held-out \\|ΔF\\| RMS | held-out \\|ΔM\\| RMS | wrench angle |",
        "|---|---|---|---|---|---|",
    ]
    for name, h in held.items():
        for key in (
            "exact",
            "paper",
            "model",
            "turn",
            *(("fe",) if "fe" in h else ()),
            "ellipsoid",
            "quartic",
        ):
            s = h[key]["test"]
            k = h[key]["fit"].get("n_params", 1)
            lines.append(
                f"| {SHORT[name]} | {NAMES[key]} | {k} | {s['force_rms_N']:.2f} N ({s['force_rel']:.0%}) | "
                f"{s['torque_rms_Nmm']:.1f} N·mm ({s['torque_rel']:.0%}) | {s['angle_deg']:.1f}° |"
            )
    return lines


def table_across(across: dict) -> list[str]:
    lines = [
        "| predicted layout | f from the other four | exact: \\|ΔF\\|, \\|ΔM\\| "
        "| ellipsoid: \\|ΔF\\|, \\|ΔM\\| "
        "| quartic: \\|ΔF\\|, \\|ΔM\\| |",
        "|---|---|---|---|---|",
    ]
    for name, row in across.items():
        cells = [
            f"{row[k]['test']['force_rel']:.0%}, {row[k]['test']['torque_rel']:.0%}"
            for k in ("exact", *SURFACES)
        ]
        lines.append(f"| {SHORT[name]} | {row['exact']['f']:.3f} | " + " | ".join(cells) + " |")
    return lines


def table_table1(t1: dict) -> list[str]:
    lines = ["| layout | f = F0/N | F0 (N) | M0 (N·mm) | a | m |", "|---|---|---|---|---|---|"]
    for name, rows in t1.items():
        cells = []
        for key, scale, fmt in (
            ("f", 1, ".3f"),
            ("F0", 1, ".2f"),
            ("M0", 1000, ".0f"),
            ("a", 1, ".2f"),
            ("m", 1, ".2f"),
        ):
            r = rows[key]
            lo, hi = (scale * v for v in r["ci95"])
            cells.append(
                f"{scale * r['fitted']:{fmt}} ({lo:{fmt}} – {hi:{fmt}}); map {scale * r['map']:{fmt}}"
            )
        lines.append(f"| {SHORT[name]} | " + " | ".join(cells) + " |")
    return lines


def table_diagnosis(per_log: dict) -> list[str]:
    lines = [
        "| layout | named | parameters (95 %) | held-out RMSE before → after | ΔBIC | lack of fit |",
        "|---|---|---|---|---|---|",
    ]
    for name, d in per_log.items():
        pars = "; ".join(f"{k} = {_ci(v['value'], v['ci95'], '.4g')}" for k, v in d["parameters"].items())
        g = d["gain"]
        lof = (
            "yes: " + d["lack_of_fit"]["message"].split(":")[1].strip()[:90]
            if d["lack_of_fit"]["detected"]
            else "no"
        )
        lines.append(
            f"| {SHORT[name]} | {' + '.join(d['causes'])}{' ¹' if d['failed_with_every_cause'] else ''} "
            f"| {pars or '–'} | {g['rmse_before']:.3f} → "
            f"{g['rmse_after']:.3f} | {g['delta_bic']:.1f} | {lof} |"
        )
    return lines


def table_pooled(pooled: dict) -> list[str]:
    lines = ["| cause | ΔBIC summed over the five logs | admissible in |", "|---|---|---|"]
    for r in pooled["candidates"]:
        where = ", ".join(SHORT[g] for g in r["admissible_in"]) or "none"
        lines.append(f"| {r['name']} | {r['delta_bic_sum']:.1f} | {where} |")
    return lines


def table_extras(ex: dict) -> list[str]:
    lines = [
        "| layout | model | parameters | ΔBIC vs Coulomb | held-out \\|ΔF\\|, \\|ΔM\\| |",
        "|---|---|---|---|---|",
    ]
    for name, rows in ex.items():
        for key, r in rows.items():
            extra = {k: v for k, v in r.items() if k in ("mu", "h_m", "lambda_m", "f")}
            shown = ", ".join(
                f"{k} = " + (", ".join(f"{x:.3f}" for x in v) if isinstance(v, list) else f"{v:.4g}")
                for k, v in extra.items()
            )
            s = r["test"]
            lines.append(
                f"| {SHORT[name]} | {key.replace('_', ' ')} | {r['k']}{': ' + shown if shown else ''} | "
                f"{r['delta_bic']:.1f} | {s['force_rel']:.0%}, {s['torque_rel']:.0%} |"
            )
    return lines


# -- the study --------------------------------------------------------------------------------


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
    (args.out / "results.json").write_text(json.dumps(_plain(res), indent=1, allow_nan=True) + "\n")
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
