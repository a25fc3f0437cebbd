"""The exact stretched-string tire rolling without sliding: Pacejka's kinematic yaw response.

Pacejka, *Tire and Vehicle Dynamics*, ch. 5 (the string-based out-of-plane models,
around his Eq. 5-78): a string of lateral stiffness c per length under tension,
relaxation length σ, on a contact line of half length a that sticks to the road.
The wheel rolls straight at speed V and yaws by ψ(t) about the contact centre.
In the wheel's frame the deflection v(x, t) of the contact line keeps its
road position, v(x, t) + x ψ(t) = v₁(t') + a ψ(t'), t' = t − (a − x)/V (laid
down at the leading edge), and the string outside the contact decays over σ,
whose slope continuity at the leading edge gives

    v̇₁ + (V/σ) v₁ = V ψ − a ψ̇.

The force and aligning moment on the wheel (per c):

    F_y / c = σ v₁ + ∫ v dx + σ v₂,   M_z / c = σ (a + σ)(v₁ − v₂) + ∫ x v dx,

v₂ = v(−a). For ψ = ψ₀ e^{iωt} everything depends on the path frequency
k = ω/V only: `yaw_response` is the closed form, `simulate_yaw` the same string
marched in time (the contact line shifted by one node per step, the exact
transport, and v₁'s equation integrated by RK4), an independent computation.
For σ = 3a the moment's amplitude dips near a path wavelength 2π/k of 11.65a
(`dip_wavelength`; an anchor of docs/dynamics-anchors.md).
"""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError


def yaw_response(wavelength, a: float, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """(F_y, M_z) per c and per unit yaw amplitude (complex) at path wavelengths ``wavelength`` (m)."""
    lam = np.asarray(wavelength, float)
    if a <= 0 or sigma <= 0 or np.any(lam <= 0):
        raise ArgumentError("a, sigma and the wavelengths must be positive")
    k = 2 * np.pi / lam
    v1 = (1 - 1j * k * a) / (1j * k + 1 / sigma)
    amp = v1 + a  # v(x) = amp e^{-ik(a-x)} - x
    ika = 1j * k
    # ∫_{-a}^{a} e^{-ik(a-x)} dx and ∫ x e^{-ik(a-x)} dx, closed forms
    e2 = np.exp(-2 * ika * a)
    i0 = (1 - e2) / ika
    i1 = (a * (1 + e2)) / ika - (1 - e2) / (ika * ika)
    v2 = amp * e2 + a
    fy = sigma * v1 + amp * i0 + sigma * v2  # ∫ x dx over the patch is 0
    mz = sigma * (a + sigma) * (v1 - v2) + amp * i1 - 2 * a**3 / 3
    return fy, mz


def dip_wavelength(a: float, sigma: float, lo: float = 4.0, hi: float = 30.0) -> float:
    """Path wavelength (m) of the local minimum of |M_z| between ``lo`` a and ``hi`` a."""
    from scipy.optimize import minimize_scalar

    grid = np.linspace(lo * a, hi * a, 400)
    mag = np.abs(yaw_response(grid, a, sigma)[1])
    inner = np.nonzero((mag[1:-1] < mag[:-2]) & (mag[1:-1] < mag[2:]))[0]
    if inner.size == 0:
        raise ArgumentError(
            f"no dip of the aligning moment between {lo:g}a and {hi:g}a for sigma = {sigma:g}"
        )
    i = int(inner[0]) + 1
    res = minimize_scalar(
        lambda w: float(np.abs(yaw_response(w, a, sigma)[1])),
        bracket=(grid[i - 1], grid[i], grid[i + 1]),
        tol=1e-10,
    )
    return float(res.x)


def simulate_yaw(wavelength: float, a: float, sigma: float, *, nodes: int = 400, periods: int = 6):
    """(|F_y|, |M_z|) per c and unit yaw amplitude, by marching the string in time (module docstring).

    The speed is 1 (only the path matters); the step is the node spacing, so the contact
    line's road-fixed points move exactly one node per step. The amplitude is read over
    the last wavelength, after ``periods`` − 1 of settling (σ decays within one or two).
    """
    from scipy.integrate import trapezoid

    if nodes < 8 or periods < 2:
        raise ArgumentError("nodes must be at least 8 and periods at least 2")
    x = np.linspace(a, -a, nodes)  # leading edge first
    dt = float(x[0] - x[1])  # the path per step (V = 1): one node
    k = 2 * np.pi / wavelength
    ys = np.zeros(nodes)  # road positions Y = v + x psi of the contact points
    v1 = 0.0

    def dv1(t, v):
        return np.sin(k * t) - v / sigma - a * k * np.cos(k * t)

    out_f, out_m = [], []
    n = int(np.ceil(periods * wavelength / dt))
    last = n - int(np.ceil(wavelength / dt))
    for step in range(n + 1):
        t = step * dt
        if step:
            s = dt / 4  # v1 over one step, RK4 in 4 sub-steps
            for j in range(4):
                tj = t - dt + j * s
                k1 = dv1(tj, v1)
                k2 = dv1(tj + s / 2, v1 + s * k1 / 2)
                k3 = dv1(tj + s / 2, v1 + s * k2 / 2)
                k4 = dv1(tj + s, v1 + s * k3)
                v1 += s * (k1 + 2 * k2 + 2 * k3 + k4) / 6
            ys[1:] = ys[:-1].copy()
        ys[0] = v1 + a * np.sin(k * t)
        v = ys - x * np.sin(k * t)  # x decreasing: ∫ from −a to a is −trapezoid(., x)
        fy = sigma * v1 - trapezoid(v, x) + sigma * v[-1]
        mz = sigma * (a + sigma) * (v1 - v[-1]) - trapezoid(x * v, x)
        if step >= last:
            out_f.append(fy)
            out_m.append(mz)
    return 0.5 * (max(out_f) - min(out_f)), 0.5 * (max(out_m) - min(out_m))
