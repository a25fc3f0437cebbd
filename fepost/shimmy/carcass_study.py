"""The carcass tire against the whole tire's rolling runs, and the verdicts that rest on the brush again.

``python -m fepost.shimmy.carcass_study fe|gripping|touchdown`` prints the tables of
docs/touchdown.md (the whole tire's map and stiffnesses, `WHOLE`):

* ``fe``: the tread's slip stiffness, the carcass springs, the steady braking and driving
  forces at the pre-wound runs' slips and the first-order build-up fitted over the building-up run's 1.6 m,
  for the carcass tire and for the lumped brush, beside the FE runs' values;
* ``gripping``: the example gear's largest growth rate over 20–150 m/s at held slips of 1, 3
  and 20 %: rigid sliding wheel (the same elements' Coulomb forces), lumped brush, carcass
  tire (and the carcass tire without its torsion);
* ``touchdown``: the touchdown runs of the page's table on the lumped brush and on the
  carcass tire.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .brush import BrushTire, rig_stiffness
from .carcass import FE_TREAD_STIFFNESS, CarcassTire, rig_torsional_stiffness

#: The whole tire (issue 39): its rolling model's static partner, its rig folder, its rolling runs.
WHOLE = Path("meshes/rig-tire360")
STATIC = WHOLE / "roll" / "roll_static.vtu"
#: The tread's C_κ/N: the brush estimate from the tread rubber's shear stiffness over the static
#: patch's strips (scripts/tiremodel/aircraft_roll360_results.brush_slope on roll_brake020.json).
TREAD_SLIP_STIFFNESS = 11.15
#: The whole tire's free rolling radius (m; docs/rolling.md: 0.5706–0.5707 m).
ROLLING_RADIUS = 0.5706
#: The FE runs: the pre-wound braking run's slip against R_e and its steady Fx/N; the building-up
#: run's travel (m) and its fitted relaxation length (m) (docs/rolling.md, the --table output).
FE_SLIP, FE_FORCE, FE_TRAVEL, FE_SIGMA = -0.0178, -0.154, 1.6, 1.10
#: The pre-wound driving run (roll_drive020w): its slip against R_e and its steady Fx/N.
FE_DRIVE_SLIP, FE_DRIVE_FORCE = 0.0223, 0.189


@dataclass(frozen=True)
class WholeTire:
    """The whole tire's map as a pressure quadrature, its friction level and standstill stiffnesses."""

    quad: object
    f: float
    standstill: tuple[float, float, float]

    @classmethod
    def read(cls, static=STATIC, rig=WHOLE) -> WholeTire:
        from ..analysis import analyse
        from ..friction.quadrature import PressureQuadrature

        an = analyse(static)
        k, kz = rig_stiffness(rig), rig_torsional_stiffness(rig)
        return cls(
            PressureQuadrature.from_polar(an.static_map), an.coefficients.f, (k["K_x"], k["K_y"], kz["K_z"])
        )

    def lumped(self, nx: int, ny: int) -> BrushTire:
        return BrushTire.from_quadrature(self.quad, f=self.f, stiffness=self.standstill[:2], nx=nx, ny=ny)

    def carcass(self, nx: int, ny: int, torsion: bool = True, blend: float = 0.0) -> CarcassTire:
        k = self.standstill if torsion else self.standstill[:2]
        return CarcassTire.from_quadrature(
            self.quad, f=self.f, standstill=k, slip_stiffness=TREAD_SLIP_STIFFNESS, nx=nx, ny=ny, blend=blend
        )


def build_up(
    tire, kappa: float, travel: float, points: int = 41, side: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """(X, Fx) of the tire rolled from rest at the slip ``kappa`` (against the rolling speed's
    road speed V: V_r = (1 + κ) V) over ``travel`` metres (quasi-static: the rates scale with V);
    with ``side`` (a side slip angle, rad, κ = 0) (X, Fy) of the side force's build-up instead."""
    from scipy.integrate import solve_ivp

    V, n = 1.0, tire.n
    vr = (1.0 + kappa) * V

    def rhs(_t, X):
        dx, dy, _ = tire.rates(X[:n], X[n:], V - vr, side * V, 0.0, vr)
        return np.concatenate([dx, dy])

    xs = np.linspace(0.0, travel, points)
    sol = solve_ivp(
        rhs, (0.0, travel / V), np.zeros(2 * n), method="RK23", t_eval=xs / V, rtol=1e-7, atol=1e-12
    )
    axis = 1 if side else 0
    force = np.array([tire.resultants(sol.y[:n, k], sol.y[n:, k])[axis] for k in range(xs.size)])
    return xs, force


def first_order(x, fx) -> tuple[float, float]:
    """(σ, F_inf) of F = F_inf (1 − exp(−X/σ)) by least squares, as the FE runs' fit."""
    from scipy.optimize import curve_fit

    (sigma, f_inf), _ = curve_fit(
        lambda xx, s, fi: fi * -np.expm1(-xx / s), x, fx, p0=(0.5 * float(x[-1]), float(fx[-1]))
    )
    return float(sigma), float(f_inf)


def fe_lines(whole: WholeTire, grid=(16, 6)) -> list[str]:
    ct, lump = whole.carcass(*grid), whole.lumped(*grid)
    kc = ct.carcass
    out = [
        f"standstill K_x, K_y, K_z = {whole.standstill[0]:.4g} N/m, {whole.standstill[1]:.4g} N/m, "
        f"{whole.standstill[2]:.4g} N m/rad; tread {ct.provenance['tread_stiffness']}",
        f"carcass K_cx, K_cy, K_cz = {kc[0]:.4g} N/m, {kc[1]:.4g} N/m, {kc[2]:.4g} N m/rad; "
        f"tread K_t = {ct.tread_totals[0]:.4g} N/m, {ct.tread_totals[2]:.4g} N m/rad; "
        f"grid {grid[0]} x {grid[1]}, a = {ct.half_length:.3f} m",
    ]
    rubber = CarcassTire.from_quadrature(
        whole.quad,
        f=whole.f,
        standstill=whole.standstill,
        tread_stiffness=FE_TREAD_STIFFNESS,
        nx=grid[0],
        ny=grid[1],
    )
    out.append(
        f"the tread rubber's own G/h ({FE_TREAD_STIFFNESS:.3g} N/m^3) would give C_kappa/N = "
        f"{rubber.tread.slip_stiffness() / rubber.load:.2f} on this binned map"
    )
    V, kap, kd = 1.0, FE_SLIP, FE_DRIVE_SLIP

    def steady_fx(tire, slip: float) -> float:
        """Steady Fx/N rolling at ``slip`` (wheel speed (1 + slip) V)."""
        return tire.resultants(*tire.steady(-slip * V, 0.0, 0.0, (1 + slip) * V))[0] / tire.load

    for name, tire in (("carcass", ct), ("lumped", lump)):
        c_k = (ct.tread if isinstance(tire, CarcassTire) else tire).slip_stiffness() / tire.load
        fx, fd = steady_fx(tire, kap), steady_fx(tire, kd)
        x, f = build_up(tire, kap, FE_TRAVEL)
        sigma, f_inf = first_order(x, f / tire.load)
        ca = -tire.resultants(*tire.steady(0.0, 1e-4 * V, 0.0, V))[1] / 1e-4 / tire.load
        xs, fy = build_up(tire, 0.0, 5 * FE_TRAVEL, points=81, side=1e-4)
        sigma_y = first_order(xs, fy / tire.load)[0]
        out.append(
            f"{name}: C_kappa/N {c_k:.2f}, steady Fx/N at kappa {kap:+.4f} {fx:+.4f} (FE {FE_FORCE:+.3f}), "
            f"at {kd:+.4f} {fd:+.4f} (FE {FE_DRIVE_FORCE:+.3f}), "
            f"build-up over {FE_TRAVEL:g} m: sigma {sigma:.3f} m (FE {FE_SIGMA:.2f}), F_inf/N {f_inf:+.4f}; "
            f"C_alpha/N {ca:.2f}, side force's build-up at 1e-4 rad over {5 * FE_TRAVEL:g} m: "
            f"sigma_y {sigma_y:.3f} m"
        )
    return out


def gripping_lines(whole: WholeTire, grid=(16, 6), speeds=tuple(range(20, 151, 10))) -> list[str]:
    from .gear import load_gear
    from .gripping import GripModel
    from .linear import Linearisation

    gear = load_gear("examples/gear_a320_main.json")
    lump = whole.lumped(*grid)
    nx, ny = grid
    tires: dict[str, BrushTire | CarcassTire] = {
        "lumped": lump,
        "carcass": whole.carcass(nx, ny),
        "carcass, no torsion": whole.carcass(nx, ny, torsion=False),
    }
    out = []
    for kap in (0.01, 0.03, 0.2):
        g = gear.replace(slip_ratio=kap)
        rigid = Linearisation.of(g, lump.sliding_contact())
        gr = np.array([rigid.growth(float(V))[0] for V in speeds])
        line = f"slip {kap:g}: rigid sliding wheel max growth {gr.max():+.2f} 1/s"
        if np.any(gr > 0):
            from scipy.optimize import brentq

            k = int(np.argmax(gr > 0))
            if k > 0:
                onset = brentq(lambda v, r=rigid: r.growth(v)[0], speeds[k - 1], speeds[k], xtol=0.01)
                line += f", unstable above {onset:.1f} m/s"
            else:
                line += f", unstable from {speeds[0]} m/s"
        for name, tire in tires.items():
            rates = [GripModel(g, tire).growth_rate(float(V)) for V in speeds]
            k = int(np.argmax(rates))
            line += f"; {name} {rates[k]:+.2f} 1/s at {speeds[k]} m/s"
        out.append(line)
    return out


def touchdown_lines(whole: WholeTire, cases=None, duration: float = 2.0) -> list[str]:
    from .gear import load_gear
    from .touchdown import BLEND, GRID, simulate_touchdown

    gear = load_gear("examples/gear_a320_main_touchdown.json").replace(
        tire_stiffness_x=whole.standstill[0],
        tire_stiffness_y=whole.standstill[1],
        rolling_radius=ROLLING_RADIUS,
    )
    tires: dict[str, BrushTire | CarcassTire] = {
        "lumped": replace(whole.lumped(*GRID), blend=BLEND),
        "carcass": whole.carcass(*GRID, blend=BLEND),
    }
    cases = cases or [(v, s, 0.5, 0.0) for v in (50, 70, 90) for s in (0.5, 1.5, 3.0)] + [
        (70, 1.5, 0.5, 5.0),
        (70, 1.5, 2.0, 0.0),
    ]
    out = []
    for v, s, yaw, crab in cases:
        for name, tire in tires.items():
            t0 = time.process_time()
            r = simulate_touchdown(
                gear, tire, v, sink_rate=s, yaw=math.radians(yaw), crab=math.radians(crab), duration=duration
            )
            roll = float(np.mean(r.x[4:, -1])) * gear.rolling_radius / v
            cpu = time.process_time() - t0
            out.append(
                f"| {v} | {s} | {yaw} | {crab} | {name} | {r.spin_up_time:.3f} | {r.verdict} "
                f"| {r.amplitude:.4f} | {r.window_amplitudes[-1]:.1e} | {r.energy_residual:.0e} "
                f"| {roll:.5f} | {cpu:.1f} |"
            )
            print(out[-1], flush=True)
    return out


def main(argv=None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    what: dict[str, Callable[[WholeTire], list[str]]] = {
        "fe": fe_lines,
        "gripping": gripping_lines,
        "touchdown": touchdown_lines,
    }
    if len(args) != 1 or args[0] not in what:
        print("usage: python -m fepost.shimmy.carcass_study fe|gripping|touchdown", file=sys.stderr)
        return 2
    for line in what[args[0]](WholeTire.read()):
        print(line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
