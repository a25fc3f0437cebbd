"""Physics beyond the vocabulary: friction per leg, the finger's tilt, an edge-loaded base."""

from __future__ import annotations

import numpy as np
from scipy import optimize

from .fits import SCALE, fit_level, gaussian_bic, scores
from .layouts import (
    BASE_STEP,
    EDGE_LENGTHS,
    Layout,
    edge_distance,
    point_wrench,
    statics_loads,
    support_points,
    triangle_grid,
)


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
