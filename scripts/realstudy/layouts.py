"""The study's layouts: the logs and maps of each, its predictions at the pushes' twists, point sums."""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

SHARED = REPO.parent / "shared" / "real" / "planar-sliding"
#: The hardboard layouts (folder names of the upstream logs): the only logs the study reads.
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
