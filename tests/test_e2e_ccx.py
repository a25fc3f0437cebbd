"""End-to-end: mesh with gmsh, solve a coarse tire with CalculiX, export, check.

Marked ``ccx``; skipped when the ``ccx`` executable is not on PATH.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:  # scripts/ is a plain folder (namespace package) at the repo root
    sys.path.insert(0, str(REPO))

HAVE_CCX = shutil.which("ccx") is not None
needs_ccx = pytest.mark.skipif(not HAVE_CCX, reason="CalculiX 'ccx' is not on PATH")


def _integral(vtu) -> float:
    import pyvista as pv

    mesh = pv.read(vtu)
    return float(np.asarray(mesh.integrate_data().point_data["CPRESS"])[0])


@pytest.fixture(scope="module")
def coarse_static(coarse_static_tire):
    """The coarse static tire solved once per session (tests/conftest.py; the .frd tests read
    the same solve): its exported folder and the build's wall time."""
    out, _, elapsed = coarse_static_tire
    return out, elapsed


@pytest.mark.ccx
@pytest.mark.slow
@needs_ccx
def test_coarse_model_cpress_integral_matches_reaction(coarse_static):
    out, elapsed = coarse_static
    side = json.loads((out / "static.json").read_text())
    assert side["reaction_z"] > 0
    assert _integral(out / "static.vtu") == pytest.approx(side["reaction_z"], rel=0.03)
    assert (out / "static.e").stat().st_size > 0
    # budget: well under 3 minutes on 2 cores (measured ~1.5 min on an idle machine)
    assert elapsed < 300


@pytest.mark.ccx
@pytest.mark.slow
@needs_ccx
def test_coarse_model_through_fepost_coefficients(coarse_static, tmp_path, small_accuracy_grid):
    try:
        import fepost.cli.coefficients  # noqa: F401
    except ImportError:
        pytest.skip("fepost coefficients is not available yet")
    from fepost.cli import main

    out, _ = coarse_static
    side = json.loads((out / "static.json").read_text())
    js = tmp_path / "coef.json"
    assert main(["coefficients", str(out / "static.vtu"), "--json", str(js)]) == 0
    res = json.loads(js.read_text())
    assert res["N"] == pytest.approx(side["reaction_z"], rel=0.03)
    assert res["N_fe"] == pytest.approx(side["reaction_z"], rel=0.03)


def test_missing_ccx_one_line_error_and_outputs_untouched(tmp_path, monkeypatch, capsys):
    from scripts.tiremodel.__main__ import main

    out = tmp_path / "meshes"
    out.mkdir()
    keep = out / "static.vtu"
    keep.write_bytes(b"previous result")
    before = {f.name: f.read_bytes() for f in out.iterdir()}
    empty = tmp_path / "bin"
    empty.mkdir()
    monkeypatch.setenv("PATH", str(empty))
    rc = main(["build", "--case", "all", "--coarse", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc != 0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1
    assert "ccx" in lines[0] and "not found" in lines[0]
    assert {f.name: f.read_bytes() for f in out.iterdir()} == before


def test_aircraft_deck_cards(tmp_path):
    """The aircraft-tire deck (coarse mesh, no solve): one orientation per carcass element,
    engineering-constant carcass and Neo-Hooke rubber, amplitudes for pressure and road
    travel, results at the requested times only, y = 0 symmetry and the clamped bead."""
    pytest.importorskip("gmsh")
    from scripts.tiremodel import aircraft_deck as ad
    from scripts.tiremodel.aircraft_geometry import build_aircraft_mesh, coarse_aircraft_params

    mesh = build_aircraft_mesh(coarse_aircraft_params())
    assert np.abs(mesh.nodes[mesh.symmetry_nodes, 1]).max() < 1e-12
    assert mesh.nodes[:, 1].min() > -1e-12  # half model
    # material frames: unit, orthogonal; meridional axis along y on the crown centre line
    np.testing.assert_allclose(np.linalg.norm(mesh.meridian, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", mesh.meridian, mesh.circumferential), 0.0, atol=1e-12)
    stage = ad.Stage(0.1, 0.0, (("half", 0.5), ("end", 1.0)))
    info = ad.write_aircraft_deck(tmp_path / "a.inp", mesh, [stage], residual_tolerance=0.02)
    text = (tmp_path / "a.inp").read_text()
    n_carcass = int((mesh.layer == 1).sum())
    assert text.count("*ORIENTATION, NAME=") == n_carcass
    assert text.count("*ELASTIC, TYPE=ENGINEERING CONSTANTS") == 2
    assert text.count("*HYPERELASTIC, NEO HOOKE") == 2
    assert "*BOUNDARY, AMPLITUDE=AROADZ" in text and "*DLOAD, AMPLITUDE=APRESS" in text
    assert "*CONTROLS, PARAMETERS=FIELD\n0.02" in text
    assert info.output_times == {
        "inflation": ad.INFLATION_TIME,
        "half": ad.INFLATION_TIME + 0.5,
        "end": ad.INFLATION_TIME + 1.0,
    }
    assert "SYMN, 2, 2" in text and "BEAD, 1, 3" in text
    for c in ad.CARCASS.values():
        assert ad.orthotropic_ok(c)
