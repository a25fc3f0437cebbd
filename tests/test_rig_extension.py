"""The load-transfer extension of the friction model (fepost.rig.extension, fepost.rig.compare)
and the rig section of the report (fepost.report.rigsection)."""

from __future__ import annotations

import csv
import importlib.util
import json
import re
import shutil
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fepost.errors import ArgumentError, FitError
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.reference_maps import tire_like
from fepost.rig.extension import (
    ShiftLaw,
    cross_validate,
    identify_shift,
    predict_shifted,
    shifted_resultants,
)

ROOT = Path(__file__).resolve().parents[1]
RIG = ROOT / "meshes" / "rig"
LAW = FrictionLaw(f=0.3)


def _law(hx: float, hy: float) -> ShiftLaw:
    return ShiftLaw(hx, hy, 0.0, 0.0, (hx, hx), (hy, hy), 0.0, 0.0, 0.0, 0.0, 1)


def _kinematics():
    """Slides in three directions, spin ratios 0 to 3, both spin signs (as the rig programme)."""
    out = []
    for d in (0.0, 45.0, 90.0):
        for ratio in (0.0, 0.5, 1.2, 3.0):
            for sign in (1.0, -1.0) if ratio else (1.0,):
                v = 0.05
                out.append((v * np.cos(np.radians(d)), v * np.sin(np.radians(d)), sign * ratio * v / 0.15))
    return np.array(out).T


@pytest.fixture(scope="module")
def quad():
    return tire_like(nr=24, nphi=48)


def _synthetic_runs(quad, h, noise, seed):
    """Each synthetic run's map: the static map moved to the fixed point of the known law; its
    centre-of-pressure shift measured on that moved map (a second computation), plus noise."""
    vx, vy, wz = _kinematics()
    pred = predict_shifted(quad, vx, vy, wz, law=_law(*h), friction=LAW)
    n = quad.load
    c0 = np.array([np.sum(quad.sigma * quad.dA * quad.x), np.sum(quad.sigma * quad.dA * quad.y)]) / n
    shifts = []
    for dx, dy in zip(pred.dx, pred.dy, strict=True):
        q = quad.shifted(float(dx), float(dy))
        shifts.append(np.array([np.sum(q.sigma * q.dA * q.x), np.sum(q.sigma * q.dA * q.y)]) / q.load - c0)
    rng = np.random.default_rng(seed)
    shifts = np.array(shifts) + noise * rng.standard_normal((len(shifts), 2))
    forces = np.column_stack([pred.resultants.Fx, pred.resultants.Fy]) / n
    return shifts, forces, (vx, vy, wz)


def test_identify_recovers_known_height(quad):
    """Noise-free synthetic maps give h to round-off; with noise the 95 % intervals cover it."""
    h = (0.012, 0.045)
    shifts, forces, _ = _synthetic_runs(quad, h, 0.0, 0)
    law = identify_shift(shifts, forces)
    assert law.h_x == pytest.approx(h[0], rel=1e-9) and law.h_y == pytest.approx(h[1], rel=1e-9)
    covered = 0
    for seed in range(20):
        shifts, forces, _ = _synthetic_runs(quad, h, 3e-4, seed)
        law = identify_shift(shifts, forces)
        assert law.interval_x[0] < law.h_x < law.interval_x[1]
        covered += law.interval_x[0] <= h[0] <= law.interval_x[1]
        covered += law.interval_y[0] <= h[1] <= law.interval_y[1]
    # 40 intervals at 95 %: fewer than 35 covering has probability < 1 %
    assert covered >= 35
    assert law.to_dict()["n"] == shifts.shape[0]


def test_shifted_integrals_agree_with_the_moved_map(quad):
    """The kinematic shortcut equals the exact integrals over the moved quadrature."""
    vx, vy, wz = _kinematics()
    dx, dy = 0.004, -0.007
    a = shifted_resultants(quad, vx, vy, wz, dx=dx, dy=dy, law=LAW)
    b = friction_resultants(quad.shifted(dx, dy), vx, vy, wz, LAW)
    scale = LAW.f * quad.load
    for q in ("Fx", "Fy", "Mz"):
        np.testing.assert_allclose(getattr(a, q), getattr(b, q), rtol=0, atol=1e-9 * scale)


def test_zero_height_is_the_static_map(quad):
    vx, vy, wz = _kinematics()
    pred = predict_shifted(quad, vx, vy, wz, law=_law(0.0, 0.0), friction=LAW)
    ref = friction_resultants(quad, vx, vy, wz, LAW)
    for q in ("Fx", "Fy", "Mz"):
        assert np.array_equal(getattr(pred.resultants, q), getattr(ref, q))
    assert pred.iterations == 1 and not np.any(pred.dx) and not np.any(pred.dy)


def test_fixed_point_converges(quad):
    """The converged shift reproduces itself: d = h F(d) / N."""
    vx, vy, wz = _kinematics()
    law = _law(0.012, 0.045)
    pred = predict_shifted(quad, vx, vy, wz, law=law, friction=LAW)
    assert pred.iterations < 30 and pred.change <= 1e-12
    again = shifted_resultants(quad, vx, vy, wz, dx=pred.dx, dy=pred.dy, law=LAW)
    np.testing.assert_allclose(pred.dx, law.h_x * again.Fx / quad.load, rtol=0, atol=1e-11)
    np.testing.assert_allclose(pred.dy, law.h_y * again.Fy / quad.load, rtol=0, atol=1e-11)
    assert np.max(np.abs(pred.dy)) > 0.01  # a real shift, not a trivial one
    with pytest.raises(FitError, match="no fixed point after 2 iterations"):
        predict_shifted(quad, vx, vy, wz, law=law, friction=LAW, tol=0.0, max_iter=2)


def test_cross_validation_holds_out_each_group(quad):
    h = (0.012, 0.045)
    shifts, forces, (vx, vy, wz) = _synthetic_runs(quad, h, 0.0, 0)
    groups = [f"d{int(round(np.degrees(np.arctan2(b, a))))}" for a, b in zip(vx, vy, strict=True)]
    cv = cross_validate(quad, vx, vy, wz, shifts=shifts, forces=forces, groups=groups, friction=LAW)
    assert cv.groups == ("d0", "d45", "d90")
    full = predict_shifted(quad, vx, vy, wz, law=_law(*h), friction=LAW).resultants
    np.testing.assert_allclose(cv.Fx, full.Fx, atol=1e-8 * quad.load)  # exact data: every fold finds h


def test_cross_validation_refuses_a_fold_too_small_to_identify(quad):
    shifts, forces, (vx, vy, wz) = _synthetic_runs(quad, (0.012, 0.045), 0.0, 0)
    keep = np.arange(4)  # four runs, two groups: holding either out leaves two
    groups = ["a", "a", "b", "b"]
    with pytest.raises(ArgumentError, match="holding out group 'a' leaves 2 run"):
        cross_validate(
            quad, vx[keep], vy[keep], wz[keep], shifts=shifts[keep], forces=forces[keep], groups=groups
        )


def test_cross_validation_names_the_fold_whose_training_runs_have_no_force_along_an_axis(quad):
    """Holding out the only group with lateral force leaves runs whose Fy is rounding (a
    longitudinal slide, pure spins): h_y cannot be identified, and the error says which fold
    (an unchecked fit divided rounding by rounding and the fixed point ran away)."""
    shifts, forces, (vx, vy, wz) = _synthetic_runs(quad, (0.012, 0.045), 0.0, 0)
    n = len(vx)
    groups = np.full(n, "lat", dtype=object)
    groups[np.argsort(np.abs(forces[:, 1]))[:3]] = "other"
    forces = forces.copy()
    forces[groups == "other", 1] = 1e-16
    with pytest.raises(FitError, match="holding out group 'lat': identify_shift: no run has a force along y"):
        cross_validate(quad, vx, vy, wz, shifts=shifts, forces=forces, groups=list(groups))


def test_bad_input_is_one_line():
    with pytest.raises(ArgumentError, match=r"must both be \(n, 2\)"):
        identify_shift(np.zeros((4, 2)), np.zeros((3, 2)))
    with pytest.raises(ArgumentError, match="at least 3 runs"):
        identify_shift(np.zeros((2, 2)), np.ones((2, 2)))
    with pytest.raises(FitError, match=r"no run has a force along x \(largest \|Fx/N\| 0\)"):
        identify_shift(np.ones((4, 2)), np.zeros((4, 2)))
    # a force that is zero by symmetry comes out of a solver as rounding, not as 0
    rounding = np.column_stack([np.full(4, 0.3), np.full(4, 1e-16)])
    with pytest.raises(FitError, match="along y .* h_y cannot be identified"):
        identify_shift(np.full((4, 2), 0.01), rounding)
    with pytest.raises(ArgumentError, match="law must be a ShiftLaw"):
        predict_shifted(tire_like(nr=8, nphi=16), 0.1, 0.0, 0.0, law=(0.01, 0.01))


# -- the committed rig runs -----------------------------------------------------------------


def _study():
    spec = importlib.util.spec_from_file_location("rig_study", ROOT / "scripts" / "rig_study.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("rig_study", mod)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def committed():
    assert (RIG / "static.vtu").is_file(), "meshes/rig/static.vtu (committed sample data) is missing"
    study = _study()
    runs = study._runs(RIG)
    table, static, preds, shifts = study.predictions(RIG, runs, 0.3)
    ext, law = study.extension(table, static, shifts, 0.3)
    preds.update(ext)
    _, summary = study.misfit_table(table, static, preds, 0.3)
    return SimpleNamespace(static=static, runs=runs, summary={s["model"]: s for s in summary}, law=law)


def _table_rows() -> dict[str, list[float]]:
    out = {}
    for line in (ROOT / "docs" / "rig" / "table.txt").read_text().splitlines():
        m = re.match(r"\| (\(.*?) \| ([-\d.]+) \| ([-\d.]+) \| ([-\d.]+) \| ([-\d.]+) \|$", line)
        if m:
            out[m.group(1)] = [float(m.group(k)) for k in range(2, 6)]
    return out


def test_committed_gain_is_what_the_docs_state(committed):
    """Recomputed misfits equal the committed table to its printed 4 decimals (half a unit
    of the last digit), and the held-out gain over (b) is the one the docs state."""
    study = _study()
    rows = _table_rows()
    for label in (*study.MODELS.values(), *study.EXTENSION.values()):
        s = committed.summary[label]
        got = [s["rms_F"], s["max_F"], s["rms_Mz"], s["max_Mz"]]
        np.testing.assert_allclose(got, rows[label], rtol=0, atol=5.01e-5, err_msg=label)
    b = committed.summary[study.MODELS["exact"]]
    cv = committed.summary[study.EXTENSION["shift"]]
    # docs/rig.md: the held-out load-transfer law cuts RMS |dF| from 0.054 to 0.020 fN
    # and RMS dMz from 0.017 to 0.010 fNR
    assert round(b["rms_F"], 3) == 0.054 and round(cv["rms_F"], 3) == 0.020
    assert round(b["rms_Mz"], 3) == 0.017 and round(cv["rms_Mz"], 3) == 0.010
    text = (ROOT / "docs" / "rig.md").read_text()
    law = committed.law
    assert f"| x | {law.h_x * 1e3:.2f} |" in text and f"| y | {law.h_y * 1e3:.2f} |" in text
    assert f"| {study.EXTENSION['shift']} | {cv['rms_F']:.4f} | {cv['max_F']:.4f} |" in text


def test_compare_runs_agrees_with_the_study(committed):
    """fepost.rig.compare (the report's path) gives the study's (b) and all-runs (e) rows."""
    from fepost.rig.compare import compare_runs

    study = _study()
    cmp = compare_runs(committed.static, committed.runs)
    for which, label in (("static", study.MODELS["exact"]), ("shifted", study.EXTENSION["fit"])):
        m, s = cmp.misfit(which), committed.summary[label]
        for k in ("rms_F", "max_F", "rms_Mz", "max_Mz"):
            assert m[k] == pytest.approx(s[k], rel=1e-9), (which, k)
    assert cmp.law.h_x == pytest.approx(committed.law.h_x, rel=1e-12)
    assert json.loads(json.dumps(cmp.to_dict()))["law"]["n"] == len(committed.runs)


def test_report_section_with_and_without_rig_runs(committed, tmp_path):
    from fepost.analysis import analyse
    from fepost.report.html import environment
    from fepost.report.providers import DEFAULT_SECTIONS
    from fepost.report.rigsection import TITLE, rig_section

    assert rig_section in DEFAULT_SECTIONS
    section = rig_section(SimpleNamespace(analysis=committed.static, options=None), tmp_path)
    assert section is not None and section.title == TITLE
    assert len(section.table) == 1 + len(committed.runs) and section.table[0][0] == "run"
    assert any("h_x = 11.65 mm" in p for p in section.paragraphs)
    html = environment().get_template("sections/generic.html.j2").render(section=section)
    assert "d045_a40n" in html
    other = analyse(ROOT / "meshes" / "static.vtu")  # the sample tire: no rig runs beside it
    assert rig_section(SimpleNamespace(analysis=other, options=None), tmp_path) is None


def test_study_with_too_few_runs_fails_in_one_line(tmp_path, capsys):
    """Three runs in three groups: the held-out extension cannot be identified; the study says so
    in one line, exits 2 and writes nothing."""
    import shutil

    rig = tmp_path / "rig"
    rig.mkdir()
    for name in ("static", "spin_p", "d000_slide", "d090_slide"):
        for f in (ROOT / "meshes" / "rig-tire360").glob(f"{name}.*"):
            shutil.copy(f, rig / f.name)
    out = tmp_path / "out"
    assert _study().main(["--rig", str(rig), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("rig_study: cross_validate: holding out group")
    assert "need at least 3" in err[-1] and not out.exists()


def test_study_without_the_extension_sets_chosen_runs_side_by_side(tmp_path, capsys):
    """``--runs`` picks runs by name and ``--no-extension`` stops after (a)-(d) and the
    decomposition: what a programme whose folds cannot identify (e) yet can be compared on."""
    names = ["d000_slide", "d090_slide", "spin_p", "d090_a20p"]
    out = tmp_path / "out"
    args = ["--rig", str(ROOT / "meshes" / "rig-tire360"), "--out", str(out), "--no-extension"]
    assert _study().main([*args, "--runs", *names]) == 0
    table = (out / "table.txt").read_text()
    assert "Misfit over 4 rig runs" in table and "(b) - (c): pressure redistribution" in table
    assert "(e) and the load-transfer heights not computed (--no-extension)" in table
    assert "h_x" not in table
    with open(out / "misfit.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["run"] for r in rows] == names
    assert not any(k.endswith("_shift") for k in rows[0])
    # the pure slides sit at the Coulomb limit in the FE and in every exact prediction
    slide = rows[0]
    assert float(slide["Fx_fe"]) == pytest.approx(-1.0, abs=1e-3)
    assert float(slide["Fx_exact"]) == pytest.approx(-1.0, abs=1e-9)
    assert not (out / "rig_shift.png").exists() and (out / "rig_090.png").is_file()
    capsys.readouterr()
    bad = tmp_path / "bad"
    assert _study().main([*args[:2], "--out", str(bad), "--runs", "d000_slide", "d030_slide"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"rig_study: --runs: no run d030_slide in {ROOT / 'meshes' / 'rig-tire360'}"]
    assert not bad.exists()


def test_the_tracked_steady_state_tables_are_the_all_component_check():
    """The steady-state tables of docs/rig/ and docs/rig/aircraft/ are what rig_study computes
    now: every force component and N judged (scripts/tiremodel/steadiness), |F| beside; on the
    sector 4 of 29 runs are steady, on the small tire 9 (docs/rig.md)."""
    study = _study()
    for rig, table, steady in (
        (RIG, ROOT / "docs" / "rig" / "table.txt", 9),
        (ROOT / "meshes" / "rig-aircraft", ROOT / "docs" / "rig" / "aircraft" / "table.txt", 4),
    ):
        runs = study._runs(rig)
        lines = study.steady_lines(study.steady_state(runs, 0.3))
        text = table.read_text()
        assert "\n".join(lines[1:]) in text
        assert f"Steady state: {steady} of {len(runs)} runs" in text


def test_convergence_rows_print_a_zero_force_as_zero(committed):
    """The convergence rows of the small tire's study (a spin's forces of 1e-6 fN or less, a
    slide's side force of 1e-16) print 0.0000, not -0.0000; the values are still signed."""
    rows = _study().convergence(RIG, committed.static, 0.3)
    spin = next(r for r in rows if r.startswith("| spin_p | finer mesh |"))
    assert "-0.0000" not in "".join(rows)
    assert "| 0.0000, 0.0000, -0.4953 | -0.0063, -0.0054, -0.4906 |" in spin


# -- runs replaced by their longer or finer-stepped solves ------------------------------------------

XFINE = ROOT / "meshes" / "rig-tire360" / "xfine"


def _copy_run(src: Path, dst: Path, name: str) -> None:
    dst.mkdir(parents=True, exist_ok=True)
    for suffix in (".json", ".vtu"):
        shutil.copyfile(src / f"{name}{suffix}", dst / f"{name}{suffix}")


def test_longer_folders_replace_the_runs_of_their_names():
    study = _study()
    runs = study._runs(XFINE)
    inc05 = XFINE / "inc05"
    out, lines = study.replace_runs(XFINE, runs, [inc05])
    moved = {p.stem for p in study._runs(inc05)}
    assert len(out) == len(runs) == 29 and moved and len(lines) == len(moved)
    for before, after in zip(runs, out, strict=True):
        assert after == (inc05 / before.name if before.stem in moved else before)
    assert "d090_a40p: " in "".join(lines) and "(0.45 m, 31 steps)" in lines[0]


def test_longer_folders_must_share_the_base_and_the_run_names(tmp_path):
    study = _study()
    runs = study._runs(XFINE)
    other = tmp_path / "other"  # a static map of another base: the coarser whole-tire mesh
    shutil.copytree(ROOT / "meshes" / "rig-tire360" / "inc05", other)
    with pytest.raises(ArgumentError, match=r"other: its static.json names another base"):
        study.replace_runs(XFINE, runs, [other])
    same = tmp_path / "same"
    _copy_run(XFINE / "inc05", same, "d090_a40p")
    shutil.copyfile(XFINE / "static.json", same / "static.json")
    # a run in two folders: the last folder's
    out, lines = study.replace_runs(XFINE, runs, [XFINE / "inc05", same])
    assert same / "d090_a40p.vtu" in out and XFINE / "inc05" / "d090_a40p.vtu" not in out
    assert XFINE / "inc05" / "d090_a60p.vtu" in out
    assert sum("d090_a40p" in line for line in lines) == 1 and f"d090_a40p: {same} " in "".join(lines)
    # a run of the rig left out of the selection stays out
    fewer = [r for r in runs if r.stem != "d090_a40p"]
    assert study.replace_runs(XFINE, fewer, [same]) == (fewer, [])
    stranger = tmp_path / "stranger"
    _copy_run(XFINE / "inc05", stranger, "d090_a40p")
    shutil.copyfile(XFINE / "static.json", stranger / "static.json")
    for suffix in (".json", ".vtu"):
        (stranger / f"d090_a40p{suffix}").rename(stranger / f"d090_a99p{suffix}")
    with pytest.raises(ArgumentError, match=r"stranger: run d090_a99p is not one of the runs"):
        study.replace_runs(XFINE, runs, [stranger])
    with pytest.raises(ArgumentError, match=r"nowhere: no readable static.json"):
        study.replace_runs(XFINE, runs, [tmp_path / "nowhere"])
