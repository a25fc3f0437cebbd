"""``fepost predict`` and its API (fepost.friction.predict), and the model in ``coefficients``.

Inputs: the CalculiX samples in meshes/ (static, and the rolling stand-in).
Each output column is checked against an independent call of the function it
claims to be (exact integrals, closed forms, the model rebuilt from its JSON).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from fepost.analysis import analyse
from fepost.cli import main
from fepost.errors import DataError
from fepost.friction.closed_form import components
from fepost.friction.exact import friction_resultants
from fepost.friction.law import FrictionLaw
from fepost.friction.model import GeneralisedModel
from fepost.friction.predict import OUTPUT_COLUMNS, parse_kinematics, predict
from fepost.friction.quadrature import PressureQuadrature

MESHES = Path(__file__).resolve().parents[1] / "meshes"
STATIC, ROLLING = MESHES / "static.vtu", MESHES / "rolling.vtu"
GOAL = 0.03


@pytest.fixture(scope="module")
def kin_csv(tmp_path_factory):
    rng = np.random.default_rng(4)
    n = 40
    vx, vy = rng.normal(0, 1.0, (2, n))
    wz = rng.normal(0, 15.0, n)
    vx[:3], vy[:3] = 0.0, 0.0  # pure spin
    wz[3:6] = 0.0  # pure sliding
    path = tmp_path_factory.mktemp("kin") / "kin.csv"
    lines = ["# kinematics for fepost predict", "t,wz,vy,vx,comment", ""]
    lines += [f"{i},{float(wz[i])!r},{float(vy[i])!r},{float(vx[i])!r},row{i}" for i in range(n)]
    path.write_text("\n".join(lines) + "\n")
    return path, vx, vy, wz


@pytest.fixture(scope="module")
def rolling_run(kin_csv, tmp_path_factory):
    d = tmp_path_factory.mktemp("out")
    out, js = d / "pred.csv", d / "model.json"
    code = main(
        [
            "predict",
            str(STATIC),
            "--rolling",
            str(ROLLING),
            "--kinematics",
            str(kin_csv[0]),
            "--out",
            str(out),
            "--model-json",
            str(js),
        ]
    )
    assert code == 0
    return out, js


def _read(path):
    with open(path) as fh:
        rows = list(csv.reader(fh))
    return rows[0], np.array(rows[1:], float)


def test_columns_rows_and_each_model(rolling_run, kin_csv):
    out, js = rolling_run
    _, vx, vy, wz = kin_csv
    header, table = _read(out)
    assert tuple(header) == OUTPUT_COLUMNS
    col = {h: table[:, i] for i, h in enumerate(header)}
    np.testing.assert_array_equal(col["vx"], vx)  # same rows, same order, exact values
    np.testing.assert_array_equal(col["vy"], vy)
    np.testing.assert_array_equal(col["wz"], wz)
    an = analyse(STATIC, ROLLING)
    c = an.coefficients
    ex = friction_resultants(PressureQuadrature.from_polar(an.rolling_map), vx, vy, wz, FrictionLaw(f=c.f))
    for q in ("Fx", "Fy", "Mz"):
        np.testing.assert_allclose(col[f"{q}_exact"], getattr(ex, q), rtol=1e-12, atol=1e-9)
    pfx, pfy, pmz = components(vx, vy, wz, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=c.k_x, radius=c.R)
    np.testing.assert_allclose(col["Fx_paper"], pfx, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(col["Fy_paper"], pfy, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(col["Mz_paper"], pmz, rtol=1e-12, atol=1e-9)
    model = GeneralisedModel.from_json(js.read_text())
    mfx, mfy, mmz = model(vx, vy, wz)
    np.testing.assert_allclose(col["Fx_model"], mfx, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(col["Fy_model"], mfy, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(col["Mz_model"], mmz, rtol=1e-12, atol=1e-9)
    # the generalised model is close to the exact integrals, the paper's forms are not
    err_model = np.max(np.hypot(col["Fx_model"] - col["Fx_exact"], col["Fy_model"] - col["Fy_exact"]))
    err_paper = np.max(np.hypot(col["Fx_paper"] - col["Fx_exact"], col["Fy_paper"] - col["Fy_exact"]))
    assert err_model <= GOAL * model.F0 < err_paper
    assert np.max(np.abs(col["Mz_model"] - col["Mz_exact"])) <= GOAL * model.M0


def test_without_rolling_the_static_map_is_used(kin_csv, tmp_path):
    path, vx, vy, wz = kin_csv
    an = analyse(STATIC)
    law = FrictionLaw(f=an.coefficients.f)
    pred = predict(vx[:8], vy[:8], wz[:8], pmap=an.static_map, coefficients=an.coefficients, law=law)
    assert pred.map == "static"
    ex = friction_resultants(PressureQuadrature.from_polar(an.static_map), vx[:8], vy[:8], wz[:8])
    np.testing.assert_allclose(pred.exact.Mz, ex.Mz, rtol=1e-12)
    c = an.coefficients
    _, pfy, _ = components(vx[:8], vy[:8], wz[:8], F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=0.0, radius=c.R)
    np.testing.assert_allclose(pred.paper.Fy, pfy, rtol=1e-12)


def test_coefficients_prints_the_generalised_model(capsys, tmp_path):
    js = tmp_path / "c.json"
    assert main(["coefficients", str(STATIC), "--json", str(js)]) == 0
    out = capsys.readouterr().out
    assert "generalised model" in out and "a along x, y" in out and "use  " in out
    d = json.loads(js.read_text())
    for key in ("N", "R", "F0", "M0", "a", "m", "b", "b1", "f", "patch"):  # contract keys untouched
        assert key in d
    model = GeneralisedModel.from_dict(d["model"]["static"])
    assert model.F0 == pytest.approx(d["F0"], rel=1e-9)
    assert model.M0 == pytest.approx(d["M0"], rel=1e-9)
    assert "recommendation" in d["model"] and d["model"]["rolling"] is None


BAD = [
    ("vx,vy\n1,2\n", "missing column(s) wz in the header"),
    ("vx,vy,wz\n1,2,abc\n", "line 2, column wz: not a number: 'abc'"),
    ("vx,vy,wz\n1,2,3\n1,nan,3\n", "line 3, column vy: not a finite number: 'nan'"),
    ("vx,vy,wz\n1,2\n", "line 2, column wz: missing"),
    ("# only a comment\n\n", "no header row"),
    ("vx,vy,wz\n", "no data rows after the header"),
    ("vx,vx,vy,wz\n1,2,3,4\n", "column 'vx' appears twice"),
    ("vx,vy,wz\n1,,3\n", "line 2, column vy: not a number: 'an empty cell'"),
]


@pytest.mark.parametrize("text,message", BAD)
def test_bad_kinematics_one_line_exit_2_nothing_written(text, message, tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text(text)
    out = tmp_path / "out.csv"
    code = main(["predict", str(STATIC), "--kinematics", str(bad), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err.count("\n") == 0 and str(bad) in err and message in err, err
    assert not out.exists()


def test_missing_binary_and_unwritable(tmp_path, capsys, kin_csv):
    out = tmp_path / "out.csv"
    assert main(["predict", str(STATIC), "--kinematics", str(tmp_path / "nope.csv"), "--out", str(out)]) == 2
    assert "no such file" in capsys.readouterr().err
    binary = tmp_path / "bin.csv"
    binary.write_bytes(b"vx,vy,wz\n\x00\x01\x02\n")
    assert main(["predict", str(STATIC), "--kinematics", str(binary), "--out", str(out)]) == 2
    assert "binary" in capsys.readouterr().err
    code = main(
        ["predict", str(STATIC), "--kinematics", str(kin_csv[0]), "--out", str(tmp_path / "no" / "o.csv")]
    )
    err = capsys.readouterr().err
    assert code == 2 and "does not exist" in err and err.count("\n") == 1
    assert not out.exists() and list(tmp_path.glob(".*tmp")) == []


def test_parse_kinematics_api():
    k = parse_kinematics("vx,vy,wz\r\n1,2,3\r\n\r\n# c\r\n4,5,6\r\n", source="mem")
    np.testing.assert_array_equal(k.vx, [1.0, 4.0])
    np.testing.assert_array_equal(k.lines, [2, 5])
    with pytest.raises(DataError, match="^mem: line 2, column vx"):
        parse_kinematics("vx,vy,wz\ninf,0,0\n", source="mem")
