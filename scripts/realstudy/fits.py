"""Friction fits, held-out scores, the limit surfaces, across layouts, Table 1 on the pushes."""

from __future__ import annotations

import numpy as np
from scipy import stats

from .layouts import PHYSICS, RHO, SPLIT_SEED, TRAIN_SHARE, Layout

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
