"""The generalised coupled sliding–spin friction model (any patch shape, explicit formulas).

Why a dissipation potential
---------------------------
Under Coulomb's law the power the road takes from the tire is D = ∬ μσ |w| dA,
w = (v_x − ω_z y, v_y + ω_z x), and the exact resultants are its gradient:
F = −∂D/∂v, M_z = −∂D/∂ω_z (differentiate under the integral: ∂|w|/∂v = ŵ).
D is even and homogeneous of degree 1 in (v_x, v_y, ω_z R), so it is a function
on a sphere. The model approximates D and takes F and M_z from it analytically,
so it inherits three properties of the exact model for free: the power identity
F·v + M_z ω_z = −D (never negative: the model cannot feed energy into a shimmy
simulation), reciprocity ∂F/∂ω_z = ∂M_z/∂v, and rate independence.

The formulas (u = ω_z R, v = (v_x, v_y), J v = (−v_y, v_x))
------------------------------------------------------------
Base, with F0 = f N (N), Û0 = M0/(F0 R), Q̂ (2×2), Ŝ (2×2), ĝ, x̂ (2-vectors):

    P  = |v|⁶ + 3 u² |v|² (vᵀQ̂v) + 3 Û0⁵ u⁴ (vᵀŜv) + Û0⁶ u⁶
    D0 = F0 · [ P^{1/6}  +  (ĝ·Jv) u |u|³ / (u² + |v|²)²  −  (x̂·Jv) u |v|² / (|v|² + u²)^{3/2} ]

* P^{1/6} is the symmetric part. Near pure spin it gives the torque M0 and the
  force slope −(f/|ω_z|) S v exactly (S = ∬σ ê_r ê_rᵀ/r dA, Ŝ = R S/N); near
  pure sliding the force fN and the torque slope −(f ω_z/|v|) v̂ᵀQ v̂ exactly
  (Q = ∬σ p pᵀ dA, Q̂ = Q/(N R²)), for every sliding direction. With Q̂ = Ŝ = Û0 = 1
  it is √(|v|² + u²): the ellipsoidal limit surface; the paper's square-root
  forms are of that family.
* The ĝ term (ĝ = −∬σ ê_r dA / N) is the force at pure spin of an asymmetric map
  (−f ∬σ ê_φ dA: the rolling shift's lateral force); the x̂ term (x̂ = x_c/R) is
  the torque at pure sliding of a map whose centre of pressure is off the
  origin, −f N x_c × v̂. Their blending factors leave the symmetric limits intact.

Correction, for ω_z ≠ 0 (θ, t as in `fepost.friction.basis`, s = sgn ω_z,
ε = tan(πt/2), c = cos(πt/2) = |u|/√(u² + |v|²)):

    Û = t³ (1 − t)² Σ C[k, l] B_k(θ) T_l(2t − 1)          (dimensionless)
    D = D0 + F0 |u| Û
    F += s F0 (Û_r ê_θ − Û_θ/ε ê_r),   M_z += s F0 R (ε Û_r − Û),
    Û_r = (2/π) c² ∂Û/∂t,  ε Û_r = (2/π) c √(1 − c²) ∂Û/∂t,   ê_r = (cos θ, sin θ), ê_θ = (−sin θ, cos θ).

The weight t³(1 − t)² vanishes to third order at pure spin and to second order
at pure sliding (in ω_z/|v|), so the correction changes none of the limits
above: the value and the first derivative of every resultant at both ends come
from the base alone. C is computed by least squares against the exact
integrals over the map on a grid of the sphere (`fepost.friction.build`).

Anisotropic friction (τ = −μσ (ŵ_x, α ŵ_y)) is not a gradient law; the model
then scales F_y by α and adds (α − 1) G to M_z, with G = ∬ x τ_y dA of the
isotropic law modelled directly (base with its exact limits, plus a correction
with weight t²(1 − t)²), see `GeneralisedModel.lateral_moment`.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from types import MappingProxyType
from typing import Any

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError, DataError
from . import basis, kernel
from .exact import Resultants, checked_kinematics
from .law import store_reals

#: Format tag of the JSON export.
FORMAT = "fepost-friction-model/1"
#: Points per evaluation chunk (keeps the working arrays in cache-sized blocks).
CHUNK = 1 << 14
#: ``backend="auto"`` uses the compiled kernel (`fepost.friction.kernel`, needs numba)
#: from this many points on: numpy takes a fraction of a second for them, about what
#: importing numba costs once per process (fewer points stay with numpy).
KERNEL_MIN_POINTS = 1 << 20
#: The evaluation backends of `GeneralisedModel.evaluate`.
BACKENDS = ("auto", "numba", "numpy")
#: Weight exponents of the potential correction (pure spin, pure sliding) ...
POTENTIAL_WEIGHT = (3, 2)
#: ... and of the anisotropic-torque correction.
DIRECT_WEIGHT = (2, 2)


def _matrix(name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name} must be numbers of shape {shape}, got {value!r}") from None
    if arr.shape != shape:
        raise ArgumentError(f"{name} must have shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ArgumentError(f"{name} must be finite, got {arr.tolist()!r}")
    return frozen(arr)


@dataclass(frozen=True)
class GeneralisedModel:
    """Coefficients of the generalised model and its evaluation (module docstring).

    ``f`` friction coefficient, ``anisotropy`` α = f_y/f_x, ``R`` (m) the radius of
    u = ω_z R, ``F0`` = fN (N), ``M0`` = f∬σ r dA (N·m); dimensionless ``Q`` (Q̂),
    ``S`` (Ŝ), ``g`` (ĝ), ``xc`` (x̂); ``correction`` C of shape (2K + 1, L).
    For α ≠ 1: ``g0`` (Ĝ0 = −∬σ r cos²φ dA /(N R)), ``g1`` (ĝ1 = −∬σ cos φ sin φ ê_φ dA / N)
    and ``correction_g``. ``accuracy``: the largest errors measured against the
    exact integrals when the model was built; ``source``: the map it came from.
    """

    f: float
    R: float
    F0: float
    M0: float
    Q: np.ndarray
    S: np.ndarray
    g: np.ndarray
    xc: np.ndarray
    correction: np.ndarray
    anisotropy: float = 1.0
    g0: float = 0.0
    g1: np.ndarray = field(default_factory=lambda: np.zeros(2))
    correction_g: np.ndarray | None = None
    accuracy: Mapping[str, Any] = field(default_factory=dict)
    source: str = ""

    def __post_init__(self) -> None:
        store_reals(self, ("f", "R", "F0", "M0", "anisotropy", "g0"))
        for name in ("R", "F0", "M0", "anisotropy"):
            if getattr(self, name) <= 0:
                raise ArgumentError(f"{name} must be positive, got {getattr(self, name)!r}")
        if self.f < 0:
            raise ArgumentError(f"f must be >= 0, got {self.f!r}")
        for name, shape in (("Q", (2, 2)), ("S", (2, 2)), ("g", (2,)), ("xc", (2,)), ("g1", (2,))):
            object.__setattr__(self, name, _matrix(name, getattr(self, name), shape))
        c = np.asarray(self.correction, float)
        if c.ndim != 2 or c.shape[0] % 2 != 1 or c.shape[1] < 1:
            raise ArgumentError(f"correction must have shape (2K+1, L), got {c.shape}")
        object.__setattr__(self, "correction", _matrix("correction", c, c.shape))
        if self.correction_g is not None:
            cg = np.asarray(self.correction_g, float)
            if cg.ndim != 2 or cg.shape[0] % 2 != 1:
                raise ArgumentError(f"correction_g must have shape (2K+1, L), got {cg.shape}")
            object.__setattr__(self, "correction_g", _matrix("correction_g", cg, cg.shape))
        object.__setattr__(self, "accuracy", MappingProxyType(dict(self.accuracy)))

    # -- derived, interpretable -------------------------------------------------
    @property
    def U0(self) -> float:
        """Û0 = M0/(F0 R): the pure-spin torque over fN R (2/3 for a uniform disc, 3π/16 for Hertz)."""
        return self.M0 / (self.F0 * self.R)

    @property
    def order(self) -> tuple[int, int]:
        """(K, L): Fourier harmonics in θ and Chebyshev terms in t of the correction."""
        return (self.correction.shape[0] - 1) // 2, self.correction.shape[1]

    def direction_coefficients(self, beta) -> dict[str, np.ndarray]:
        """The paper's a and m for sliding along β (rad), and the sextic form's couplings.

        √a(β) = 1/(v̂ᵀŜv̂) (force slope at pure spin) and √m(β) = Û0/(v̂ᵀQ̂v̂) (torque
        slope at pure sliding), v̂ = (cos β, sin β); κ1 = v̂ᵀQ̂v̂/Û0² = 1/(√m Û0) and
        κ2 = Û0 v̂ᵀŜv̂ = Û0/√a: along β the base is D⁶ = (F0 v)⁶ + 3κ1 (F0 v)⁴ (M0 ω)²
        + 3κ2 (F0 v)² (M0 ω)⁴ + (M0 ω)⁶, the ellipsoidal limit surface when κ1 = κ2 = 1.
        """
        b = np.asarray(beta, float)
        vh = np.stack([np.cos(b), np.sin(b)], -1)
        s = np.einsum("...i,ij,...j->...", vh, self.S, vh)
        q = np.einsum("...i,ij,...j->...", vh, self.Q, vh)
        return {"a": 1.0 / s**2, "m": (self.U0 / q) ** 2, "kappa1": q / self.U0**2, "kappa2": self.U0 * s}

    def substituted(self, **arrays) -> GeneralisedModel:
        """A copy with some of F0, M0 (positive floats) and Q, S, g, xc (arrays of their
        shapes) replaced, without re-validating the rest (for fits that evaluate the
        model at many coefficient values); ``accuracy`` is dropped."""
        allowed = {"F0": (), "M0": (), "Q": (2, 2), "S": (2, 2), "g": (2,), "xc": (2,)}
        new = object.__new__(GeneralisedModel)
        new.__dict__.update(self.__dict__)
        for name, value in arrays.items():
            if name not in allowed:
                raise ArgumentError(f"substituted takes {', '.join(allowed)}, got {name!r}")
            if allowed[name]:
                value = _matrix(name, value, allowed[name])
            else:
                value = float(value)
                if not (np.isfinite(value) and value > 0):
                    raise ArgumentError(f"{name} must be positive and finite, got {value!r}")
            new.__dict__[name] = value
        new.__dict__["accuracy"] = MappingProxyType({})
        new.__dict__.pop("kernel_coefficients", None)  # packed from the old numbers
        return new

    def without_correction(self) -> GeneralisedModel:
        """The base model alone (its tensors; no fitted correction): the interpretable level."""
        cg = None if self.correction_g is None else np.zeros_like(self.correction_g)
        return replace(
            self, correction=np.zeros_like(self.correction), correction_g=cg, accuracy={}, source=self.source
        )

    # -- evaluation -------------------------------------------------------------
    def __call__(self, vx, vy, wz) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(F_x, F_y, M_z) on the tire (N, N, N·m about the patch origin) for sliding
        velocities ``vx``, ``vy`` (m/s) and spin ``wz`` (rad/s); arrays broadcast.

        No input checks beyond broadcasting (the fast path for time integration);
        `resultants` checks its inputs. Same as ``evaluate(vx, vy, wz)``.
        """
        return self.evaluate(vx, vy, wz)

    def evaluate(
        self, vx, vy, wz, *, backend: str = "auto", out=None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`__call__` with a choice of ``backend``: ``"numba"`` the compiled kernel
        (`fepost.friction.kernel`, the optional numba dependency), ``"numpy"`` whole-array
        numpy, ``"auto"`` (default) the kernel from `KERNEL_MIN_POINTS` points on when
        numba is installed, numpy otherwise. All give the same numbers to round-off.

        ``out``: three writeable, C-contiguous float64 arrays of the broadcast shape that
        receive F_x, F_y, M_z and are returned (a simulation loop then allocates nothing
        per call; they may be the inputs themselves).
        """
        if backend not in BACKENDS:
            raise ArgumentError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
        if backend == "numba" and not kernel.AVAILABLE:
            raise ArgumentError(
                "backend 'numba' needs numba (pip install fepost[fast]), which is not installed"
            )
        vx, vy, wz = np.broadcast_arrays(np.asarray(vx, float), np.asarray(vy, float), np.asarray(wz, float))
        shape = vx.shape
        fvx, fvy, fwz = (np.ascontiguousarray(a.ravel()) for a in (vx, vy, wz))
        n = fvx.size
        flat = None if out is None else tuple(a.reshape(n) for a in _checked_out(out, shape))
        if backend == "numba" or (backend == "auto" and kernel.AVAILABLE and n >= KERNEL_MIN_POINTS):
            fx, fy, mz = kernel.evaluate(self.kernel_coefficients, fvx, fvy, fwz, out=flat)
        else:
            fx, fy, mz = (np.empty(n), np.empty(n), np.empty(n)) if flat is None else flat
            for start in range(0, n, CHUNK):
                sl = slice(start, start + CHUNK)
                fx[sl], fy[sl], mz[sl] = self._evaluate(fvx[sl], fvy[sl], fwz[sl])
        if out is not None:
            return out[0], out[1], out[2]
        return fx.reshape(shape), fy.reshape(shape), mz.reshape(shape)

    @cached_property
    def kernel_coefficients(self) -> kernel.KernelCoefficients:
        """The numbers packed for the compiled kernel (computed once per model)."""
        return kernel.coefficients(self)

    def resultants(self, vx, vy, wz) -> Resultants:
        """`__call__` with checked inputs, as a `Resultants`."""
        vx, vy, wz, shape = checked_kinematics(vx, vy, wz)
        fx, fy, mz = self(vx, vy, wz)
        return Resultants(fx.reshape(shape), fy.reshape(shape), mz.reshape(shape))

    def dissipation(self, vx, vy, wz) -> np.ndarray:
        """D (W) of the isotropic model: −(F·v + M_z ω_z) = D ≥ 0 (Euler's identity)."""
        vx, vy, wz = (np.asarray(a, float) for a in np.broadcast_arrays(vx, vy, wz))
        u = wz * self.R
        v2 = vx * vx + vy * vy
        d0 = self._potential_base(vx, vy, u, v2)
        t, cos1, sin1, sgn, c, _ = _sphere_coordinates(vx.ravel(), vy.ravel(), u.ravel())
        w, _ = basis.weight(t, *POTENTIAL_WEIGHT)
        s0, _, _ = basis.sums(self.correction, cos1, sin1, t)
        corr = self.F0 * np.abs(u.ravel()) * w * s0
        return d0 + corr.reshape(d0.shape)

    def _potential_base(self, vx, vy, u, v2):
        U0 = self.U0
        qv = self.Q[0, 0] * vx * vx + 2 * self.Q[0, 1] * vx * vy + self.Q[1, 1] * vy * vy
        sv = self.S[0, 0] * vx * vx + 2 * self.S[0, 1] * vx * vy + self.S[1, 1] * vy * vy
        u2 = u * u
        P = v2**3 + 3 * u2 * v2 * qv + 3 * U0**5 * u2 * u2 * sv + U0**6 * u2**3
        jx, jy = -vy, vx
        a = u2 + v2
        with np.errstate(invalid="ignore", divide="ignore"):
            t1 = np.where(a > 0, (self.g[0] * jx + self.g[1] * jy) * u * np.abs(u) ** 3 / a**2, 0.0)
            t2 = np.where(a > 0, -(self.xc[0] * jx + self.xc[1] * jy) * u * v2 / a**1.5, 0.0)
        return self.F0 * (P ** (1 / 6) + t1 + t2)

    def _evaluate(self, vx, vy, wz):
        R, F0, U0 = self.R, self.F0, self.U0
        # every resultant is of degree 0 in (v, u): scale the largest component to 1,
        # so that P ~ |v|⁶ neither underflows nor overflows (as the compiled kernel)
        vx, vy, u = _normalised(vx, vy, wz * R)
        u2 = u * u
        v2 = vx * vx + vy * vy
        Q, S = self.Q, self.S
        Qvx, Qvy = Q[0, 0] * vx + Q[0, 1] * vy, Q[0, 1] * vx + Q[1, 1] * vy
        Svx, Svy = S[0, 0] * vx + S[0, 1] * vy, S[0, 1] * vx + S[1, 1] * vy
        qv = vx * Qvx + vy * Qvy
        sv = vx * Svx + vy * Svy
        k5 = U0**5
        P = v2**3 + 3.0 * u2 * v2 * qv + 3.0 * k5 * u2 * u2 * sv + U0**6 * u2**3
        live = P > 0
        inv = np.divide(1.0, P ** (5.0 / 6.0), out=np.zeros_like(P), where=live)
        # ∂P/∂v / 6 and ∂P/∂u / 6
        cv = v2 * v2 + u2 * qv
        cq = u2 * v2
        cs = k5 * u2 * u2
        dvx = (cv * vx + cq * Qvx + cs * Svx) * inv
        dvy = (cv * vy + cq * Qvy + cs * Svy) * inv
        du = (u * v2 * qv + 2.0 * k5 * u * u2 * sv + U0**6 * u * u2 * u2) * inv
        # asymmetric terms
        gx, gy = self.g
        xx, xy = self.xc
        jx, jy = -vy, vx
        a = u2 + v2
        ia = np.divide(1.0, a, out=np.zeros_like(a), where=a > 0)
        au = np.abs(u)
        gj = gx * jx + gy * jy
        w1 = u * au**3 * ia * ia  # T1 = gj w1
        dw1_du = (4.0 * au**3 - 4.0 * u * au**3 * u * ia) * ia * ia
        dw1_dv2 = -2.0 * u * au**3 * ia**3
        # ∂(gj)/∂v = Jᵀ g = (g_y, −g_x)
        dvx += gy * w1 + gj * dw1_dv2 * 2.0 * vx
        dvy += -gx * w1 + gj * dw1_dv2 * 2.0 * vy
        du += gj * dw1_du
        xj = xx * jx + xy * jy
        ia15 = ia * np.sqrt(ia)
        w2 = u * v2 * ia15  # T2 = −xj w2
        dw2_du = v2 * ia15 - 3.0 * u2 * v2 * ia15 * ia
        dw2_dv2 = u * ia15 - 1.5 * u * v2 * ia15 * ia
        dvx -= xy * w2 + xj * dw2_dv2 * 2.0 * vx
        dvy -= -xx * w2 + xj * dw2_dv2 * 2.0 * vy
        du -= xj * dw2_du
        fx = -F0 * dvx
        fy = -F0 * dvy
        mz = -F0 * R * du
        # correction (only where ω_z ≠ 0)
        t, cos1, sin1, sgn, c, sn = _sphere_coordinates(vx, vy, u)
        spin = sgn != 0
        if np.any(self.correction) and np.any(spin):
            w, dw = basis.weight(t, *POTENTIAL_WEIGHT)
            s0, st, sth = basis.sums(self.correction, cos1, sin1, t)
            U = w * s0
            Ut = dw * s0 + w * st
            Ur = (2.0 / np.pi) * c * c * Ut
            rUr = (2.0 / np.pi) * c * sn * Ut
            Uth_r = np.divide(w * sth * c, sn, out=np.zeros_like(sn), where=sn > 0)
            # J∇Û = Û_r ê_θ − (Û_θ/ε) ê_r
            fx += sgn * F0 * (-Ur * sin1 - Uth_r * cos1)
            fy += sgn * F0 * (Ur * cos1 - Uth_r * sin1)
            mz += sgn * F0 * R * (rUr - U)
        alpha = self.anisotropy
        if alpha != 1.0:
            fy = alpha * fy
            mz = mz + (alpha - 1.0) * self._lateral_moment(vx, vy, u, v2, t, cos1, sin1, sgn)
        return fx, fy, mz

    def lateral_moment(self, vx, vy, wz) -> np.ndarray:
        """G = ∬ x τ_y dA (N·m) of the isotropic law, as modelled (used when α ≠ 1).

        Base, ρ² = u² + |v|²: G0 = F0 R [Ĝ0 u³ + (Jv·ĝ1) u² − x̂_x v_y |v|²
        − u (Q̂_xx |v|² − (Jv)_x (Q̂ Jv)_x)] / ρ³, exact in value and slope at
        both ends; plus s F0 R t²(1 − t)² Σ C_g B T.
        """
        vx, vy, wz = (np.asarray(a, float).ravel() for a in np.broadcast_arrays(vx, vy, wz))
        u = wz * self.R
        t, cos1, sin1, sgn, _, _ = _sphere_coordinates(vx, vy, u)
        return self._lateral_moment(vx, vy, u, vx * vx + vy * vy, t, cos1, sin1, sgn)

    def _lateral_moment(self, vx, vy, u, v2, t, cos1, sin1, sgn):
        rho2 = u * u + v2
        irho3 = np.divide(1.0, rho2**1.5, out=np.zeros_like(rho2), where=rho2 > 0)
        Q = self.Q
        jx, jy = -vy, vx
        qjx = Q[0, 0] * jx + Q[0, 1] * jy
        base = (
            self.g0 * u**3
            + (self.g1[0] * jx + self.g1[1] * jy) * u * u
            - self.xc[0] * vy * v2
            - u * (Q[0, 0] * v2 - jx * qjx)
        ) * irho3
        out = self.F0 * self.R * base
        if self.correction_g is not None and np.any(self.correction_g):
            w, _ = basis.weight(t, *DIRECT_WEIGHT)
            s0, _, _ = basis.sums(self.correction_g, cos1, sin1, t)
            out = out + sgn * self.F0 * self.R * w * s0
        return out

    # -- export -----------------------------------------------------------------
    def to_dict(self) -> dict:
        """The coefficients as plain JSON data (the export format; see ``docs/model.md``)."""
        K, L = self.order
        d: dict[str, Any] = {
            "format": FORMAT,
            "units": "SI: F0 in N, M0 in N m, R in m; Q, S, g, xc, g0, g1 and corrections dimensionless",
            "f": self.f,
            "anisotropy": self.anisotropy,
            "R": self.R,
            "F0": self.F0,
            "M0": self.M0,
            "U0": self.U0,
            "Q": self.Q.tolist(),
            "S": self.S.tolist(),
            "g": self.g.tolist(),
            "xc": self.xc.tolist(),
            "K": K,
            "L": L,
            "correction": self.correction.tolist(),
            "correction_weight": list(POTENTIAL_WEIGHT),
            "g0": self.g0,
            "g1": self.g1.tolist(),
            "correction_g": None if self.correction_g is None else self.correction_g.tolist(),
            "correction_g_weight": list(DIRECT_WEIGHT),
            "accuracy": dict(self.accuracy),
            "source": self.source,
        }
        return d

    def to_json(self) -> str:
        from ..output import to_json

        return to_json(self.to_dict())

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> GeneralisedModel:
        """Rebuild a model from `to_dict` output (a one-line error names a bad key)."""
        if not isinstance(d, Mapping):
            raise DataError(f"model must be a JSON object, got {type(d).__name__}")
        if d.get("format") != FORMAT:
            raise DataError(f"model format must be {FORMAT!r}, got {d.get('format')!r}")
        keys = ("f", "R", "F0", "M0", "Q", "S", "g", "xc", "correction")
        missing = [k for k in keys if k not in d]
        if missing:
            raise DataError(f"model is missing key(s) {', '.join(missing)}")
        try:
            return cls(
                f=d["f"],
                R=d["R"],
                F0=d["F0"],
                M0=d["M0"],
                Q=d["Q"],
                S=d["S"],
                g=d["g"],
                xc=d["xc"],
                correction=d["correction"],
                anisotropy=d.get("anisotropy", 1.0),
                g0=d.get("g0", 0.0),
                g1=d.get("g1", [0.0, 0.0]),
                correction_g=d.get("correction_g"),
                accuracy=d.get("accuracy", {}) or {},
                source=str(d.get("source", "")),
            )
        except ArgumentError as exc:
            raise DataError(f"model: {exc}") from None

    @classmethod
    def from_json(cls, text: str) -> GeneralisedModel:
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise DataError(f"model JSON is not valid JSON ({exc.msg} at line {exc.lineno})") from None
        return cls.from_dict(data)


def _normalised(vx, vy, u):
    """(v_x, v_y, u) over max(|v_x|, |v_y|, |u|) (zeros stay zeros)."""
    s = np.maximum(np.maximum(np.abs(vx), np.abs(vy)), np.abs(u))
    k = np.divide(1.0, s, out=np.zeros_like(s), where=s > 0)
    return vx * k, vy * k, u * k


def _sphere_coordinates(vx, vy, u):
    """t, cos θ, sin θ, sgn(ω_z), c = cos(πt/2), sn = sin(πt/2) (module docstring)."""
    v = np.hypot(vx, vy)
    au = np.abs(u)
    rho = np.hypot(v, au)
    sgn = np.sign(u)
    live = rho > 0
    c = np.divide(au, rho, out=np.ones_like(rho), where=live)
    sn = np.divide(v, rho, out=np.zeros_like(rho), where=live)
    t = (2.0 / np.pi) * np.arctan2(v, au)
    moving = v > 0
    cos1 = np.divide(-vy * sgn, v, out=np.ones_like(v), where=moving)
    sin1 = np.divide(vx * sgn, v, out=np.zeros_like(v), where=moving)
    return t, cos1, sin1, sgn, c, sn


def _checked_out(out, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``out`` of `GeneralisedModel.evaluate`, or a one-line `ArgumentError` naming what is wrong."""
    if not isinstance(out, (tuple, list)) or len(out) != 3:
        raise ArgumentError("out must be three arrays (F_x, F_y, M_z)")
    for k, a in enumerate(out):
        ok = isinstance(a, np.ndarray) and a.dtype == np.float64 and a.shape == shape
        if not (ok and a.flags.c_contiguous and a.flags.writeable):
            got = f"{a.dtype} {a.shape}" if isinstance(a, np.ndarray) else type(a).__name__
            raise ArgumentError(
                f"out[{k}] must be a writeable C-contiguous float64 array of shape {shape}, got {got}"
            )
    if any(np.may_share_memory(out[i], out[j]) for i, j in ((0, 1), (0, 2), (1, 2))):
        raise ArgumentError("out: the three arrays must not overlap")
    return out[0], out[1], out[2]
