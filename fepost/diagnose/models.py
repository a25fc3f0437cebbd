"""Models over the exact integrals: one extension or several at once, with their geometry.

A model is a set of extensions of the simulation (`fepost.diagnose.causes`)
sharing the friction level f. Its prediction, in the dimensionless units of
`Simulation.scales <fepost.diagnose.simulation.Simulation.scales>`, is

    f · [(1 − c_p)(B₀₀ + c_v (B₀₁ − B₀₀)) + c_p (B₁₀ + c_v (B₁₁ − B₁₀))] + o / scale,

where B_pv are exact resultants (`friction_resultants`)
of four laws with f = 1: Coulomb (B₀₀), pressure-dependent with c_p = 1 (B₁₀, whose
load scaling is λ² since μσ ∝ σ²), speed-dependent with c_v = 1 (B₀₁) and both
(B₁₁). The local coefficient μ = f (1 + c_p(σ/σ_ref − 1))(1 + c_v|w|) is bilinear
in (c_p, c_v), so these four give the law exactly while no factor is clipped at
zero (the parameter bounds keep them positive). Anisotropy α = f_y/f_x scales
the lateral traction only, so each resultant is affine in α:
B(α) = B(1) + (α − 1)(B(2) − B(1)). Offsets o add to the channels. Only the
terms a model needs are evaluated (one for ``friction_level``, two for a
single pressure-, speed- or direction-dependent law, up to eight for a pair).

Geometry (the stretch s of ``elliptic_patch``, the shift dx, dy of
``pressure_shift`` and the rim share c_rim of ``pressure_shape``,
`fepost.diagnose.shape`; reshaped first, then stretched, then shifted) changes
the pressure map, so every
B depends on it and needs new exact integrals per geometry. Those are cached
(`CACHE_SIZE` per `Predictor`, shared by all models). A geometric
model also offers ``expand(values)``: the same formula with each B replaced by
its second-order Taylor expansion in the geometry about ``values``, from central
differences of step `GEOMETRY_STEP` (first and second derivatives, and
mixed ones). `fepost.diagnose.fitting.fit` iterates these local models.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..friction.exact import friction_resultants
from ..friction.law import FrictionLaw
from .measured import MeasuredData
from .shape import reshaped, rim_weight
from .simulation import Simulation

#: Kept exact evaluations per predictor (law term, anisotropy, geometry; shifts per row).
CACHE_SIZE = 256

#: Central-difference step of the geometric derivatives (first, second and mixed),
#: in units of each parameter's scale (0.2 × 0.05 = 1 % stretch; 0.2 × 0.05R = 0.01R
#: shift). Deliberately not tiny: the exact resultants jump by ~1e-4 f·N when an
#: instantaneous centre of rotation crosses the patch boundary (the interpolated
#: pressure is not zero there), which would swamp a small-step difference; the
#: step's truncation error is O(h²) and affects only the Gauss–Newton path and
#: the intervals.
GEOMETRY_STEP = 0.2

#: Geometric parameters and their no-effect values, in the order of the geometry tuple.
GEOMETRY = (("s", 1.0), ("dx", 0.0), ("dy", 0.0), ("c_rim", 0.0))
IDENTITY = tuple(v for _, v in GEOMETRY)
OFFSETS = ("offset_Fx", "offset_Fy", "offset_Mz")
#: Crosstalk terms of the load cell, c_ab: measured channel a gains c_ab × true channel b
#: (channels x = Fx, y = Fy, z = Mz), with (a, b) their positions.
CROSSTALK = {"c_xy": (0, 1), "c_xz": (0, 2), "c_yx": (1, 0), "c_yz": (1, 2), "c_zx": (2, 0), "c_zy": (2, 1)}


def apply_sensor(index: dict, p, out: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """The load cell's view of the true channels ``out`` (n, 3, scaled): C·out, then offsets.

    C = I + the crosstalk terms present in ``index`` (SI: c_xy, c_yx in 1; c_xz,
    c_yz in 1/m; c_zx, c_zy in m); in scaled channels C'_ab = C_ab s_b/s_a.
    """
    if "c_xy" in index:
        C = np.eye(3)
        for name, (a, b) in CROSSTALK.items():
            C[a, b] = p[index[name]] * scale[b] / scale[a]
        out = out @ C.T
    if OFFSETS[0] in index:
        out = out + np.array([p[index[o]] for o in OFFSETS]) / scale
    return out


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
    """A model: ``predict(values) -> (n, 3)`` dimensionless channels.

    ``nested`` names the models that are special cases of this one. Models that
    move the pressure map also give ``expand(values)``: a cheap Candidate with
    the same parameters, exact at ``values`` and second-order accurate in the
    geometry about them (module docstring). ``extensions`` are the causes the
    model combines (empty for ``none`` and ``friction_level``).
    """

    name: str
    parameters: tuple[Parameter, ...]
    predict: Callable[[np.ndarray], np.ndarray]
    nested: tuple[str, ...]
    description: str
    expand: Callable[..., Candidate] | None = None
    extensions: tuple[str, ...] = ()

    @property
    def n_params(self) -> int:
        return len(self.parameters)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)


class Predictor:
    """Exact resultants at the data's kinematics, grouped by pressure map (roll).

    ``resultants(law, power, transform)`` returns the (n, 3) dimensionless
    channels for the law, with each row's map scaled by λ = N_row/N_map (``power``
    2 for a pressure-dependent part, see the module docstring) and the
    quadratures optionally transformed (``transform(quad) -> quad``).
    `raw` caches them per (law term, anisotropy, geometry).
    """

    def __init__(self, sim: Simulation, data: MeasuredData) -> None:
        self.sim = sim
        self.n = len(data)
        self.vx, self.vy, self.wz = np.array(data.vx), np.array(data.vy), np.array(data.wz)
        self.groups = {r: np.flatnonzero(data.roll == r) for r in (-1, 0, 1)}
        self.groups = {r: i for r, i in self.groups.items() if i.size}
        self.scale = sim.scales()
        loads = data.loads(sim.load)
        self.loads = loads
        lam = np.ones(self.n)
        if data.N is not None:
            for r, idx in self.groups.items():
                lam[idx] = loads[idx] / sim.quads[r].load
        self.lam = lam
        self.sigma_ref = sim.pressure_ref
        self.evaluations = 0
        self._cache: OrderedDict[tuple, np.ndarray] = OrderedDict()
        self._rims: dict[int, tuple] = {}

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

    def coulomb_moved(self, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """Coulomb resultants (f = 1, scaled) with each row's map moved by its own (dx_i, dy_i) (m).

        Exact: the map moved by d gives the force of the unmoved map at the
        velocity v + ω×d of the moved origin, and the torque about the patch
        origin gains d × F (docs/diagnose.md, ``load_transfer``).
        """
        dx = np.asarray(dx, float)
        dy = np.asarray(dy, float)
        # the load-transfer fits ask for the same shifts again (its derivatives about the
        # start and about the fit's result): kept with the geometry's resultants (`raw`)
        key = ("moved", hashlib.sha1(np.ascontiguousarray([dx, dy]).tobytes()).hexdigest())
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
            return hit.copy()
        vx = self.vx - self.wz * dy
        vy = self.vy + self.wz * dx
        law = FrictionLaw(f=1.0, pressure_ref=self.sigma_ref)
        out = np.empty((self.n, 3))
        for r, idx in self.groups.items():
            res = friction_resultants(self.sim.quads[r], vx[idx], vy[idx], self.wz[idx], law)
            out[idx] = np.column_stack([res.Fx, res.Fy, res.Mz]) * self.lam[idx, None]
        self.evaluations += 1
        out[:, 2] += dx * out[:, 1] - dy * out[:, 0]
        out /= self.scale
        self._cache[key] = out
        if len(self._cache) > CACHE_SIZE:
            self._cache.popitem(last=False)
        return out.copy()

    def raw(self, term: tuple[int, int], alpha: float, geometry: tuple[float, ...]) -> np.ndarray:
        """B_term (f = 1) with anisotropy ``alpha`` on the map changed by ``geometry`` (s, dx, dy, c_rim)."""
        key = (term, float(alpha), *(float(g) for g in geometry))
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
            return hit
        cp, cv = term
        law = FrictionLaw(
            f=1.0, pressure_coef=float(cp), speed_coef=float(cv), anisotropy=float(alpha),
            pressure_ref=self.sigma_ref,
        )  # fmt: skip
        s, dx, dy, c_rim = (float(g) for g in geometry)

        def transform(q):
            if c_rim:
                q = reshaped(q, c_rim, self.rim_weight(q))
            if s != 1.0:
                q = q.stretched(s)
            if dx or dy:
                q = q.shifted(dx, dy)
            return q

        moved = (s, dx, dy, c_rim) != IDENTITY
        value = self.resultants(law, power=2 if cp else 1, transform=transform if moved else None)
        value.setflags(write=False)
        self._cache[key] = value
        if len(self._cache) > CACHE_SIZE:
            self._cache.popitem(last=False)
        return value

    def rim_weight(self, quad):
        """The rim weight of ``quad`` (one of the simulation's maps), computed once per map."""
        hit = self._rims.get(id(quad))
        if hit is None or hit[0] is not quad:
            hit = self._rims[id(quad)] = (quad, rim_weight(quad))
        return hit[1]

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


@dataclass(frozen=True)
class _Layout:
    """Where each kind of parameter sits in a model's value vector."""

    index: dict
    terms: tuple[tuple[int, int], ...]
    alphas: tuple[float, ...]
    geometric: tuple[int, ...]  # positions in the value vector
    geometry_slots: tuple[int, ...]  # their slot in (s, dx, dy)

    @classmethod
    def of(cls, parameters: tuple[Parameter, ...]) -> _Layout:
        index = {p.name: j for j, p in enumerate(parameters)}
        press, speed = "c_p" in index, "c_v" in index
        terms = [(0, 0)] + [(1, 0)] * press + [(0, 1)] * speed + [(1, 1)] * (press and speed)
        alphas = (1.0, 2.0) if "alpha" in index else (1.0,)
        slots = [k for k, (name, _) in enumerate(GEOMETRY) if name in index]
        geometric = tuple(index[GEOMETRY[k][0]] for k in slots)
        return cls(index, tuple(terms), alphas, geometric, tuple(slots))

    def geometry(self, p) -> tuple[float, ...]:
        g = list(IDENTITY)
        for j, k in zip(self.geometric, self.geometry_slots, strict=True):
            g[k] = float(p[j])
        return tuple(g)

    def keys(self):
        return [(t, a) for t in self.terms for a in self.alphas]


def _combine(layout: _Layout, p, raw: dict, scale: np.ndarray) -> np.ndarray:
    """The model formula (module docstring) from the raw bases ``raw[(term, alpha)]``."""
    idx = layout.index
    anis = "alpha" in idx

    def b(term):
        one = raw[(term, 1.0)]
        if not anis:
            return one
        return one + (p[idx["alpha"]] - 1.0) * (raw[(term, 2.0)] - one)

    def speed_law(lo, hi):
        if "c_v" not in idx:
            return b(lo)
        blo = b(lo)
        return blo + p[idx["c_v"]] * (b(hi) - blo)

    m = speed_law((0, 0), (0, 1))
    if "c_p" in idx:
        cp = p[idx["c_p"]]
        m = (1.0 - cp) * m + cp * speed_law((1, 0), (1, 1))
    return apply_sensor(idx, p, p[idx["f"]] * m, scale)


def extension_model(
    pred: Predictor,
    name: str,
    parameters: tuple[Parameter, ...],
    nested: tuple[str, ...],
    description: str,
    extensions: tuple[str, ...],
) -> Candidate:
    """A `Candidate` combining the parameters' effects exactly (module docstring)."""
    layout = _Layout.of(parameters)
    keys = layout.keys()
    scale = pred.scale

    def raw_at(g):
        return {k: pred.raw(k[0], k[1], g) for k in keys}

    if not layout.geometric:
        fixed = raw_at(IDENTITY)
        return Candidate(
            name, parameters, lambda p: _combine(layout, p, fixed, scale), nested, description,
            None, extensions,
        )  # fmt: skip

    geo = [parameters[j] for j in layout.geometric]
    steps = np.array([GEOMETRY_STEP * q.scale for q in geo])
    bounds = [(q.lower, q.upper) for q in geo]

    def predict(p):
        return _combine(layout, p, raw_at(layout.geometry(p)), scale)

    def expand(at, order: int = 2) -> Candidate:
        at = np.asarray(at, float)
        g0 = at[list(layout.geometric)]
        m = g0.size

        def raw_g(gv):
            full = at.copy()
            full[list(layout.geometric)] = gv
            return raw_at(layout.geometry(full))

        b0 = raw_g(g0)
        grad = {k: np.empty((m, *v.shape)) for k, v in b0.items()}
        hess = {k: np.zeros((m, m, *v.shape)) for k, v in b0.items()}
        plus = []
        for j, h in enumerate(steps):
            gp, gm = g0.copy(), g0.copy()
            gp[j] = min(g0[j] + h, bounds[j][1])
            gm[j] = max(g0[j] - h, bounds[j][0])
            hp, hm = gp[j] - g0[j], g0[j] - gm[j]
            bp, bm = raw_g(gp), raw_g(gm)
            for k in keys:
                # second-order divided differences on the (possibly uneven) stencil
                if hp and hm:
                    grad[k][j] = (bp[k] - bm[k]) / (hp + hm)
                    if order > 1:
                        curv = hp * bm[k] + hm * bp[k] - (hp + hm) * b0[k]
                        hess[k][j, j] = 2.0 * curv / (hp * hm * (hp + hm))
                else:
                    grad[k][j] = (bp[k] - b0[k]) / hp if hp else (b0[k] - bm[k]) / hm
            plus.append((gp, hp))
        if order > 1:
            for j in range(m):
                for i in range(j + 1, m):
                    hj, hi = plus[j][1], plus[i][1]
                    if not (hj and hi):
                        continue
                    gji = g0.copy()
                    gji[j], gji[i] = plus[j][0][j], plus[i][0][i]
                    bji, bj, bi = raw_g(gji), raw_g(plus[j][0]), raw_g(plus[i][0])
                    for k in keys:
                        hess[k][j, i] = hess[k][i, j] = (bji[k] - bj[k] - bi[k] + b0[k]) / (hj * hi)

        def local(p):
            dg = np.asarray(p, float)[list(layout.geometric)] - g0
            raw = {}
            for k in keys:
                v = b0[k] + np.tensordot(dg, grad[k], axes=1)
                if order > 1:
                    v = v + 0.5 * np.tensordot(dg, np.tensordot(dg, hess[k], axes=(0, 1)), axes=1)
                raw[k] = v
            return _combine(layout, p, raw, scale)

        kind = "local quadratic model" if order > 1 else "local linear model"
        return Candidate(name, parameters, local, nested, f"{description} ({kind})", None, extensions)

    return Candidate(name, parameters, predict, nested, description, expand, extensions)


def with_fixed(cand: Candidate, name: str, value: float, new_name: str | None = None) -> Candidate:
    """``cand`` with the parameter ``name`` held at ``value`` (its expansions too)."""
    j = cand.names.index(name)
    params = cand.parameters[:j] + cand.parameters[j + 1 :]

    def full(p):
        return np.insert(np.asarray(p, float), j, value)

    def predict(p):
        return cand.predict(full(p))

    expand = None
    if cand.expand is not None:
        inner = cand.expand

        def expand(at, order: int = 2):
            return with_fixed(inner(full(at), order=order), name, value, new_name)

    return Candidate(
        new_name or f"{cand.name}|{name}={value:g}", params, predict, (),
        f"{cand.description}, {name} = {value:g}", expand, cand.extensions,
    )  # fmt: skip
