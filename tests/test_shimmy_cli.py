"""fepost shimmy: bad gear files refused in one line (exit 2), and the whole command on a sample map."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fepost.cli import main
from fepost.shimmy import GearFileError, load_gear

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "gear_a320_main.json"
STATIC = REPO / "meshes" / "aircraft" / "static_100.vtu"


def _gear(tmp_path, change=None, drop=None, text=None) -> Path:
    data = json.loads(EXAMPLE.read_text())
    if change:
        data.update(change)
    if drop:
        del data[drop]
    p = tmp_path / "gear.json"
    p.write_text(text if text is not None else json.dumps(data))
    return p


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"drop": "lateral_stiffness"}, ["missing key 'lateral_stiffness'"]),
        ({"change": {"trail": -0.1}}, ["trail must be >= 0", "-0.1"]),
        ({"change": {"yaw_inertia": 0}}, ["yaw_inertia must be > 0"]),
        ({"change": {"torsional_stifness": 1e6}}, ["unknown key 'torsional_stifness'"]),
        ({"change": {"slip_ratio": 1.5}}, ["slip_ratio must be in (0, 1]"]),
        ({"change": {"lateral_mass": "700"}}, ["lateral_mass must be a number"]),
        ({"change": {"wheels": 3}}, ["wheels must be 1 or 2"]),
        ({"text": "{not json"}, ["not JSON (line 1"]),
        ({"text": "[1, 2]"}, ["must hold a JSON object"]),
    ],
)
def test_bad_gear_file_one_line_exit_2(tmp_path, capsys, kwargs, words):
    gear = _gear(tmp_path, **kwargs)
    out = tmp_path / "out"
    status = main(["shimmy", str(STATIC), "--gear", str(gear), "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2, err
    assert err.count("\n") == 1 and err.startswith("fepost: error: "), err
    assert str(gear) in err
    for w in words:
        assert w in err, err
    assert not out.exists()
    with pytest.raises(GearFileError):
        load_gear(gear)


def test_missing_gear_file(tmp_path, capsys):
    missing = tmp_path / "nowhere.json"
    assert main(["shimmy", str(STATIC), "--gear", str(missing), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err == f"fepost: error: {missing}: gear file not found\n"


def test_unknown_friction_model_is_a_usage_error(tmp_path, capsys):
    status = main(
        ["shimmy", str(STATIC), "--gear", str(EXAMPLE), "--out", str(tmp_path / "o"), "--models", "hertz"]
    )
    assert status == 2
    assert "--models" in capsys.readouterr().err


def test_example_gear_file_cites_every_parameter():
    from fepost.shimmy.gear import PARAMETERS

    g = load_gear(EXAMPLE)
    assert set(g.sources) == set(PARAMETERS)


def test_shimmy_end_to_end_writes_the_contract(tmp_path, capsys):
    if not STATIC.is_file():
        pytest.skip(f"{STATIC} not shipped")
    out = tmp_path / "shimmy"
    status = main(
        [
            "shimmy",
            str(STATIC),
            "--gear",
            str(EXAMPLE),
            "--out",
            str(out),
            "--models",
            "closed_forms,generalised",
            "--speeds",
            "60",
            "--duration",
            "3",
            "--trails",
            "4",
            "--branch-speeds",
            "3",
        ]
    )
    captured = capsys.readouterr()
    assert status == 0, captured.err
    progress = captured.err.splitlines()
    n = len(progress)
    assert n > 5 and all(line.startswith(f"[{k + 1}/{n}] ") for k, line in enumerate(progress)), progress
    assert "figures" in progress[-1] and "done in" in progress[-1]
    data = json.loads((out / "shimmy.json").read_text())
    assert {"gear", "model", "friction_models", "simulations", "anchor"} <= set(data)
    assert set(data["friction_models"]) == {"closed_forms", "generalised"}
    for name, fm in data["friction_models"].items():
        assert {"critical_speed", "critical_speed_ci95", "frequency_hz", "stability"} <= set(fm), name
        assert {"boundaries", "unstable_ranges"} <= set(fm), name
        onsets = [b["speed"] for b in fm["boundaries"] if b["direction"] == "onset"]
        assert fm["critical_speed"] == onsets[0], "the critical speed is the first onset"
        assert all(set(b) == {"speed", "direction", "frequency_hz"} for b in fm["boundaries"])
        assert fm["unstable_ranges"][0][0] == onsets[0]
        assert len(fm["stability"]) == 60
        assert set(fm["stability"][0]) == {"speed", "growth_rate", "frequency_hz"}
        assert [r["trail"] for r in fm["trail_map"]] == pytest.approx([0.0, 0.1, 0.2, 0.3])
    for row in data["simulations"]:
        assert {"speed", "friction_model", "csv", "verdict", "amplitude"} <= set(row)
        assert row["verdict"] in ("decays", "grows", "limit_cycle")
        assert (out / row["csv"]).is_file()
        assert row["agrees_with_linear"]
    for name, fm in data["friction_models"].items():
        branch = fm["limit_cycle_branch"]
        assert len(branch) == 3 and branch[-1]["verdict"] in ("limit_cycle", "grows"), name
        assert branch[0]["speed"] == pytest.approx(0.8 * fm["critical_speed"]), name
    assert set(data["anchor"]) == {"reference", "published", "computed"}
    assert data["gear"]["trail"] == {"value": 0.1, "unit": "m"}
    for fig in (
        "stability_map.png",
        "eigenvalue_paths.png",
        "time_histories.png",
        "limit_cycle_amplitude.png",
        "stability_plane.png",
        "stability_damping.png",
        "stability_stiffness.png",
        "damping_frequency.png",
        "mode_shapes.png",
    ):
        assert (out / fig).stat().st_size > 1000, fig


def test_report_section_from_a_gear_file(aircraft, tmp_path):
    from types import SimpleNamespace

    from fepost.report.shimmysection import shimmy_section

    assert shimmy_section(SimpleNamespace(analysis=aircraft, gear=None), tmp_path) is None
    section = shimmy_section(SimpleNamespace(analysis=aircraft, gear=str(EXAMPLE)), tmp_path)
    assert section is not None and section.key == "shimmy"
    head, *rows = section.table
    assert [r[0] for r in rows] == ["closed_forms", "generalised", "exact"]
    assert float(rows[0][1]) < float(rows[2][1]), "closed forms below the exact integrals on this tire"
    data = json.loads((tmp_path / "shimmy" / "shimmy.json").read_text())
    assert data["simulations"] == []
    assert (tmp_path / "shimmy_stability.png").is_file()


def test_report_refuses_a_bad_gear_file_before_work(tmp_path, capsys):
    gear = _gear(tmp_path, change={"lateral_damping": -1.0})
    out = tmp_path / "rep"
    assert main(["report", str(STATIC), "--gear", str(gear), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "lateral_damping must be >= 0" in err and str(gear) in err
    assert not out.exists()


def test_speed_range_must_increase(tmp_path, capsys):
    argv = ["shimmy", str(STATIC), "--gear", str(EXAMPLE), "--out", str(tmp_path / "o")]
    assert main([*argv, "--speed-min", "50", "--speed-max", "20"]) == 2
    err = capsys.readouterr().err
    assert err == "fepost: error: argument --speed-max: must be above --speed-min (50), got 20\n"
    assert main([*argv, "--speeds", "1"]) == 2
    assert "--speeds" in capsys.readouterr().err


def test_steady_state_zero_to_round_off_is_a_steady_state(aircraft):
    """The documented commands failed at their defaults: the trail sweep's long trails, on the
    generalised and exact models of a nearly symmetric map, have a steady state of about 1e-18
    that scipy's root finder reports as "not making good progress"; it is a steady state."""
    import numpy as np

    from fepost.shimmy.contact import model_contact
    from fepost.shimmy.equations import equilibrium, rhs

    contact = model_contact(aircraft.model_summary.static)
    gear = load_gear(EXAMPLE)
    for trail in (0.26, 0.28, 0.3):
        g = gear.replace(trail=trail)
        x0 = equilibrium(g, contact)
        assert np.max(np.abs(x0)) < 1e-12, trail
        assert np.max(np.abs(rhs(x0, 1.0, g, contact))) < 1e-9, trail
