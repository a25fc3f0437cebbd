"""``load_transfer``: the centre of pressure moves with the friction force.

A tire tilts under traction: its centre of pressure moves by

    dx_i = h_x · Fx_i / N_i,    dy_i = h_y · Fy_i / N_i

(h_x, h_y effective heights in m; Fx, Fy the friction force on the tire, N the
row's load), so every test point has its own shift of the pressure map, which
in turn changes the force. The model solves that fixed point per row with the
exact integrals of the moved map. Moving the map by d is the same as keeping it
and moving the kinematics to v + ω×d (the sliding velocity of the moved
origin), with the torque about the patch origin gaining d × F
(`Predictor.coulomb_moved`; the synthetic data move the map itself,
`PressureQuadrature.shifted`, and the tests compare the two). So one exact
evaluation gives every row its own shift at once.

Fitting follows ``pressure_shift`` (`fepost.diagnose.models`): ``expand(values)``
evaluates the exact resultants at the rows' converged shifts d⁰ and at d⁰ ± δ
along x and y (δ = `SHIFT_STEP` × R, plus one mixed point), builds each
row's second-order Taylor model of the resultants in its own shift, and solves
the fixed point in that local model (exact at d⁰). ``predict(values)`` (the exact
model) starts from the local model about zero shift and corrects the shifts by
Newton steps on exact evaluations until they move by less than
`SHIFT_TOL` × R (`MAX_EXACT` evaluations at most; the map
d ↦ h F(d)/N contracts for |h| f ≲ the patch radius, the parameter bounds).
Where it does not (a map of a few small supports, whose force turns sharply as the
centre of rotation passes a support), the shifts are kept finite and within the patch
radius R (`_bounded`: a centre of pressure cannot leave the patch), so the model
predicts poorly there and the fit moves away, instead of the iteration running to
infinity.

h_x, h_y are the effective heights; h = 0 is no effect (``friction_level``). The
model combines with the sensor causes (offsets, crosstalk: applied after), not
with the other physical extensions.
"""

from __future__ import annotations

import numpy as np

from .models import Candidate, Parameter, Predictor, apply_sensor

#: Shift step of the local model's differences, in units of the patch radius R.
SHIFT_STEP = 0.01
#: The exact fixed point stops when every row's shift moves by less than this × R.
SHIFT_TOL = 1e-7
#: Exact evaluations of one exact prediction, at most.
MAX_EXACT = 6
#: Iterations of the fixed point inside a local model.
LOCAL_ITERATIONS = 60


def _bounded(d: np.ndarray, previous: np.ndarray, radius: float) -> np.ndarray:
    """Shifts ``d`` (n, 2) with non-finite rows put back to ``previous`` and rows longer
    than ``radius`` scaled back to it (module docstring)."""
    d = np.where(np.all(np.isfinite(d), axis=1)[:, None], d, previous)
    length = np.hypot(d[:, 0], d[:, 1])
    return d * np.minimum(1.0, radius / np.maximum(length, 1e-300))[:, None]


def _local(B0, G, H, d0):
    """The resultants' second-order model in each row's shift: d (n, 2) -> (n, 3)."""

    def at(d):
        e = d - d0
        return B0 + np.einsum("ncj,nj->nc", G, e) + 0.5 * np.einsum("ncjk,nj,nk->nc", H, e, e)

    return at


def _derivatives(pred: Predictor, d0: np.ndarray, step: float):
    """Exact B at d⁰ and its first and second differences in each row's (dx, dy)."""
    ex, ey = np.array([step, 0.0]), np.array([0.0, step])

    def ev(d):
        return pred.coulomb_moved(d[:, 0], d[:, 1])

    B0 = ev(d0)
    bxp, bxm, byp, bym = ev(d0 + ex), ev(d0 - ex), ev(d0 + ey), ev(d0 - ey)
    bxy = ev(d0 + ex + ey)
    G = np.stack([(bxp - bxm) / (2 * step), (byp - bym) / (2 * step)], axis=-1)
    hxx = (bxp - 2 * B0 + bxm) / step**2
    hyy = (byp - 2 * B0 + bym) / step**2
    hxy = (bxy - bxp - byp + B0) / step**2
    H = np.stack([np.stack([hxx, hxy], -1), np.stack([hxy, hyy], -1)], -1)
    return B0, G, H


def load_transfer_model(
    pred: Predictor,
    name: str,
    parameters: tuple[Parameter, ...],
    nested: tuple[str, ...],
    description: str,
    extensions: tuple[str, ...],
) -> Candidate:
    """The ``load_transfer`` model (module docstring), with sensor terms when ``parameters`` have them."""
    index = {p.name: j for j, p in enumerate(parameters)}
    scale = pred.scale
    R = pred.sim.radius
    step = SHIFT_STEP * R
    per_force = scale[:2][None, :] / pred.loads[:, None]  # scaled force -> F/N
    zero = np.zeros((pred.n, 2))
    state: dict = {}

    def heights(p):
        return np.array([p[index["h_x"]], p[index["h_y"]]])

    def target(p, B):
        return heights(p)[None, :] * p[index["f"]] * B[:, :2] * per_force

    def solve_local(p, model, d):
        for _ in range(LOCAL_ITERATIONS):
            new = _bounded(target(p, model(d)), d, R)
            if np.max(np.abs(new - d)) < SHIFT_TOL * R:
                return new
            d = new
        return d

    def about_zero():
        if "zero" not in state:
            state["zero"] = _derivatives(pred, zero, step)
        return state["zero"]

    def exact_shift(p):
        """Each row's shift at the exact fixed point, and the resultants there."""
        B0, G, H = about_zero()
        d = solve_local(p, _local(B0, G, H, zero), zero)
        k = heights(p)[None, :, None] * p[index["f"]] * per_force[:, :, None]
        jac = np.eye(2)[None] - k * G[:, :2, :]  # d(d - target)/dd, rows (n, 2, 2)
        B = pred.coulomb_moved(d[:, 0], d[:, 1])
        for _ in range(MAX_EXACT - 1):
            r = target(p, B) - d
            if np.max(np.abs(r)) < SHIFT_TOL * R:
                break
            d = _bounded(d + np.linalg.solve(jac, r[..., None])[..., 0], d, R)
            B = pred.coulomb_moved(d[:, 0], d[:, 1])
        return d, B

    def predict(p):
        p = np.asarray(p, float)
        return apply_sensor(index, p, p[index["f"]] * exact_shift(p)[1], scale)

    def expand(at, order: int = 2) -> Candidate:
        at = np.asarray(at, float)
        d0 = exact_shift(at)[0]
        B0, G, H = _derivatives(pred, d0, step)
        if order < 2:
            H = np.zeros_like(H)
        model = _local(B0, G, H, d0)

        def local(p):
            p = np.asarray(p, float)
            d = solve_local(p, model, d0)
            return apply_sensor(index, p, p[index["f"]] * model(d), scale)

        kind = "local quadratic model" if order > 1 else "local linear model"
        return Candidate(name, parameters, local, nested, f"{description} ({kind})", None, extensions)

    return Candidate(name, parameters, predict, nested, description, expand, extensions)
