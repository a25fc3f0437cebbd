"""The sweep's parts that need no cluster: inputs, pairs, sidecars, table, work folder, progress."""

from __future__ import annotations

import io
import json
import math
import os

import pytest

from fepost.errors import ArgumentError, InputFileError, OutputError
from fepost.options import AnalysisOptions, check_friction
from fepost.sweep.inputs import expand_inputs
from fepost.sweep.jobs import Job, run_job
from fepost.sweep.metadata import case_metadata
from fepost.sweep.pairs import pair_sources, parse_rolling_pairs
from fepost.sweep.progress import ProgressBar
from fepost.sweep.steps import time_steps
from fepost.sweep.store import WorkFolder
from fepost.sweep.table import COLUMNS, NAMES, csv_text, normalise, read_table, write_table


def touch(path, text="x"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_expand_files_folders_globs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("runs/b.vtu", "runs/a.e", "runs/notes.txt", "runs/.hidden.vtu", "runs/sub/c.vtu", "x.vtk"):
        touch(tmp_path / name)
    src = expand_inputs(["x.vtk", "runs", "runs/**/*.vtu"])
    # the folder: its FE exports by name, not the sub-folder, not hidden or other files
    assert [s.given for s in src] == ["x.vtk", "runs/a.e", "runs/b.vtu", "runs/sub/c.vtu"]
    assert src[0].path == str(tmp_path / "x.vtk") and src[0].error is None
    # an input naming nothing is a usage error, not a row
    with pytest.raises(ArgumentError, match="^missing.vtu: no such file or folder$"):
        expand_inputs(["x.vtk", "missing.vtu"])
    with pytest.raises(ArgumentError, match=r"^none\*.e: no FE export matches this pattern$"):
        expand_inputs(["none*.e"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(ArgumentError, match="^empty: folder holds no FE exports"):
        expand_inputs(["empty"])
    # one file reached twice is one source, at its first place
    assert [s.given for s in expand_inputs(["runs/b.vtu", "runs", "./runs/b.vtu"])] == [
        "runs/b.vtu",
        "runs/a.e",
    ]


def test_rolling_pairs_rule(tmp_path):
    for name in ("c1_static.vtu", "c1_rolling.vtu", "c2_static.vtu", "other.vtu"):
        touch(tmp_path / name)
    src = expand_inputs([str(tmp_path)])
    pairs = pair_sources(src, parse_rolling_pairs("static=rolling"))
    got = {os.path.basename(p.static.given): p.rolling and os.path.basename(p.rolling) for p in pairs}
    # the rolling map is consumed; c2 has no partner and other.vtu no token: static-only rows
    assert got == {"c1_static.vtu": "c1_rolling.vtu", "c2_static.vtu": None, "other.vtu": None}
    with pytest.raises(ArgumentError, match="no input has a rolling partner"):
        pair_sources(src, parse_rolling_pairs("stat=roll"))
    for bad in ("=rolling", "static=", "a=a", "a/b=c", "nonsense"):
        with pytest.raises(ArgumentError, match="--rolling-pairs"):
            parse_rolling_pairs(bad)


def test_rolling_pairs_csv(tmp_path):
    s1, r1 = touch(tmp_path / "m/s1.vtu"), touch(tmp_path / "m/r1.vtu")
    csv = tmp_path / "m/pairs.csv"
    csv.write_text("# pairs\n\nstatic,rolling,comment\ns1.vtu,r1.vtu,rated load\n")
    pairs = pair_sources(expand_inputs([str(tmp_path / "m")]), parse_rolling_pairs(str(csv)))
    assert [(p.static.path, p.rolling) for p in pairs] == [(str(s1), str(r1))]
    for text, message in (
        ("", "empty CSV"),
        ("a,b\nx,y\n", "the header must name the columns static and rolling"),
        ("static,rolling\ns1.vtu\n", "data row 1 lacks a static or rolling path"),
        ("static,rolling\nnope.vtu,r1.vtu\n", "no such static file"),
        ("static,rolling\ns1.vtu,r1.vtu\ns1.vtu,r2.vtu\n", "is paired twice"),
    ):
        csv.write_text(text)
        with pytest.raises(ArgumentError, match=message):
            parse_rolling_pairs(str(csv))
    with pytest.raises(ArgumentError, match="cannot read"):
        parse_rolling_pairs(str(tmp_path / "absent.csv"))


def test_sidecar_metadata():
    assert case_metadata(None) == {"case": None, "load": None, "deflection": None, "inflation_pressure": None}
    side = {"case": 7, "reaction_z": 1.5e5, "deflection": 0.04, "inflation_pressure": 1.2e6, "other": "x"}
    assert case_metadata(side) == {
        "case": "7",
        "load": 1.5e5,
        "deflection": 0.04,
        "inflation_pressure": 1.2e6,
    }
    assert case_metadata({"load": 2.0e5, "reaction_z": 1.9e5})["load"] == 2.0e5  # a prescribed load wins


def _ramp(tmp_path, sidecar):
    """A 3-step Exodus map beside ``sidecar`` (text)."""
    import numpy as np

    from fepost.synthetic import disc_mesh, write_exodus

    p, c = disc_mesh(8)
    pts = np.column_stack([p, np.zeros(len(p))])
    r2 = (p**2).sum(axis=1)
    e = write_exodus(
        tmp_path / "ramp.e",
        pts,
        c,
        [{"CPRESS": k * 1e5 * np.clip(1.0 - r2, 0.0, None)} for k in (1, 2, 3)],
        times=[0.0, 0.5, 1.0],
    )
    e.with_suffix(".json").write_text(sidecar)
    return e


def test_per_step_sidecar_lists_are_resolved_by_the_reader_at_the_step_read(tmp_path):
    """Every number key may list one value per time step: the reader gives the step's value
    (also the report's inflation pressure and the solver reaction N is compared with)."""
    from fepost.reader import read_contact

    e = _ramp(
        tmp_path,
        json.dumps(
            {
                "case": "ramp",
                "load": [1.0e4, 2.0e4, 3.0e4],
                "reaction_z": [0.9e4, 1.9e4, 2.9e4],
                "inflation_pressure": [1.0e6, 1.1e6, 1.2e6],
                "deflection": 0.04,
            }
        ),
    )
    for step in (0, 1, 2):
        field = read_contact(e, step=step)
        assert field.reaction_z == [0.9e4, 1.9e4, 2.9e4][step]
        assert case_metadata(field.sidecar) == {
            "case": "ramp",
            "load": [1.0e4, 2.0e4, 3.0e4][step],
            "deflection": 0.04,
            "inflation_pressure": [1.0e6, 1.1e6, 1.2e6][step],
        }
    assert read_contact(e).sidecar["load"] == 3.0e4  # no step given: the last one
    for text, message in (
        ('{"load": [1, 2]}', r"ramp\.json: 'load' lists 2 values but .*ramp\.e has 3 time steps"),
        (
            '{"deflection": "large"}',
            r"ramp\.json: sidecar key 'deflection' must be a finite number, got 'large'",
        ),
        ('{"load": true}', r"sidecar key 'load' must be a finite number"),
        ('{"load": [1, true, 3]}', r"sidecar key 'load' must be a finite number or a non-empty list"),
        ('{"load": []}', r"sidecar key 'load' must be a finite number or a non-empty list"),
        ('{"load": 1e999}', r"unreadable sidecar JSON|must be a finite number"),
        ("[1, 2]", r"sidecar JSON must be an object"),
        ("{oops", r"unreadable sidecar JSON"),
    ):
        e.with_suffix(".json").write_text(text)
        with pytest.raises(InputFileError, match=message):
            read_contact(e, step=0)


def test_per_step_sidecar_list_beside_a_file_without_steps(analytic_mesh):
    from fepost.reader import read_contact

    f = analytic_mesh("one.vtu")
    f.with_suffix(".json").write_text('{"load": [1, 2]}')
    with pytest.raises(InputFileError, match=r"'load' lists 2 values but .*one\.vtu has no time steps"):
        read_contact(f)


def test_time_steps_adapter(tmp_path):
    import numpy as np

    from fepost.synthetic import disc_mesh, write_exodus

    assert time_steps(touch(tmp_path / "a.vtu")) is None  # not a series
    p, c = disc_mesh(4)
    pts = np.column_stack([p, np.zeros(len(p))])
    e = write_exodus(
        tmp_path / "s.e",
        pts,
        c,
        [{"CPRESS": np.ones(len(p)) * k} for k in range(4)],
        times=[0.0, 0.5, 1.25, 2.0],
    )
    assert time_steps(e) == (0.0, 0.5, 1.25, 2.0)
    with pytest.raises(InputFileError, match="empty file"):
        time_steps(touch(tmp_path / "z.e", ""))
    with pytest.raises(InputFileError, match="no such file"):
        time_steps(tmp_path / "absent.exo")


def test_table_csv_round_trip_and_types(tmp_path):
    row = {
        "source": "a.vtu",
        "status": "ok",
        "N": 0.1 + 0.2,
        "R": 1e-300,
        "circular": True,
        "step": 3,
        "time": math.nan,
        "k_x": None,
    }
    norm = normalise(row)
    assert list(norm) == list(NAMES)
    assert norm["time"] is None and norm["k_x"] is None and norm["error"] == "" and norm["rolling"] == ""
    err = normalise({"source": "b.e", "status": "error", "error": "b.e: broken"})
    parquet, csv = write_table([norm, err], tmp_path)
    back_p, back_c = read_table(parquet), read_table(csv)
    assert back_p[0]["N"] == 0.1 + 0.2 and back_c[0]["N"] == 0.1 + 0.2  # exact round trip
    assert back_c[0]["circular"] is True and back_c[0]["step"] == 3 and back_c[1]["N"] is None
    assert csv_text([norm]).splitlines()[0] == ",".join(NAMES)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left
    assert {c.kind for c in COLUMNS} == {"str", "int", "float", "bool"}


def test_error_job_and_one_line_messages():
    job = Job("x*.vtu", None, None, AnalysisOptions(), error="x*.vtu: no FE export\nmatches  this")
    row = run_job(job)
    assert row["status"] == "error" and row["error"] == "x*.vtu: no FE export matches this"


def test_row_identity_follows_inputs_and_options(tmp_path):
    f = touch(tmp_path / "a.vtu")
    base = Job("a.vtu", str(f), None, AnalysisOptions())
    assert base.key() == Job("a.vtu", str(f), None, AnalysisOptions()).key()
    assert base.key() != Job("a.vtu", str(f), 2, AnalysisOptions()).key()
    assert base.key() != Job("a.vtu", str(f), None, AnalysisOptions(), friction=0.5).key()
    assert base.key() != Job("a.vtu", str(f), None, AnalysisOptions(units="mm-N-MPa")).key()
    assert base.key() != Job("a.vtu", str(f), None, AnalysisOptions(allow_load_mismatch=True)).key()
    # the options' step is the job's business: it does not make another row
    assert base.key() == Job("a.vtu", str(f), None, AnalysisOptions(step=3)).key()
    before = base.key()
    os.utime(f, ns=(1, 1))
    assert base.key() != before  # the file changed
    no_side = base.key()
    f.with_suffix(".json").write_text("{}")
    with_side = base.key()
    assert with_side != no_side  # a sidecar appeared
    f.with_suffix(".json").write_text('{"load": 1}')
    assert base.key() != with_side  # the sidecar changed


def test_analysis_options_validated():
    bad = (
        {"rule": "simpson"}, {"nr": 1}, {"threshold": 1.5}, {"units": "furlongs"}, {"field": ""},
        {"rolling_axis": (0, 0, 0)}, {"rolling_axis": (1, 2)}, {"allow_load_mismatch": "yes"},
        {"inflation_pressure": -1.0}, {"inflation_pressure": math.inf}, {"step": 1.5},
    )  # fmt: skip
    for kw in bad:
        with pytest.raises(ArgumentError):
            AnalysisOptions(**kw)
    for f in (0, math.nan, True, 11.0, "0.3"):
        with pytest.raises(ArgumentError, match=r"friction coefficient in \[0.001, 10\]"):
            check_friction(f)
    assert check_friction(0.001) == 0.001 and check_friction(10) == 10.0


def test_work_folder_lock_and_refusals(tmp_path):
    out = tmp_path / "out"
    with WorkFolder(out) as w:
        w.save_row("k", {"status": "ok", "N": 1.0})
        assert w.load_row("k") == {"status": "ok", "N": 1.0}
        with pytest.raises(OutputError, match="another fepost sweep is writing into this folder"):
            WorkFolder(out).__enter__()
    with WorkFolder(out) as w:  # released
        assert w.load_row("k") is not None
        w.row_path("bad").write_text("{trunc")
        assert w.load_row("bad") is None  # unreadable: recomputed
    with WorkFolder(out, fresh=True) as w:
        assert w.load_row("k") is None
    other = tmp_path / "other"
    touch(other / "mine.txt")
    with pytest.raises(OutputError, match="holds other files than an earlier sweep"):
        WorkFolder(other).__enter__()
    with WorkFolder(other, force=True):
        pass
    with pytest.raises(OutputError, match="exists and is not a folder"):
        WorkFolder(other / "mine.txt").__enter__()


def test_progress_bar_draws_only_when_asked():
    buf = io.StringIO()
    bar = ProgressBar(4, done=1, stream=buf, enabled=True)
    for ok in (True, False, True, True):
        bar.update(ok)
    bar.close()
    last = buf.getvalue().rstrip("\n").split("\r")[-1]
    assert last.startswith("[" + "#" * ProgressBar.width + "] 5/5 rows  1 error")
    quiet = io.StringIO()  # not a terminal: nothing drawn
    bar = ProgressBar(3, stream=quiet)
    bar.update(True)
    bar.close()
    assert quiet.getvalue() == ""


def test_the_single_file_options_reach_the_rows():
    """``AnalysisOptions.make`` takes the keyword arguments ``analyse`` takes; every one reaches
    the rows and their identity."""
    from fepost.polar import PolarGrid

    kwargs = {
        "field": "CPRESS:0",
        "displacement": None,
        "grid": PolarGrid.make(16, 32, "trapezoid"),
        "threshold": 1e-4,
        "rolling_axis": (0.0, 1.0, 0.0),
        "units": "mm-N-MPa",
    }
    o = AnalysisOptions.make(**kwargs)
    assert o.grid.shape == (16, 32) and o.grid.rule == "trapezoid"
    assert o.reading()["units"].name == "mm-N-MPa" and o.displacement is None
    assert o.to_dict() == {
        "field": "CPRESS:0", "step": None, "displacement": None, "units": "mm-N-MPa", "surface": None,
        "nr": 16, "nphi": 32, "rule": "trapezoid", "threshold": 1e-4, "rolling_axis": [0.0, 1.0, 0.0],
        "allow_load_mismatch": False, "inflation_pressure": None,
    }  # fmt: skip
    assert Job("a", "/a", None, o).key() != Job("a", "/a", None, AnalysisOptions.make(o, units="SI")).key()
    # a change to None keeps the value (a caller passing its own defaults), except displacement
    assert AnalysisOptions.make(o, field=None) == o
    assert AnalysisOptions.make(displacement=None).displacement is None
    with pytest.raises(ArgumentError, match="unknown analysis option 'friction'"):
        AnalysisOptions.make(friction=1.0)
    assert repr(AnalysisOptions()) == "AnalysisOptions()"
    assert repr(AnalysisOptions(units="mm-N-MPa")) == "AnalysisOptions(units='mm-N-MPa')"


def test_workers_must_run_this_fepost():
    """A cluster whose workers lack fepost, or run another version, is refused before any row."""
    from fepost import __version__
    from fepost.errors import ClusterError
    from fepost.sweep.engine import Cluster

    class FakeClient:
        def __init__(self, versions):
            self.versions = versions

        def get_versions(self, packages):
            assert packages == ["fepost"]
            return {"workers": {addr: {"packages": {"fepost": v}} for addr, v in self.versions.items()}}

    Cluster._check_workers(FakeClient({"tcp://a:1": __version__, "tcp://b:1": __version__}))
    with pytest.raises(ClusterError, match="Dask worker tcp://b:1 cannot import fepost"):
        Cluster._check_workers(FakeClient({"tcp://a:1": __version__, "tcp://b:1": None}))
    with pytest.raises(
        ClusterError, match=f"Dask worker tcp://a:1 runs fepost 0.0.1, this client {__version__}"
    ):
        Cluster._check_workers(FakeClient({"tcp://a:1": "0.0.1"}))
    for bad in (0, -2, 1.5, True):
        with pytest.raises(ArgumentError, match="--workers must be a positive whole number"):
            Cluster(workers=bad)
