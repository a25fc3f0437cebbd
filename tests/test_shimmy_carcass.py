"""The brush on a carcass: its limits, its lag, the whole tire's rolling runs, its energy, its gear keys."""

from __future__ import annotations

import json
import math
import types
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from fepost.errors import ArgumentError
from fepost.shimmy.carcass import (
    CarcassTire,
    buildup_length,
    carcass_from_standstill,
    rig_torsional_stiffness,
)
from fepost.shimmy.carcass_study import (
    FE_DRIVE_FORCE,
    FE_DRIVE_SLIP,
    FE_FORCE,
    FE_SIGMA,
    FE_SLIP,
    FE_TRAVEL,
    WHOLE,
    WholeTire,
    build_up,
    first_order,
)
from fepost.shimmy.gear import load_gear
from fepost.shimmy.gripping import GripModel

GEAR = "examples/gear_a320_main_touchdown.json"


@pytest.fixture(scope="module")
def whole():
    return WholeTire.read()


@pytest.fixture(scope="module")
def tire(whole):
    """The carcass tire on the whole tire's map, coarse (8 x 3)."""
    return whole.carcass(8, 3)


def _rectangle(length=0.5, width=0.3, nx=40, ny=1, pressure=1e6):
    """A uniform pressure over a rectangle, as the attributes of a pressure quadrature (4 nodes a cell)."""
    xs = (np.arange(4 * nx) + 0.5) / (4 * nx) * length - length / 2
    ys = (np.arange(4 * ny) + 0.5) / (4 * ny) * width - width / 2
    x, y = np.meshgrid(xs, ys)
    da = np.full(x.size, length * width / x.size)
    return types.SimpleNamespace(x=x.ravel(), y=y.ravel(), sigma=np.full(x.size, pressure), dA=da, radius=0.2)


def _state(tire, kappa=0.03, V=10.0):
    """A state off the steady one: the steady total deflections at ``kappa``, skewed."""
    qx, qy = tire.steady(kappa * V, 0.2 * kappa * V, 0.5 * kappa, (1 - kappa) * V)
    ramp = np.linspace(0.7, 1.2, qx.size)
    return qx * ramp, qy * ramp[::-1] + 1e-5


# -- (1) the rigid carcass is today's brush -----------------------------------------------------------


def test_rigid_carcass_is_todays_brush_to_round_off(whole):
    lump = whole.lumped(8, 3)
    for blend in (0.0, 0.02):
        b = replace(lump, blend=blend)
        rigid = CarcassTire(b, (math.inf, math.inf, math.inf))
        q = _state(b)
        args = (0.4, -0.1, 0.3, 9.5, 2.0)
        for got, want in zip(rigid.rates(*q, *args), b.rates(*q, *args), strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
        assert rigid.resultants(*q, 0.7) == pytest.approx(b.resultants(*q, 0.7), rel=1e-13)
        assert rigid.energy(*q) == pytest.approx(b.energy(*q), rel=1e-13)
        assert rigid.released(*q, 9.5) == pytest.approx(b.released(*q, 9.5), rel=1e-13)


def test_stiff_carcass_tends_to_todays_brush_as_one_over_its_stiffness(whole):
    """Carcass springs 1e3 and 1e6 times the standstill stiffness on today's lumped brush: the steady
    force and the gear's growth rate (held slip 3 %, 60 m/s) approach today's, the error ~1/K_c."""
    lump = whole.lumped(8, 3)
    gear = load_gear("examples/gear_a320_main.json")
    k = whole.standstill
    want_f = lump.resultants(*lump.steady(0.3, 0.0, 0.0, 9.7))[0]
    want_g = GripModel(gear, lump).growth_rate(60.0)
    errors = []
    for factor in (1e3, 1e6):
        stiff = CarcassTire(lump, tuple(factor * kk for kk in k))
        fx = stiff.resultants(*stiff.steady(0.3, 0.0, 0.0, 9.7))[0]
        errors.append((abs(fx / want_f - 1), abs(GripModel(gear, stiff).growth_rate(60.0) - want_g)))
    # the steady force: the translated carcass moves no element against the road (round-off)
    assert errors[0][0] < 1e-11 and errors[1][0] < 1e-11
    # the growth rate: 2.7e-3 and 2.7e-6 1/s, the error 1000 times smaller for 1000 times the spring
    assert errors[1][1] < 1e-5
    assert errors[0][1] / errors[1][1] == pytest.approx(1e3, rel=0.1)


# -- (2) the steady slip curve is the tread's ---------------------------------------------------------


def test_steady_slip_curve_is_the_treads(tire):
    """With the carcass translated only (no twist), no element moves against the road: the steady
    forces are the tread-only brush's, to round-off, over the whole slip curve. With its torsion the
    binned map's small moment under braking (the cells' load centroid 0.2 mm off the axis: nodes on a
    cell boundary go to the cell above) twists the carcass and steers the patch: Fx within 1e-5, a
    side force under 2e-3 f N (1.4e-3 at 3 % of slip). Rolled from rest the tire
    reaches the steady force (8 m at 1.8 % of braking slip)."""
    t, V = tire.tread, 1.0
    scale = t.f * t.load
    no_twist = replace(tire, carcass=(*tire.carcass[:2], math.inf))
    for kappa in (-0.2, -0.03, FE_SLIP, -0.005, 0.01, 0.05):
        vr = (1 + kappa) * V
        want = t.resultants(*t.steady(V - vr, 0.0, 0.0, vr))
        got = no_twist.resultants(*no_twist.steady(V - vr, 0.0, 0.0, vr))
        np.testing.assert_allclose(got, want, atol=1e-9 * scale)
        twisted = tire.resultants(*tire.steady(V - vr, 0.0, 0.0, vr))
        assert twisted[0] == pytest.approx(want[0], rel=1e-5) and abs(twisted[1]) < 2e-3 * scale
    for vy in (-0.05, 0.004, 0.2):
        got = no_twist.resultants(*no_twist.steady(0.0, vy, 0.0, V))
        np.testing.assert_allclose(got, t.resultants(*t.steady(0.0, vy, 0.0, V)), atol=1e-9 * scale)
    x, fx = build_up(tire, FE_SLIP, 8.0, points=3)
    steady = tire.resultants(*tire.steady(-FE_SLIP, 0.0, 0.0, 1 + FE_SLIP))[0]
    assert fx[-1] == pytest.approx(steady, abs=2e-3 * scale)


def test_carcass_twist_steers_the_patch(tire):
    """With its torsion the carcass twists by φ = Mz/K_cz, and the side force is the tread's at the
    side slip less V_r φ: the classical loss of cornering stiffness through the carcass's torsion."""
    t, V, vy = tire.tread, 1.0, 1e-3
    qx, qy = tire.steady(0.0, vy, 0.0, V)
    fx, fy, mz = tire.resultants(qx, qy)
    phi = tire.carcass_deflection(qx, qy)[2]
    assert phi == pytest.approx(mz / tire.carcass[2], rel=1e-9)
    assert fy == pytest.approx(t.resultants(*t.steady(0.0, vy - V * phi, 0.0, V))[1], rel=1e-9)
    assert abs(fy) < 0.6 * abs(t.resultants(*t.steady(0.0, vy, 0.0, V))[1])
    # the carcass balances the tread: K_C U = (Fx, Fy, Mz)
    u = tire.carcass_deflection(qx, qy)
    np.testing.assert_allclose(np.array(tire.carcass) * u, [fx, fy, mz], rtol=1e-9, atol=1e-6)


# -- (3) the small-slip build-up: a first-order lag ---------------------------------------------------


def test_build_up_is_the_closed_forms_lag():
    """A uniform rectangular patch (L = 0.5 m) with a carcass: the slowest mode of the linear tire is
    the root of K_c = (2C/L²)(σ(e^(L/σ) − 1) − L) (`buildup_length`, the delay equation's) within 1.5 %
    with 40 cells, closer with 80; that root is C_κ/K_c + L/3 within 1 %; and the build-up rolled from
    rest at a small slip is first order beyond the first patch length with that σ within 1 %."""
    sigmas, closed = [], []
    for nx in (40, 80):
        ct = CarcassTire.from_quadrature(
            _rectangle(nx=nx), f=0.3, standstill=(1.5e6, 5e5), slip_stiffness=10.0, nx=nx, ny=1
        )
        t, n = ct.tread, ct.n
        jac = np.empty((n, n))
        for k in range(n):
            e = np.zeros(n)
            e[k] = 1e-9
            jac[:, k] = ct.rates(e, np.zeros(n), 0.0, 0.0, 0.0, 1.0)[0] / 1e-9
        slow = np.max(np.linalg.eigvals(jac).real)
        sigmas.append(-1.0 / slow)
        c, length = t.slip_stiffness(), nx * t.h
        closed.append(buildup_length(c, ct.carcass[0], length))
        assert closed[-1] == pytest.approx(c / ct.carcass[0] + length / 3, rel=0.01)
    assert sigmas[0] == pytest.approx(closed[0], rel=0.015)
    assert abs(sigmas[1] / closed[1] - 1) < 0.6 * abs(sigmas[0] / closed[0] - 1)
    from scipy.optimize import curve_fit

    x, fx = build_up(ct, -1e-4, 6.0, points=61)
    tail = x >= 0.5  # beyond the first patch length: F = F_inf − A exp(−X/σ)
    (sigma, _, _), _ = curve_fit(
        lambda xx, s, fi, a: fi - a * np.exp(-xx / s), x[tail], fx[tail], p0=(1.0, fx[-1], fx[-1])
    )
    assert sigma == pytest.approx(sigmas[1], rel=0.01)


# -- (4) against the whole tire's FE runs ------------------------------------------------------------


def test_against_the_whole_tires_rolling_runs(whole):
    """On the whole tire's map (16 x 6), tread calibrated to C_κ/N = 11.15 (the tread rubber's brush
    estimate), carcass from the rig's standstill K_x = 1.69e6 N/m. Measured, not forced: the steady
    Fx/N at the pre-wound run's slip is −0.174 against the FE's −0.154 (13 % more), the build-up
    fitted over the building-up run's 1.6 m has σ = 1.16 m against 1.10 m (5 % longer); the lumped
    brush gives −0.039 and 0.20 m."""
    ct, lump = whole.carcass(16, 6), whole.lumped(16, 6)
    assert ct.tread.slip_stiffness() / ct.load == pytest.approx(11.15, rel=1e-12)
    assert ct.carcass[0] == pytest.approx(2.095e6, rel=2e-3)
    got, drive = {}, {}
    for name, t in (("carcass", ct), ("lumped", lump)):
        fx = t.resultants(*t.steady(-FE_SLIP, 0.0, 0.0, 1 + FE_SLIP))[0] / t.load
        x, f = build_up(t, FE_SLIP, FE_TRAVEL)
        got[name] = (fx, first_order(x, f / t.load)[0])
        drive[name] = t.resultants(*t.steady(-FE_DRIVE_SLIP, 0.0, 0.0, 1 + FE_DRIVE_SLIP))[0] / t.load
    # the pre-wound driving run (roll_drive020w, +0.189 at +0.0223): the carcass tire 5 % above it
    assert drive["carcass"] == pytest.approx(0.1993, abs=0.001)
    assert drive["carcass"] / FE_DRIVE_FORCE - 1 == pytest.approx(0.055, abs=0.01)
    assert drive["lumped"] == pytest.approx(0.0471, abs=0.001)
    assert got["carcass"][0] == pytest.approx(-0.1737, abs=0.001)
    assert got["carcass"][1] == pytest.approx(1.159, abs=0.005)
    assert got["lumped"][0] == pytest.approx(-0.0394, abs=0.001)
    assert got["lumped"][1] == pytest.approx(0.196, abs=0.005)
    # the stated differences from the FE runs
    assert got["carcass"][0] / FE_FORCE - 1 == pytest.approx(0.13, abs=0.01)
    assert got["carcass"][1] / FE_SIGMA - 1 == pytest.approx(0.05, abs=0.01)


def test_rig_torsional_stiffness_is_the_spins_first_moment_over_turn():
    k = rig_torsional_stiffness(WHOLE)
    assert k["K_z"] == pytest.approx(9.249e4, rel=1e-3)
    h = json.loads((WHOLE / "spin_p.json").read_text())["history"]
    assert -h["Mz"][10] / h["tire_rotation"][10] == pytest.approx(
        k["K_z"], rel=0.02
    )  # the secant at 1e-3 rad
    with pytest.raises(ArgumentError, match=r"nowhere/spin_p\.json: cannot read the rig run's history"):
        rig_torsional_stiffness(Path("meshes/nowhere"))


# -- (5) energy -------------------------------------------------------------------------------------


def test_carcass_stores_and_returns_the_sliding_dissipates(tire):
    """Rolled 3 m at 1.8 % of braking slip, then 4 m free: tread and carcass energy change by the
    work on the slip plus the transport's minus the sliding's, to the integrator's tolerance; the
    carcass holds most of the elastic energy while braking and gives it back when the slip ends."""
    from scipy.integrate import solve_ivp

    n, V = tire.n, 1.0

    def rhs(t, X):
        vr = (1 + FE_SLIP) * V if t < 3.0 else V
        qx, qy = X[:n], X[n : 2 * n]
        dx, dy, lam = tire.rates(qx, qy, V - vr, 0.0, 0.0, vr)
        fx = tire.resultants(qx, qy)[0]
        return np.concatenate(
            [dx, dy, [-fx * (V - vr), tire.released(qx, qy, vr), tire.dissipation(qx, qy, lam)]]
        )

    def carcass_share(X):
        ex, ey, u = tire.tread_deflections(X[:n], X[n : 2 * n])
        return (
            0.5
            * (tire.carcass[0] * u[0] ** 2 + tire.carcass[1] * u[1] ** 2)
            / tire.energy(X[:n], X[n : 2 * n])
        )

    x0 = np.zeros(2 * n + 3)
    sol = solve_ivp(
        rhs, (0.0, 7.0), x0, method="RK45", rtol=1e-9, atol=1e-13, t_eval=[3.0, 7.0], max_step=0.01
    )
    mid, end = sol.y[:, 0], sol.y[:, 1]
    slip_work, released, sliding = end[-3:]
    e_mid = tire.energy(mid[:n], mid[n : 2 * n])
    change = tire.energy(end[:n], end[n : 2 * n])
    assert change - (slip_work + released - sliding) == pytest.approx(0.0, abs=1e-6 * e_mid)
    assert sliding > 0.05 * slip_work > 0
    assert carcass_share(mid) > 0.7
    assert change < 0.02 * e_mid  # returned: the free-rolling tire unloads


def test_touchdown_on_the_carcass_tire_balances_its_energy(whole):
    """The touchdown of docs/touchdown.md on the carcass tire (8 x 3, 0.4 s): the balance closes,
    the wheels spin up, half the forward work is lost to sliding."""
    from fepost.shimmy.touchdown import simulate_touchdown, touchdown_tire

    gear = _whole_gear()
    tire = touchdown_tire(gear, whole.quad, whole.f, nx=8, ny=3)
    assert isinstance(tire, CarcassTire) and tire.tread.blend > 0
    run = simulate_touchdown(gear, tire, 70.0, sink_rate=1.5, yaw=0.01, duration=0.4)
    t = run.energy_terms
    assert run.energy_residual < 1e-5
    assert t["sliding"] == pytest.approx(0.5 * t["work_forward"], rel=0.05)
    assert 0.1 < run.spin_up_time < 0.13


# -- the gear file and the command ------------------------------------------------------------------


def _whole_gear(**changes):
    g = load_gear(GEAR).replace(
        tire_stiffness_x=1.691e6,
        tire_stiffness_y=5.37e5,
        tire_stiffness_z=9.249e4,
        tread_slip_stiffness=11.15,
    )
    return g.replace(**changes) if changes else g


def test_gear_keys_are_optional_and_refused_when_impossible(whole, tmp_path, capsys):
    from fepost.cli import main
    from fepost.shimmy.touchdown import touchdown_tire

    plain = load_gear(GEAR)
    assert "tread_slip_stiffness" not in plain.to_dict() and "tire_stiffness_z" not in plain.to_dict()
    assert _whole_gear().to_dict()["tread_slip_stiffness"] == {"value": 11.15, "unit": ""}
    with pytest.raises(ArgumentError, match="tread_slip_stiffness and the tire's stiffness: standstill K_x"):
        touchdown_tire(_whole_gear(tread_slip_stiffness=1.0), whole.quad, whole.f, nx=8, ny=3)
    with pytest.raises(ArgumentError, match="give exactly one of tread_stiffness"):
        CarcassTire.from_quadrature(whole.quad, f=0.3, standstill=(1e6, 1e6), nx=4, ny=2)
    with pytest.raises(ArgumentError, match="carcass: the stiffnesses"):
        CarcassTire(whole.lumped(4, 2), (1.0, -1.0, math.inf))
    with pytest.raises(ArgumentError, match="standstill K_y must be positive"):
        carcass_from_standstill(whole.lumped(4, 2), (1.0, 0.0))
    with pytest.raises(ArgumentError, match="sliding: a mask of 24 elements expected"):
        whole.carcass(8, 3).frozen_at(np.ones(3, bool))
    # the command: an impossible carcass is one line, exit 2, nothing written
    data = json.loads(Path(GEAR).read_text())
    data.update(tread_slip_stiffness=0.5, tire_stiffness_z=9.249e4)
    gear_file = tmp_path / "gear.json"
    gear_file.write_text(json.dumps(data))
    out = tmp_path / "out"
    args = ["shimmy", "meshes/rig-tire360/roll/roll_static.vtu", "--gear", str(gear_file), "--out", str(out)]
    args += ["--models", "closed_forms", "--speeds", "5", "--trails", "0", "--branch-speeds", "0"]
    args += ["--no-simulation", "--no-intervals", "--no-progress", "--touchdown", "60"]
    args += ["--touchdown-duration", "0.12"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is not below the tread's own" in err[0]
    assert not out.exists()
    data.update(tread_slip_stiffness=11.15, tire_stiffness_x=1.691e6, tire_stiffness_y=5.37e5)
    gear_file.write_text(json.dumps(data))
    assert main(args) == 0
    rows = json.loads((out / "shimmy.json").read_text())["touchdown"]
    assert len(rows) == 1 and {"speed", "spin_up_time", "verdict", "amplitude", "csv"} <= set(rows[0])
    assert json.loads((out / "shimmy.json").read_text())["gear"]["tire_stiffness_z"]["unit"] == "N m/rad"
