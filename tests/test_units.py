"""Unit systems: a model in mm-N-MPa or in-lbf-psi gives the SI coefficients; wrong scales are caught."""

import json

import meshio
import numpy as np
import pytest

from fepost import analyse
from fepost.cli import main
from fepost.errors import ArgumentError, InputFileError, ScaleError, ScaleWarning
from fepost.reader import units
from fepost.reader.units import SYSTEMS, unit_system
from fepost.synthetic import write_map

R, PEAK = 0.12, 8.0e5


def _rescaled(tmp_path, name, length, pressure, reaction=None):
    """The same Hertz map written in other units: coordinates / length, pressure / pressure."""
    si = write_map(tmp_path / "si.vtu", "hertz", radius=R, peak=PEAK, n_rings=20, k_x=0.0)
    m = meshio.read(si)
    m.points = m.points / length
    m.point_data["CPRESS"] = m.point_data["CPRESS"] / pressure
    path = tmp_path / name
    meshio.write(path, m)
    if reaction is not None:
        path.with_suffix(".json").write_text(json.dumps({"reaction_z": reaction}))
    return si, path


@pytest.mark.parametrize("system", ["mm-N-MPa", "mm-t-s", "mm-kg-ms", "in-lbf-psi", "cm-g-s", "m-kN-kPa"])
def test_a_model_in_other_units_gives_the_si_coefficients(tmp_path, system):
    s = unit_system(system)
    si, path = _rescaled(tmp_path, "scaled.vtu", s.length, s.pressure)
    ref = analyse(si).coefficients
    got = analyse(path, units=system)
    c = got.coefficients
    for key in ("N", "R", "F0", "M0", "a", "m"):
        assert getattr(c, key) == pytest.approx(getattr(ref, key), rel=1e-9), key
    assert got.to_dict()["units"] == f"{s.name} (given)"


def test_a_model_in_millimetres_read_as_metres_is_refused(tmp_path, capsys):
    _, path = _rescaled(tmp_path, "mm.vtu", 1e-3, 1e6)
    with pytest.raises(
        ScaleError,
        match=r"mm\.vtu: implausible scale for a contact patch: patch radius 120 m is "
        r"outside 1e-05-20 m \(in millimetres\? try --units mm-N-MPa\)",
    ):
        analyse(path)
    assert main(["coefficients", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("fepost: error: ") and "--units" in err[0]
    assert main(["coefficients", str(path), "--units", "mm-N-MPa"]) == 0


def test_absurd_pressures_are_refused(tmp_path):
    path = write_map(tmp_path / "p.vtu", "hertz", radius=R, peak=1e-300, n_rings=10)
    with pytest.raises(ScaleError, match=r"p\.vtu: implausible scale .*peak contact pressure 1e-300 Pa"):
        analyse(path)
    path = write_map(tmp_path / "q.vtu", "hertz", radius=R, peak=1e300, n_rings=10)
    with pytest.raises(
        InputFileError, match=r"q\.vtu: pressure values of 'CPRESS' up to 1e\+300 \(beyond 1e\+30"
    ):
        analyse(path, units="SI")  # not even with units vouched for


def test_explicit_units_turn_the_refusal_into_a_warning(tmp_path):
    path = write_map(tmp_path / "big.vtu", "hertz", radius=40.0, peak=PEAK, n_rings=10)
    with pytest.warns(ScaleWarning, match=r"big\.vtu: implausible scale in SI: patch radius 40 m"):
        a = analyse(path, units="SI")
    assert a.coefficients.R == pytest.approx(40.0, rel=1e-3)


def test_sidecar_reaction_is_converted_and_checked(tmp_path):
    s = unit_system("mm-kN-GPa")
    si, path = _rescaled(tmp_path, "k.vtu", s.length, s.pressure, reaction=None)
    n = analyse(si).static_patch.N_fe
    path.with_suffix(".json").write_text(json.dumps({"reaction_z": n / s.force}))
    a = analyse(path, units=s)
    assert a.static_field.reaction_z == pytest.approx(n, rel=1e-12)
    path.with_suffix(".json").write_text(json.dumps({"reaction_z": n}))  # the sidecar forgot the units
    with pytest.warns(
        ScaleWarning,
        match=r"k\.vtu: N_fe = .* differs from the solver's reaction .* \(a factor 0\.001: "
        r"wrong --units\?\)",
    ):
        analyse(path, units=s)


def test_unit_system_names_and_aliases():
    assert unit_system(None) is None
    assert unit_system("si").is_si and unit_system("m-N-Pa").is_si
    assert unit_system("MM-T-S") is unit_system("mm-N-MPa")
    assert unit_system("mm_kg_ms") is unit_system("mm-kN-GPa")
    gpa = unit_system("mm-kg-ms")
    assert (gpa.length, gpa.force, gpa.pressure, gpa.time) == (1e-3, 1e3, 1e9, 1e-3)
    psi = unit_system("in-lbf-psi")
    assert psi.pressure == pytest.approx(6894.757293168361, rel=1e-15)  # lbf/in² in Pa
    for s in SYSTEMS:  # consistency: pressure = force / length²
        assert s.pressure == pytest.approx(s.force / s.length**2, rel=1e-14), s.name
    with pytest.raises(ArgumentError, match=r"--units: unknown unit system 'furlong'; known: SI, mm-N-MPa"):
        unit_system("furlong")
    assert units.describe(None) == "SI (assumed)"
    assert units.describe(gpa) == "mm-kN-GPa (given)"


def test_unknown_units_on_the_command_line(tmp_path, capsys):
    path = write_map(tmp_path / "m.vtu", "hertz", radius=R, peak=PEAK, n_rings=8)
    assert main(["coefficients", str(path), "--units", "parsec"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [err[0]] and "--units: unknown unit system 'parsec'" in err[0]
    np.testing.assert_equal(len(err), 1)
