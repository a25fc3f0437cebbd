"""The tire's contact for the shimmy model: forces from fepost's friction models.

Each adapter is a `Contact`: ``forces(vx, vy, wz)`` gives the friction force
(Fx, Fy in N) and torque (Mz in N·m about the patch origin) on one tire in its
patch frame (x rolling direction, y lateral; docs/theory.md) for the sliding
velocity (vx, vy) of the patch origin and the spin wz, as `fepost.friction.predict`
evaluates them:

* ``closed_forms``: the paper's (1.3)/(1.7) with F0, M0, a, m, k_x, R, written so
  that they are analytic away from v = u = 0 (F∥ v̂ = F0 v/√(v² + a u²), the sign
  functions absorbed into u = R wz), which lets complex-step derivatives through;
  equal to `fepost.friction.closed_form.components` for real input;
* ``generalised``: fepost's generalised model (`fepost.friction.model.GeneralisedModel`);
* ``exact``: the exact Coulomb integrals over the pressure map
  (`fepost.friction.exact.friction_resultants`).

`jacobian` gives ∂(Fx, Fy, Mz)/∂(vx, vy, wz): by complex step where the adapter
takes complex input (the closed forms), else by scipy's adaptive high-order
central differences (`scipy.differentiate.jacobian`) with its error estimate.

Coulomb friction does not depend on the sliding speed, only on the direction of
(vx, vy, R wz): every model here is homogeneous of degree 0 in the kinematics
(`fepost.shimmy.table` tabulates a model over that sphere of directions for the
time integration). ``scalar`` is a fast one-point version of ``forces`` (Python
floats in and out) where the adapter has one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import ArgumentError

#: The friction models by name, in the order of the shimmy JSON contract.
MODEL_NAMES = ("closed_forms", "generalised", "exact")
#: Complex step (relative to the kinematics' scale): round-off free derivatives.
COMPLEX_STEP = 1e-30

Forces = tuple[np.ndarray, np.ndarray, np.ndarray]


def closed_form_forces(
    vx, vy, wz, *, F0: float, M0: float, a: float, m: float, k_x: float, R: float
) -> Forces:
    """(Fx, Fy, Mz) of the paper's closed forms, analytic (complex input allowed).

    Examples
    --------
    >>> Fx, Fy, Mz = closed_form_forces(1.0, 0.0, 0.0, F0=100.0, M0=10.0, a=1.0, m=9.0, k_x=0.1, R=0.2)
    >>> float(Fx), float(Fy), float(Mz)
    (-100.0, 0.0, 0.0)
    """
    vx, vy, wz = np.broadcast_arrays(*(np.asarray(q) for q in (vx, vy, wz)))
    u = R * wz
    v2 = vx * vx + vy * vy
    den_f = np.sqrt(v2 + a * u * u)
    fx = -F0 * vx / den_f
    fy = -F0 * vy / den_f - k_x * M0 / (2.0 * R) * u / np.sqrt(u * u + 0.25 * m * v2)
    mz = -M0 * u / np.sqrt(u * u + m * v2)
    return fx, fy, mz


@dataclass(frozen=True)
class Contact:
    """One tire's friction model: ``forces(vx, vy, wz) -> (Fx, Fy, Mz)`` (module docstring).

    ``R``: the patch radius (m) of the spin speed u = R wz; ``F0``, ``M0``: the
    model's sliding force and spin torque (N, N·m); ``complex_ok``: whether
    ``forces`` takes complex input (complex-step derivatives).
    """

    name: str
    forces: Callable[..., Forces]
    R: float
    F0: float
    M0: float
    complex_ok: bool = False
    info: dict = field(default_factory=dict)
    scalar: Callable[[float, float, float], tuple[float, float, float]] | None = None

    def __call__(self, vx, vy, wz) -> Forces:
        return self.forces(vx, vy, wz)

    def jacobian(self, vx: float, vy: float, wz: float) -> np.ndarray:
        """∂(Fx, Fy, Mz)/∂(vx, vy, wz) at one kinematic point (3 × 3; N s/m, N s, ...)."""
        k0 = np.array([vx, vy, wz], float)
        scale = np.array([1.0, 1.0, 1.0 / self.R]) * max(float(np.hypot(vx, vy)), self.R * abs(wz))
        if self.complex_ok:
            return _complex_step(self.forces, k0, scale)
        return _richardson(self.forces, k0, scale)

    def scaled(self, factor: float) -> Contact:
        """The same model with every force and torque times ``factor`` (a friction level f'/f)."""
        base = self.forces

        def forces(vx, vy, wz):
            fx, fy, mz = base(vx, vy, wz)
            return factor * fx, factor * fy, factor * mz

        one = self.scalar

        def scalar(vx, vy, wz):
            fx, fy, mz = one(vx, vy, wz)  # type: ignore[misc]
            return factor * fx, factor * fy, factor * mz

        return Contact(
            self.name,
            forces,
            self.R,
            factor * self.F0,
            factor * self.M0,
            self.complex_ok,
            {**self.info, "scale": factor},
            scalar if one is not None else None,
        )


def _complex_step(fun, k0: np.ndarray, scale: np.ndarray) -> np.ndarray:
    jac = np.empty((3, 3))
    for j in range(3):
        k = k0.astype(complex)
        h = COMPLEX_STEP * scale[j]
        k[j] += 1j * h
        out = fun(k[0], k[1], k[2])
        jac[:, j] = [float(np.imag(o)) / h for o in out]
    return jac


def _richardson(fun, k0: np.ndarray, scale: np.ndarray) -> np.ndarray:
    from scipy.differentiate import jacobian

    def f(z):  # z: (3, ...) kinematics in units of scale
        shape = z.shape[1:]
        out = fun(*(np.ravel(z[i]) * scale[i] for i in range(3)))
        return np.stack([np.reshape(o, shape) for o in out])

    res = jacobian(f, k0 / scale, initial_step=0.05, order=8, tolerances={"rtol": 1e-10})
    return np.asarray(res.df) / scale[None, :]


def closed_forms_contact(*, F0: float, M0: float, a: float, m: float, k_x: float, R: float) -> Contact:
    """The paper's closed forms as a `Contact` (complex-step capable)."""
    coef = {"F0": F0, "M0": M0, "a": a, "m": m, "k_x": k_x, "R": R}
    for key, value in coef.items():
        if not np.isfinite(value):
            raise ArgumentError(f"{key} must be finite, got {value!r}")

    def forces(vx, vy, wz):
        return closed_form_forces(vx, vy, wz, **coef)

    half_m = 0.25 * m
    kx_term = k_x * M0 / (2.0 * R)

    def scalar(vx: float, vy: float, wz: float) -> tuple[float, float, float]:
        u = R * wz
        v2 = vx * vx + vy * vy
        if v2 == 0.0 and u == 0.0:
            return 0.0, 0.0, 0.0
        uu = u * u
        den = math.sqrt(v2 + a * uu)
        return (
            -F0 * vx / den,
            -F0 * vy / den - kx_term * u / math.sqrt(uu + half_m * v2),
            -M0 * u / math.sqrt(uu + m * v2),
        )

    return Contact("closed_forms", forces, R, F0, M0, complex_ok=True, info=dict(coef), scalar=scalar)


def model_contact(model, name: str = "generalised") -> Contact:
    """A `fepost.friction.model.GeneralisedModel` as a `Contact` (real input only)."""

    def forces(vx, vy, wz):
        vx, vy, wz = np.broadcast_arrays(*(np.atleast_1d(np.asarray(q, float)) for q in (vx, vy, wz)))
        return model(vx.ravel(), vy.ravel(), wz.ravel())

    f0 = -float(forces(1.0, 0.0, 0.0)[0][0])
    m0 = -float(forces(0.0, 0.0, 1.0)[2][0])
    return Contact(name, forces, float(model.R), f0, m0)


def exact_contact(quad, law, R: float) -> Contact:
    """The exact Coulomb integrals over a pressure quadrature as a `Contact` (real input only)."""
    from ..friction.exact import friction_resultants

    if law.depends_on_speed:
        raise ArgumentError("the shimmy model needs a rate-independent friction law (no speed dependence)")

    def forces(vx, vy, wz):
        r = friction_resultants(quad, vx, vy, wz, law, threads=1)
        return np.ravel(r.Fx), np.ravel(r.Fy), np.ravel(r.Mz)

    f0 = -float(forces(1.0, 0.0, 0.0)[0][0])
    m0 = -float(forces(0.0, 0.0, 1.0)[2][0])
    return Contact("exact", forces, float(R), f0, m0)
