"""The tire between sliding and gripping: a brush of tread elements over the FE contact patch.

The rigid wheel of `fepost.shimmy.equations` slides over its whole patch. A real
tire grips where the slip is small: its tread deflects, and only where the
deflection's force reaches the local friction limit does it slide. This module
models that with the classical brush (Pacejka, *Tire and Vehicle Dynamics*, ch. 3),
built on fepost's data:

* the elements: the FE pressure map (`fepost.friction.quadrature.PressureQuadrature`)
  binned into ``nx`` × ``ny`` cells over its loaded nodes; element i sits at the
  load centroid (x_i, y_i) of its cell (patch frame, origin the static centre of
  pressure) and carries the cell's load n_i, so its friction limit is f n_i;
* the stiffness: the tire's tangential stiffness K_x, K_y (N/m, tire against road
  at standstill, carcass and tread in series) shared among the elements by loaded
  area, k_i = K A_i / A. Where they come from is the caller's (`rig_stiffness`
  reads them from the rig runs' force build-up);
* the deflection e_i (m, road contact point relative to its root on the wheel);
  the force of the road on the tire through element i is F_i = (k_xi e_xi, k_yi e_yi).

Kinematics (docs/theory.md, section 3): for the patch origin sliding at (vx, vy)
and spinning at wz, the wheel's material point at (x_i, y_i) moves over the road at
w_i = (vx − wz y_i, vy + wz x_i). The tread runs backwards through the patch at the
rolling speed V_r = Ω R_e, entering undeflected at the leading edge. Along each row
of cells (spacing h, first-order upwind):

    ė_i = d_i − λ_i F̂_i,     d_i = −w_i + V_r (e_ahead − e_i)/h

with λ_i = 0 while the element sticks (|F_i| < f n_i, or |F_i| = f n_i and the
force turning inwards) and otherwise the slip rate that keeps |F_i| = f n_i
(λ = F̂·K d / F̂·K F̂, Coulomb: the tip slides along the force, dissipating
|F_i| λ_i); a force past the limit (integration drift) returns to it at the rate
`BrushTire.beta`, which also gives the linearisation a definite side. The tire's
resultants are F = Σ F_i and Mz = Σ (x_i F_yi − y_i F_xi).

Limits (tested): every element sliding (the slip large against the elastic
deflection f n_i/k_i, or the stiffness going to infinity at a finite slip), the
forces are Σ −f n_i ŵ_i, the exact Coulomb integrals over the binned map, i.e.
the rigid sliding wheel of `fepost.shimmy.equations`; no element sliding (small
motions about free rolling), the brush is linear with cornering and slip stiffness
C ≈ K a_eff and relaxation length ≈ the patch's half-length, and with the
stiffness to infinity and the patch to a point it becomes the non-holonomic wheel
(rolling without side slip).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import ArgumentError

#: Default element grid (cells along x and y).
NX, NY = 16, 6
#: The rig runs (meshes/rig-aircraft) whose first increments give K_x and K_y, and the
#: path (m) over which the force is read as elastic (the rig's stick slope adds 0.36 mm at peak).
RIG_RUNS = {"x": "d000_slide", "y": "d090_slide"}
RIG_ELASTIC_PATH = 1e-4
#: Least rate (1/s) at which a sliding element's force returns to its limit (`BrushTire.beta`).
RETURN_RATE = 200.0
#: Relative closeness to the friction limit read as on it (the steady march's round-off).
ON_LIMIT = 1e-9


@dataclass(frozen=True)
class BrushTire:
    """Tread elements over a contact patch (module docstring).

    ``x``, ``y``: element positions (m); ``limit``: f n_i (N) at the full load;
    ``kx``, ``ky``: element stiffnesses (N/m); ``ahead``: index of the element
    ahead in the same row (−1 at the leading edge); ``h``: the row spacing (m);
    ``R``: the patch radius (m) of spin speeds; ``f``, ``load``: friction level and
    normal load (N); ``provenance``: where each parameter comes from; ``blend``: 0 for
    the sharp stick-slip switch, else the share of the friction limit below it over
    which an element's slip rate is blended in from 0 (a smooth switch for the time
    integration's steps; the dissipation |F_i| λ_i stays exact, so does the energy
    balance).
    """

    x: np.ndarray
    y: np.ndarray
    limit: np.ndarray
    kx: np.ndarray
    ky: np.ndarray
    ahead: np.ndarray
    h: float
    R: float
    f: float
    load: float
    provenance: dict = field(default_factory=dict)
    blend: float = 0.0

    @property
    def n(self) -> int:
        """Number of elements."""
        return int(self.x.size)

    @property
    def half_length(self) -> float:
        """Half the patch length along x (m): the brush's relaxation length to first order."""
        return 0.5 * self.h * (int(np.max(self._row_position())) + 1)

    def slip_stiffness(self) -> float:
        """C_κ (N): the steady longitudinal force per unit slip of small slips, every element sticking,
        Σ k_xi h (m_i + 1) with m_i the element's place in its row from the leading edge (the steady
        march's e_i = −h (m_i + 1) κ / (1 − κ), κ → 0)."""
        return float(np.sum(self.kx * self.h * (self._row_position() + 1)))

    def _row_position(self) -> np.ndarray:
        pos = np.zeros(self.n, int)
        for i in range(self.n):
            j, k = i, 0
            while self.ahead[j] >= 0:
                j, k = int(self.ahead[j]), k + 1
            pos[i] = k
        return pos

    @classmethod
    def from_quadrature(
        cls, quad, *, f: float, stiffness: tuple[float, float], nx: int = NX, ny: int = NY, provenance=None
    ) -> BrushTire:
        """Bin ``quad``'s loaded nodes into ``nx`` × ``ny`` elements; ``stiffness`` = (K_x, K_y) N/m."""
        kx_total, ky_total = (float(k) for k in stiffness)
        if not (f > 0 and kx_total > 0 and ky_total > 0 and math.isfinite(kx_total * ky_total)):
            raise ArgumentError(
                f"friction level and stiffness must be positive and finite, got {f!r}, {stiffness!r}"
            )
        if nx < 1 or ny < 1:
            raise ArgumentError(f"the element grid must be at least 1 x 1, got {nx} x {ny}")
        loaded = quad.sigma > 0
        px, py, w = quad.x[loaded], quad.y[loaded], (quad.sigma * quad.dA)[loaded]
        area = quad.dA[loaded]
        if px.size == 0:
            raise ArgumentError("the pressure map has no loaded node")
        x0, x1 = float(px.min()), float(px.max())
        y0, y1 = float(py.min()), float(py.max())
        h = (x1 - x0) / nx if x1 > x0 else 1e-3
        hy = (y1 - y0) / ny if y1 > y0 else 1e-3
        # row 0 of the grid at the leading edge (largest x)
        ix = np.minimum(((x1 - px) / h).astype(int), nx - 1) if x1 > x0 else np.zeros(px.size, int)
        iy = np.minimum(((py - y0) / hy).astype(int), ny - 1) if y1 > y0 else np.zeros(px.size, int)
        cell = ix * ny + iy
        load = np.bincount(cell, w, nx * ny)
        acell = np.bincount(cell, area, nx * ny)
        keep = load > 0
        cx = np.bincount(cell, w * px, nx * ny)[keep] / load[keep]
        cy = np.bincount(cell, w * py, nx * ny)[keep] / load[keep]
        index = -np.ones(nx * ny, int)
        index[keep] = np.arange(int(keep.sum()))
        ahead_cell = np.arange(nx * ny) - ny
        ahead = np.where(ahead_cell >= 0, index[np.maximum(ahead_cell, 0)], -1)[keep]
        share = acell[keep] / acell[keep].sum()
        total = float(load.sum())
        return cls(
            x=cx,
            y=cy,
            limit=f * load[keep],
            kx=kx_total * share,
            ky=ky_total * share,
            ahead=ahead,
            h=float(h),
            R=float(quad.radius),
            f=float(f),
            load=total,
            provenance=dict(provenance or {}),
        )

    def stiffer(self, factor: float) -> BrushTire:
        """The same brush with every element's stiffness times ``factor``."""
        return replace(self, kx=self.kx * factor, ky=self.ky * factor)

    def shrunk(self, factor: float) -> BrushTire:
        """The patch scaled about its origin by ``factor`` (positions, spacing and radius)."""
        return replace(self, x=self.x * factor, y=self.y * factor, h=self.h * factor, R=self.R * factor)

    # -- the element equations --------------------------------------------------------------
    def rates(self, ex, ey, vx, vy, wz, vr: float, growth: float = 0.0):
        """(ėx, ėy, λ) of the elements for the wheel's slip (vx, vy, wz) at the patch origin.

        ``vr``: rolling speed (m/s); λ: the elements' slip rates (m/s); ``growth``: ṡ/s (1/s)
        of the load share s while the load builds up (see `resultants`): the deflections
        then relax by −(ṡ/s) e, the new, undeflected tread entering the growing patch.
        """
        wx = vx - wz * self.y
        wy = vy + wz * self.x
        ax, ay = self.ahead_deflections(ex, ey)
        dx = -wx + vr * (ax - ex) / self.h - growth * ex
        dy = -wy + vr * (ay - ey) / self.h - growth * ey
        fx, fy = self.kx * ex, self.ky * ey
        fn = np.hypot(fx, fy)
        lim = self.limit
        safe = np.where(fn > 0, fn, 1.0)
        nx, ny = fx / safe, fy / safe
        drive = nx * self.kx * dx + ny * self.ky * dy + self.beta(vr) * (fn - lim)
        stiff = np.where(fn > 0, nx * nx * self.kx + ny * ny * self.ky, 1.0)
        if self.blend > 0:
            share = np.clip((fn / np.where(lim > 0, lim, 1.0) - 1.0) / self.blend + 1.0, 0.0, 1.0)
            lam = np.where((drive > 0) & (fn > 0), share * drive / stiff, 0.0)
        else:
            lam = np.where((fn >= (1 - ON_LIMIT) * lim) & (drive > 0) & (fn > 0), drive / stiff, 0.0)
        return dx - lam * nx, dy - lam * ny, lam

    def ahead_deflections(self, ex, ey) -> tuple[np.ndarray, np.ndarray]:
        """The deflections of the element ahead of each (0 at the leading edge: the tread enters
        undeflected)."""
        has = self.ahead >= 0
        idx = np.where(has, self.ahead, 0)
        return np.where(has, ex[idx], 0.0), np.where(has, ey[idx], 0.0)

    def beta(self, vr: float) -> float:
        """Rate (1/s) at which a sliding element's force returns to the friction limit when past it
        (integration drift, linearisation): well above the tread's transport rate V_r/h."""
        return 2.0 * abs(vr) / self.h + RETURN_RATE

    def resultants(self, ex, ey, scale: float = 1.0) -> tuple[float, float, float]:
        """(Fx, Fy, Mz) of the road on the tire (N, N, N·m about the patch origin).

        ``scale``: the share s of the full load while it builds up: the patch's stiffness
        and its friction limits both grow with it (F_i = s K e_i, |F_i| ≤ s f n_i), so the
        limit in e stays |K e_i| ≤ f n_i.
        """
        fx, fy = scale * self.kx * ex, scale * self.ky * ey
        return float(fx.sum()), float(fy.sum()), float((self.x * fy - self.y * fx).sum())

    def energy(self, ex, ey, scale: float = 1.0) -> float:
        """Elastic energy of the tread (J)."""
        return float(0.5 * scale * (self.kx * ex * ex + self.ky * ey * ey).sum())

    def dissipation(self, ex, ey, lam, scale: float = 1.0) -> float:
        """Power of the sliding elements (W): Σ |F_i| λ_i (|F_i| = s f n_i on the limit)."""
        return float(scale * (np.hypot(self.kx * ex, self.ky * ey) * lam).sum())

    def released(self, ex, ey, vr: float) -> float:
        """Power of the transport term (W, at the full load): Σ F_i · V_r (e_ahead − e_i)/h (the tread
        leaving the patch)."""
        ax, ay = self.ahead_deflections(ex, ey)
        return float(vr / self.h * np.sum(self.kx * ex * (ax - ex) + self.ky * ey * (ay - ey)))

    def on_limit(self, ex, ey) -> np.ndarray:
        """Mask of the elements at their friction limit (|F_i| at f n_i to `ON_LIMIT`)."""
        return np.hypot(self.kx * ex, self.ky * ey) >= (1 - ON_LIMIT) * self.limit

    def steady(self, vx: float, vy: float, wz: float, vr: float) -> tuple[np.ndarray, np.ndarray]:
        """The elements' steady deflections (ex, ey) at a constant slip (the rates' fixed point).

        Marches each row from the leading edge: e_i = e_ahead − (h/V_r) w_i, returned to the
        friction limit along K e/|K e| where it exceeds it (a scalar root per element). With
        ``vr`` = 0 every element slides: F_i = −f n_i ŵ_i.
        """
        wx = vx - wz * self.y
        wy = vy + wz * self.x
        ex, ey = np.zeros(self.n), np.zeros(self.n)
        if vr <= 0:
            wn = np.hypot(wx, wy)
            safe = np.where(wn > 0, wn, 1.0)
            return -self.limit * wx / safe / self.kx, -self.limit * wy / safe / self.ky
        for i in np.argsort(self._row_position(), kind="stable"):
            a = int(self.ahead[i])
            tx = (ex[a] if a >= 0 else 0.0) - self.h * wx[i] / vr
            ty = (ey[a] if a >= 0 else 0.0) - self.h * wy[i] / vr
            ex[i], ey[i] = _return(tx, ty, self.kx[i], self.ky[i], self.limit[i])
        return ex, ey

    def sliding_forces(self, vx, vy, wz):
        """(Fx, Fy, Mz) with every element sliding: Σ −f n_i ŵ_i (arrays of kinematic points)."""
        return sliding_point_forces(self.x, self.y, self.limit, vx, vy, wz)

    def sliding_contact(self):
        """`sliding_forces` as a `fepost.shimmy.contact.Contact` (the brush's full-sliding limit)."""
        from .contact import Contact

        def one(vx, vy, wz):
            fx, fy, mz = self.sliding_forces(vx, vy, wz)
            return float(fx), float(fy), float(mz)

        f0 = -float(self.sliding_forces(1.0, 0.0, 0.0)[0])
        m0 = -float(self.sliding_forces(0.0, 0.0, 1.0)[2])
        return Contact(
            "brush_sliding", self.sliding_forces, self.R, f0, m0, info={"elements": self.n}, scalar=one
        )


def sliding_point_forces(x, y, limit, vx, vy, wz):
    """(Fx, Fy, Mz) of point contacts at (``x``, ``y``) (m), each sliding at its friction limit
    ``limit`` (N) against its motion over the road, for the patch origin's slip (vx, vy, wz)
    (arrays of kinematic points): Σ −limit_i ŵ_i, the moment about the origin."""
    vx, vy, wz = np.broadcast_arrays(*(np.asarray(q, float)[..., None] for q in (vx, vy, wz)))
    wx = vx - wz * y
    wy = vy + wz * x
    wn = np.hypot(wx, wy)
    safe = np.where(wn > 0, wn, 1.0)
    fx = -limit * wx / safe
    fy = -limit * wy / safe
    return fx.sum(-1), fy.sum(-1), (x * fy - y * fx).sum(-1)


def _return(tx: float, ty: float, kx: float, ky: float, lim: float) -> tuple[float, float]:
    """The trial deflection, or its return to |K e| = lim: e_j = t_j / (1 + μ k_j / lim).

    |K e(μ)| is convex and decreasing in μ; its root lies between the roots of the isotropic
    cases with k_max and k_min, and Newton's steps from the lower one approach it from the left.
    """
    size0 = math.hypot(kx * tx, ky * ty)
    if size0 <= lim:
        return tx, ty
    if lim <= 0:
        return 0.0, 0.0
    mu = (size0 / lim - 1.0) * lim / max(kx, ky)
    for _ in range(60):
        ax, ay = 1.0 + mu * kx / lim, 1.0 + mu * ky / lim
        fx, fy = kx * tx / ax, ky * ty / ay
        size = math.hypot(fx, fy)
        if size - lim <= 1e-14 * lim:
            break
        slope = -(fx * fx * kx / ax + fy * fy * ky / ay) / (lim * size)
        mu -= (size - lim) / slope
    return tx / (1.0 + mu * kx / lim), ty / (1.0 + mu * ky / lim)


def rig_stiffness(folder) -> dict:
    """The tire's tangential stiffness K_x, K_y (N/m) from the rig's pure slides (``folder``).

    The rig (docs/rig.md) moves the rim rigidly over the road from the static state; the
    first increments of ``d000_slide`` (along x) and ``d090_slide`` (along y), up to
    `RIG_ELASTIC_PATH` of path, are elastic: the force over the path is the stiffness of
    the tire against the road at standstill (carcass and tread in series, and the rig's
    stick slope, 5e8 Pa/m, which adds about 2 % of compliance).
    """
    out: dict = {}
    for axis, run in RIG_RUNS.items():
        p = Path(folder) / f"{run}.json"
        k, n, name = rig_elastic_slope(p, "path", "F" + axis, RIG_ELASTIC_PATH, "m of path")
        out["K_" + axis] = k
        out["K_" + axis + "_source"] = f"{name}: -F{axis}/path over the first {n} increments"
    return out


def rig_elastic_slope(p: Path, x_key: str, y_key: str, limit: float, unit: str) -> tuple[float, int, str]:
    """(−y/x by least squares through 0, increments used, file name) over the increments of the rig
    run ``p``'s ``history`` with 0 < x ≤ ``limit`` (``unit``: what x is, for the message): the
    elastic start of a slide (force over path) or of a spin (moment over turn)."""
    try:
        hist = json.loads(p.read_text(encoding="utf-8"))["history"]
        x = np.asarray(hist[x_key], float)
        y = np.asarray(hist[y_key], float)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ArgumentError(f"{p}: cannot read the rig run's history ({type(exc).__name__})") from None
    m = (x > 0) & (x <= limit)
    if m.sum() < 2:
        raise ArgumentError(f"{p}: fewer than 2 increments within {limit} {unit}")
    return float(-np.sum(y[m] * x[m]) / np.sum(x[m] ** 2)), int(m.sum()), p.name
