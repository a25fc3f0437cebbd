"""A friction model tabulated over the sphere of kinematic directions, for time integration.

Every friction model of `fepost.shimmy.contact` is homogeneous of degree 0 in
(vx, vy, wz): its forces depend on the direction β = atan2(vy, vx) of sliding and
on γ = atan2(R wz, |v|) only. `DirectionTable` evaluates the model once on a
regular (β, γ) grid over the whole sphere (β padded beyond ±π, γ from pole to
pole), fits bicubic splines (scipy's ``RectBivariateSpline``) and stores, per grid
cell, the bicubic Hermite polynomial of the splines' values and derivatives at
the cell's corners. A point is then a cell look-up and three 16-term
polynomials in plain Python (`DirectionTable.one`, about 10 µs), so the
exact integrals and the generalised model cost the same in a time integration
as the closed forms. The table's error against its model is tested
(tests/test_shimmy_contact.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .contact import Contact

#: Grid over the sphere: β over a full turn (plus padding), γ from pole to pole.
TABLE_NB, TABLE_NG, PAD = 145, 73, 3
#: Hermite basis: p(t) = [1 t t² t³] · H · [p(0), p(1), p'(0), p'(1)].
_H = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [-3, 3, -2, -1], [2, -2, 1, 1]])


@dataclass(frozen=True)
class DirectionTable:
    """Bicubic Hermite cells of (Fx, Fy, Mz) over (β, γ) (module docstring)."""

    contact: Contact
    beta0: float
    gamma0: float
    hb: float
    hg: float
    shape: tuple[int, int]
    cells: tuple  # cells[i][j]: 48 floats, 16 per component, row-major in (t power, u power)

    @classmethod
    def build(cls, contact: Contact, nb: int = TABLE_NB, ng: int = TABLE_NG) -> DirectionTable:
        from scipy.interpolate import RectBivariateSpline

        hb = 2 * np.pi / (nb - 1)
        beta = -np.pi - PAD * hb + hb * np.arange(nb + 2 * PAD)
        gamma = np.linspace(-np.pi / 2, np.pi / 2, ng)
        hg = float(gamma[1] - gamma[0])
        B, G = np.meshgrid(beta, gamma, indexing="ij")
        vx, vy, wz = np.cos(G) * np.cos(B), np.cos(G) * np.sin(B), np.sin(G) / contact.R
        values = contact(vx.ravel(), vy.ravel(), wz.ravel())
        comps = []
        for val in values:
            s = RectBivariateSpline(beta, gamma, np.reshape(np.real(val), B.shape))
            f = s(beta, gamma)
            fb = s(beta, gamma, dx=1) * hb
            fg = s(beta, gamma, dy=1) * hg
            fbg = s(beta, gamma, dx=1, dy=1) * hb * hg
            comps.append(_cells(f, fb, fg, fbg))
        coef = np.concatenate(comps, axis=-1)  # (nb-1, ng-1, 48)
        cells = tuple(tuple(tuple(float(c) for c in cell) for cell in row) for row in coef)
        return cls(contact, float(beta[0]), float(gamma[0]), float(hb), hg, coef.shape[:2], cells)

    def one(self, vx: float, vy: float, wz: float) -> tuple[float, float, float]:
        """(Fx, Fy, Mz) at one kinematic point (Python floats)."""
        b = math.atan2(vy, vx)
        g = math.atan2(self.contact.R * wz, math.sqrt(vx * vx + vy * vy))
        x = (b - self.beta0) / self.hb
        y = (g - self.gamma0) / self.hg
        i = min(max(int(x), 0), self.shape[0] - 1)
        j = min(max(int(y), 0), self.shape[1] - 1)
        t, u = x - i, y - j
        c = self.cells[i][j]
        out = []
        for k in (0, 16, 32):
            r0 = c[k] + u * (c[k + 1] + u * (c[k + 2] + u * c[k + 3]))
            r1 = c[k + 4] + u * (c[k + 5] + u * (c[k + 6] + u * c[k + 7]))
            r2 = c[k + 8] + u * (c[k + 9] + u * (c[k + 10] + u * c[k + 11]))
            r3 = c[k + 12] + u * (c[k + 13] + u * (c[k + 14] + u * c[k + 15]))
            out.append(r0 + t * (r1 + t * (r2 + t * r3)))
        return out[0], out[1], out[2]

    def __call__(self, vx, vy, wz):
        """Arrays in, arrays out (the `Contact.forces` signature), point by point."""
        vx, vy, wz = np.broadcast_arrays(*(np.asarray(q, float) for q in (vx, vy, wz)))
        res = np.array(
            [self.one(a, b, c) for a, b, c in zip(vx.ravel(), vy.ravel(), wz.ravel(), strict=True)]
        )
        res = res.reshape(vx.shape + (3,))
        return res[..., 0], res[..., 1], res[..., 2]

    def as_contact(self) -> Contact:
        """The table as a `Contact` (named as its model; ``scalar`` is `one`)."""
        c = self.contact
        return Contact(c.name, self, c.R, c.F0, c.M0, False, {**c.info, "tabulated": True}, self.one)


def _cells(f, fb, fg, fbg) -> np.ndarray:
    """Per-cell coefficient arrays a[p, q] of Σ a_pq t^p u^q, flattened to 16."""

    def corners(a):
        return np.stack([a[:-1, :-1], a[:-1, 1:], a[1:, :-1], a[1:, 1:]], axis=-1)  # 00, 01, 10, 11

    c, cb, cg, cbg = corners(f), corners(fb), corners(fg), corners(fbg)
    F = np.empty(c.shape[:2] + (4, 4))
    F[..., 0, :] = np.stack([c[..., 0], c[..., 1], cg[..., 0], cg[..., 1]], axis=-1)
    F[..., 1, :] = np.stack([c[..., 2], c[..., 3], cg[..., 2], cg[..., 3]], axis=-1)
    F[..., 2, :] = np.stack([cb[..., 0], cb[..., 1], cbg[..., 0], cbg[..., 1]], axis=-1)
    F[..., 3, :] = np.stack([cb[..., 2], cb[..., 3], cbg[..., 2], cbg[..., 3]], axis=-1)
    A = np.einsum("ij,...jk,lk->...il", _H, F, _H)
    return A.reshape(c.shape[:2] + (16,))
