"""The command-line shell: help, version, light start, option ranges, exit statuses,
warnings at the edge, interruption and closed pipes."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

import fepost
import fepost.cli as cli
import fepost.errors
from fepost.cli import COMMANDS, EXIT_STATUSES, build_parser, main
from fepost.cli import _validate as v
from fepost.synthetic import write_map

ROOT = Path(__file__).resolve().parents[1]
#: Modules that must not be imported to build the parser or to print help.
HEAVY = ("numpy", "scipy", "pyvista", "vtk", "vtkmodules", "matplotlib", "lmfit", "meshio", "netCDF4")


@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    return write_map(tmp_path_factory.mktemp("cli") / "s.vtu", "hertz", radius=0.1, peak=3e5, n_rings=8)


def run(capsys, argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert "Traceback" not in err
    assert len(lines) == 1, lines
    assert lines[0].startswith("fepost: error: ")
    return lines[0]


def subcommands():
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    return sub.choices


# --- help and version ------------------------------------------------------------------


def test_top_level_help_lists_every_command_and_the_exit_statuses(capsys):
    code, out, err = run(capsys, ["--help"])
    assert code == 0 and err == ""
    assert out.startswith("usage: fepost ")
    for name in COMMANDS:
        assert re.search(rf"^\s+{name}\b", out, re.M), name
    for status in EXIT_STATUSES:
        assert re.search(rf"^\s+{status}\s+\S", out, re.M), status


@pytest.mark.parametrize("command", COMMANDS)
def test_every_subcommand_help_renders(capsys, command):
    """argparse %-formats help strings: a stray '%' crashed `fepost --help`."""
    code, out, err = run(capsys, [command, "--help"])
    assert code == 0 and err == ""
    assert out.startswith(f"usage: fepost {command} ")
    assert "%(" not in out and "LibraryDefault" not in out


def test_every_help_string_survives_formatting():
    """Format every action's help on its own (the crash was in one help string)."""
    parsers = [build_parser(), *subcommands().values()]
    for p in parsers:
        formatter = p._get_formatter()
        for action in p._actions:
            if action.help:
                formatter._expand_help(action)  # raises on a lone '%'


def test_version(capsys):
    code, out, err = run(capsys, ["--version"])
    assert code == 0 and err == ""
    assert out.strip() == f"fepost {fepost.__version__}"
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["version"] == fepost.__version__


def test_defaults_shown_in_help_are_the_library_defaults():
    """Help reads heavy modules' constants from their source; the run imports them: same values."""
    seen = 0
    for p in subcommands().values():
        for action in p._actions:
            if isinstance(action.default, v.LibraryDefault):
                assert action.default.literal() == action.default.value, action.dest
                seen += 1
    assert seen >= 5


def test_defaults_resolved_before_the_command_runs(monkeypatch, small_map, capsys):
    seen = {}

    def fake_run(args):
        seen.update(vars(args))
        return 0

    import fepost.cli.table1 as t1

    monkeypatch.setattr(t1, "run", fake_run)
    assert main(["table1", "--static", str(small_map)]) == 0
    from fepost.identify import DEFAULT_AMPLITUDE
    from fepost.polar import DEFAULT_NR
    from fepost.table1 import DEFAULT_SEED

    assert (seen["seed"], seen["amplitude"], seen["nr"]) == (DEFAULT_SEED, DEFAULT_AMPLITUDE, DEFAULT_NR)


def test_table1_without_inputs_uses_the_reports_sample_pair(monkeypatch, tmp_path, capsys):
    """`fepost table1` and `fepost report` without inputs read the same maps (the aircraft
    tire at rated load, static and rolled freely), so the two show the same table."""
    import fepost.analysis
    from fepost.report.samples import sample_inputs

    seen = []

    def fake_analyse(static, rolling, **kwargs):
        seen.append((Path(static), None if rolling is None else Path(rolling)))
        raise KeyboardInterrupt  # stop here: the command's own interrupt path, exit 130

    monkeypatch.setattr(fepost.analysis, "analyse", fake_analyse)
    assert main(["table1"]) == 130
    static, rolling = sample_inputs()
    assert seen == [(static, rolling)]
    assert static.name == "static_100.vtu" and static.parent.name == "aircraft"
    assert rolling is not None and rolling.name == "roll_free.vtu" and rolling.parent.name == "rig-aircraft"


# --- light start -------------------------------------------------------------------------

_PROBE = """
import sys
import fepost, fepost.cli as cli
p = cli.build_parser()
p.format_help()
sub = next(a for a in p._actions if a.dest == "command")
for s in sub.choices.values():
    s.format_help()
heavy = sorted({m.split(".")[0] for m in sys.modules} & set(sys.argv[1:]))
print(",".join(heavy))
"""


def test_building_the_parser_and_all_help_imports_nothing_heavy():
    """Every registered subcommand module must be light at import (run() imports the rest)."""
    r = subprocess.run(
        [sys.executable, "-c", _PROBE, *HEAVY], capture_output=True, text=True, timeout=60, check=True
    )
    assert r.stdout.strip() == "", f"imported while building the parser: {r.stdout.strip()}"


def test_import_fepost_is_light_and_the_api_still_there():
    code = "import sys, fepost; print(any(m.split('.')[0] in sys.argv[1:] for m in sys.modules))"
    r = subprocess.run([sys.executable, "-c", code, *HEAVY], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "False"
    from fepost.analysis import Analysis, analyse

    assert fepost.analyse is analyse and fepost.Analysis is Analysis
    assert "analyse" in dir(fepost)
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        fepost.nope  # noqa: B018


def test_commands_are_registered_from_the_list(monkeypatch):
    """Registering a command is one entry in COMMANDS; each module has add_parser and run."""
    from importlib import import_module

    assert list(subcommands()) == list(COMMANDS)
    for name in COMMANDS:
        module = import_module(f"fepost.cli.{name}")
        assert callable(module.add_parser) and callable(module.run)
    monkeypatch.setattr(cli, "COMMANDS", [c for c in COMMANDS if c != "report"])
    assert "report" not in subcommands()


# --- option ranges -----------------------------------------------------------------------

BAD_OPTIONS = [
    (["--friction", "0"], r"argument --friction: must be a friction coefficient in \[0.001, 10\], got '0'"),
    (["--friction", "-0.3"], r"argument --friction: must be a friction coefficient in .*, got '-0.3'"),
    (
        ["--friction", "nan"],
        r"argument --friction: must be a friction coefficient in \[0.001, 10\], got 'nan'",
    ),
    (
        ["--friction", "inf"],
        r"argument --friction: must be a friction coefficient in \[0.001, 10\], got 'inf'",
    ),
    (["--friction", "high"], r"argument --friction: not a number: 'high'"),
    (["--threshold", "0"], r"argument --threshold: must be a number between 0 and 1 \(exclusive\), got '0'"),
    (["--threshold", "1"], r"argument --threshold: must be a number between 0 and 1"),
    (["--threshold=-1e-3"], r"argument --threshold: must be a number between 0 and 1"),
    (["--nr", "1"], r"argument --nr: must be an integer in \[2, 4096\], got '1'"),
    (["--nr", "64.5"], r"argument --nr: not an integer: '64.5'"),
    (["--nphi", "100000"], r"argument --nphi: must be an integer in \[4, 16384\], got '100000'"),
    (["--nr", "4096", "--nphi", "16384"], r"--nr 4096 x --nphi 16384 = 67,108,864 grid nodes need about"),
    (["--json", ""], r"argument --json: must not be empty"),
    (["--field", " "], r"argument --field: must not be empty"),
    (["--rule", "simpson"], r"argument --rule: invalid choice: 'simpson'"),
    (["--bogus"], r"unrecognized argument '--bogus' \(see 'fepost coefficients --help'\)"),
    (
        ["--frcition", "0.4"],
        r"'--frcition' \(did you mean --friction\?\) \(see 'fepost coefficients --help'\)",
    ),
    (["--nphi=64", "--thresold=0.1"], r"'--thresold=0.1' \(did you mean --threshold\?\)"),
]


@pytest.mark.parametrize(("extra", "message"), BAD_OPTIONS)
def test_bad_options_are_one_line_exit_2(capsys, small_map, tmp_path, extra, message):
    if "16384" in extra and (v._physical_memory() or 0) > 2 * 4096 * 16384 * v.BYTES_PER_GRID_NODE:
        pytest.skip("this machine could hold the largest grid")
    code, out, err = run(capsys, ["coefficients", small_map, *extra])
    assert code == 2 and out == ""
    assert re.search(message, one_error(err))


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["table1", "--seed", "-1"], r"argument --seed: must be an integer >= 0, got '-1'"),
        (["table1", "--seed", "1e3"], r"argument --seed: not an integer: '1e3'"),
        (["table1", "--n-points", "1"], r"argument --n-points: must be an integer in \[2, 1000000\]"),
        (["table1", "--span", "0"], r"argument --span: must be a number in \(0, 100\], got '0'"),
        (["table1", "--span", "1000"], r"argument --span: must be a number in \(0, 100\], got '1000'"),
        (["table1", "--amplitude", "5"], r"argument --amplitude: must be a number in \[0, 2\], got '5'"),
        (["table1", "--k-x", "nan"], r"argument --k-x: must be a number in \[-10, 10\], got 'nan'"),
        (["table1", "--friction", "1e-300"], r"argument --friction: must be a friction coefficient in \["),
        (["report", "--out", "x", "--friction", "11"], r"argument --friction: must be a friction coeff"),
        (["report", "--out", "x", "--seed", "-7"], r"argument --seed: must be an integer >= 0, got '-7'"),
        (["report", "--out", "x", "--inflation-pressure",
         "abc"], r"--inflation-pressure: unknown pressure unit 'abc'"),
        (["report", "--out", "x", "--inflation-pressure",
         "0kPa"], r"--inflation-pressure: must be a positive pressure"),
        (["report", "--out", "x", "--inflation-pressure",
         "1e3GPa"], r"--inflation-pressure: must be a positive pressure up to 1 GPa"),
        (["report"], r"the following arguments are required: --out"),
        (["diagnose", "--simulation", "s.vtu", "--measured", "m.csv", "--out", "o", "--folds", "1"],
         r"argument --folds: must be an integer >= 2, got '1'"),
        (["diagnose", "--simulation", "s.vtu", "--measured", "m.csv", "--out", "o", "--seed", "-2"],
         r"argument --seed: must be an integer >= 0, got '-2'"),
        (["diagnose", "--measured", "m.csv", "--out", "o"], r"arguments are required: --simulation"),
        (["frobnicate"], r"unknown command 'frobnicate' \(see 'fepost --help'\)"),
        (["coefficent", "x.vtu"], r"unknown command 'coefficent' \(did you mean coefficients\?\)"),
        (["sweep", "x", "--out", "o", "--wrokers", "2"], r"--workers\?\) \(see 'fepost sweep --help'\)"),
    ],
)  # fmt: skip
def test_bad_options_of_each_command(capsys, argv, message):
    code, out, err = run(capsys, argv)
    assert code == 2 and out == ""
    assert re.search(message, one_error(err))


def test_implausible_friction_warns_and_runs(capsys, small_map, tmp_path):
    argv = ["coefficients", small_map, "--friction", "3", "--json", tmp_path / "c.json"]
    code, out, err = run(capsys, argv)
    assert code == 0
    assert err.strip() == (
        "fepost: warning (OptionWarning): --friction 3 is above 1.5, implausible for a tire on a road "
        "(dry asphalt about 0.8-1.2); going on with it"
    )
    assert re.search(r"^f\s+3$", out, re.M)
    for ok in ("1.5", "0.01"):
        assert run(capsys, ["coefficients", small_map, "--friction", ok])[0:3:2] == (0, "")


def test_validators_directly():
    import argparse

    assert v.friction("0.3") == 0.3 and v.seed("0") == 0 and v.fraction("0.5") == 0.5
    assert v.integer_in(2)("7") == 7 and v.number_in(0, 10)("10") == 10.0 and v.span("100") == 100.0
    with pytest.raises(argparse.ArgumentTypeError, match="not an integer: '9{10}"):
        v.seed("9" * 5000)  # longer than int() converts: still a one-line refusal
    with pytest.warns(fepost.errors.OptionWarning):
        v.friction("1.6")


# --- exit statuses at the edge -------------------------------------------------------------


def _replace_run(monkeypatch, fn):
    import fepost.cli.coefficients as c

    monkeypatch.setattr(c, "run", fn)


def test_unexpected_exception_is_one_line_exit_3_and_debug_shows_it(monkeypatch, capsys, small_map):
    def boom(args):
        raise ValueError("unexpected\nstate")

    _replace_run(monkeypatch, boom)
    code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 3
    assert one_error(err) == (
        "fepost: error: internal error: ValueError: unexpected state (rerun with --debug and report it)"
    )
    with pytest.raises(ValueError, match="unexpected"):
        main(["--debug", "coefficients", str(small_map)])


def test_os_error_naming_a_file_is_exit_2(monkeypatch, capsys, small_map):
    def denied(args):
        raise PermissionError(13, "Permission denied", "/some/where.vtu")

    _replace_run(monkeypatch, denied)
    code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 2 and one_error(err) == "fepost: error: /some/where.vtu: Permission denied"


def test_long_messages_are_cut_in_the_middle(monkeypatch, capsys, small_map):
    from fepost.errors import DataError

    def long(args):
        raise DataError("data.csv: header " + "x" * 200_000 + " end")

    _replace_run(monkeypatch, long)
    code, _, err = run(capsys, ["coefficients", small_map])
    line = one_error(err)
    assert code == 2 and len(line) <= cli.MESSAGE_MAX + 40
    assert line.startswith("fepost: error: data.csv: header x") and line.endswith("x end")


def test_ctrl_c_is_exit_130(monkeypatch, capsys, small_map):
    def interrupted(args):
        raise KeyboardInterrupt

    _replace_run(monkeypatch, interrupted)
    code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 130 and err == "fepost: interrupted\n"


def test_sigterm_unwinds_with_exit_143_and_restores_the_handler(monkeypatch, capsys, small_map):
    reached = []

    def terminated(args):
        os.kill(os.getpid(), signal.SIGTERM)
        reached.append("after")  # never: the handler raises at once
        return 0

    _replace_run(monkeypatch, terminated)
    before = signal.getsignal(signal.SIGTERM)
    code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 143 and err == "fepost: terminated by SIGTERM\n" and not reached
    assert signal.getsignal(signal.SIGTERM) is before


def test_a_signal_during_an_import_waits_for_the_import_to_finish(monkeypatch, capsys, small_map, tmp_path):
    """Raising inside an import crashes VTK's extension modules (SIGSEGV): the signal is
    recorded, the import completes, and the run stops right after it."""
    (tmp_path / "slow_module_for_signal.py").write_text(
        "import os, signal, time\n"
        "os.kill(os.getpid(), signal.SIGTERM)\n"
        "for _ in range(200):\n"
        "    time.sleep(0.001)  # the handler runs here, inside the import\n"
        "DONE = True\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    reached = []

    def importing(args):
        import time

        import slow_module_for_signal

        reached.append(slow_module_for_signal.DONE)
        time.sleep(5)  # the deferred signal ends the run here
        reached.append("slept")
        return 0

    _replace_run(monkeypatch, importing)
    code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 143 and err == "fepost: terminated by SIGTERM\n"
    assert reached == [True]
    sys.modules.pop("slow_module_for_signal", None)


def test_a_signal_changed_into_another_exception_still_stops_the_run(monkeypatch, capsys, small_map):
    """A library may turn the signal's exception into its own (VTK: an interrupted import
    becomes ImportError, then "cannot read the file"): the exit status follows the signal."""
    from fepost.errors import InputFileError

    def swallowed(args):
        try:
            os.kill(os.getpid(), signal.SIGTERM)
        except BaseException:
            raise InputFileError("map.vtu: cannot read .vtu file (Failed to load vtkIOXML)") from None

    _replace_run(monkeypatch, swallowed)
    code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 143 and err == "fepost: terminated by SIGTERM\n"


# --- warnings at the edge ------------------------------------------------------------------


def _numpy_warning(args):
    np.array([0.0]) / 0.0
    return 0


@pytest.mark.filterwarnings("default::RuntimeWarning")
def test_numpy_warnings_are_not_shown_to_users_but_shown_with_debug(monkeypatch, capsys, small_map):
    _replace_run(monkeypatch, _numpy_warning)
    assert run(capsys, ["coefficients", small_map]) == (0, "", "")
    code, _, err = run(capsys, ["--debug", "coefficients", small_map])
    assert code == 0
    expected = r"fepost: debug: RuntimeWarning at test_cli\.py:\d+: invalid value encountered in divide\n"
    assert re.fullmatch(expected, err)


def test_numpy_warnings_are_defects_under_the_test_suite(monkeypatch, capsys, small_map):
    """pyproject turns RuntimeWarning into an error: at the CLI edge that is exit status 3."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        _replace_run(monkeypatch, _numpy_warning)
        code, _, err = run(capsys, ["coefficients", small_map])
    assert code == 3 and "RuntimeWarning: invalid value encountered in divide" in one_error(err)


def test_real_commands_emit_no_numpy_warning(capsys, small_map, tmp_path):
    """coefficients and table1 on a real map (a numpy warning would be exit status 3 here)."""
    assert run(capsys, ["coefficients", small_map, "--json", tmp_path / "c.json"])[0] == 0
    assert run(capsys, ["table1", "--static", small_map, "--source", "exact"])[0] == 0


# --- the exit-status page ------------------------------------------------------------------


def test_exit_status_page_lists_every_status():
    page = (ROOT / "docs" / "cli-exit-codes.md").read_text()
    for status in EXIT_STATUSES:
        assert re.search(rf"^\| {status} \|", page, re.M), status
    assert "docs/cli-exit-codes.md" in cli._epilog()


# --- real processes: pipes and start-up ----------------------------------------------------


def _fepost(*args, **kw):
    return subprocess.Popen(
        [sys.executable, "-W", "error::RuntimeWarning", "-m", "fepost", *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        **kw,
    )


@pytest.mark.parametrize("argv", [["--help"], ["coefficients", "SMALL"]], ids=["help", "coefficients"])
def test_closed_pipe_is_a_quiet_exit_141(small_map, argv):
    """`fepost ... | head -1` with the reader gone before anything is written."""
    p = _fepost(*[small_map if a == "SMALL" else a for a in argv])
    p.stdout.close()  # the reading end closes first: every write fails with EPIPE
    err = p.stderr.read().decode()
    assert p.wait(timeout=60) == 141
    assert err == ""


def test_pipe_into_head_through_a_shell(small_map):
    fepost_ = f'"{sys.executable}" -m fepost'
    script = f'{fepost_} coefficients "{small_map}" | head -1; echo "status ${{PIPESTATUS[0]}}"'
    r = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=60)
    lines = r.stdout.splitlines()
    assert lines[0].startswith("static map") and lines[-1] in ("status 0", "status 141")
    assert r.stderr == ""


def test_usage_error_in_a_real_process():
    p = _fepost("table1", "--seed", "-1")
    out, err = p.communicate(timeout=60)
    assert p.returncode == 2 and out == b""
    assert err.decode() == (
        "fepost: error: argument --seed: must be an integer >= 0, got '-1' (see 'fepost table1 --help')\n"
    )


@pytest.mark.parametrize(
    ("text", "pa"),
    [
        ("1.38e6", 1.38e6),
        ("1380kPa", 1.38e6),
        ("1.38 MPa", 1.38e6),
        ("13.8bar", 1.38e6),
        # psi from its definition: a pound-force (0.45359237 kg x 9.80665 m/s^2) per square inch
        ("200psi", 200 * 0.45359237 * 9.80665 / 0.0254**2),
    ],
)
def test_inflation_pressure_takes_units(text, pa):
    assert v.pressure(text) == pytest.approx(pa, rel=1e-12)


def test_an_implausible_inflation_pressure_warns():
    with pytest.warns(fepost.errors.OptionWarning, match="a bare number is Pa"):
        assert v.pressure("1.38") == 1.38  # MPa meant, Pa given


@pytest.mark.parametrize("argv", [[], ["--debug"]])
def test_fepost_alone_prints_the_help_as_a_usage_error(capsys, argv):
    """A bare ``fepost`` shows the whole help (on stderr, as argparse's usage errors go) and
    exits 2 as argparse does when the required COMMAND is missing (docs/cli-exit-codes.md)."""
    code, out, err = run(capsys, argv)
    assert code == 2 and out == ""
    assert err.startswith("usage: fepost ") and all(name in err for name in COMMANDS)
    assert "exit status:" in err and "Traceback" not in err


def test_result_objects_have_a_short_repr(small_map, tmp_path):
    from fepost.analysis import analyse

    a = analyse(small_map, small_map)
    text = repr(a)
    assert len(text.splitlines()) == 1 and len(text) < 400
    assert f"N={a.coefficients.N:.6g} N" in text and f"R={a.coefficients.R:.6g} m" in text
    assert "k_x=" in text and "array" not in text


def test_the_parser_is_built_once_per_process(monkeypatch, capsys):
    """Commands run one after the other in one process (a script calling `main`) share one
    parser; `build_parser` still gives a new one (the documentation's reference reads it)."""
    from fepost import cli

    built = []
    real = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: built.append(1) or real())
    for _ in range(3):
        assert main(["--version"]) == 0
    assert len(built) == 1
    assert real() is not real()
