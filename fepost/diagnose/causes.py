"""The candidate causes: physical extensions of the simulation, as parametrised models.

Every model predicts the three channels of every test point through the exact
integrals (THEORY.md §3, :func:`~fepost.friction.exact.friction_resultants`),
in the dimensionless units of :meth:`Simulation.scales <fepost.diagnose.simulation.Simulation.scales>`:
Fx/(f₀N), Fy/(f₀N), Mz/(f₀NR) with the nominal f₀ and the static map's N and R.

All extensions share the friction level f; each adds its own 1–3 parameters,
which equal a "no effect" value on the nested model ``friction_level``:

============================== ===================== ===============================
cause                          parameters            no-effect value
============================== ===================== ===============================
``none``                       (f = f₀ fixed)        –
``friction_level``             f                     f = f₀ (→ ``none``)
``pressure_dependent_friction`` f, c_p               c_p = 0
``speed_dependent_friction``   f, c_v (s/m)          c_v = 0
``anisotropic_friction``       f, α = f_y/f_x        α = 1
``elliptic_patch``             f, s                  s = 1
``pressure_shift``             f, dx, dy (m)         dx = dy = 0
``sensor_offset``              f, oFx, oFy (N), oMz  offsets = 0
============================== ===================== ===============================

Linear structure (the speed of the fits). The exact resultants are linear in f,
and — while no local coefficient is clipped at zero — in c_p, in c_v and in α
(Fx does not depend on α; Fy ∝ α; Mz = M_a + α M_b). So four exact evaluations
at the data's kinematics, with the laws (f=1), (f=1, c_p=1), (f=1, c_v=1) and
(f=1, α=2), give those models exactly for every parameter value in their bounds:
c_p ∈ [−1/(λσ_max/σ_ref − 1), 1] and c_v > −1/max|w|, where no clipping occurs.
Only ``elliptic_patch`` (stretch x → sx, y → y/s at equal area and load) and
``pressure_shift`` move the pressure map and need new exact integrals per
geometry; f stays linear there too. The load scaling σ → λσ multiplies the
Coulomb part by λ and the pressure-dependent part by λ².
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..friction.exact import friction_resultants
from ..friction.law import FrictionLaw
from .measured import MeasuredData
from .simulation import Simulation

CAUSES = (
    "none",
    "friction_level",
    "pressure_dependent_friction",
    "speed_dependent_friction",
    "elliptic_patch",
    "anisotropic_friction",
    "pressure_shift",
    "sensor_offset",
)

#: Kept exact evaluations per geometric model (stretch or shift values).
CACHE_SIZE = 64


@dataclass(frozen=True)
class Parameter:
    """One model parameter: ``name``, ``unit``, start value, bounds and a typical size."""

    name: str
    unit: str
    start: float
    lower: float
    upper: float
    scale: float
    null: float | None = None  # the no-effect value (None: f, free in every model)
    description: str = ""


@dataclass(frozen=True)
class Candidate:
    """A cause as a model: ``predict(values) -> (n, 3)`` dimensionless channels.

    ``nested`` names the models that are special cases of this one (``none`` and,
    for the extensions, ``friction_level``). Models that move the pressure map
    (costly exact integrals per geometry) also give ``expand(values)``: a
    cheap :class:`Candidate` with the same parameters whose prediction is the
    second-order Taylor expansion of the exact resultants in the geometry about
    ``values`` (f enters linearly and exactly); :func:`fepost.diagnose.fitting.fit`
    iterates it (a Newton-type method on the geometry) and the held-out check
    refits it.
    """

    name: str
    parameters: tuple[Parameter, ...]
    predict: Callable[[np.ndarray], np.ndarray]
    nested: tuple[str, ...]
    description: str
    expand: Callable[[np.ndarray], Candidate] | None = None

    @property
    def n_params(self) -> int:
        return len(self.parameters)


class Predictor:
    """Exact resultants at the data's kinematics, grouped by pressure map (roll).

    ``resultants(law, power, transform)`` returns the (n, 3) dimensionless
    channels for the law, with each row's map scaled by λ (see the module
    docstring; ``power`` 2 for the pressure-dependent part) and the quadratures
    optionally transformed (``transform(quad) -> quad``).
    """

    def __init__(self, sim: Simulation, data: MeasuredData) -> None:
        self.sim = sim
        self.n = len(data)
        self.vx, self.vy, self.wz = np.array(data.vx), np.array(data.vy), np.array(data.wz)
        self.groups = {r: np.flatnonzero(data.roll == r) for r in (-1, 0, 1)}
        self.groups = {r: i for r, i in self.groups.items() if i.size}
        self.scale = sim.scales()
        loads = data.loads(sim.load)
        lam = np.ones(self.n)
        if data.N is not None:
            for r, idx in self.groups.items():
                lam[idx] = loads[idx] / sim.quads[r].load
        self.lam = lam
        self.sigma_ref = sim.pressure_ref
        self.evaluations = 0

    def resultants(self, law: FrictionLaw, power: int = 1, transform=None) -> np.ndarray:
        out = np.empty((self.n, 3))
        for r, idx in self.groups.items():
            quad = self.sim.quads[r]
            if transform is not None:
                quad = transform(quad)
            res = friction_resultants(quad, self.vx[idx], self.vy[idx], self.wz[idx], law)
            out[idx] = np.column_stack([res.Fx, res.Fy, res.Mz]) * self.lam[idx, None] ** power
        self.evaluations += 1
        return out / self.scale

    def max_slip_speed(self) -> float:
        """An upper bound of |w| over every patch point and test point (m/s)."""
        reach = max(q.radius for q in self.sim.quads.values())
        return float(np.max(np.hypot(self.vx, self.vy) + np.abs(self.wz) * reach))

    def max_pressure_ratio(self) -> float:
        """max over rows and maps of λ σ_max / σ_ref."""
        top = 0.0
        for r, idx in self.groups.items():
            top = max(
                top,
                float(np.max(self.lam[idx])) * float(np.max(self.sim.quads[r].sigma)) / self.sigma_ref,
            )
        return top


class _GeometryCache:
    """Exact f = 1 resultants per geometry tuple, least recently used dropped first."""

    def __init__(self, compute: Callable[[tuple], np.ndarray]) -> None:
        self.compute = compute
        self.store: OrderedDict[tuple, np.ndarray] = OrderedDict()

    def __call__(self, key: tuple) -> np.ndarray:
        key = tuple(float(k) for k in key)
        hit = self.store.get(key)
        if hit is not None:
            self.store.move_to_end(key)
            return hit
        value = self.compute(key)
        self.store[key] = value
        if len(self.store) > CACHE_SIZE:
            self.store.popitem(last=False)
        return value


#: Central-difference step of the geometric derivatives (first, second and mixed),
#: in units of each parameter's
#: scale (0.2 × 0.05 = 1 % stretch; 0.2 × 0.05R = 0.01R shift). Deliberately not
#: tiny: the exact resultants jump by ~1e-4 f·N when an instantaneous centre of
#: rotation crosses the patch boundary (the interpolated pressure is not zero
#: there), which would swamp a small-step difference; the step's truncation
#: error is O(h²) and affects only the Gauss–Newton path and the intervals.
GEOMETRY_STEP = 0.2


def _geometric(
    name: str,
    parameters: tuple[Parameter, ...],
    basis: Callable[[tuple], np.ndarray],
    nested: tuple[str, ...],
    description: str,
) -> Candidate:
    """A candidate f·B(g) with B the exact f = 1 resultants for geometry g = values[1:]."""

    def predict(p):
        return p[0] * basis(tuple(p[1:]))

    steps = np.array([GEOMETRY_STEP * q.scale for q in parameters[1:]])
    bounds = [(q.lower, q.upper) for q in parameters[1:]]

    def expand(at):
        at = np.asarray(at, float)
        g0 = at[1:]
        m = g0.size
        b0 = basis(tuple(g0))
        grad = np.empty((m, *b0.shape))
        hess = np.zeros((m, m, *b0.shape))
        plus = []
        for j, h in enumerate(steps):
            gp, gm = g0.copy(), g0.copy()
            gp[j] = min(g0[j] + h, bounds[j][1])
            gm[j] = max(g0[j] - h, bounds[j][0])
            hp, hm = gp[j] - g0[j], g0[j] - gm[j]
            bp, bm = basis(tuple(gp)), basis(tuple(gm))
            # second-order divided differences on the (possibly uneven) stencil
            grad[j] = (bp - bm) / (hp + hm) if hp and hm else ((bp - b0) / hp if hp else (b0 - bm) / hm)
            if hp and hm:
                hess[j, j] = 2.0 * (hp * bm + hm * bp - (hp + hm) * b0) / (hp * hm * (hp + hm))
            plus.append((gp, hp))
        for j in range(m):
            for k in range(j + 1, m):
                gjk = g0.copy()
                gjk[j], gjk[k] = plus[j][0][j], plus[k][0][k]
                hj, hk = plus[j][1], plus[k][1]
                if hj and hk:
                    bjk = basis(tuple(gjk))
                    bj, bk = basis(tuple(plus[j][0])), basis(tuple(plus[k][0]))
                    hess[j, k] = hess[k, j] = (bjk - bj - bk + b0) / (hj * hk)

        def local(p):
            dg = np.asarray(p[1:], float) - g0
            quad = np.tensordot(dg, np.tensordot(dg, hess, axes=(0, 1)), axes=1)
            return p[0] * (b0 + np.tensordot(dg, grad, axes=1) + 0.5 * quad)

        return Candidate(name, parameters, local, nested, description + " (local quadratic model)")

    return Candidate(name, parameters, predict, nested, description, expand)


def build_candidates(pred: Predictor) -> dict[str, Candidate]:
    """Every cause of :data:`CAUSES` as a :class:`Candidate` over the predictor's points."""
    sim = pred.sim
    f0 = sim.friction
    R = sim.radius
    ref = pred.sigma_ref
    base = pred.resultants(FrictionLaw(f=1.0))
    press = pred.resultants(FrictionLaw(f=1.0, pressure_coef=1.0, pressure_ref=ref), power=2)
    speed = pred.resultants(FrictionLaw(f=1.0, speed_coef=1.0)) - base
    aniso2 = pred.resultants(FrictionLaw(f=1.0, anisotropy=2.0))
    m_b = aniso2[:, 2] - base[:, 2]
    m_a = base[:, 2] - m_b
    scale = pred.scale

    f_par = Parameter("f", "1", f0, 0.01 * f0, 10.0 * f0, f0, None, "friction coefficient (along x)")

    ratio = pred.max_pressure_ratio()
    cp_low = -1.0 / (ratio - 1.0) if ratio > 1.0 else -10.0
    cv_low = -1.0 / pred.max_slip_speed() if pred.max_slip_speed() > 0 else -10.0

    coulomb = FrictionLaw(f=1.0)
    stretch = _GeometryCache(lambda g: pred.resultants(coulomb, transform=lambda q: q.stretched(g[0])))
    shift = _GeometryCache(lambda g: pred.resultants(coulomb, transform=lambda q: q.shifted(g[0], g[1])))

    def aniso(p):
        f, a = p
        return f * np.column_stack([base[:, 0], a * base[:, 1], m_a + a * m_b])

    cands = [
        Candidate(
            "none",
            (),
            lambda p: f0 * base,
            (),
            "the simulation as it is: exact integrals, nominal f",
        ),
        Candidate(
            "friction_level",
            (f_par,),
            lambda p: p[0] * base,
            ("none",),
            "one friction coefficient f ≠ f₀",
        ),
        Candidate(
            "pressure_dependent_friction",
            (
                f_par,
                Parameter("c_p", "1", 0.0, cp_low, 1.0, 0.1, 0.0, "μ = f (1 + c_p (σ/σ_ref − 1))"),
            ),
            lambda p: p[0] * ((1.0 - p[1]) * base + p[1] * press),
            ("none", "friction_level"),
            "local friction coefficient depends on local contact pressure",
        ),
        Candidate(
            "speed_dependent_friction",
            (
                f_par,
                Parameter("c_v", "s/m", 0.0, 0.999 * cv_low, 10.0, 0.05, 0.0, "μ = f (1 + c_v |w|)"),
            ),
            lambda p: p[0] * (base + p[1] * speed),
            ("none", "friction_level"),
            "local friction coefficient depends on local sliding speed |w|",
        ),
        _geometric(
            "elliptic_patch",
            (
                f_par,
                Parameter("s", "1", 1.0, 0.5, 2.0, 0.05, 1.0, "stretch x → s·x, y → y/s (aspect s²)"),
            ),
            stretch,
            ("none", "friction_level"),
            "the real patch is elongated along x (equal area and load)",
        ),
        Candidate(
            "anisotropic_friction",
            (f_par, Parameter("alpha", "1", 1.0, 0.2, 5.0, 0.1, 1.0, "α = f_y/f_x")),
            aniso,
            ("none", "friction_level"),
            "friction differs along x and along y",
        ),
        _geometric(
            "pressure_shift",
            (
                f_par,
                Parameter(
                    "dx",
                    "m",
                    0.0,
                    -0.5 * R,
                    0.5 * R,
                    0.05 * R,
                    0.0,
                    "shift of the pressure map along x",
                ),
                Parameter(
                    "dy",
                    "m",
                    0.0,
                    -0.5 * R,
                    0.5 * R,
                    0.05 * R,
                    0.0,
                    "shift of the pressure map along y",
                ),
            ),
            shift,
            ("none", "friction_level"),
            "the real centre of pressure lies elsewhere than the simulated one",
        ),
        Candidate(
            "sensor_offset",
            (
                f_par,
                Parameter(
                    "offset_Fx",
                    "N",
                    0.0,
                    -np.inf,
                    np.inf,
                    0.01 * scale[0],
                    0.0,
                    "constant added to Fx",
                ),
                Parameter(
                    "offset_Fy",
                    "N",
                    0.0,
                    -np.inf,
                    np.inf,
                    0.01 * scale[1],
                    0.0,
                    "constant added to Fy",
                ),
                Parameter(
                    "offset_Mz",
                    "N·m",
                    0.0,
                    -np.inf,
                    np.inf,
                    0.01 * scale[2],
                    0.0,
                    "constant added to Mz",
                ),
            ),
            lambda p: p[0] * base + np.asarray(p[1:4]) / scale,
            ("none", "friction_level"),
            "constant offsets in the measured Fx, Fy, Mz",
        ),
    ]
    return {c.name: c for c in cands}
