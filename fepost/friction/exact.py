"""Exact dry-friction resultants of a pressure map (Coulomb's law at every point), by quadrature.

For a patch sliding at (v_x, v_y) (m/s) and spinning at ω_z (rad/s) the tire
point (x, y) slides at w = (v_x − ω_z y, v_y + ω_z x) and carries the traction
τ = −μσ (ŵ_x, α ŵ_y) of `FrictionLaw`. The
resultants on the tire are F = ∬ τ dA (N) and M_z = ∬ (x τ_y − y τ_x) dA (N·m)
about the patch origin.

Singularity subtraction
-----------------------
When ω_z ≠ 0 the direction field ŵ = sgn(ω_z)·ê_θ(p − p0) turns about the
instantaneous centre of rotation p0 = (−v_y/ω_z, v_x/ω_z): bounded, but
discontinuous at p0, which spoils any fixed quadrature when p0 lies inside the
patch. With g = μσ (Pa) and g0 = g(p0) (μ at |w| = 0) we integrate

    ∬ g ŵ dA = ∬ (g − g0) ŵ dA  +  g0 ∬_domain ŵ dA,

the first term on the quadrature nodes (its integrand vanishes at p0, so it is
continuous there) and the second analytically in polar coordinates about p0,
with ρ_max(θ) the distance from p0 to the domain boundary along θ:

    ∬ ê_θ dA = (−I_y, I_x),    I = ∫₀^{2π} (cos θ, sin θ) ρ_max²/2 dθ,
    ∬ (α x ê_θ,y − y ê_θ,x) dA = α p0_x I_x + p0_y I_y + ∫ (α cos²θ + sin²θ) ρ_max³/3 dθ.

ρ_max is analytic and periodic, so the periodic trapezoid converges spectrally;
its strip of analyticity narrows like √δ as p0 nears the boundary (δ = 1 − q,
q the ellipse level of p0), and the number of θ nodes grows accordingly
(`_theta_nodes`).

Centres on and near the boundary
--------------------------------
Just outside (1 ≤ q < `OUTSIDE_BAND`) the integrand turns within a node spacing
of the edge: a uniform disc lost 1.2e-4 of fN there, a jump against the value
just inside. Such centres are subtracted too, L the constant g at the boundary
point c + (p0 − c)/q, with ρ_maxⁿ replaced by ρ_outⁿ − ρ_inⁿ over the directions
[θ_c − Δ, θ_c + Δ] that meet the domain; with θ = θ_c + Δ cos φ the integrand is
smooth and even in φ (ρ_out − ρ_in ∝ sin φ), so the midpoint rule in φ converges
spectrally, `OUTSIDE_NODES` at any distance. Near a square-root edge (Hertz)
g's gradient grows like δ^(−1/2) and its term cost 1.9e-4 of fN at δ = 1e-6:
inside, it is scaled by min(1, δ/`GRADIENT_TAPER`). The integrals do not depend
on L, only the error does: below 2e-5 of fN on either side of the boundary, the
uniform disc's to round-off (tests/test_friction_continuity.py).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import partial

import numpy as np

from .._arrays import frozen
from .._blas import one_blas_thread
from .._threads import default_threads
from ..errors import ArgumentError
from . import chunksums, nodesums
from . import turns as turns_mod
from .law import FrictionLaw
from .quadrature import Ellipse, PressureQuadrature, turn_angles

#: Trapezoid nodes in θ: at least this many ...
THETA_MIN = 64
#: ... at most this many (p0 closer than ~1e-7 of the size to the boundary) ...
THETA_MAX = 1 << 16
#: ... and enough for exp(−THETA_DECAY) relative error given the analytic strip.
THETA_DECAY = 25.0
#: Midpoints in φ about a centre on or outside the boundary: round-off (~1e-15 of the
#: moments) at every distance from it, also on it (64 give ≤ 7e-13; aspect 2.5 tried).
OUTSIDE_NODES = 256
#: Finite-difference step for ∇(μσ) at the ICR, relative to the larger semi-axis.
FD_STEP = 1e-4
#: Centres of rotation outside the domain up to this ellipse level are subtracted too
#: (with g at the boundary); beyond it the node sums alone are exact to round-off.
OUTSIDE_BAND = 2.0
#: Inside, the gradient term of the subtraction is scaled by min(1, (1 − q)/this).
GRADIENT_TAPER = 0.01
#: g at the boundary is taken this far (in ellipse level) inside it.
EDGE_INSET = 1e-9


@dataclass(frozen=True)
class Resultants:
    """Friction resultants on the tire: ``Fx``, ``Fy`` (N) and ``Mz`` (N·m) about the
    patch origin, one entry per kinematic point (shape of the broadcast inputs)."""

    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray

    def __post_init__(self) -> None:
        for name in ("Fx", "Fy", "Mz"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def to_dict(self) -> dict:
        return {"Fx": self.Fx.tolist(), "Fy": self.Fy.tolist(), "Mz": self.Mz.tolist()}


def checked_kinematics(vx, vy, wz) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, ...]]:
    """``vx``, ``vy`` (m/s), ``wz`` (rad/s) as flat float arrays of their broadcast shape,
    and that shape; `fepost.errors.ArgumentError` naming the argument for a value that
    is not a finite number or shapes that do not broadcast."""
    arrays = {}
    for name, value, unit in (("vx", vx, "m/s"), ("vy", vy, "m/s"), ("wz", wz, "rad/s")):
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ArgumentError(
                f"{name} must be a number or an array of numbers ({unit}), got {value!r}"
            ) from None
        bad = ~np.isfinite(arr)
        if np.any(bad):
            where = np.argwhere(bad)[0]
            at = f" at index {tuple(int(i) for i in where)}" if arr.ndim else ""
            raise ArgumentError(f"{name} must be finite ({unit}), got {float(arr[tuple(where)])!r}{at}")
        arrays[name] = arr
    shape = arrays["vx"].shape
    for name in ("vy", "wz"):
        try:
            shape = np.broadcast_shapes(shape, arrays[name].shape)
        except ValueError:
            raise ArgumentError(
                f"{name} has shape {arrays[name].shape}, which does not broadcast with {shape}"
            ) from None
    vx, vy, wz = (np.broadcast_to(arrays[n], shape).ravel() for n in ("vx", "vy", "wz"))
    return vx, vy, wz, shape


def _theta_nodes(domain: Ellipse, level: np.ndarray) -> np.ndarray:
    """Trapezoid node counts (powers of two) for p0 at ellipse level q < 1; `OUTSIDE_NODES`
    midpoints for q ≥ 1."""
    delta = np.maximum(1.0 - level, 1e-300)
    aspect = max(domain.ax, domain.ay) / min(domain.ax, domain.ay)
    need = THETA_DECAY * aspect / np.sqrt(2.0 * delta)
    n = np.minimum(np.exp2(np.ceil(np.log2(np.maximum(need, THETA_MIN)))), THETA_MAX)
    return np.where(level < 1.0, n, OUTSIDE_NODES).astype(int)


def ray_integrals(domain: Ellipse, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Polar moments of ``domain`` about points p0 = (px, py), shape (k, 9).

    With c = cos θ, s = sin θ and ρ = ρ_max(θ), each column is ∫₀^{2π} · dθ of:
    c ρ²/2, s ρ²/2 (m²); c² ρ³/3, cs ρ³/3, s² ρ³/3 (m³);
    c³ ρ⁴/4, c²s ρ⁴/4, cs² ρ⁴/4, s³ ρ⁴/4 (m⁴).
    For a point on or outside the boundary (level ≥ 1) ρⁿ is ρ_outⁿ − ρ_inⁿ over the
    directions that meet the domain (`_outside_rays`).
    """
    px = np.asarray(px, float).ravel()
    py = np.asarray(py, float).ravel()
    out = np.empty((px.size, 9))
    level = domain.level(px, py)
    counts = _theta_nodes(domain, level)
    inside = level < 1.0
    for n in np.unique(counts):
        for where in (inside, ~inside):
            idx = np.flatnonzero((counts == n) & where)
            block = max(1, chunksums.CHUNK_ELEMENTS // int(n))
            for start in range(0, idx.size, block):
                j = idx[start : start + block]
                if where is inside:
                    out[j] = _inside_rays(domain, px[j], py[j], int(n))
                else:
                    out[j] = _outside_rays(domain, px[j], py[j], int(n))
    return out


def _moments(r2: np.ndarray, r3: np.ndarray, r4: np.ndarray, c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The 9 columns of `ray_integrals` from weighted ρ-powers (points, nodes) and the
    nodes' cos, sin: (nodes,), the same for every point, or (points, nodes).

    Each power meets its trigonometric factors in one pass: a matrix product against the
    (nodes, k) factors when they are shared (3 products instead of 9 matrix-vector ones;
    the rays about a centre near the edge have up to 65 536 nodes)."""
    cc, cs, ss = c * c, c * s, s * s
    groups = ((r2, 2.0, (c, s)), (r3, 3.0, (cc, cs, ss)), (r4, 4.0, (cc * c, cc * s, c * ss, ss * s)))
    out = np.empty((r2.shape[0], 9))
    k = 0
    for r, power, trig in groups:
        cols = slice(k, k + len(trig))
        if c.ndim == 1:
            np.matmul(r, np.column_stack(trig), out=out[:, cols])
        else:
            out[:, cols] = np.column_stack([np.einsum("ij,ij->i", r, t) for t in trig])
        out[:, cols] /= power
        k += len(trig)
    return out


def _inside_rays(domain: Ellipse, px: np.ndarray, py: np.ndarray, n: int) -> np.ndarray:
    """`ray_integrals` about inside points by the periodic trapezoid of ``n`` nodes."""
    theta = np.arange(n) * (2.0 * np.pi / n)
    c, s = np.cos(theta), np.sin(theta)
    rho = domain.ray_length(px[:, None], py[:, None], theta[None, :])
    r2 = rho * rho * (2.0 * np.pi / n)
    r3 = r2 * rho
    return _moments(r2, r3, r3 * rho, c, s)


def _outside_rays(domain: Ellipse, px: np.ndarray, py: np.ndarray, n: int) -> np.ndarray:
    """`ray_integrals` about points on or outside the boundary: over the directions
    [θ_c − Δ, θ_c + Δ] that meet the domain, θ = θ_c + Δ cos φ, ``n`` midpoints in φ."""
    dx = (px - domain.cx) / domain.ax
    dy = (py - domain.cy) / domain.ay
    level = np.hypot(dx, dy)
    # the tangent directions in the coordinates where the domain is the unit disc, then
    # as angles in the patch (the affine map keeps rays from p0 rays, and their order)
    half = np.arcsin(np.minimum(1.0, 1.0 / level))
    towards = np.arctan2(-dy, -dx)
    t1, t2 = (
        np.arctan2(domain.ay * np.sin(towards + k * half), domain.ax * np.cos(towards + k * half))
        for k in (-1.0, 1.0)
    )
    span = np.mod(t2 - t1, 2.0 * np.pi)
    centre = t1 + span / 2.0
    phi = (np.arange(n) + 0.5) * (np.pi / n)
    theta = centre[:, None] + (span[:, None] / 2.0) * np.cos(phi)[None, :]
    weight = (span[:, None] / 2.0) * np.sin(phi)[None, :] * (np.pi / n)  # dθ
    c, s = np.cos(theta), np.sin(theta)
    ex, ey = c / domain.ax, s / domain.ay
    qa = ex * ex + ey * ey
    qb = -np.minimum(dx[:, None] * ex + dy[:, None] * ey, 0.0)  # −b ≥ 0 towards the domain
    qc = np.maximum(dx * dx + dy * dy - 1.0, 0.0)[:, None]
    root = np.sqrt(np.maximum(qb * qb - qa * qc, 0.0))
    far = (qb + root) / qa
    near = np.divide(qc, qb + root, out=np.zeros_like(far), where=qb + root > 0)
    gap = 2.0 * root / qa * weight  # (ρ_out − ρ_in) dθ
    r2 = gap * (far + near)
    r3 = gap * (far * far + far * near + near * near)
    r4 = r2 * (far * far + near * near)
    return _moments(r2, r3, r4, c, s)


def _rays(domain: Ellipse, idx: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """`ray_integrals` about the centres of the points ``idx`` (all integrated)."""
    return ray_integrals(domain, px, py)


def _turned_rays(
    domain: Ellipse, idx: np.ndarray, px: np.ndarray, py: np.ndarray, *, n0: int, turns: int
) -> np.ndarray:
    """`ray_integrals` about the centres of points ``idx`` in ``turns`` groups of ``n0``
    (`friction_resultants`' ``turns``) on a disc about the origin: a centre whose first-group
    twin has the same trapezoid, turned onto itself, takes the twin's moments turned
    (`fepost.friction.turns`); the others (a level on the edge of a node count) are integrated."""
    group, twin = np.divmod(idx, n0)
    first = np.flatnonzero(group == 0)
    out = np.empty((idx.size, 9))
    out[first] = ray_integrals(domain, px[first], py[first])
    where = np.full(n0, -1)  # row of each first-group point among the centres
    where[twin[first]] = first
    counts = _theta_nodes(domain, domain.level(px, py))
    src = where[twin]
    ok = (group > 0) & (src >= 0)
    ok[ok] = (counts[ok] == counts[src[ok]]) & (counts[ok] * group[ok] % turns == 0)
    rows = np.flatnonzero(ok)
    c, s = turn_angles(turns)
    out[rows] = turns_mod.turn_rays(out[src[rows]], c[group[rows]], s[group[rows]])
    rest = np.flatnonzero((group > 0) & ~ok)
    if rest.size:
        out[rest] = ray_integrals(domain, px[rest], py[rest])
    return out


def _turned_sums(setting: _Setting, *, vx, vy, wz, layout, turns: int) -> tuple[np.ndarray, np.ndarray]:
    """The node sums of ``turns`` groups of points from the first group's (`fepost.friction.turns`):
    ``vx``, ``vy``, ``wz`` are the first group's kinematics."""
    law = setting.law
    nodes = chunksums.node_matrices(setting.quad, law, setting.sigma_ref)
    with one_blas_thread():
        wx, wy, speed = chunksums.directions(nodes, law, vx, vy, wz)
        fields: tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]] = ((wx,), (wy,))
        if speed is not None:  # columns 0, 1 with the speed factor, the others without
            factor = law.speed_factor(speed)
            fields = ((wx * factor, wx), (wy * factor, wy))
        return turns_mod.correlated_sums(*fields, nodes.bx, nodes.by, layout, turns)


def _g_and_gradient(quad, law, sigma_ref, px, py) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """g = μσ at |w| = 0 (Pa) and its gradient (Pa/m) at inside points, by differences.

    Central differences of ``sigma_at`` with step ``FD_STEP``·size; a probe that
    falls outside the domain is replaced by the centre value (one-sided difference).
    """
    d = quad.domain
    h = FD_STEP * max(d.ax, d.ay)

    def g(x, y):
        s = np.asarray(quad.sigma_at(x, y), float)
        return law.f * law.pressure_factor(s, sigma_ref) * s

    g0 = g(px, py)
    grads = []
    for ex, ey in ((h, 0.0), (0.0, h)):
        ip = d.level(px + ex, py + ey) < 1.0
        im = d.level(px - ex, py - ey) < 1.0
        gp = np.where(ip, g(px + ex, py + ey), g0)
        gm = np.where(im, g(px - ex, py - ey), g0)
        span = h * (ip.astype(float) + im.astype(float))
        grads.append(np.divide(gp - gm, span, out=np.zeros_like(g0), where=span > 0))
    return g0, grads[0], grads[1]


#: The node-sum backends of `friction_resultants`.
BACKENDS = ("auto", "numba", "numpy")
#: Kinematic points per task of the compiled node sums (threads share the tasks).
KERNEL_BLOCK = 64
#: ``backend="auto"`` takes the compiled node sums from this many (points × nodes)
#: on: numpy needs about half a second for them, what importing numba costs once per
#: process (a short command such as ``fepost coefficients`` stays with numpy).
KERNEL_MIN_ELEMENTS = 1 << 24


@dataclass(frozen=True)
class _Setting:
    """What one call integrates: the map, the law, σ_ref (Pa) and the subtraction order."""

    quad: PressureQuadrature
    law: FrictionLaw
    sigma_ref: float
    order: int


def friction_resultants(
    quad: PressureQuadrature,
    vx,
    vy,
    wz,
    law: FrictionLaw | None = None,
    *,
    subtract: bool | int = True,
    threads: int | None = None,
    backend: str = "auto",
    turns: int = 1,
) -> Resultants:
    """Exact friction force (N) and torque (N·m) on the tire for each kinematic point.

    ``vx``, ``vy``: sliding velocity of the patch origin relative to the road (m/s);
    ``wz``: spin about the road normal (rad/s); scalars or arrays that broadcast.
    ``law``: the local friction law (default: Coulomb with f = 0.3).
    ``subtract``: order of the ICR singularity subtraction (module docstring):
    2 (or ``True``, default) removes g(p0) + ∇g(p0)·(p − p0), 1 only g(p0),
    0 (or ``False``) integrates the raw discontinuous field (for studies only).
    ``threads``: worker threads over chunks of kinematic points (default: the CPU count, or
    the environment's ``FEPOST_THREADS``, `fepost._threads`).
    ``backend``: the node sums by ``"numba"`` (compiled, `fepost.friction.nodesums`,
    the optional numba dependency; ~10x faster), ``"numpy"``, or ``"auto"`` (default:
    numba when installed and the job has `KERNEL_MIN_ELEMENTS` points × nodes or
    more); the same numbers to round-off.
    ``turns``: the points are ``turns`` equal groups in order, group k being the first
    turned by 2πk/turns about the patch origin (as `fepost.friction.build.sphere_nodes`
    lays them out; `ArgumentError` when they are not). On a polar quadrature about the
    origin whose angle count ``turns`` divides, the groups' node sums and polar moments
    are then the first group's, turned (`fepost.friction.turns`: the same numbers to
    round-off, about ``turns`` times less work); otherwise the hint changes nothing.
    """
    if not isinstance(quad, PressureQuadrature):
        raise ArgumentError(f"quad must be a PressureQuadrature, got {type(quad).__name__}")
    law = FrictionLaw() if law is None else law
    if not isinstance(law, FrictionLaw):
        raise ArgumentError(f"law must be a FrictionLaw, got {type(law).__name__}")
    order = {True: 2, False: 0}.get(subtract, subtract) if isinstance(subtract, bool) else subtract
    if order not in (0, 1, 2):
        raise ArgumentError(f"subtract must be True, False, 0, 1 or 2, got {subtract!r}")
    if threads is not None and (isinstance(threads, bool) or int(threads) != threads or threads < 1):
        raise ArgumentError(f"threads must be a positive integer, got {threads!r}")
    if backend not in BACKENDS:
        raise ArgumentError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if backend == "numba" and not nodesums.AVAILABLE:
        raise ArgumentError("backend 'numba' needs numba (pip install fepost[fast]), which is not installed")
    vx, vy, wz, shape = checked_kinematics(vx, vy, wz)
    d = quad.domain
    n0 = turns_mod.check_groups(vx, vy, wz, turns, scale=float(np.hypot(abs(d.cx) + d.ax, abs(d.cy) + d.ay)))
    layout = turns_mod.polar_layout(quad, int(turns)) if backend != "numba" and n0 else None
    sigma_ref = law.reference_pressure(quad.mean_pressure) if law.pressure_coef else 1.0
    setting = _Setting(quad=quad, law=law, sigma_ref=sigma_ref, order=order)
    workers = threads or default_threads()
    big = vx.size * quad.x.size >= KERNEL_MIN_ELEMENTS
    centres = _centres(setting, vx=vx, vy=vy, wz=wz)
    with ThreadPoolExecutor(max_workers=1) as side:
        # the polar moments about the centres need no node sums: with more than one worker
        # they are computed meanwhile, on a thread of their own
        rays = None
        moments = _rays if layout is None else partial(_turned_rays, n0=n0, turns=int(turns))
        if centres[0].size and workers > 1:
            rays = side.submit(moments, quad.domain, centres[0], centres[1], centres[2])
        if layout is not None:
            sx, sy = _turned_sums(
                setting, vx=vx[:n0], vy=vy[:n0], wz=wz[:n0], layout=layout, turns=int(turns)
            )
        elif backend == "numpy" or (backend == "auto" and not (nodesums.AVAILABLE and big)):
            sx, sy = _numpy_sums(setting, vx=vx, vy=vy, wz=wz, workers=workers)
        else:
            sx, sy = _compiled_sums(setting, vx=vx, vy=vy, wz=wz, workers=workers)
        r: np.ndarray | None = None
        if rays is not None:
            r = rays.result()
        elif centres[0].size:
            r = moments(quad.domain, centres[0], centres[1], centres[2])
    with one_blas_thread():
        fx, fy, mz = _finish(setting, vx=vx, vy=vy, wz=wz, sx=sx, sy=sy, centres=centres, rays=r)
    return Resultants(fx.reshape(shape), fy.reshape(shape), mz.reshape(shape))


def _numpy_sums(setting: _Setting, *, vx, vy, wz, workers: int) -> tuple[np.ndarray, np.ndarray]:
    """The node sums (points, 7) by whole-array numpy and BLAS (`fepost.friction.chunksums`)."""
    nodes = chunksums.node_matrices(setting.quad, setting.law, setting.sigma_ref)
    return chunksums.numpy_sums(nodes, setting.law, vx, vy, wz, workers)


def _compiled_sums(setting: _Setting, *, vx, vy, wz, workers: int) -> tuple[np.ndarray, np.ndarray]:
    """The node sums (points, 7) by the compiled loop (`fepost.friction.nodesums`)."""
    quad, law = setting.quad, setting.law
    g = chunksums.node_loads(quad, law, setting.sigma_ref)
    x = np.ascontiguousarray(quad.x, float)
    y = np.ascontiguousarray(quad.y, float)
    weights = nodesums.columns(x, y, g, np.asarray(quad.dA, float))
    k = vx.size
    sx = np.empty((k, 7))
    sy = np.empty((k, 7))

    def work(start: int) -> None:
        sl = slice(start, start + KERNEL_BLOCK)
        sx[sl], sy[sl] = nodesums.node_sums(
            vx[sl], vy[sl], wz[sl], x=x, y=y, weights=weights, speed_coef=law.speed_coef
        )

    chunksums.in_parallel(work, range(0, k, KERNEL_BLOCK), workers)
    return sx, sy


def _centres(setting: _Setting, *, vx, vy, wz) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indices, p0x, p0y) of the points whose centre of rotation p0 lies inside the domain
    or outside it below the level `OUTSIDE_BAND` (where the subtraction applies; none
    without it)."""
    if not setting.order:
        return np.empty(0, np.int64), np.empty(0), np.empty(0)
    # only centres that can lie within the band are computed: |p0| = |v|/|wz| is bounded by the
    # band's reach, so a spin so small that the centre is far away (or |v|/|wz| overflows) is none
    dom = setting.quad.domain
    reach = 2.0 * (np.hypot(dom.cx, dom.cy) + OUTSIDE_BAND * max(dom.ax, dom.ay))
    spin = np.abs(wz) * reach >= np.hypot(vx, vy)
    spin &= wz != 0
    p0x = np.zeros(vx.size)
    p0y = np.zeros(vx.size)
    p0x[spin] = -vy[spin] / wz[spin]
    p0y[spin] = vx[spin] / wz[spin]
    i = np.flatnonzero(spin & (setting.quad.domain.level(p0x, p0y) < OUTSIDE_BAND))
    return i, p0x[i], p0y[i]


def _finish(
    setting: _Setting, *, vx, vy, wz, sx, sy, centres, rays
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F_x, F_y, M_z) from the node sums, with the ICR subtraction where it applies
    (``centres`` from `_centres`, ``rays`` the `ray_integrals` about them)."""
    alpha = setting.law.anisotropy
    fx = -sx[:, 0]
    fy = -alpha * sy[:, 0]
    mz = -(alpha * sy[:, 1] - sx[:, 1])
    i, px, py = centres
    if i.size:
        dx, dy, dm = _subtraction(setting, px=px, py=py, sgn=np.sign(wz[i]), X=sx[i], Y=sy[i], rays=rays)
        fx[i] += dx
        fy[i] += dy
        mz[i] += dm
    return fx, fy, mz


def _subtracted_field(setting: _Setting, px, py) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """L(p0) (Pa) and ∇L (Pa/m) of the subtracted L = L(p0) + ∇L·(p − p0) for centres p0:
    inside, g(p0) and (order 2) g's gradient scaled by min(1, (1 − q)/`GRADIENT_TAPER`);
    outside, g at the boundary point p_b = c + (p0 − c)/q (`EDGE_INSET` inside), no gradient."""
    quad, law = setting.quad, setting.law
    d = quad.domain
    level = d.level(px, py)
    inside = level < 1.0
    scale = np.where(inside, 1.0, (1.0 - EDGE_INSET) / np.maximum(level, 1.0))
    bx, by = d.cx + (px - d.cx) * scale, d.cy + (py - d.cy) * scale
    gx = np.zeros(px.size)
    gy = np.zeros(px.size)
    if setting.order == 2 and np.any(inside):
        g0, gx[inside], gy[inside] = _g_and_gradient(quad, law, setting.sigma_ref, px[inside], py[inside])
        taper = np.minimum(1.0, (1.0 - level[inside]) / GRADIENT_TAPER)
        gx[inside] *= taper
        gy[inside] *= taper
    s0 = np.asarray(quad.sigma_at(bx, by), float)
    g = law.f * law.pressure_factor(s0, setting.sigma_ref) * s0
    if setting.order == 2 and np.any(inside):
        g[inside] = g0
    return g, gx, gy


def _subtraction(setting: _Setting, *, px, py, sgn, X, Y, rays) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For points whose ICR p0 = (px, py) is inside, with node sums X, Y (rows of sx, sy):
    the change of (F_x, F_y, M_z) when the node sums of L ŵ, L = g0 + G·(p − p0), are
    swapped for their exact integrals over the domain."""
    g0, gx, gy = _subtracted_field(setting, px, py)
    alpha = setting.law.anisotropy
    c0 = g0 - gx * px - gy * py  # L = c0 + gx·x + gy·y
    # columns 2..6 of X: ŵx @ dA·(1, x, y, xy, y²); of Y: ŵy @ dA·(1, x, y, x², xy)
    node_x = c0 * X[:, 2] + gx * X[:, 3] + gy * X[:, 4]
    node_y = c0 * Y[:, 2] + gx * Y[:, 3] + gy * Y[:, 4]
    node_m = alpha * (c0 * Y[:, 3] + gx * Y[:, 5] + gy * Y[:, 6]) - (
        c0 * X[:, 4] + gx * X[:, 5] + gy * X[:, 6]
    )
    ix, iy, cc, cs, ss, qccc, qccs, qcss, qsss = rays.T
    exact_x = sgn * (-g0 * iy - (gx * cs + gy * ss))
    exact_y = sgn * (g0 * ix + gx * cc + gy * cs)
    exact_m = sgn * (
        g0 * (alpha * px * ix + py * iy + alpha * cc + ss)
        + gx * (alpha * px * cc + py * cs + alpha * qccc + qcss)
        + gy * (alpha * px * cs + py * ss + alpha * qccs + qsss)
    )
    return node_x - exact_x, alpha * (node_y - exact_y), node_m - exact_m
