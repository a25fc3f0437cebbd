"""Rig recordings: every format read alike, steady holds found, batch-means errors, a hidden cause named."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import signal

from fepost.analysis import analyse
from fepost.cli import main
from fepost.diagnose import diagnose
from fepost.diagnose.holds import HoldRule, batch_means, find_holds
from fepost.diagnose.inputs import load_measured
from fepost.diagnose.measured import write_csv
from fepost.diagnose.recording import Columns
from fepost.diagnose.synthetic import analytic_map, synthesize
from fepost.diagnose.synthetic_recording import synthetic_recording, write_recording
from fepost.errors import ArgumentError, DataError

FORMATS = (".csv", ".parquet", ".mat", ".mat73", ".tdx")
#: The rig's names and units used when writing (the reader maps them back).
NAMES = {"Fx": "FX_kN", "Fy": "FY_kN", "Mz": "MZ_Nm", "time": "RUNTIME", "wz": "YAWRATE"}
FACTORS = {"Fx": 1e3, "Fy": 1e3, "wz": np.pi / 180.0}
UNITS = {"Fx": "kN", "Fy": "kN", "Mz": "Nm", "time": "s", "vx": "m/s", "vy": "m/s", "wz": "deg/s"}
COLUMNS = Columns.parse("Fx=FX_kN,Fy=FY_kN,Mz=MZ_Nm,wz=YAWRATE", "Fx=kN,Fy=kN,wz=deg/s")


@pytest.fixture(scope="module")
def pmap():
    return analytic_map("hertz", 0.1, 3.0e5)


@pytest.fixture(scope="module")
def recording(pmap):
    syn = synthesize(pmap, "friction_level", {"f": 0.27}, n=60, seed=1, noise=0.0)
    return syn, synthetic_recording(syn, sd=(60.0, 60.0, 3.0), rho=0.9, seed=2)


def _write(rec, folder, suffix):
    return write_recording(rec, folder / f"rec{suffix}", names=NAMES, factors=FACTORS, units=UNITS)


def _columns(suffix):
    # TYDEX states its units in the channel table: only the names are mapped
    return Columns(COLUMNS.names, {}) if suffix == ".tdx" else COLUMNS


def test_every_format_gives_the_same_holds(recording, tmp_path):
    syn, rec = recording
    got = {}
    for suffix in FORMATS:
        got[suffix] = find_holds(_write(rec, tmp_path, suffix), _columns(suffix))
    ref = got[".parquet"]
    assert ref.count == len(syn.data)
    # every hold lies inside one test point's hold, none takes a ramp row
    ids = rec["hold_id"]
    for a, b in ref.row_spans:
        assert ids[a] >= 0 and np.all(ids[a : b + 1] == ids[a])
    assert ref.rows_total == ids.size
    assert ref.rows_total - ref.rows_used >= np.count_nonzero(ids < 0)
    for suffix, h in got.items():
        np.testing.assert_allclose(h.data.forces, ref.data.forces, rtol=1e-7, atol=1e-6, err_msg=suffix)
        np.testing.assert_allclose(h.data.wz, ref.data.wz, rtol=1e-7, atol=1e-9, err_msg=suffix)
    # the means are the true forces to within their standard errors (second computation: the generator)
    se, _ = ref.pure_error()
    z = (ref.data.forces - np.asarray(syn.clean)) / se
    assert np.all(np.abs(z) < 5.0)
    assert 0.75 < np.sqrt(np.mean(z**2)) < 1.3


def test_batch_means_account_for_autocorrelation():
    """AR(1) noise, ρ = 0.9: the batch-means SE matches the scatter of hold means (σ/√n does not)."""
    rng = np.random.default_rng(0)
    rho, n = 0.9, 600
    means, ses = [], []
    for _ in range(400):
        x = signal.lfilter([np.sqrt(1 - rho**2)], [1, -rho], rng.normal(size=n + 500))[500:]
        m, se, dof = batch_means(x)
        means.append(m)
        ses.append(se)
        assert dof >= 1
    actual = np.sqrt(np.mean(np.square(means)))
    assert actual == pytest.approx(np.sqrt((1 + rho) / (1 - rho) / n), rel=0.1)  # AR(1) theory
    assert np.sqrt(np.mean(np.square(ses))) == pytest.approx(actual, rel=0.12)
    assert actual > 3 * (1 / np.sqrt(n))  # the naive SE is far too small


def test_point_column_gives_the_rig_holds(recording, tmp_path):
    syn, rec = recording
    rec = dict(rec)
    rec["point"] = np.where(rec["hold_id"] >= 0, rec["hold_id"], np.nan)
    path = write_recording(rec, tmp_path / "p.parquet")
    h = find_holds(path, Columns({"point": "point"}), HoldRule(use_point=True))
    assert h.count == len(syn.data)
    assert h.rows_used == np.count_nonzero(rec["hold_id"] >= 0)
    # without transitions between them, consecutive points are still told apart
    keep = rec["hold_id"] >= 0
    packed = {k: v[keep] for k, v in rec.items()}
    packed["time"] = np.arange(packed["time"].size) / 200.0
    h2 = find_holds(write_recording(packed, tmp_path / "q.parquet"), Columns({"point": "point"}),
                    HoldRule(use_point=True))  # fmt: skip
    assert h2.count == len(syn.data) and h2.rows_used == packed["time"].size
    np.testing.assert_allclose(h2.data.forces, h.data.forces, rtol=1e-12)


@pytest.mark.parametrize("suffix", FORMATS)
def test_hidden_cause_in_a_recording_is_named(pmap, suffix, tmp_path):
    syn = synthesize(pmap, "pressure_dependent_friction", {"c_p": 0.3}, n=60, seed=4, noise=0.0)
    rec = synthetic_recording(syn, sd=(60.0, 60.0, 3.0), rho=0.8, seed=5, hold=2.0, ramp=0.5)
    d = diagnose(pmap, _write(rec, tmp_path, suffix), friction=0.3, columns=_columns(suffix))
    assert d.cause == "pressure_dependent_friction"
    lo, hi = d.parameters["c_p"].ci95
    assert lo < 0.3 < hi
    assert d.holds is not None and d.holds.count == 60
    assert d.to_dict()["holds"]["rows_left_out"] == d.holds.rows_total - d.holds.rows_used
    assert d.lack_of_fit["pure_error_source"] == "scatter within holds"


def test_tables_of_points_stay_tables(pmap, tmp_path):
    syn = synthesize(pmap, "none", {}, n=40, seed=1)
    path = tmp_path / "points.csv"
    write_csv(syn.data, path)
    data, holds = load_measured(path)
    assert holds is None and len(data) == 40
    np.testing.assert_allclose(data.Fx, syn.data.Fx, rtol=1e-9)


def test_bad_recordings_are_one_line_errors(recording, tmp_path):
    _, rec = recording
    path = write_recording(rec, tmp_path / "r.parquet", names={"Fx": "LOADCELL_1"})
    with pytest.raises(DataError, match=r"r\.parquet: no column for Fx .*--columns"):
        find_holds(path)
    with pytest.raises(DataError, match=r"column 'nope' \(given for Fx by --columns\) is not in the file"):
        find_holds(path, Columns({"Fx": "nope"}))
    with pytest.raises(ArgumentError, match=r"--channel-units: unit 'furlong' of Fx is not one of N, kN"):
        Columns.parse("Fx=FX_N", "Fx=furlong")
    with pytest.raises(ArgumentError, match=r"--columns: expected NAME=VALUE pairs"):
        Columns.parse("Fx")
    back = dict(rec)
    back["time"] = rec["time"][::-1].copy()
    bad = write_recording(back, tmp_path / "t.parquet")
    with pytest.raises(DataError, match=r"no steady hold found .*; 47799 clock reset\(s\) cut the recording"):
        find_holds(bad)
    with pytest.raises(DataError, match=r"row 2, column time: time must increase \(--strict-recording\)"):
        find_holds(bad, rule=HoldRule(strict=True))
    ramp = {k: np.linspace(0, 1, 500) for k in ("time", "vx", "vy", "wz", "Fx", "Fy", "Mz")}
    with pytest.raises(DataError, match="no steady hold found"):
        find_holds(write_recording(ramp, tmp_path / "ramp.parquet"))


def test_cli_reads_a_rig_csv_with_its_names_and_units(analytic_mesh, tmp_path, capsys):
    """``fepost diagnose`` on a recording CSV: exit 0, holds in the JSON and the recording figure."""
    static = analytic_mesh("static.vtu", "hertz", radius=0.1, peak=3e5)
    a = analyse(static, friction=0.3)
    syn = synthesize(a.static_map, "friction_level", {"f": 0.27}, n=40, seed=1, noise=0.0)
    rec = synthetic_recording(syn, sd=(60.0, 60.0, 3.0), rho=0.8, seed=2, hold=2.0, ramp=0.5)
    path = _write(rec, tmp_path, ".csv")
    out = tmp_path / "out"
    names, units = "Fx=FX_kN,Fy=FY_kN,Mz=MZ_Nm,wz=YAWRATE", "Fx=kN,Fy=kN,wz=deg/s"
    args = [
        "diagnose",
        "--simulation",
        str(static),
        "--measured",
        str(path),
        "--columns",
        names,
        "--channel-units",
        units,
    ]
    assert main([*args, "--out", str(out)]) == 0
    data = json.loads((out / "diagnosis.json").read_text())
    assert data["holds"]["count"] == 40 and data["cause"] == "friction_level"
    assert data["holds"]["rows_used"] + data["holds"]["rows_left_out"] == rec["time"].size
    assert "recording.png" in data["figures"] and (out / "recording.png").stat().st_size > 1000
    capsys.readouterr()
    bad = [*args[:-1], "Fx=furlong", "--out", str(tmp_path / "o2")]  # the last item is the units
    assert main(bad) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "furlong" in err[0]
    assert not (tmp_path / "o2").exists()
