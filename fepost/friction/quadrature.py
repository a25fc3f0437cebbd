"""A pressure field as a flat quadrature rule, ready for the friction integrals.

`PressureQuadrature` holds nodes (x, y) in the patch frame (m), their area
weights dA (m²), the pressure σ (Pa) at the nodes, the elliptic ``domain`` that the
weights integrate over, and ``sigma_at(x, y)``, the pressure at arbitrary points.

Invariant: the weights integrate over exactly ``domain`` (Σ g·dA ≈ ∬_domain g dA),
and σ = 0 outside it. The exact friction integrals rely on this when they add the
singular part at the instantaneous centre of rotation analytically over
``domain`` (see `fepost.friction.exact`). `from_polar`, `stretched`
and `shifted` preserve it.

`edge_grid` builds a polar grid whose radial rule is Gauss–Legendre in t
with ρ = sin(πt/2). It integrates maps with a square-root edge, σ ∝ √(1 − ρ²)
(Hertz), spectrally, where plain Gauss–Legendre in ρ converges only like nr⁻³.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError
from ..polar import PolarGrid, PolarMap

#: Default grid for the friction integrals (see `edge_grid` and the README
#: of ``benchmarks/bench_friction.py``): 64 radial × 128 angular nodes, the
#: smallest grid that meets 1e-4 of fN and M0 on every reference map there.
FRICTION_NR = 64
FRICTION_NPHI = 128


def edge_grid(nr: int = FRICTION_NR, nphi: int = FRICTION_NPHI) -> PolarGrid:
    """A `PolarGrid` with the radial substitution ρ = sin(πt/2).

    Gauss–Legendre nodes t_i, weights w_i on [0, 1]; ρ_i = sin(πt_i/2) and the
    radial weight w_i·(π/2)·cos(πt_i/2) = w_i·dρ/dt. Since √(1 − ρ²) = cos(πt/2),
    a Hertzian edge becomes smooth in t. Periodic trapezoid in φ. Rule name ``"sine"``.
    """
    base = PolarGrid.make(nr, nphi)  # validates nr, nphi
    t = base.rho
    rho = np.sin(0.5 * np.pi * t)
    w_rho = base.w_rho * 0.5 * np.pi * np.cos(0.5 * np.pi * t)
    return PolarGrid(frozen(rho), frozen(w_rho), base.phi, base.w_phi, "sine")


@dataclass(frozen=True)
class Ellipse:
    """Axis-aligned ellipse: centre (cx, cy) and semi-axes (ax, ay), all in m."""

    cx: float
    cy: float
    ax: float
    ay: float

    def __post_init__(self) -> None:
        for name in ("cx", "cy", "ax", "ay"):
            value = getattr(self, name)
            if not np.isfinite(value):
                raise ArgumentError(f"domain {name} must be finite (m), got {value!r}")
            object.__setattr__(self, name, float(value))
        for name in ("ax", "ay"):
            if getattr(self, name) <= 0:
                raise ArgumentError(f"domain {name} must be positive (m), got {getattr(self, name)!r}")

    @property
    def area(self) -> float:
        """π·ax·ay (m²)."""
        return float(np.pi * self.ax * self.ay)

    def level(self, x, y) -> np.ndarray:
        """q = √(((x−cx)/ax)² + ((y−cy)/ay)²): < 1 inside, 1 on the boundary."""
        return np.hypot(
            (np.asarray(x, float) - self.cx) / self.ax, (np.asarray(y, float) - self.cy) / self.ay
        )

    def ray_length(self, px, py, theta) -> np.ndarray:
        """Distance (m) from an inside point (px, py) to the boundary along angle θ.

        The positive root of |((p + ρ ê(θ)) − c)/axes| = 1, a quadratic in ρ.
        ``px, py`` broadcast against ``theta``.
        """
        c, s = np.cos(theta), np.sin(theta)
        dx = (np.asarray(px, float) - self.cx) / self.ax
        dy = (np.asarray(py, float) - self.cy) / self.ay
        ex, ey = c / self.ax, s / self.ay
        qa = ex * ex + ey * ey
        qb = np.asarray(dx * ex + dy * ey)  # half the linear coefficient
        qc = np.minimum(dx * dx + dy * dy - 1.0, 0.0)
        # Positive root in the cancellation-free form: (−b + √(b² − ac))/a where b <= 0,
        # −c / (b + √(b² − ac)) where b > 0 (in place: the rays are up to 65 536 long).
        disc = np.asarray(qb * qb - qa * qc)
        np.sqrt(disc, out=disc)
        rho = np.asarray((disc - qb) / qa)
        disc += qb
        ahead = qb > 0
        rho[ahead] = np.broadcast_to(-qc, rho.shape)[ahead] / disc[ahead]
        return rho

    def max_distance_from(self, x0: float = 0.0, y0: float = 0.0) -> float:
        """Largest distance (m) from (x0, y0) to a point of the ellipse."""
        t = np.linspace(0.0, 2.0 * np.pi, 1 << 14, endpoint=False)
        d2 = (self.cx + self.ax * np.cos(t) - x0) ** 2 + (self.cy + self.ay * np.sin(t) - y0) ** 2
        i = int(np.argmax(d2))
        # Refine by a parabola through the three samples about the maximum.
        h = t[1] - t[0]
        f0, f1, f2 = d2[i - 1], d2[i], d2[(i + 1) % t.size]
        den = f0 - 2 * f1 + f2
        tt = t[i] + (0.5 * h * (f0 - f2) / den if den < 0 else 0.0)
        best = (self.cx + self.ax * np.cos(tt) - x0) ** 2 + (self.cy + self.ay * np.sin(tt) - y0) ** 2
        return float(np.sqrt(max(best, f1)))


SigmaFunction = Callable[[np.ndarray, np.ndarray], np.ndarray]

#: Largest distance of a node from its place on a polar grid (relative to the domain's
#: larger semi-axis) for a ``polar`` layout to be accepted: round-off of the coordinates.
POLAR_TOL = 1e-12


def turn_angles(turns: int) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of 2πk/turns, k = 0..turns−1."""
    a = np.arange(turns) * (2.0 * np.pi / turns)
    return np.cos(a), np.sin(a)


def turn_misfit(x: np.ndarray, y: np.ndarray) -> float:
    """Largest distance of the in-plane vectors (``x``, ``y``)[k] (each (T, n)) from row 0's
    turned by 2πk/T: 0 to round-off when every row is the first turned (a polar grid's
    angles, ring by ring; the groups of turned kinematics of `fepost.friction.turns`)."""
    c, s = turn_angles(x.shape[0])
    x0, y0 = x[:1], y[:1]
    gx = c[:, None] * x0 - s[:, None] * y0
    gy = s[:, None] * x0 + c[:, None] * y0
    return float(np.max(np.hypot(gx - x, gy - y), initial=0.0))


@dataclass(frozen=True)
class PressureQuadrature:
    """A pressure field as nodes, weights and values, with its integration domain.

    ``x``, ``y``: node coordinates in the patch frame (m); ``dA``: weights (m²);
    ``sigma``: pressure at the nodes (Pa); ``domain``: the `Ellipse` the
    weights integrate over (it holds the whole support); ``sigma_at(x, y)``: the
    pressure (Pa) at arbitrary points (m), 0 outside the support. Arrays are flat
    and read-only. ``polar``: (n_r, n_φ) when the nodes are a polar grid about the
    domain's centre, ring by ring, node (i, j) at angle φ_0 + 2πj/n_φ (as `from_polar`
    makes them; the exact integrals use its rotation symmetry, `fepost.friction.turns`).
    """

    x: np.ndarray
    y: np.ndarray
    dA: np.ndarray
    sigma: np.ndarray
    domain: Ellipse
    sigma_at: SigmaFunction
    source: str = ""
    polar: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        arrays = {}
        for name in ("x", "y", "dA", "sigma"):
            arr = frozen(np.ravel(getattr(self, name)))
            if not np.all(np.isfinite(arr)):
                raise ArgumentError(f"{name} must hold finite values, got a non-finite entry")
            arrays[name] = arr
        n = arrays["x"].size
        for name, arr in arrays.items():
            if arr.size != n:
                raise ArgumentError(f"{name} must have {n} entries like x, got {arr.size}")
            object.__setattr__(self, name, arr)
        if np.any(arrays["dA"] < 0):
            raise ArgumentError("dA must be non-negative (m²), got a negative weight")
        if not isinstance(self.domain, Ellipse):
            raise ArgumentError(f"domain must be an Ellipse, got {type(self.domain).__name__}")
        if not callable(self.sigma_at):
            raise ArgumentError(f"sigma_at must be callable, got {type(self.sigma_at).__name__}")
        if self.polar is not None:
            try:
                nr, nphi = (int(v) for v in self.polar)
            except (TypeError, ValueError):
                raise ArgumentError(f"polar must be (n_r, n_phi) or None, got {self.polar!r}") from None
            if nr < 1 or nphi < 1 or nr * nphi != n:
                raise ArgumentError(f"polar {self.polar!r} does not lay out the {n} nodes")
            # node (i, j) of ring i is its node (i, 0) turned by 2πj/nphi
            off = turn_misfit(
                (arrays["x"] - self.domain.cx).reshape(nr, nphi).T,
                (arrays["y"] - self.domain.cy).reshape(nr, nphi).T,
            )
            if not off <= POLAR_TOL * max(self.domain.ax, self.domain.ay):
                raise ArgumentError(
                    f"polar {self.polar!r}: the nodes are not a polar grid about the domain centre, "
                    f"ring by ring (off by {off:.3g} m)"
                )
            object.__setattr__(self, "polar", (nr, nphi))

    # -- constructors -------------------------------------------------------------
    @classmethod
    def from_polar(cls, pmap: PolarMap) -> PressureQuadrature:
        """Nodes, weights and values of a `PolarMap`.

        The domain is the disc of radius ``pmap.radius`` about ``pmap.centre``;
        ``sigma_at`` is the map's bilinear (ρ, φ) interpolation.
        """
        if not isinstance(pmap, PolarMap):
            raise ArgumentError(f"pmap must be a PolarMap, got {type(pmap).__name__}")
        cx, cy = pmap.centre
        x, y = pmap.xy()

        def sigma_at(px, py, _m=pmap, _cx=cx, _cy=cy):
            return _m.interpolate(np.asarray(px, float) - _cx, np.asarray(py, float) - _cy)

        return cls(
            x=x + cx,
            y=y + cy,
            dA=pmap.area_weights(),
            sigma=pmap.sigma,
            domain=Ellipse(cx, cy, pmap.radius, pmap.radius),
            sigma_at=sigma_at,
            source=pmap.source,
            polar=pmap.sigma.shape,
        )

    # -- transforms ---------------------------------------------------------------
    def stretched(self, s: float) -> PressureQuadrature:
        """x → cx + s(x − cx), y → cy + (y − cy)/s about the domain centre.

        Area-preserving (Jacobian 1), so the weights, the load N and the contact
        area are unchanged: the "elliptic patch" hypothesis with aspect s².
        """
        if not (np.isfinite(s) and s > 0):
            raise ArgumentError(f"s must be a positive finite stretch factor, got {s!r}")
        s = float(s)
        d = self.domain
        inner = self.sigma_at

        def sigma_at(px, py):
            px = np.asarray(px, float)
            py = np.asarray(py, float)
            return inner(d.cx + (px - d.cx) / s, d.cy + (py - d.cy) * s)

        return PressureQuadrature(
            x=d.cx + s * (self.x - d.cx),
            y=d.cy + (self.y - d.cy) / s,
            dA=self.dA,
            sigma=self.sigma,
            domain=Ellipse(d.cx, d.cy, d.ax * s, d.ay / s),
            sigma_at=sigma_at,
            source=f"{self.source} stretched({s:g})".strip(),
        )

    def shifted(self, dx: float, dy: float) -> PressureQuadrature:
        """The pressure field moved by (dx, dy) m in the patch frame ("pressure shift")."""
        for name, value in (("dx", dx), ("dy", dy)):
            if not np.isfinite(value):
                raise ArgumentError(f"{name} must be a finite shift in m, got {value!r}")
        dx, dy = float(dx), float(dy)
        d = self.domain
        inner = self.sigma_at

        def sigma_at(px, py):
            return inner(np.asarray(px, float) - dx, np.asarray(py, float) - dy)

        return PressureQuadrature(
            x=self.x + dx,
            y=self.y + dy,
            dA=self.dA,
            sigma=self.sigma,
            domain=Ellipse(d.cx + dx, d.cy + dy, d.ax, d.ay),
            sigma_at=sigma_at,
            source=f"{self.source} shifted({dx:g}, {dy:g})".strip(),
        )

    # -- integrals ----------------------------------------------------------------
    @property
    def load(self) -> float:
        """N = Σ σ dA (N)."""
        return float(self.sigma @ self.dA)

    @property
    def contact_area(self) -> float:
        """Area (m²) of the loaded nodes, σ > 0."""
        return float(self.dA[self.sigma > 0].sum())

    @property
    def mean_pressure(self) -> float:
        """N / contact area (Pa)."""
        area = self.contact_area
        return self.load / area if area > 0 else 0.0

    @property
    def radius(self) -> float:
        """R (m): the smallest circle about the patch origin that holds the domain."""
        return self.domain.max_distance_from(0.0, 0.0)
