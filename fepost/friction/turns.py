"""Rotation symmetry of the exact friction integrals: kinematics turned about the patch origin.

The model's fit and check grids (`fepost.friction.build.sphere_nodes`) hold the
same kinematic points turned by 2πk/T, k = 0..T−1 (T directions θ). When the
quadrature is a polar grid about the patch origin with an angle count n_φ that
T divides, turning the kinematics by 2πk/T moves the sliding-velocity field
onto the same nodes, s_k = k·n_φ/T angle steps on:

    w(θ + 2πk/T, node (i, j)) = R(2πk/T) · w(θ, node (i, j − s_k)),

because w = v − ω_z ẑ × p and the in-plane rotation R commutes with ẑ ×. The
node sums Σ_j ŵ(j)·c(j) of every node column c (g dA, g dA x, dA, ...) are then
circular cross-correlations, along the angle index, of the first group's
direction fields with the columns:

    Σ_j ŵ_k(i, j) c(i, j) = R(2πk/T) · Σ_j ŵ_0(i, j − s_k) c(i, j),

summed over the rings i. The direction fields (a square root and a division per
point and node: the bulk of the exact integrals) are computed for the first
group only, 1/T of the points, and the correlations for all shifts at once by
FFT along the angle index (`correlated_sums`). A speed factor of μ goes with
the direction (|w| is the same on the turned node).

The polar moments of the domain about each instantaneous centre of rotation
(`fepost.friction.exact.ray_integrals`) turn alike when the domain is a disc
about the origin: the centre of group k is the first group's turned, and the
moments ∫ ê⊗…⊗ê ρⁿ dθ are tensors of order 1, 2, 3 (`turn_rays`). The periodic
trapezoid that computes them maps onto itself when T divides its node count
(powers of two from 64 up).

Both give the direct sums' numbers to round-off (tests/test_friction_turns.py):
the FFT sums in another order, and turned node coordinates differ from the
stored ones in the last bit.
"""

from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from .quadrature import PressureQuadrature, turn_angles, turn_misfit

#: Largest distance of a point of group k from group 0's turned, relative to the
#: largest speed scale of the kinematics, accepted as "the same point turned".
GROUP_TOL = 1e-12


def polar_layout(quad: PressureQuadrature, turns: int) -> tuple[int, int] | None:
    """(n_r, n_φ) when ``quad`` is a polar grid about the patch origin whose angle count
    ``turns`` divides and whose domain is a disc about the origin (else None: the sums
    are done directly)."""
    if turns < 2 or quad.polar is None:
        return None
    nr, nphi = quad.polar
    d = quad.domain
    if nphi % turns or d.cx != 0.0 or d.cy != 0.0 or d.ax != d.ay:
        return None
    return nr, nphi


def check_groups(vx: np.ndarray, vy: np.ndarray, wz: np.ndarray, turns: int, scale: float) -> int:
    """Points per group when the flat kinematics are ``turns`` groups, group k being group
    0 turned by 2πk/turns (ω_z unchanged); `ArgumentError` naming ``turns`` otherwise.
    ``scale`` (m): turns ω_z into a speed for the tolerance."""
    if isinstance(turns, bool) or int(turns) != turns or turns < 1:
        raise ArgumentError(f"turns must be a positive integer, got {turns!r}")
    if vx.size % turns:
        raise ArgumentError(f"turns={turns} does not divide the {vx.size} kinematic points into groups")
    n0 = vx.size // turns
    if turns == 1 or n0 == 0:
        return n0
    tol = GROUP_TOL * max(float(np.abs(vx).max()), float(np.abs(vy).max()), float(np.abs(wz).max()) * scale)
    w = wz.reshape(turns, n0)
    off = max(
        turn_misfit(vx.reshape(turns, n0), vy.reshape(turns, n0)), float(np.abs(w - w[:1]).max()) * scale
    )
    if not off <= tol:
        raise ArgumentError(
            f"turns={turns}: the kinematic points are not {turns} groups of {n0}, group k the "
            f"first turned by 2pi k/{turns} (off by {off:.3g})"
        )
    return n0


def correlated_sums(
    kx: tuple[np.ndarray, ...],
    ky: tuple[np.ndarray, ...],
    columns_x: np.ndarray,
    columns_y: np.ndarray,
    layout: tuple[int, int],
    turns: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The node sums of all groups from the first group's direction fields.

    ``kx``, ``ky``: (n0, nodes) direction fields ŵ_x, ŵ_y of the first group: one pair for
    all columns, or two when μ depends on the speed (the first with the speed factor, for
    columns 0 and 1; the second for the rest). ``columns_x``, ``columns_y``: (nodes, c)
    node columns, as `fepost.friction.exact` lays them out. Returns sx = Σ ŵ_x·columns_x
    and sy = Σ ŵ_y·columns_y, (turns·n0, c), group by group.
    """
    nr, nphi = layout
    n0 = kx[0].shape[0]
    c, s = turn_angles(turns)
    step = nphi // turns
    ncol = columns_x.shape[1]
    sx = np.empty((turns, n0, ncol))
    sy = np.empty((turns, n0, ncol))
    for fx, fy, cols in zip(kx, ky, _column_sets(ncol, len(kx)), strict=True):
        fx_, fy_ = _field_spectrum(fx, nr, nphi), _field_spectrum(fy, nr, nphi)
        gx_, gy_ = (
            _column_spectrum(columns_x[:, cols], nr, nphi),
            _column_spectrum(columns_y[:, cols], nr, nphi),
        )
        # ŵ_0 correlated with each column at the groups' shifts: (n0, turns, c)
        xx = _correlate(fx_, gx_, nphi)[:, ::step]
        yx = _correlate(fy_, gx_, nphi)[:, ::step]
        xy = _correlate(fx_, gy_, nphi)[:, ::step]
        yy = _correlate(fy_, gy_, nphi)[:, ::step]
        # turned by 2πk/turns: ŵ_k = R ŵ_0(shifted)
        sx[:, :, cols] = np.moveaxis(c[None, :, None] * xx - s[None, :, None] * yx, 1, 0)
        sy[:, :, cols] = np.moveaxis(s[None, :, None] * xy + c[None, :, None] * yy, 1, 0)
    return sx.reshape(turns * n0, ncol), sy.reshape(turns * n0, ncol)


def _column_sets(ncol: int, nsets: int) -> list[slice]:
    """Columns per direction field: one field for all, or the first two (speed factor)
    and the rest."""
    return [slice(0, ncol)] if nsets == 1 else [slice(0, 2), slice(2, ncol)]


def _field_spectrum(field: np.ndarray, nr: int, nphi: int) -> np.ndarray:
    """conj(DFT) of (n0, nodes) fields along the angle index, as (frequency, n0, ring)."""
    return np.conj(np.fft.rfft(field.reshape(-1, nr, nphi), axis=2)).transpose(2, 0, 1)


def _column_spectrum(columns: np.ndarray, nr: int, nphi: int) -> np.ndarray:
    """DFT of (nodes, c) columns along the angle index, as (frequency, ring, c)."""
    return np.fft.rfft(columns.T.reshape(-1, nr, nphi), axis=2).transpose(2, 1, 0)


def _correlate(field: np.ndarray, columns: np.ndarray, nphi: int) -> np.ndarray:
    """out[l, s, c] = Σ_i Σ_j f[l, (i, j)] · g[(i, j + s), c] (angle index mod nphi) for every
    shift s, (n0, nphi, c), from the spectra of `_field_spectrum` and `_column_spectrum`:
    per frequency a sum over the rings, (n0 × nr) @ (nr × c)."""
    return np.fft.irfft(np.matmul(field, columns), n=nphi, axis=0).transpose(1, 0, 2)


def turn_rays(rays: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The polar moments (columns of `fepost.friction.exact.ray_integrals`) about centres
    turned by the angles of cos ``c`` and sin ``s``: order-1, 2 and 3 tensors of ê."""
    ix, iy, cc, cs, ss, q0, q1, q2, q3 = rays.T
    c2, s2, cs_ = c * c, s * s, c * s
    out = np.empty_like(rays)
    out[:, 0] = c * ix - s * iy
    out[:, 1] = s * ix + c * iy
    out[:, 2] = c2 * cc - 2.0 * cs_ * cs + s2 * ss
    out[:, 3] = cs_ * cc + (c2 - s2) * cs - cs_ * ss
    out[:, 4] = s2 * cc + 2.0 * cs_ * cs + c2 * ss
    # ccc, ccs, css, sss of ê' = (c ê_x − s ê_y, s ê_x + c ê_y)
    out[:, 5] = c2 * c * q0 - 3.0 * c2 * s * q1 + 3.0 * c * s2 * q2 - s2 * s * q3
    out[:, 6] = c2 * s * q0 + (c2 * c - 2.0 * c * s2) * q1 + (s2 * s - 2.0 * c2 * s) * q2 + s2 * c * q3
    out[:, 7] = c * s2 * q0 + (2.0 * c2 * s - s2 * s) * q1 + (c2 * c - 2.0 * s2 * c) * q2 - c2 * s * q3
    out[:, 8] = s2 * s * q0 + 3.0 * s2 * c * q1 + 3.0 * s * c2 * q2 + c2 * c * q3
    return out
