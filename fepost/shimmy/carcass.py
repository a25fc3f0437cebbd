"""The brush on a carcass: tread elements of the tread's stiffness on a carcass spring in series.

`fepost.shimmy.brush.BrushTire` lumps the carcass into the tread: its elements share the
tire's standstill stiffness, so its slip stiffness is about K a and its relaxation length
about the patch's half length a. The whole tire rolled in CalculiX (docs/rolling.md,
`meshes/rig-tire360/roll/`) grips about five times harder at small slips and relaxes
about five times slower: its grip is the tread's, its lag the carcass's. This module
puts the brush's elements, with the tread's own stiffness, on a carcass that deflects as
a whole under the patch's resultant:

* the tread: element i of the binned map has the stiffness k_i = c A_i (N/m), c (N/m³)
  the tread's shear stiffness per contact area, G_t / h_t for a solid tread of shear
  modulus G_t and depth h_t (the FE tire's: 1.5e6 Pa over 0.020 m, 7.5e7 N/m³);
* the carcass: the belt under the patch displaced rigidly by U = (u_x, u_y, φ) against
  the rim (m, m, rad about the patch origin), held by the springs K_C = diag(K_cx, K_cy,
  K_cz) (N/m, N/m, N m/rad). Each may be infinite (rigid in that direction). From the
  tire's standstill stiffness K (the rig's slides and pure spin, `rig_stiffness`) and the
  tread's K_t (c A along x and y, Σ k_i r_i² about z) in series, 1/K = 1/K_c + 1/K_t
  (`carcass_from_standstill`).

State per element: q_i, the road contact point relative to its undeformed position on
the wheel (tread plus carcass). The carcass is massless, so U is the state's algebraic
function that balances the carcass springs against the tread, K_C U = Σ B_iᵀ k_i e_i,
with e_i = q_i − B_i U the tread's own deflection and B_i U = (u_x − φ y_i, u_y + φ x_i)
the carcass's displacement at the element: U = (K_C + Σ B_iᵀ k_i B_i)⁻¹ Σ B_iᵀ k_i q_i.
The road's force on element i is F_i = k_i e_i; the resultants are Σ F_i and Σ (x_i F_yi
− y_i F_xi) = K_C U.

Kinematics: a sticking element's contact point stays on the road while its undeformed
position moves over the road at the wheel's slip w_i (`fepost.shimmy.brush`), so
Dq_i/Dt = −w_i; the tread runs back through the patch at V_r and enters it undeflected
against the carcass (e = 0), and its carcass root, carried back along a belt turned by
φ, moves sideways by V_r φ. Along each row (first-order upwind as the brush):

    q̇_i = −w_i + V_r (e_ahead − e_i)/h + V_r (0, φ) − (ṡ/s) q_i − λ_i F̂_i

with λ_i the Coulomb slip rate of a sliding element, now found together with the
carcass's motion U̇ (which every element's slip moves): a 3 × 3 linear system on the
elements at their limit, repeated until the set of sliding elements stops changing.

Energy (tested): E = ½ Σ e_iᵀ k_i e_i + ½ Uᵀ K_C U, and dE/dt = Σ F_i · q̇_i (the carcass
terms cancel because K_C U = Σ B_iᵀ F_i): the work on the slip, the tread's leaving the
patch and the twist's transport (`released`), the sliding (Σ |F_i| λ_i), and the dilution
of a growing patch, whose carcass stiffness grows with its load like its tread's.

Limits (tested): K_C → ∞ gives `BrushTire` (U → 0, q = e); the steady slip curve with
no carcass twist (κ or pure side slip with K_cz infinite) is the tread-only brush's
exactly (a translated carcass moves no element against the road); with a torsional
carcass the side force's moment twists the carcass by Mz/K_cz, which steers the patch
by V_r φ (the classical loss of cornering stiffness through the carcass's torsion).
The small-slip build-up is a first-order lag of length about C_κ/K_cx plus a third of
the patch length (the closed form of a uniform patch in `buildup_length`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from ..errors import ArgumentError
from .brush import ON_LIMIT, BrushTire, rig_elastic_slope

#: The tread's shear stiffness per contact area (N/m³) of the FE tire: tread rubber's
#: shear modulus 1.5e6 Pa (scripts/tiremodel/aircraft_deck.py, RUBBER["TREAD"]) over the
#: crown rubber's depth 0.020 m (aircraft_roll360_results.TREAD_DEPTH).
FE_TREAD_STIFFNESS = 1.5e6 / 0.020
#: The rig's pure spin (meshes/rig-tire360/spin_p.json) and the turn (rad) up to which its
#: moment is read as elastic: 0.1 mm at the patch's end (0.25 m), as `brush.RIG_ELASTIC_PATH`.
RIG_SPIN, RIG_ELASTIC_TURN = "spin_p", 4e-4
#: Most passes over the set of sliding elements in one evaluation of the rates.
PASSES = 30
#: Cells carrying less than this share of the load are left out of the carcass tire: the patch's
#: corners (on the whole tire's map, 12 x 4 cells: 4 cells of 5e-6 to 2e-5 of the load, 5e-5 of f N
#: together), whose stiffness-to-limit ratio, 50-170 times the median, alone sets the time
#: integration's step while an element slides (its direction follows its slip at k_i |w| / (f n_i)).
MIN_LOAD_SHARE = 1e-4


@dataclass(frozen=True)
class CarcassTire:
    """Tread elements (``tread``: a `BrushTire` with the tread's stiffness) on carcass springs
    ``carcass`` = (K_cx, K_cy, K_cz) (N/m, N/m, N m/rad; ``math.inf``: rigid) (module docstring).

    The state of each element is its total deflection q (the arguments named ``qx``, ``qy``);
    the methods are those of `BrushTire` that `fepost.shimmy.gripping.GripModel` uses.
    """

    tread: BrushTire
    carcass: tuple[float, float, float]
    provenance: dict = field(default_factory=dict)
    #: None, or the mask of the elements held on their sliding branch (the others stick): the
    #: linearisation's branch (`frozen_at`)
    frozen: np.ndarray | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        kc = tuple(float(k) for k in self.carcass)
        if len(kc) != 3 or not all(k > 0 for k in kc) or any(math.isnan(k) for k in kc):
            raise ArgumentError(
                "carcass: the stiffnesses (K_cx, K_cy, K_cz) must be positive (inf: rigid), "
                f"got {self.carcass!r}"
            )
        object.__setattr__(self, "carcass", kc)

    # -- what GripModel reads of a tire ---------------------------------------------------------
    @property
    def n(self) -> int:
        return self.tread.n

    @property
    def f(self) -> float:
        return self.tread.f

    @property
    def load(self) -> float:
        return self.tread.load

    @property
    def R(self) -> float:
        return self.tread.R

    @property
    def half_length(self) -> float:
        return self.tread.half_length

    @property
    def standstill(self) -> tuple[float, float, float]:
        """The tire's standstill stiffness (K_x, K_y, K_z): tread and carcass in series, per direction."""
        t = self.tread_totals
        return tuple(1.0 / (1.0 / k + 1.0 / kt) for k, kt in zip(self.carcass, t, strict=True))  # type: ignore[return-value]

    @cached_property
    def tread_totals(self) -> tuple[float, float, float]:
        """The tread's own stiffness K_t (`tread_totals`)."""
        return tread_totals(self.tread)

    @cached_property
    def _free(self) -> np.ndarray:
        """Indices of the carcass's compliant directions (finite springs)."""
        return np.array([k for k in range(3) if math.isfinite(self.carcass[k])], int)

    @cached_property
    def _gain(self) -> np.ndarray:
        """G (3 × 2n): U = G [qx; qy]; rows of rigid directions 0."""
        t, n = self.tread, self.tread.n
        b = np.zeros((2 * n, 3))  # [B_x rows; B_y rows]
        b[:n, 0], b[:n, 2] = 1.0, -t.y
        b[n:, 1], b[n:, 2] = 1.0, t.x
        k = np.concatenate([t.kx, t.ky])
        gain = np.zeros((3, 2 * n))
        fr = self._free
        if fr.size:
            bk = (b * k[:, None])[:, fr]  # K B, free columns
            m = b[:, fr].T @ bk + np.diag([self.carcass[j] for j in fr])
            gain[fr] = np.linalg.solve(m, bk.T)
        return gain

    def carcass_deflection(self, qx, qy) -> np.ndarray:
        """U = (u_x, u_y, φ) (m, m, rad) that balances the carcass springs against the tread."""
        return self._gain @ np.concatenate([np.asarray(qx, float), np.asarray(qy, float)])

    def tread_deflections(self, qx, qy) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(ex, ey, U): the tread's own deflections e = q − B U and the carcass's U."""
        u = self.carcass_deflection(qx, qy)
        t = self.tread
        return qx - (u[0] - u[2] * t.y), qy - (u[1] + u[2] * t.x), u

    # -- the element equations ------------------------------------------------------------------
    def rates(self, qx, qy, vx, vy, wz, vr: float, growth: float = 0.0):
        """(q̇x, q̇y, λ) for the wheel's slip (vx, vy, wz) at the patch origin (module docstring);
        arguments as `BrushTire.rates`."""
        t = self.tread
        ex, ey, u = self.tread_deflections(qx, qy)
        ax, ay = t.ahead_deflections(ex, ey)
        # the unconstrained rates (no sliding)
        dqx = -(vx - wz * t.y) + vr * (ax - ex) / t.h - growth * qx
        dqy = -(vy + wz * t.x) + vr * (ay - ey) / t.h + vr * u[2] - growth * qy
        fx, fy = t.kx * ex, t.ky * ey
        fn = np.hypot(fx, fy)
        lim = t.limit
        lam = self._slip_rates(dqx, dqy, fx, fy, fn, lim, t.beta(vr))
        safe = np.where(fn > 0, fn, 1.0)
        return dqx - lam * fx / safe, dqy - lam * fy / safe, lam

    def _slip_rates(self, dqx, dqy, fx, fy, fn, lim, beta) -> np.ndarray:
        """λ of the sliding elements with the carcass's motion they cause (a 3 × 3 system per pass)."""
        t, n = self.tread, self.tread.n
        safe = np.where(fn > 0, fn, 1.0)
        nx, ny = fx / safe, fy / safe
        stiff = np.where(fn > 0, nx * nx * t.kx + ny * ny * t.ky, 1.0)
        if t.blend > 0:
            share = np.clip((fn / np.where(lim > 0, lim, 1.0) - 1.0) / t.blend + 1.0, 0.0, 1.0)
        else:
            share = (fn >= (1 - ON_LIMIT) * lim).astype(float)
        share = np.where(fn > 0, share, 0.0)
        gain = self._gain
        # p_i: d(F̂·K ė_i)/dU̇ = −F̂ᵀ K B_i; q_j: dU̇/dλ_j = −G_j F̂_j
        p = np.stack([nx * t.kx, ny * t.ky, -nx * t.kx * t.y + ny * t.ky * t.x])  # 3 × n (F̂ᵀ K B)
        q = gain[:, :n] * nx + gain[:, n:] * ny  # 3 × n (G F̂)
        udot0 = gain @ np.concatenate([dqx, dqy])
        # ė_i = dq_i − B_i U̇ before sliding; drive = F̂·K ė + β(|F| − limit)
        drive0 = nx * t.kx * dqx + ny * t.ky * dqy - p.T @ udot0 + beta * (fn - lim)
        if self.frozen is not None:  # the sliding branch, extended linearly (no switch)
            s = np.where(self.frozen, 1.0 / stiff, 0.0)
            z = np.linalg.solve(np.eye(3) - (q * s) @ p.T, (q * s) @ drive0)
            return s * (drive0 + p.T @ z)
        active = (share > 0) & (drive0 > 0)
        lam = np.zeros(n)
        for _ in range(PASSES):
            s = np.where(active, share / stiff, 0.0)
            # λ = s (drive0 + pᵀ z), z = q λ  ->  (I − q s pᵀ) z = q s drive0
            z = np.linalg.solve(np.eye(3) - (q * s) @ p.T, (q * s) @ drive0)
            drive = drive0 + p.T @ z
            lam = np.where(active, s * drive, 0.0)
            now = (share > 0) & (drive > 0)
            if np.array_equal(now, active):
                break
            active = now
        return np.maximum(lam, 0.0)

    def resultants(self, qx, qy, scale: float = 1.0) -> tuple[float, float, float]:
        """(Fx, Fy, Mz) of the road on the tire (N, N, N·m about the patch origin), as `BrushTire`."""
        ex, ey, _ = self.tread_deflections(qx, qy)
        return self.tread.resultants(ex, ey, scale)

    def energy(self, qx, qy, scale: float = 1.0) -> float:
        """Elastic energy of tread and carcass (J)."""
        ex, ey, u = self.tread_deflections(qx, qy)
        fr = self._free
        carcass = 0.5 * sum(self.carcass[j] * u[j] ** 2 for j in fr)
        return self.tread.energy(ex, ey, scale) + scale * float(carcass)

    def dissipation(self, qx, qy, lam, scale: float = 1.0) -> float:
        """Power of the sliding elements (W): Σ |F_i| λ_i."""
        ex, ey, _ = self.tread_deflections(qx, qy)
        return self.tread.dissipation(ex, ey, lam, scale)

    def released(self, qx, qy, vr: float) -> float:
        """Power of the transport terms (W): Σ F_i · (V_r (e_ahead − e_i)/h + V_r (0, φ))."""
        t = self.tread
        ex, ey, u = self.tread_deflections(qx, qy)
        return t.released(ex, ey, vr) + vr * u[2] * float(np.sum(t.ky * ey))

    def on_limit(self, qx, qy) -> np.ndarray:
        """Mask of the elements at their friction limit (to 1e-9)."""
        ex, ey, _ = self.tread_deflections(qx, qy)
        return self.tread.on_limit(ex, ey)

    def steady(self, vx: float, vy: float, wz: float, vr: float) -> tuple[np.ndarray, np.ndarray]:
        """The elements' steady total deflections (qx, qy) at a constant slip.

        The tread's are `BrushTire.steady`'s at the slip the carcass's twist φ leaves, (vx, vy − V_r φ,
        wz); φ = Mz/K_cz closes it (a scalar root, bracketed by the largest sliding moment)."""
        from scipy.optimize import brentq

        t = self.tread
        kz = self.carcass[2]

        def tread_at(phi):
            return t.steady(vx, vy - vr * phi, wz, vr)

        phi = 0.0
        if vr > 0 and math.isfinite(kz):
            bound = float(np.sum(t.limit * np.hypot(t.x, t.y))) / kz * (1 + 1e-9) + 1e-300

            def gap(p):
                return p - t.resultants(*tread_at(p))[2] / kz

            if gap(0.0) != 0.0:
                phi = brentq(gap, -bound, bound, xtol=1e-15 * max(bound, 1e-12), rtol=1e-14)
        ex, ey = tread_at(phi)
        fx, fy, mz = t.resultants(ex, ey)
        u = np.array([fx, fy, mz]) / np.asarray(self.carcass)  # 0 where rigid
        return ex + u[0] - u[2] * t.y, ey + u[1] + u[2] * t.x

    # -- derived tires --------------------------------------------------------------------------
    def frozen_at(self, sliding) -> CarcassTire:
        """The tire with the elements of the mask ``sliding`` held on their sliding branch and the
        others sticking, whatever their forces: smooth, for the linearisation about a steady state."""
        mask = np.asarray(sliding, bool)
        if mask.shape != (self.n,):
            raise ArgumentError(f"sliding: a mask of {self.n} elements expected, got shape {mask.shape}")
        return replace(self, frozen=mask)

    def stiffer_carcass(self, factor: float) -> CarcassTire:
        """The same tire with the carcass's springs times ``factor``."""
        kx, ky, kz = self.carcass
        return replace(self, carcass=(kx * factor, ky * factor, kz * factor))

    @classmethod
    def from_quadrature(
        cls,
        quad,
        *,
        f: float,
        standstill: tuple[float, ...],
        tread_stiffness: float = 0.0,
        slip_stiffness: float = 0.0,
        nx: int,
        ny: int,
        blend: float = 0.0,
        provenance=None,
    ) -> CarcassTire:
        """Tread elements over ``quad``'s loaded nodes on the carcass that leaves the tire's standstill
        stiffness ``standstill`` = (K_x, K_y[, K_z]) (N/m, N/m, N m/rad; K_z absent or 0: rigid in
        torsion; `carcass_from_standstill`). The elements' stiffness per area: either
        ``tread_stiffness`` c (N/m³, k_i = c A_i), or calibrated so that the brush's linear slip
        stiffness C_κ / N is ``slip_stiffness`` (`BrushTire.slip_stiffness`); exactly one of them."""
        given = [
            (name, float(v))
            for name, v in (("tread_stiffness", tread_stiffness), ("slip_stiffness", slip_stiffness))
            if v
        ]
        if len(given) != 1:
            raise ArgumentError("give exactly one of tread_stiffness (N/m^3) and slip_stiffness (C_kappa/N)")
        name, value = given[0]
        if not (value > 0 and math.isfinite(value)):
            raise ArgumentError(f"{name} must be positive and finite, got {value!r}")
        unit = BrushTire.from_quadrature(quad, f=f, stiffness=(1.0, 1.0), nx=nx, ny=ny)
        area = float(quad.dA[quad.sigma > 0].sum())
        unit = _without_faint_cells(unit)
        c = value if name == "tread_stiffness" else value * unit.load / unit.slip_stiffness() / area
        tread = replace(unit, kx=unit.kx * c * area, ky=unit.ky * c * area, blend=blend)
        kc = carcass_from_standstill(tread, standstill)
        prov = {
            "tread_stiffness": f"{c:.4g} N/m^3 over {area:.4g} m^2 of loaded area"
            + ("" if name == "tread_stiffness" else f" (calibrated to C_kappa/N = {value:g})"),
            **dict(provenance or {}),
        }
        return cls(tread, kc, prov)


def _without_faint_cells(tire: BrushTire) -> BrushTire:
    """``tire`` without the elements below `MIN_LOAD_SHARE` of its load (an element whose element
    ahead is left out enters the patch at the leading edge); the load is the kept elements'."""
    keep = tire.limit >= MIN_LOAD_SHARE * tire.limit.sum()
    if keep.all():
        return tire
    index = -np.ones(tire.n, int)
    index[keep] = np.arange(int(keep.sum()))
    ahead = np.where(tire.ahead >= 0, index[np.maximum(tire.ahead, 0)], -1)[keep]
    return replace(
        tire,
        x=tire.x[keep],
        y=tire.y[keep],
        limit=tire.limit[keep],
        kx=tire.kx[keep],
        ky=tire.ky[keep],
        ahead=ahead,
        load=float(tire.limit[keep].sum() / tire.f),
    )


def tread_totals(tread: BrushTire) -> tuple[float, float, float]:
    """The tread's own stiffness K_t: Σ k_xi, Σ k_yi (N/m) and Σ (k_yi x_i² + k_xi y_i²) (N m/rad)."""
    t = tread
    return float(t.kx.sum()), float(t.ky.sum()), float((t.ky * t.x**2 + t.kx * t.y**2).sum())


def carcass_from_standstill(tread: BrushTire, standstill) -> tuple[float, float, float]:
    """(K_cx, K_cy, K_cz) with 1/K = 1/K_c + 1/K_t per direction: K_t the tread's own
    (`tread_totals`); ``standstill`` (K_x, K_y[, K_z]), K_z absent or 0: rigid."""
    ks = [float(k) for k in standstill] + [0.0] * (3 - len(standstill))
    if len(ks) != 3:
        raise ArgumentError(f"standstill: (K_x, K_y[, K_z]) expected, got {standstill!r}")
    kt = tread_totals(tread)
    out = []
    for name, k, kt_j in zip(("K_x", "K_y", "K_z"), ks, kt, strict=True):
        if name == "K_z" and k == 0.0:
            out.append(math.inf)
            continue
        if not (k > 0 and math.isfinite(k)):
            raise ArgumentError(f"standstill {name} must be positive and finite, got {k!r}")
        if k >= kt_j:
            raise ArgumentError(
                f"standstill {name} = {k:.4g} is not below the tread's own {kt_j:.4g}: "
                "no carcass in series can give it (tread_stiffness too low?)"
            )
        out.append(1.0 / (1.0 / k - 1.0 / kt_j))
    return out[0], out[1], out[2]


def rig_torsional_stiffness(folder) -> dict:
    """The tire's standstill torsional stiffness K_z (N m/rad) from the rig's pure spin ``spin_p`` in
    ``folder``: −Mz over the turn, least squares through 0 over the turns up to `RIG_ELASTIC_TURN`."""
    k, n, name = rig_elastic_slope(
        Path(folder) / f"{RIG_SPIN}.json", "tire_rotation", "Mz", RIG_ELASTIC_TURN, "rad of turn"
    )
    return {"K_z": k, "K_z_source": f"{name}: -Mz/turn over the first {n} increments"}


def buildup_length(slip_stiffness: float, carcass: float, length: float) -> float:
    """The decay length (m) of the small-slip build-up of a brush with a uniform rectangular patch of
    ``length`` (2a, m) and slip stiffness C (N) on a carcass spring K_c (N/m): the root σ of
    K_c = (2C/L²) (σ (e^(L/σ) − 1) − L), L = ``length``, the slowest mode of the delay equation
    K_c u(X) = −(2C/L²) ∫₀ᴸ (κ x + u(X) − u(X − x)) dx; about C/K_c + L/3 when L ≪ σ."""
    from scipy.optimize import brentq

    c, kc, L = float(slip_stiffness), float(carcass), float(length)
    if not (c > 0 and kc > 0 and L > 0):
        raise ArgumentError(f"buildup_length needs positive C, K_c and L, got {c!r}, {kc!r}, {L!r}")
    w = 2.0 * c / L**2

    def gap(sigma):
        r = L / sigma
        return w * sigma * (math.expm1(r) - r) - kc

    lo = c / kc * 0.5
    hi = c / kc + L
    while gap(hi) > 0:
        hi *= 2.0
    return float(brentq(gap, lo, hi, xtol=1e-14, rtol=1e-12))
