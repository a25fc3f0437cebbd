"""Steady rolling of the whole aircraft tire (issue 39, part 3): deck, solve, sidecar, driver.

- a tiny whole-tire deck (half model, 10 degree layers) rolled 20 mm by CalculiX with the rim
  free to turn: no torque, rim and road in balance, the sidecar's integrals and labels;
- the deck: the whole rig tire's contact lines, the turn held while loading and released
  (or imposed) in the roll;
- the driver's resume rule with a fake solver (no CalculiX);
- the steadiness and turn-rate readers on a made-up history.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import math
import shutil

import numpy as np
import pytest

from scripts.tiremodel import aircraft_roll360_programme as prog
from scripts.tiremodel import aircraft_roll360_results as results
from scripts.tiremodel.aircraft_roll360_run import History, steadiness, steady_turn_rate

HAVE_GMSH = importlib.util.find_spec("gmsh") is not None
needs_gmsh = pytest.mark.skipif(not HAVE_GMSH, reason="gmsh is not installed (the 'model' extra)")
needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed")


@pytest.fixture(scope="module")
def tiny_mesh():
    from scripts.tiremodel.aircraft_roll360_deck import build_mesh

    return build_mesh("tiny")


def _tiny_plan(rotation=None):
    from scripts.tiremodel.aircraft_roll360_deck import Plan

    # the rated-load rim travel and 20 mm of roll (13 s of CPU). The coarse deck's 100 mm faces
    # make its roll fragile: at a light load (60 mm, six contact nodes) it stalled 13 mm into it
    return Plan(0.1241, 0.02, rotation, print_every=0.25, frames=1)


@pytest.mark.slow
@pytest.mark.ccx
@needs_gmsh
@needs_ccx
def test_tiny_free_roll_end_to_end(tiny_mesh, tmp_path):
    """The free rim rolls without torque; rim and road balance; the sidecar says what the run is.
    Then the same roll driven 3 % faster than the free rim turned: a driving torque and force, and
    free rolling found again from the two runs' torques (the driven programme's rule)."""
    from scripts.tiremodel.aircraft_roll360_run import solve, write_run, write_static

    spec = prog.RunSpec(prog.FREE, None)
    result = solve(shutil.which("ccx"), tiny_mesh, "tiny", _tiny_plan(), tmp_path / "work")
    h = result.history
    radius = 1.0 / steady_turn_rate(h)
    static = write_static(tiny_mesh, result, tmp_path, prog.STATIC)
    side = write_run(
        tiny_mesh, result, tmp_path, prog.FREE, spec.labels(prog.Setup(mesh_kind="tiny"), radius)
    )
    n = side["reaction"]["force"][2]
    # no torque on a free rim: the rotation node's reaction is the solver's residual only
    # (measured 0.59 N m against f N R = 34.5 kN m: 1.7e-5)
    assert abs(side["axle_torque_Nm"]) < 1e-3 * 0.3 * n * side["loaded_radius_m"]
    # the rim turned: R_e between the loaded radius and the unloaded one (0.584 m)
    assert side["loaded_radius_m"] < radius < 0.584
    assert side["longitudinal_slip"] == pytest.approx(0.0, abs=1e-12)
    # rim against road: road + rim - bead pressure load = 0 within 0.5 % of N (measured 3e-5 of N
    # along x, 4e-7 along z at the end of the roll; 3e-6 along z in the static state)
    for s in (side, static):
        bal = s["balance"]["residual_over_N"]
        assert abs(bal[0]) < 5e-3 and abs(bal[2]) < 5e-3
        # and the bead's pressure load is what separates the rim's reaction from the road's
        assert abs(s["balance"]["rim_force"][2] + s["balance"]["road_force"][2]) > 0.05 * n
    # the contact pressure carries the road reaction (the coarse deck's 100 mm faces: 2.95 % short)
    assert side["cpress_integral_projected"] == pytest.approx(n, rel=0.035)
    assert "free to turn" in side["description"] and side["imposed"].startswith("axle travel only")
    assert side["steadiness"]["printed_times"] >= 2 and side["cpu_s"] > 0.0
    assert 0.0 < results.brush_slope(side) < 50.0
    for ext in (".vtu", ".dat.txt", ".json"):
        assert (tmp_path / f"{prog.FREE}{ext}").is_file()
    assert json.loads((tmp_path / f"{prog.FREE}.json").read_text())["deck_sha256"] == result.deck_sha256
    # the progress listing reads the same records from the work folder
    lines = prog.progress(tmp_path)
    assert lines[0].startswith("tiny:") and len(lines) == 1 + h.time.size
    assert float(lines[-1].split()[3]) == pytest.approx(n, abs=0.1)

    # driven against a reference radius: the free rim's R_e, turned at slip +0.03 and wound by
    # 2 mrad over the roll's first 1 %
    setup = prog.Setup(mesh_kind="tiny", travel=0.02, reference_radius=radius)
    drive = prog.RunSpec(prog.run_name(0.03, 0.002), 0.03, 0.002)
    assert drive.name == "roll_drive030w"
    plan = dataclasses.replace(_tiny_plan(drive.plan(radius, setup).rotation), prewind=0.002)
    driven = solve(shutil.which("ccx"), tiny_mesh, "tiny_drive", plan, tmp_path / "work_drive")
    dside = write_run(tiny_mesh, driven, tmp_path, drive.name, drive.labels(setup, radius))
    assert (
        "against the reference radius" in dside["description"] and "wound by +0.002" in dside["description"]
    )
    # the pre-wind adds to the turn; the slip is read over the last fifth, after it
    assert dside["rim_rotation_deg"] == pytest.approx(math.degrees(plan.rotation + 0.002), rel=1e-5)
    assert "effective_rolling_radius_m" not in dside and dside["slip_radius_m"] == radius
    # the slip read back from the printed turns (the .dat's 7 digits; measured 8e-7 off)
    assert dside["longitudinal_slip"] == pytest.approx(0.03, abs=1e-5)
    # a driving run: the road pushes the tire forward, the axle drives the rim (the free run's
    # torque is 1.7e-5 of f N R; this one's is 3 orders larger)
    assert dside["longitudinal_force_ratio"] > 0.0
    torque = dside["axle_torque_tail_mean_Nm"]
    assert abs(torque) > 100 * abs(side["axle_torque_tail_mean_Nm"])
    fr = results.free_rolling([results.RunPoint.from_sidecar(s) for s in (side, dside)])
    # the torque line's zero is the free rim's turn rate, within its residual torque's share
    assert fr.effective_radius == pytest.approx(radius, rel=1e-3)
    assert fr.slips[drive.name] == pytest.approx(0.03, abs=1e-3)


@needs_gmsh
def test_deck_uses_the_whole_rig_tire_contact_and_releases_the_turn(tiny_mesh, tmp_path):
    from scripts.tiremodel import aircraft_rig_deck as ard
    from scripts.tiremodel.aircraft_roll360_deck import road_block, write_deck

    free, imposed = _tiny_plan(), _tiny_plan(0.0357)
    write_deck(tmp_path / "free.inp", tiny_mesh, free)
    write_deck(tmp_path / "imp.inp", tiny_mesh, imposed)
    text_free, text_imp = ((tmp_path / f).read_text() for f in ("free.inp", "imp.inp"))
    pair = ard.WHOLE.model_lines(tiny_mesh, "x", road_block(free))
    k = pair.index("*SURFACE INTERACTION, NAME=SI")
    assert "\n".join(pair[k : k + 7]) in text_free
    # two steps: the turn held (ROTN 2) while loading; the roll re-states every condition
    assert text_free.count("*STEP, NLGEOM") == 2 and "*BOUNDARY, OP=NEW" in text_free
    roll_free = text_free.split("*BOUNDARY, OP=NEW")[1]
    assert "ROTN, 2, 2," not in roll_free
    # an imposed turn: one step, the turn and the road's travel on the roll's amplitude (0 until
    # the roll), the roll's criteria throughout
    assert text_imp.count("*STEP, NLGEOM") == 1 and "OP=NEW" not in text_imp
    assert "*BOUNDARY, AMPLITUDE=AROLL\nROTN, 2, 2, 3.570000000e-02" in text_imp
    assert "*BOUNDARY, AMPLITUDE=AROLL\nROADN, 1, 1, -2.000000000e-02" in text_imp
    assert "*CONTROLS, PARAMETERS=FIELD\n0.005, 1.0" in text_imp
    # a pre-wind: the turn on its own amplitude, 0.01 rad more at 1 % of the roll, the total at its end
    write_deck(tmp_path / "wind.inp", tiny_mesh, dataclasses.replace(imposed, prewind=0.01))
    wind = (tmp_path / "wind.inp").read_text()
    assert "*BOUNDARY, AMPLITUDE=ATURN\nROTN, 2, 2, 4.570000000e-02" in wind
    amp = wind.split("*AMPLITUDE, NAME=ATURN, TIME=TOTAL TIME\n")[1].splitlines()[0].split(",")
    t1, tw, value = float(amp[2]), float(amp[4]), float(amp[5])
    assert (tw - t1) == pytest.approx(0.02) and value == pytest.approx(
        (0.01 + 0.01 * 0.0357) / 0.0457, rel=1e-11
    )
    with pytest.raises(ValueError, match="needs an imposed turn"):
        write_deck(tmp_path / "bad.inp", tiny_mesh, dataclasses.replace(free, prewind=0.01))
    assert "SYMN, 2, 2" in roll_free and "ROADN, 1, 1, -2.000000000e-02" in roll_free
    # the road is held along x while loading: the roll starts from where the loading left it
    load_step = text_free.split("*STEP, NLGEOM")[1].split("*END STEP")[0]
    assert "\nROADN, 1, 1\n" in load_step and "\nROADN, 2, 2\n" in load_step


def _fake_task(task: prog.Task) -> dict:
    from scripts.tiremodel.aircraft_roll360_run import EXPORT_VERSION

    side = {
        "deck_sha256": _fake_sha(task.spec, task.plan),
        "effective_rolling_radius_m": 0.55,
        "export_version": EXPORT_VERSION,
    }
    for ext in (".vtu", ".dat.txt"):
        (task.out / f"{task.spec.name}{ext}").write_text("x")
    (task.out / f"{task.spec.name}.json").write_text(json.dumps(side))
    CALLS.append(task.spec.name)
    return {"case": task.spec.name}


def _fake_sha(spec: prog.RunSpec, plan) -> str:
    return f"{spec.name}:{plan.rotation}"


CALLS: list[str] = []


def test_resume_runs_free_first_and_skips_finished_runs(tmp_path):
    specs = prog.programme((-0.01, 0.01))
    out, work = tmp_path / "out", tmp_path / "work"
    out.mkdir()
    free, brake, drive = specs
    setup = prog.Setup(mesh_kind="tiny")
    # the braking run finished earlier with the deck it gets now; the driving run half-written
    _fake_task(prog.Task(brake, brake.plan(0.55, setup), setup, None, out, work, 0.55))
    (out / f"{drive.name}.vtu").write_text("partial")
    CALLS.clear()
    done = prog.run_programme(
        out, work, specs, setup, task_fn=_fake_task, deck_sha=_fake_sha, processes=False, mesh=object()
    )
    assert CALLS == [free.name, drive.name] and sorted(done) == sorted(CALLS)
    CALLS.clear()
    assert (
        prog.run_programme(
            out, work, specs, setup, task_fn=_fake_task, deck_sha=_fake_sha, processes=False, mesh=object()
        )
        == []
    )
    assert CALLS == []
    # a sidecar of an older export is written again
    side = json.loads((out / f"{drive.name}.json").read_text())
    (out / f"{drive.name}.json").write_text(json.dumps({**side, "export_version": 1}))
    assert prog.run_programme(
        out, work, specs, setup, task_fn=_fake_task, deck_sha=_fake_sha, processes=False, mesh=object()
    ) == [drive.name]


def test_slip_plans_turn_against_the_free_radius():
    setup = prog.Setup(mesh_kind="tiny", travel=1.0)
    spec = prog.RunSpec(prog.run_name(-0.03), -0.03)
    assert spec.name == "roll_brake030"
    assert spec.plan(0.5, setup).rotation == pytest.approx(0.97 / 0.5)
    assert prog.RunSpec(prog.FREE, None).plan(None, setup).rotation is None
    with pytest.raises(ValueError, match="effective radius"):
        spec.plan(None, setup)


def test_steadiness_and_turn_rate_of_a_made_up_history():
    x = np.linspace(0.0, 1.0, 41)
    fz = np.full(x.size, 2.0e5)
    fx = 1.0e3 * (1.0 - np.exp(-x / 0.2))  # a relaxation length of 0.2 m
    h = History(
        time=1.2 + 2.0 * x,
        axle_travel=x,
        rotation=x / 0.56,
        road=np.column_stack([fx, 0 * x, fz]),
        rim=np.column_stack([-fx, 0 * x, -fz]),
        torque=0.5 * fx,
        road_z=np.full(x.size, 0.12),
    )
    assert steady_turn_rate(h) == pytest.approx(1 / 0.56)
    st = steadiness(h, 0.46)
    # Fx moves by 1e3 (e^-4 - e^-5) = 11.6 N over the last fifth, against f N = 6e4 N
    assert st["Fx_over_fN"] == pytest.approx(1e3 * (np.exp(-4) - np.exp(-5)) / 6e4, rel=1e-9)
    assert st["Fz_over_N"] == 0.0 and st["printed_times"] == 9 and st["steady"]
    fz2 = fz.copy()
    fz2[-1] *= 1.01  # N moving 1 % in the tail is not steady
    h2 = History(
        h.time, h.axle_travel, h.rotation, np.column_stack([fx, 0 * x, fz2]), h.rim, h.torque, h.road_z
    )
    assert not steadiness(h2, 0.46)["steady"]


RUNS = sorted(p for p in prog.OUT.glob("roll_*.json") if p.stem != prog.STATIC)


@pytest.mark.skipif(not RUNS, reason="meshes/rig-tire360/roll/ holds no rolling runs yet")
@pytest.mark.parametrize("path", RUNS, ids=lambda p: p.stem)
def test_committed_runs_balance_and_say_what_they_are(path):
    side = json.loads(path.read_text())
    assert side["kind"] == "rolling run" and side["deck_sha256"]
    for ext in (".vtu", ".dat.txt"):
        assert path.with_suffix("").with_suffix(ext).is_file()
    # rim against road within 0.5 % of N (bead pressure load included)
    assert max(abs(v) for v in side["balance"]["residual_over_N"]) < 5e-3
    n = side["reaction"]["force"][2]
    if side["case"] == prog.FREE:
        # the free rim: no torque but the solver's residual; its slip is 0 by definition
        assert "free to turn" in side["description"]
        assert abs(side["axle_torque_tail_mean_Nm"]) < 1e-3 * 0.3 * n * side["loaded_radius_m"]
    else:
        assert side["imposed_slip"] == pytest.approx(side["longitudinal_slip"], abs=2e-3)
    # the last frame's centre comes from the exact projected integral; the load integral is N's
    assert side["cpress_integral_projected"] == pytest.approx(n, rel=0.03)


def _brush_point(name, kappa_e, radius, c_over_n, f=0.3, n=2.0e5, lever=0.5, kx=math.nan):
    """A run of a brush tire (parabolic pressure): slip kappa_e against the true R_e, torque = the
    force's moment about the axle (no rolling resistance)."""
    theta = min(c_over_n * abs(kappa_e) / (3.0 * f), 1.0)
    ratio = math.copysign(f * (3 * theta - 3 * theta**2 + theta**3), kappa_e)
    return results.RunPoint(name, (1.0 + kappa_e) / radius, ratio * n * lever, ratio, n, f, kx)


def test_free_rolling_from_driven_runs_of_a_brush_tire():
    """Three runs driven against a reference 1.2 % off R_e: R_e, the slips against it, the brush
    curve's slope recovered exactly and the secant's shortfall; k_x interpolated at free rolling."""
    re_, c = 0.5625, 11.0
    ref = re_ * 1.012
    pts = [
        _brush_point(f"r{k:+.2f}", (1 + k) * re_ / ref - 1, re_, c, kx=0.05 + 2.0 * ((1 + k) * re_ / ref - 1))
        for k in (-0.02, 0.0, 0.02)
    ]
    fr = results.free_rolling(pts)
    # the torque is odd in the slip: the line through three points is exact only to the bend's
    # asymmetry (points at -0.032, -0.012, +0.008 about free rolling)
    assert fr.effective_radius == pytest.approx(re_, rel=2e-3)
    assert fr.bracketed and set(fr.runs_used) == {p.name for p in pts}
    assert fr.brush_fit_slope == pytest.approx(c, rel=0.02)
    assert fr.secant_slope < c  # the curve bends down: the secant falls short
    assert fr.kx_at_free == pytest.approx(0.05, abs=0.01)
    # symmetric runs about R_e: R_e to round-off, the brush fit exact, Fx/N = 0 at free rolling
    sym = [_brush_point(f"s{k:+.2f}", k, re_, c) for k in (-0.02, 0.02)]
    fs = results.free_rolling(sym)
    assert fs.effective_radius == pytest.approx(re_, rel=1e-12)
    assert fs.brush_fit_slope == pytest.approx(c, rel=1e-9)
    assert fs.fx_over_n_at_free == pytest.approx(0.0, abs=1e-12)
    assert fs.slips["s+0.02"] == pytest.approx(0.02, rel=1e-9)
    # runs still building up: the slip curve takes each run's fitted steady force
    half = [
        results.RunPoint(
            q.name,
            q.turn_rate,
            0.5 * q.torque,
            0.5 * q.fx_over_n,
            q.normal_load,
            q.friction,
            steady_fx_over_n=q.fx_over_n,
        )
        for q in sym
    ]
    fh = results.free_rolling(half)
    assert fh.effective_radius == pytest.approx(re_, rel=1e-12)
    assert fh.brush_fit_slope == pytest.approx(c, rel=1e-9) and fh.secant_slope == pytest.approx(
        fs.secant_slope
    )
    # both runs on one side: said so
    assert not results.free_rolling([_brush_point(f"o{k}", k, re_, c) for k in (0.01, 0.03)]).bracketed
    with pytest.raises(ValueError, match="at least two"):
        results.free_rolling(sym[:1])


def test_relaxation_length_of_a_first_order_build_up():
    x = np.linspace(0.0, 1.6, 41)
    side = {
        "history": {"axle_travel_m": x.tolist(), "Fx": (-1.2e4 * -np.expm1(-x / 0.27)).tolist()},
        "tail_means": {"Fz": 2.0e5},
        "imposed_slip": -0.01,
    }
    # nothing builds up without an imposed slip (a free rim, a run at the reference radius)
    assert results.build_up({**side, "imposed_slip": None}) is None
    assert results.build_up({**side, "imposed_slip": 0.0}) is None
    fit = results.build_up(side)
    assert fit.sigma == pytest.approx(0.27, rel=1e-6) and fit.f_inf == pytest.approx(-1.2e4, rel=1e-6)
    assert fit.sigma_se < 1e-6 * fit.sigma and fit.reached == pytest.approx(-np.expm1(-1.6 / 0.27), rel=1e-6)
    # a build-up that is not first order (a ramp): its fit says so through its standard errors
    ramp = {**side, "history": {"axle_travel_m": x.tolist(), "Fx": (-1.0e4 * np.minimum(x, 0.8)).tolist()}}
    assert results.build_up(ramp).f_inf_se > 0.01 * 8.0e3
    side["history"]["Fx"] = (0.0 * x).tolist()  # no force builds up: no length
    assert results.build_up(side) is None


def test_brush_theta_inverts_the_brush_curve():
    for theta in (0.0, 0.1, 0.5, 0.99, 1.0):
        ratio = 3 * theta - 3 * theta**2 + theta**3
        assert results.brush_theta(ratio) == pytest.approx(theta, abs=1e-12)
        assert results.brush_theta(-ratio) == pytest.approx(theta, abs=1e-12)
    assert math.isnan(results.brush_theta(1.2))


def test_driven_programme_runs_every_slip_against_the_reference(tmp_path):
    specs = prog.programme((-0.02, 0.02, 0.0), free=False)
    assert [s.name for s in specs] == ["roll_brake020", "roll_drive020", "roll_ref"]
    out, work = tmp_path / "out", tmp_path / "work"
    out.mkdir()
    setup = prog.Setup(mesh_kind="tiny", travel=1.0, reference_radius=0.57)
    CALLS.clear()
    done = prog.run_programme(
        out, work, specs, setup, task_fn=_fake_task, deck_sha=_fake_sha, processes=False, mesh=object()
    )
    # no free run needed first: every slip's deck turns against the reference radius
    assert sorted(done) == sorted(CALLS) == sorted(s.name for s in specs)
    sha = json.loads((out / "roll_drive020.json").read_text())["deck_sha256"]
    assert sha == f"roll_drive020:{1.02 / 0.57}"
    labels = specs[2].labels(setup, 0.57)
    assert "driven at the reference radius" in labels["description"] and labels["imposed_slip"] == 0.0
    assert "not R_e" in labels["description"] and "effective_rolling_radius_m" not in labels


def test_brush_slope_of_a_rectangular_patch():
    """Strips of one length 2a over a width w: C_kappa = (G/h) 2 a^2 w; over N."""
    strips = {"length": [0.4] * 5, "width": [0.06] * 5}
    slope = results.brush_slope({"static_patch_strips": strips, "static_load": 2.0e5})
    assert slope == pytest.approx(1.5e6 / 0.02 * 2 * 0.2**2 * 0.3 / 2.0e5, rel=1e-12)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--tolerances", "0", "1"], "--tolerances"),
        (["--reference-radius", "5"], "no radius of this tire"),
        (["--workers", "0"], "at least one"),
        (["--slips", "0.0"], "0 only with --reference-radius"),
        (["--reference-radius", "0.57", "--slips", "0.7"], "each in (-0.5, 0.5)"),
    ],
)
def test_programme_refuses_bad_arguments(tmp_path, capsys, argv, message):
    assert prog.main(["--work", str(tmp_path / "w"), *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "w").exists()  # nothing written


@pytest.mark.skipif(not RUNS, reason="meshes/rig-tire360/roll/ holds no rolling runs yet")
def test_table_of_the_committed_runs():
    """The table reads every committed run: one line each, its build-up fitted where its force
    builds up, the brush estimate; rim and road balance as the sidecars say."""
    lines = results.table(prog.OUT, kx=False, rig=prog.RIG)
    names = [json.loads(p.read_text())["case"] for p in RUNS]
    for name in names:
        assert sum(line.startswith(name + " ") for line in lines) == 1
    for side in results.rolling_sidecars(prog.OUT):
        fit = results.build_up(side)
        if fit is not None:  # a slip run: its force builds up over about a metre (sigma ~ 1.1 m)
            assert 0.5 < fit.sigma < 3.0 and fit.sigma_se < 0.05 * fit.sigma
            assert abs(fit.f_inf) > abs(side["tail_means"]["Fx"])
    assert any(line.startswith("brush estimate") for line in lines)


def test_traction_shift_line_through_the_maps_own_forces():
    """k_x = k0 + c Fx/N recovered from runs whose k_x lies on the line, whatever their steadiness;
    None where the forces do not spread."""
    pts = [
        results.RunPoint(f"r{i}", 1.75, 0.0, 0.0, 2.0e5, 0.3, kx=0.004 + 1.4 * fx, end_fx_over_n=fx)
        for i, fx in enumerate((-0.15, -0.11, 0.0, 0.14))
    ]
    ts = results.traction_shift(pts)
    assert ts.k0 == pytest.approx(0.004, abs=1e-12) and ts.slope == pytest.approx(1.4, rel=1e-12)
    assert ts.rms < 1e-12 and ts.runs == ("r0", "r1", "r2", "r3")
    assert results.traction_shift(pts[:1]) is None
    assert results.traction_shift([dataclasses.replace(p, end_fx_over_n=0.1) for p in pts]) is None


def test_brush_slope_of_a_steady_run_inverts_the_brush_curve():
    """A brush tire's force at any slip short of full sliding gives back its C_kappa / N exactly,
    braking or driving; free rolling gives nothing."""
    for kappa in (-0.03, -0.018, 0.0223, 0.05):
        p = _brush_point("b", kappa, 0.57, 11.0)
        assert results.brush_slope_of(p.fx_over_n, kappa, 0.3) == pytest.approx(11.0, rel=1e-12)
    assert math.isnan(results.brush_slope_of(0.0, 0.0005, 0.3))


@pytest.mark.skipif(
    not all((prog.OUT / f"{n}.json").is_file() for n in ("roll_brake020w", "roll_drive020w")),
    reason="the pre-wound braking and driving runs are not committed",
)
def test_steady_slip_runs_agree_with_the_tread_brush_estimate():
    """The two pre-wound runs, steady over the last fifth: each one's force at its slip against R_e,
    through the brush curve, against the brush estimate from the static patch's strips and the
    tread rubber (no run in it): braking and driving within 3 % of it (docs/rolling.md)."""
    sides = results.rolling_sidecars(prog.OUT)
    points = [results.RunPoint.from_sidecar(s) for s in sides]
    slips = results.free_rolling(points).slips
    steady = results.steady_brush_slopes(sides, points, slips)
    assert {"roll_brake020w", "roll_drive020w"} <= set(steady)
    assert "roll_ref" not in steady  # steady, but it does not slip
    strips = results.brush_slope(sides[-1])
    assert strips == pytest.approx(11.15, abs=0.01)
    for name in ("roll_brake020w", "roll_drive020w"):
        assert steady[name] == pytest.approx(strips, rel=0.03)
    assert slips["roll_brake020w"] < 0.0 < slips["roll_drive020w"]


def test_driven_runs_keep_the_static_partner_the_first_one_wrote(tmp_path, monkeypatch):
    """Every driven run's first step is the same deck, so the static partner its first finished run
    wrote stays as it is: a later run does not rewrite it (its description named the last run)."""
    from types import SimpleNamespace

    from scripts.tiremodel import aircraft_roll360_run as run
    from scripts.tiremodel import solve as solve_mod

    written = []

    def fake_static(mesh, result, out, name):
        written.append(result.name)
        (out / f"{name}.json").write_text(json.dumps({"description": f"from {result.name}"}))

    def fake_run(mesh, result, out, name, labels):
        return {
            "longitudinal_slip": 0.0,
            "longitudinal_force_ratio": 0.0,
            "axle_torque_tail_mean_Nm": 0.0,
            "steadiness": {"steady": True},
            "cpu_s": 1.0,
        }

    monkeypatch.setattr(solve_mod, "find_ccx", lambda: "ccx")
    monkeypatch.setattr(run, "solve", lambda ccx, mesh, name, plan, work: SimpleNamespace(name=name))
    monkeypatch.setattr(run, "write_static", fake_static)
    monkeypatch.setattr(run, "write_run", fake_run)
    setup = prog.Setup(mesh_kind="tiny", travel=1.0, reference_radius=0.57)
    for spec in prog.programme((-0.02, 0.02), free=False):
        prog.solve_and_export(prog.Task(spec, None, setup, None, tmp_path, tmp_path, 0.57))
    assert written == ["roll_brake020"]
    assert json.loads((tmp_path / f"{prog.STATIC}.json").read_text())["description"] == "from roll_brake020"
