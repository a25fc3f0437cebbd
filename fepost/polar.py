"""Polar quadrature grids on the unit disc and pressure maps sampled on them.

A `PolarGrid` holds nodes ρ ∈ [0, 1] and φ ∈ [0, 2π) with weights such
that, for a patch of radius R,

    ∬ g dA ≈ R² Σ_ij g(ρ_i, φ_j) ρ_i w_i v_j     (``dA`` weights)
    ∫₀¹ h(ρ) dρ ≈ Σ_i h(ρ_i) w_i                  (radial weights)

Two rules are offered:

``"gauss"`` (default)
    Gauss–Legendre nodes in ρ, periodic trapezoid in φ. Exponential convergence
    for smooth maps; second order across the kinks of a piecewise-linear FE field.
``"trapezoid"``
    The paper's rule: equally spaced ρ including 0 and 1, trapezoid weights,
    periodic trapezoid in φ. Second order.

A `PolarMap` is a pressure field (Pa) on such a grid, about a centre, with
radius R (m). Its integrals are in `fepost.moments`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from ._arrays import frozen
from .errors import ArgumentError

Rule = Literal["gauss", "trapezoid"]

#: Default grid, chosen from the convergence study (see README, "Accuracy").
DEFAULT_NR = 64
DEFAULT_NPHI = 128
#: Memory a grid node costs in one run, bytes: measured (peak of ``analyse`` and of the Table 1
#: exact-data fit at 2-8 million nodes: 140-220 bytes per node), doubled for the report's extra
#: maps (the command line's check, `fepost.cli._validate.check_grid`, uses the same figure).
BYTES_PER_NODE = 400


def _memory_limit() -> int:
    """Half the machine's physical memory (4 GB where it cannot be read), bytes."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES")) // 2
    except (AttributeError, OSError, ValueError):
        return 4 << 30


def _size(n: float) -> str:
    for unit, f in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= f:
            return f"{n / f:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


@dataclass(frozen=True)
class PolarGrid:
    """Nodes and weights of a polar quadrature on the unit disc."""

    rho: np.ndarray  # (nr,) radial nodes in [0, 1]
    w_rho: np.ndarray  # (nr,) weights for ∫₀¹ h(ρ) dρ
    phi: np.ndarray  # (nphi,) angles in [0, 2π)
    w_phi: np.ndarray  # (nphi,) weights for ∫₀^{2π} g(φ) dφ
    rule: str

    @classmethod
    def make(cls, nr: int = DEFAULT_NR, nphi: int = DEFAULT_NPHI, rule: Rule = "gauss") -> PolarGrid:
        """Build a grid with ``nr`` radial and ``nphi`` angular nodes."""
        if int(nr) != nr or nr < 2:
            raise ArgumentError(f"nr must be an integer >= 2, got {nr!r}")
        if int(nphi) != nphi or nphi < 4:
            raise ArgumentError(f"nphi must be an integer >= 4, got {nphi!r}")
        nr, nphi = int(nr), int(nphi)
        need = float(nr) * float(nphi) * BYTES_PER_NODE
        limit = _memory_limit()
        if need > limit:
            raise ArgumentError(
                f"polar grid nr x nphi = {nr} x {nphi} = {float(nr) * nphi:.3g} nodes would need about "
                f"{_size(need)} of memory (limit {_size(limit)}, half this machine's, about "
                f"{limit // BYTES_PER_NODE:,} nodes); the default {DEFAULT_NR} x {DEFAULT_NPHI} "
                "is accurate to ~1e-5 on smooth maps"
            )
        if rule == "gauss":
            x, w = np.polynomial.legendre.leggauss(nr)
            rho, w_rho = 0.5 * (x + 1.0), 0.5 * w
        elif rule == "trapezoid":
            rho = np.linspace(0.0, 1.0, nr)
            w_rho = np.full(nr, 1.0 / (nr - 1))
            w_rho[[0, -1]] *= 0.5
        else:
            raise ArgumentError(f"rule must be 'gauss' or 'trapezoid', got {rule!r}")
        phi = np.arange(nphi) * (2.0 * np.pi / nphi)
        w_phi = np.full(nphi, 2.0 * np.pi / nphi)
        return cls(frozen(rho), frozen(w_rho), frozen(phi), frozen(w_phi), rule)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.rho.size, self.phi.size)

    def xy(self, radius: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """Cartesian node coordinates, each of shape (nr, nphi), for a disc of ``radius``."""
        r = radius * self.rho[:, None]
        return r * np.cos(self.phi)[None, :], r * np.sin(self.phi)[None, :]

    def area_weights(self, radius: float = 1.0) -> np.ndarray:
        """Weights dA (m²) of shape (nr, nphi): ∬ g dA ≈ Σ g·dA."""
        return radius**2 * (self.rho * self.w_rho)[:, None] * self.w_phi[None, :]


@dataclass(frozen=True)
class PolarMap:
    """A pressure field sampled on a `PolarGrid` about ``centre``.

    ``sigma`` has shape (nr, nphi) in Pa, ``radius`` is R in m, ``centre`` the
    (x, y) of the grid centre in the patch frame (m; (0, 0) = static centre of
    pressure). ``valid`` marks nodes that fell on the FE surface (others are 0).
    """

    grid: PolarGrid
    radius: float
    sigma: np.ndarray
    centre: tuple[float, float] = (0.0, 0.0)
    valid: np.ndarray | None = field(default=None)
    source: str = ""

    def __post_init__(self) -> None:
        sig = frozen(self.sigma)
        if sig.shape != self.grid.shape:
            raise ArgumentError(f"sigma must have shape {self.grid.shape}, got {sig.shape}")
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise ArgumentError(f"radius must be a positive finite length in m, got {self.radius!r}")
        object.__setattr__(self, "sigma", sig)
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "centre", (float(self.centre[0]), float(self.centre[1])))
        if self.valid is not None:
            object.__setattr__(self, "valid", frozen(self.valid, dtype=bool))

    @classmethod
    def from_function(cls, func, radius: float, grid: PolarGrid | None = None, source: str = "") -> PolarMap:
        """Sample ``func(x, y) -> sigma`` (Pa, x and y in m about the centre) on ``grid``."""
        grid = grid or PolarGrid.make()
        x, y = grid.xy(radius)
        return cls(grid=grid, radius=radius, sigma=np.asarray(func(x, y), float), source=source)

    def xy(self) -> tuple[np.ndarray, np.ndarray]:
        """Node coordinates (m) relative to ``centre``, each (nr, nphi)."""
        return self.grid.xy(self.radius)

    def area_weights(self) -> np.ndarray:
        """Quadrature weights dA (m²), shape (nr, nphi)."""
        return self.grid.area_weights(self.radius)

    def integrate(self, g: np.ndarray | float = 1.0) -> float:
        """∬ σ·g dA over the disc (g sampled on the grid, or a constant)."""
        return float(np.sum(self.sigma * g * self.area_weights()))

    def angular_mean(self) -> np.ndarray:
        """σ̄(ρ): the angular mean of σ at each radial node, Pa."""
        return self.sigma @ self.grid.w_phi / (2.0 * np.pi)

    def interpolate(self, x, y) -> np.ndarray:
        """σ at arbitrary points (m, about ``centre``), bilinear in (ρ, φ); 0 outside R.

        Radial values outside the first/last node are held constant up to ρ = 1.
        """
        x = np.asarray(x, float)
        y = np.asarray(y, float)
        rho = np.hypot(x, y) / self.radius
        phi = np.mod(np.arctan2(y, x), 2.0 * np.pi)
        g = self.grid
        nphi = g.phi.size
        dphi = 2.0 * np.pi / nphi
        t = phi / dphi
        j0 = np.floor(t).astype(int) % nphi
        j1 = (j0 + 1) % nphi
        tj = t - np.floor(t)
        i1 = np.clip(np.searchsorted(g.rho, rho), 1, g.rho.size - 1)
        i0 = i1 - 1
        ti = np.clip((rho - g.rho[i0]) / (g.rho[i1] - g.rho[i0]), 0.0, 1.0)
        s = self.sigma
        val = (1 - ti) * ((1 - tj) * s[i0, j0] + tj * s[i0, j1]) + ti * (
            (1 - tj) * s[i1, j0] + tj * s[i1, j1]
        )
        return np.where(rho <= 1.0, val, 0.0)
