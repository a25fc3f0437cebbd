"""``fepost sweep`` on a real dask.distributed LocalCluster (2 worker processes).

One cluster serves the whole module (started once; ~3 s). The meshes are small
(12 graded rings, ~500 nodes), so each row takes tens of milliseconds.

Every row must equal the single-file ``fepost coefficients --json`` result of
the same file and step. The two runs are the same computation in different
processes, so they agree to round-off: the tolerance is the identity tier,
1e-12 relative.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fepost.cli import main
from fepost.options import AnalysisOptions
from fepost.report.sweeppage import write_trends
from fepost.sweep import read_table, run_sweep
from fepost.sweep.store import WORK
from fepost.sweep.table import NAMES
from fepost.synthetic import disc_mesh, write_exodus, write_map

distributed = pytest.importorskip("distributed")

#: Identity tier: the same computation in another process.
SAME = 1e-12
#: Columns copied from the --json document's top level and from its "patch".
TOP = ("N", "R", "F0", "M0", "a", "m", "b", "b1", "f", "N_fe", "aR2", "m_over_R2")
PATCH = ("aspect", "circular", "r_equiv")
RINGS = 12
N0, R0 = 1.0e4, 0.05  # reference load (N) and Hertz radius (m)


@pytest.fixture(scope="module")
def cluster():
    import logging

    import dask

    from fepost.sweep.engine import ALLOWED_FAILURES

    with (
        dask.config.set({"distributed.scheduler.allowed-failures": ALLOWED_FAILURES}),
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            silence_logs=logging.ERROR,
        ) as lc,
        distributed.Client(lc) as client,
    ):
        client.run(importlib.import_module, "fepost.analysis")  # warm workers: rows time the analysis only
        yield client


def hertz(path: Path, load: float, *, n_rings: int = RINGS, sidecar: dict | None = None, **kw) -> Path:
    """A Hertz map carrying ``load`` (N): radius ∝ N^(1/3), peak 3N/(2πR²)."""
    radius = R0 * (load / N0) ** (1.0 / 3.0)
    write_map(path, "hertz", radius=radius, peak=3 * load / (2 * math.pi * radius**2), n_rings=n_rings, **kw)
    if sidecar is not None:
        path.with_suffix(".json").write_text(json.dumps(sidecar))
    return path


def single_file(tmp_path: Path, static, *extra: str) -> dict:
    """``fepost coefficients STATIC ... --json`` run in-process; its JSON document."""
    out = tmp_path / f"single-{abs(hash((str(static), extra)))}.json"
    assert main(["coefficients", str(static), *extra, "--json", str(out)]) == 0
    return json.loads(out.read_text())


def assert_row_equals(row: dict, doc: dict) -> None:
    assert row["status"] == "ok", row["error"]
    for k in TOP:
        assert row[k] == pytest.approx(doc[k], rel=SAME), k
    for k in PATCH:
        assert row[k] == pytest.approx(doc["patch"][k], rel=SAME), k
    for k in ("k_x", "x_c"):
        if k in doc:
            assert row[k] == pytest.approx(doc[k], rel=SAME), k
        else:
            assert row[k] is None
    assert row["step"] == doc["static"]["step"]


def comparable(rows):
    """Rows without the wall time, which differs between runs."""
    return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


@pytest.fixture(scope="module")
def load_sweep(tmp_path_factory):
    """Five Hertz maps at loads 0.5–8 × N0 in three formats, with sidecars, plus a rolling pair."""
    d = tmp_path_factory.mktemp("loads")
    loads = [5e3, 1e4, 2e4, 4e4, 8e4]
    files = []
    for i, (load, suffix) in enumerate(zip(loads, [".vtu", ".vtk", ".e", ".vtu", ".vtp"], strict=True)):
        meta = {"case": f"L{i}", "load": load, "deflection": 0.01 * (i + 1), "inflation_pressure": 1.2e6}
        files.append(hertz(d / f"case{i}_static{suffix}", load, sidecar=meta))
    hertz(d / "case3_rolling.vtu", 4e4, k_x=0.15)
    return d, files, loads


def test_table_equals_single_file_json(cluster, load_sweep, tmp_path):
    d, files, loads = load_sweep
    res = run_sweep([str(d / "*_static.*")], tmp_path / "out", client=cluster)
    assert res.ok, [(r["source"], r["error"]) for r in res.rows if r["status"] != "ok"]
    assert res.computed == 5 and res.reused == 0
    assert [r["source"] for r in res.rows] == [str(f) for f in sorted(files)]
    for row in res.rows:
        assert_row_equals(dict(row), single_file(tmp_path, row["source"]))
    # both table files hold the same rows, in this order, every column
    parquet = read_table(res.parquet)
    csv = read_table(res.csv)
    assert comparable(parquet) == comparable(dict(r) for r in res.rows)
    assert [list(r) for r in csv] == [list(NAMES)] * len(csv)
    for a, b in zip(parquet, csv, strict=True):
        for k in NAMES:
            assert (a[k] or None) == (b[k] or None), k  # CSV cannot tell "" from empty
    # sidecar metadata, one value per file
    by_case = {r["case"]: r for r in parquet}
    for i, load in enumerate(loads):
        r = by_case[f"L{i}"]
        assert (r["load"], r["deflection"], r["inflation_pressure"]) == (load, 0.01 * (i + 1), 1.2e6)
    # the Parquet schema carries the units
    import pyarrow.parquet as pq

    schema = pq.read_schema(res.parquet)
    assert schema.field("M0").metadata[b"unit"] == b"N m"


def test_rolling_pairs_rule_and_csv(cluster, load_sweep, tmp_path):
    d, files, _ = load_sweep
    static, rolling = d / "case3_static.vtu", d / "case3_rolling.vtu"
    doc = single_file(tmp_path, static, "--rolling", str(rolling))
    assert doc["k_x"] == pytest.approx(0.15, rel=0.05)  # the map's own shift, O(h) on 12 rings
    # naming rule: the rolling map is consumed, not a row of its own
    res = run_sweep([str(d)], tmp_path / "rule", rolling_pairs="static=rolling", client=cluster)
    assert res.ok, [(r["source"], r["error"]) for r in res.rows if r["status"] != "ok"]
    assert len(res.rows) == 5
    row = next(r for r in res.rows if r["source"].endswith("case3_static.vtu"))
    assert row["rolling"] == str(rolling)
    assert_row_equals(dict(row), doc)
    assert all(r["k_x"] is None for r in res.rows if r is not row)
    # the same pairing from a CSV (paths relative to the CSV's folder)
    pairs = tmp_path / "pairs.csv"
    pairs.write_text(
        f"# static and rolling maps\nstatic,rolling\n{static},{os.path.relpath(rolling, tmp_path)}\n"
    )
    res2 = run_sweep([str(static)], tmp_path / "csv", rolling_pairs=str(pairs), client=cluster)
    assert_row_equals(dict(res2.rows[0]), doc)


def test_bad_files_are_error_rows_and_exit_1(cluster, load_sweep, tmp_path, capsys):
    d, files, _ = load_sweep
    bad = tmp_path / "bad"
    bad.mkdir()
    good = files[1]
    trunc = bad / "truncated.vtu"
    trunc.write_bytes(files[0].read_bytes()[: files[0].stat().st_size // 2])
    (bad / "garbage.e").write_bytes(b"\x89HDF\r\n not an exodus file")
    side = hertz(bad / "badside.vtu", 1e4)
    side.with_suffix(".json").write_text('{"load": "heavy"}')
    out = tmp_path / "out"
    argv = [
        "sweep",
        str(good),
        str(trunc),
        str(bad / "garbage.e"),
        str(side),
        str(files[2]),
        "--out",
        str(out),
        "--scheduler",
        cluster.scheduler.address,
        "--steps",
        "all",
        "--no-progress",
        "--no-trends",
    ]
    assert main(argv) == 1  # finished, some inputs failed: the table marks them
    err = capsys.readouterr().err.strip().splitlines()
    rows = read_table(out / "coefficients.parquet")
    assert [r["status"] for r in rows] == ["ok", "error", "error", "error", "ok"]
    failed = [r for r in rows if r["status"] == "error"]
    expect = [
        f"{trunc}: corrupt or truncated",
        f"{bad / 'garbage.e'}: cannot",
        f"{side.with_suffix('.json')}: sidecar key 'load' must be a finite number, got 'heavy'",
    ]
    for r, start in zip(failed, expect, strict=True):
        assert r["error"].startswith(start), r["error"]
        assert "\n" not in r["error"] and r["N"] is None
        assert f"fepost: error: {r['error']}" in err
    assert_row_equals(rows[0], single_file(tmp_path, good))
    # the same good files alone: exit 0
    assert (
        main(
            [
                "sweep",
                str(good),
                "--out",
                str(tmp_path / "ok"),
                "--scheduler",
                cluster.scheduler.address,
                "--no-progress",
                "--no-trends",
            ]
        )
        == 0
    )


def test_resume_after_sigkill(cluster, tmp_path, monkeypatch):
    """A sweep killed half-way keeps its finished rows; the re-run computes only the rest."""
    d = tmp_path / "runs"
    d.mkdir()
    loads = np.geomspace(5e3, 8e4, 12)
    for i, load in enumerate(loads):
        hertz(d / f"r{i:02d}.vtu", float(load), n_rings=30)  # ~3 000 nodes: rows of ~0.1 s
    out = tmp_path / "out"
    cmd = [
        sys.executable,
        "-m",
        "fepost",
        "sweep",
        str(d),
        "--out",
        str(out),
        "--scheduler",
        cluster.scheduler.address,
        "--no-progress",
        "--no-trends",
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    rows_dir = out / WORK / "rows"
    deadline = time.monotonic() + 60
    try:
        while not (rows_dir.is_dir() and len(list(rows_dir.glob("*.json"))) >= 2):
            assert proc.poll() is None, proc.stderr.read().decode()  # type: ignore[union-attr]
            assert time.monotonic() < deadline, "no row finished within 60 s"
            time.sleep(0.005)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    saved = {p.name: p.stat().st_mtime_ns for p in rows_dir.glob("*.json")}
    assert 2 <= len(saved) < len(loads), "the sweep finished before it was killed"
    assert not (out / "coefficients.parquet").exists()  # nothing half-written
    assert not list(rows_dir.glob(".*"))  # no partial row file
    res = run_sweep([str(d)], out, client=cluster)
    assert (res.reused, res.computed) == (len(saved), len(loads) - len(saved))
    for name, mtime in saved.items():
        assert (rows_dir / name).stat().st_mtime_ns == mtime  # not recomputed
    assert res.ok and len(res.rows) == len(loads)
    fresh = run_sweep([str(d)], tmp_path / "fresh", client=cluster)
    assert comparable(read_table(res.parquet)) == comparable(read_table(fresh.parquet))
    # a re-run of a finished sweep computes nothing and starts no cluster
    with monkeypatch.context() as m:
        m.setattr("fepost.sweep.engine.Cluster._start_local", lambda self: pytest.fail("cluster started"))
        again = run_sweep([str(d)], out, workers=1)
    assert (again.reused, again.computed) == (len(loads), 0)
    # a changed file is a new row; the others are kept
    hertz(d / "r03.vtu", float(loads[3]) * 1.5, n_rings=30)
    changed = run_sweep([str(d)], out, client=cluster)
    assert (changed.reused, changed.computed) == (len(loads) - 1, 1)
    assert changed.rows[3]["N"] == pytest.approx(1.5 * res.rows[3]["N"], rel=1e-9)


def test_exodus_time_steps(cluster, tmp_path):
    """``--steps all``: one row per time step, each equal to ``coefficients --step k``."""
    n = 12
    p2, cells = disc_mesh(RINGS)
    pts = np.column_stack([0.1 * p2, np.zeros(len(p2))])
    r = np.hypot(pts[:, 0], pts[:, 1])
    loads = np.linspace(2e4, 6e4, n)
    data = []
    for load in loads:
        a = 0.1 * (load / loads[-1]) ** (1.0 / 3.0)  # contact radius grows with the load
        p0 = 3 * load / (2 * np.pi * a**2)
        data.append({"CPRESS": p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None))})
    times = list(np.linspace(0.0, 1.1, n))
    series = write_exodus(tmp_path / "ramp.e", pts, cells, data, times=times)
    series.with_suffix(".json").write_text(json.dumps({"load": list(loads), "inflation_pressure": 1.4e6}))
    res = run_sweep([str(series)], tmp_path / "out", steps="all", client=cluster, trends=write_trends)
    assert res.ok, [(r["source"], r["error"]) for r in res.rows if r["status"] != "ok"]
    assert [r["step"] for r in res.rows] == list(range(n))
    assert [r["time"] for r in res.rows] == pytest.approx(times, rel=1e-12)
    assert [r["load"] for r in res.rows] == list(loads)
    for k in (0, 5, n - 1):
        assert_row_equals(dict(res.rows[k]), single_file(tmp_path, series, "--step", str(k)))
    assert (tmp_path / "out" / "trends" / "time_trends.png").is_file()
    # the default is the last step, with its own per-step sidecar value
    last = run_sweep([str(series)], tmp_path / "last", client=cluster)
    assert comparable(last.rows) == comparable([res.rows[-1]])


def test_trends_on_hertz_maps(cluster, load_sweep, tmp_path):
    """Hertz: R ∝ N^(1/3), M0 ∝ N^(4/3), aR² ∝ N^(2/3), m/R² ∝ N^(-2/3).

    The maps are scaled copies of one mesh, so the power laws hold to round-off
    (1e-9 on the exponent), and the fitted intervals must hold the exponents.
    """
    d, files, _ = load_sweep
    out = tmp_path / "out"
    res = run_sweep([str(f) for f in files], out, client=cluster, trends=write_trends)
    fits = {f["quantity"]: f for f in json.loads((out / "trends.json").read_text())["fits"]}
    for q, alpha in (("R", 1 / 3), ("M0", 4 / 3), ("aR2", 2 / 3), ("m_over_R2", -2 / 3)):
        assert fits[q]["exponent"] == pytest.approx(alpha, abs=1e-9), q
        lo, hi = fits[q]["ci95"]
        assert lo <= alpha <= hi, q
        assert fits[q]["n"] == 5 and fits[q]["hertz_exponent"] == pytest.approx(alpha)
    page = (out / "trends.html").read_text()
    assert "load_trends.png" in page and (out / "trends" / "load_trends.png").is_file()
    assert f"{fits['R']['exponent']:.4g}" in page
    assert all(r["source"] in page for r in res.rows)


def test_cli_option_errors(cluster, tmp_path, capsys, monkeypatch):
    f = hertz(tmp_path / "a.vtu", 1e4)
    cases = [
        (["--workers", "0"], "argument --workers: must be a whole number of processes >= 1, got '0'"),
        (["--rolling-pairs", "nonsense"], "--rolling-pairs 'nonsense': expected a naming rule"),
        (["--rolling-pairs", "a=a"], "a naming rule is STATIC=ROLLING"),
        (["--steps", "all", "--step", "2"], "--step N picks one time step of every file"),
        (
            ["--workers", "2", "--scheduler", cluster.scheduler.address],
            "--workers sizes the embedded cluster",
        ),
        (["--friction", "-1"], "argument --friction: must be a friction coefficient in [0.001, 10]"),
    ]
    for extra, message in cases:
        code = main(["sweep", str(f), "--out", str(tmp_path / "o"), *extra])
        err = capsys.readouterr().err
        assert code == 2 and message in err and "Traceback" not in err, (extra, err)
    assert not (tmp_path / "o").exists()
    monkeypatch.setattr("fepost.sweep.engine.CONNECT_TIMEOUT", 1.0)
    assert main(["sweep", str(f), "--out", str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    assert "--scheduler tcp://127.0.0.1:9: cannot connect" in capsys.readouterr().err
    # an output folder that holds something else is refused, a file too
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    for out in (other, tmp_path / "a.vtu"):
        assert main(["sweep", str(f), "--out", str(out)]) == 2
        assert "fepost: error:" in capsys.readouterr().err


def test_options_reach_every_row(cluster, tmp_path):
    f = hertz(tmp_path / "a.vtu", 1e4)
    opts = AnalysisOptions(nr=24, nphi=48, rule="trapezoid")
    res = run_sweep([str(f)], tmp_path / "o", options=opts, friction=0.45, client=cluster)
    doc = single_file(tmp_path, f, "--friction", "0.45", "--nr", "24", "--nphi", "48", "--rule", "trapezoid")
    assert_row_equals(dict(res.rows[0]), doc)
    # other options are other rows: nothing reused
    res2 = run_sweep([str(f)], tmp_path / "o", client=cluster)
    assert (res2.reused, res2.computed) == (0, 1)


def test_report_section_in_process(load_sweep, tmp_path):
    """The report's one call: a sweep on one in-process worker thread, its section and files."""
    from fepost.report.sweepembed import sweep_report_section

    d, files, _ = load_sweep
    html, written = sweep_report_section([str(d / "*_static.vtu")], tmp_path, heading_level=3)
    assert html.lstrip().startswith('<section class="fepost-sweep">') and "<h3>" in html
    assert 'src="sweep/load_trends.png"' in html
    assert set(written) >= {"sweep/coefficients.csv", "sweep/coefficients.parquet", "sweep/load_trends.png"}
    assert all((tmp_path / f).is_file() for f in written)
    assert not (tmp_path / "sweep" / WORK).exists()
    rows = read_table(tmp_path / "sweep" / "coefficients.parquet")
    assert [r["source"] for r in rows] == [str(f) for f in sorted(d.glob("*_static.vtu"))]
    assert all(r["status"] == "ok" for r in rows)


def _crash_on(path: str) -> None:
    """Worker-side: make the analysis of ``path`` kill the worker process (as a reader crash would)."""
    import fepost.analysis

    real = fepost.analysis.analyse

    def analyse(static, *args, **kwargs):
        if str(static) == path:
            os._exit(1)
        return real(static, *args, **kwargs)

    fepost.analysis.analyse = analyse


def test_worker_crash_is_an_error_row(cluster, tmp_path):
    """A file that kills its worker process fails its own row; the sweep itself goes on.

    Runs last in this module: the two workers are restarted by their nannies.
    """
    f = hertz(tmp_path / "crash.vtu", 1e4)
    cluster.run(_crash_on, str(f))
    res = run_sweep([str(f)], tmp_path / "out", client=cluster)
    assert [r["status"] for r in res.rows] == ["error"]
    assert (
        res.rows[0]["error"] == f"{f}: the worker process died while analysing it (a crash, or out of memory)"
    )
    cluster.wait_for_workers(2, timeout=60)


TOTAL_CTRL_C_ROWS = 12


def test_ctrl_c_stops_cleanly(tmp_path):
    """Ctrl-C (SIGINT to the whole process group, as a terminal sends it) on the embedded cluster.

    The client stops with exit status 130 and a one-line hint, the finished rows
    stay saved, no table is written, the workers print no traceback and no
    process is left behind.
    """
    d = tmp_path / "runs"
    d.mkdir()
    for i in range(TOTAL_CTRL_C_ROWS):
        hertz(d / f"r{i:02d}.vtu", 1e4 * (1 + i), n_rings=30)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "fepost", "sweep", str(d), "--out", str(out), "--workers", "1"]
    # A terminal's foreground job starts with Ctrl-C at its default action. A suite started as
    # a background job of a shell (`make test &`) runs with SIGINT ignored, and the sweep would
    # inherit that, rightly ignore the Ctrl-C (as under nohup), finish and exit with 0.
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        proc = subprocess.Popen(
            cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
        )
    finally:
        signal.signal(signal.SIGINT, old)
    rows_dir = out / WORK / "rows"
    deadline = time.monotonic() + 90
    try:
        while not (rows_dir.is_dir() and any(rows_dir.glob("*.json"))):
            assert proc.poll() is None, proc.communicate()[1]
            assert time.monotonic() < deadline, "no row finished within 90 s"
            time.sleep(0.005)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=90)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    assert err.strip().splitlines() == [
        f"fepost: the rows finished so far are kept in {out}: run the same command again to resume",
        "fepost: interrupted",
    ]
    assert 1 <= len(list(rows_dir.glob("*.json"))) < TOTAL_CTRL_C_ROWS
    assert not (out / "coefficients.csv").exists()
    deadline = time.monotonic() + 20  # the workers and multiprocessing's resource tracker wind down
    while left := subprocess.run(["pgrep", "-a", "-g", str(proc.pid)], capture_output=True, text=True).stdout:
        assert time.monotonic() < deadline, f"processes left in the group: {left}"
        time.sleep(0.1)


def test_report_section_provider(tmp_path):
    """The report's optional section: the sweep's table, fits and figures as a report Section."""
    from types import SimpleNamespace

    from fepost.report.html import environment
    from fepost.report.sweepsection import sweep_provider

    d = tmp_path / "aircraft"
    d.mkdir()
    loads = [5e4, 1e5, 2e5, 3e5]
    for load in loads:
        hertz(d / f"static_{load / 2e3:03.0f}.vtu", load, sidecar={"load": load})
    hertz(d / "rolling_100.vtu", 2e5, k_x=0.2)
    inputs = [str(d / "static_*.vtu"), str(d / "rolling_*.vtu")]
    report = tmp_path / "report"
    report.mkdir()
    section = sweep_provider(inputs, "static=rolling")(SimpleNamespace(friction=0.4), report)
    assert section is not None and section.key == "sweep"
    assert section.table[0][:3] == ("case", "load (N)", "N (N)")
    rows = {r[0]: r for r in section.table[1:]}
    assert list(rows) == ["static_025", "static_050", "static_100", "static_150"]  # rolling map paired
    kx = section.table[0].index("k_x")
    assert rows["static_100"][kx] == pytest.approx(0.2, rel=0.05) and rows["static_025"][kx] == "—"
    assert all(r[-1] == "ok" for r in rows.values())
    assert any(p.startswith("R ∝ N^0.333, 95\u202f% interval") for p in section.paragraphs)
    assert "sweep/coefficients.csv" in section.files and "sweep/load_trends.svg" in section.files
    assert all((report / f).is_file() for f in section.files)
    table = read_table(report / "sweep" / "coefficients.parquet")
    assert [r["f"] for r in table] == [0.4] * 4  # the report's friction coefficient
    html = environment().get_template("sections/generic.html.j2").render(section=section)
    assert "data:image/png;base64," in html and "static_150" in html
    # no sample files: no section
    assert sweep_provider([str(tmp_path / "none" / "*.vtu")])(SimpleNamespace(friction=0.3), report) is None
