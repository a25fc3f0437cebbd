"""The snags a new user met (issue 41): did-you-mean, a renamed Exodus file, P* of the rig
sidecars, the report's notation, colour scale, legends and zeros, numba's cache, the
Makefile's system packages."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
from contextlib import redirect_stderr
from pathlib import Path

import numpy as np
import pytest

from fepost.cli import main

REPO = Path(__file__).resolve().parents[1]
MESHES = REPO / "meshes"


def _run(*argv: str) -> tuple[int, str]:
    err = io.StringIO()
    with redirect_stderr(err):
        code = main(list(argv))
    return code, err.getvalue()


# ---------------------------------------------------------------- did you mean
@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--verison"], "unrecognized argument '--verison' (did you mean --version?)"),
        (["coefficients", "--verison"], "(did you mean --version?) (see 'fepost coefficients --help')"),
        (["coefficients", "--rolling-axs", "1,0,0", "x.vtu"], "(did you mean --rolling-axis?)"),
        (
            ["coefficients", "x.vtu", "--debug"],
            "--debug is an option of fepost itself, not of 'coefficients': put it before the command "
            "('fepost --debug coefficients ...')",
        ),
        (
            ["--json", "a.json", "coefficients", "x.vtu"],
            "--json is an option of 'coefficients': put it after",
        ),
    ],
)
def test_a_misspelt_or_misplaced_option_names_the_right_one(argv, said):
    code, err = _run(*argv)
    assert code == 2
    assert said in err and err.count("\n") == 1, err


def test_known_options_and_their_abbreviations_still_parse(capsys):
    assert main(["--vers"]) == 0  # argparse's unique abbreviation of --version
    assert "fepost" in capsys.readouterr().out


def test_a_misspelt_gear_key_names_the_nearest_one():
    from fepost.shimmy.gear import GearFileError, gear_from_dict

    with pytest.raises(GearFileError, match=r"unknown key 'trial' \(did you mean 'trail'\?\)"):
        gear_from_dict({"trial": 0.1}, "gear.json")
    with pytest.raises(GearFileError, match=r"unknown key 'zzzz' \(known: "):  # nothing near: no guess
        gear_from_dict({"zzzz": 0.1}, "gear.json")


# ---------------------------------------------------------------- a netCDF file under a VTK suffix
@pytest.mark.parametrize("suffix", [".vtu", ".vtk", ".vtp"])
def test_an_exodus_file_renamed_vtk_is_called_netcdf(tmp_path, suffix):
    exodus = MESHES / "static.e"
    assert exodus.is_file(), "committed sample meshes/static.e is missing"
    renamed = tmp_path / f"static{suffix}"
    shutil.copyfile(exodus, renamed)
    code, err = _run("coefficients", str(renamed))
    assert code == 2
    assert f"{renamed}: refused {suffix} file (this is a netCDF file (an Exodus II export?)" in err
    assert "give it the suffix .e or .exo" in err and err.count("\n") == 1


# ---------------------------------------------------------------- P* wherever the sidecar keeps it
def test_inflation_pressure_is_read_from_the_model_block_and_its_source_named():
    import fepost
    from fepost.report.assemble import resolve_inflation_pressure

    static = MESHES / "rig-aircraft" / "static.vtu"
    side = json.loads(static.with_suffix(".json").read_text())
    assert "inflation_pressure" not in side  # only under "model": the case of issue 41
    a = fepost.analyse(static)
    p, source = resolve_inflation_pressure(None, a)
    assert p == side["model"]["inflation_pressure"] == 1.38e6
    assert source == "sidecar static.json, key model.inflation_pressure"
    top = fepost.analyse(MESHES / "aircraft" / "static_100.vtu")
    assert resolve_inflation_pressure(None, top) == (
        1.38e6,
        "sidecar static_100.json, key inflation_pressure",
    )
    assert resolve_inflation_pressure(3e5, a) == (3e5, "option --inflation-pressure")


def test_a_model_block_pressure_is_scaled_with_the_units(tmp_path):
    """A sidecar in the model's units (mm-N-MPa): P* under "model" is converted like a top-level one."""
    from fepost.analysis import analyse
    from fepost.options import AnalysisOptions
    from fepost.report.assemble import resolve_inflation_pressure
    from fepost.synthetic import write_map

    path = write_map(tmp_path / "s.vtu", "hertz", radius=150.0, peak=0.6, n_rings=12)
    (tmp_path / "s.json").write_text(json.dumps({"model": {"inflation_pressure": 1.38}}))
    a = analyse(path, options=AnalysisOptions(units="mm-N-MPa"))
    p, source = resolve_inflation_pressure(None, a)
    assert p == pytest.approx(1.38e6, rel=1e-12) and source.endswith("key model.inflation_pressure")


# ---------------------------------------------------------------- the report's tables
def test_rounding_noise_is_shown_as_zero():
    from fepost.figures.units import number
    from fepost.report.rigsection import shown

    assert number(shown(-3.583e-16)) == "0" and number(shown(-4.85e-13)) == "0"
    assert shown(1.6914e-07) == 1.6914e-07 and shown(-0.5308) == -0.5308


def test_a_sweep_k_x_is_labelled_with_its_rolling_map():
    from fepost.report.sweepsection import TABLE, _cell, _resolved

    keys = [k for k, _ in TABLE]
    assert keys.index("rolling_kind") == keys.index("k_x") + 1  # the label right beside each k_x
    stand_in = MESHES / "aircraft" / "rolling_100.vtu"
    kinds = {_resolved(stand_in): "sliding stand-in"}
    row = {"k_x": 0.240625, "rolling": str(stand_in)}
    assert _cell(row, "k_x", kinds) == 0.240625 and _cell(row, "rolling_kind", kinds) == "sliding stand-in"
    assert _cell({"k_x": None, "rolling": ""}, "rolling_kind", kinds) == "—"
    assert (
        _cell({"k_x": 0.1, "rolling": "other.vtu"}, "rolling_kind", kinds) == "rolling map of unstated kind"
    )


def test_free_text_is_written_in_one_notation():
    from fepost.figures.units import normalise

    assert normalise("k_x = R x_c / <x^2>") == "k_x = R x_c / ⟨x²⟩"
    assert normalise("impossible under sqrt(m) = 2 A2/A3") == "impossible under √m = 2 A2/A3"
    assert normalise("widths scale as 1/sqrt(n): +-9 %") == "widths scale as 1/√n: ±9 %"
    assert normalise("(aR^2, m/R^2 do not); a = 0.052 m^1/2") == "(aR², m/R² do not); a = 0.052 √m"
    assert normalise("theta = F0; sigma_x") == "θ = F0; sigma_x"  # whole words only
    assert (
        normalise("largest |dF|/F0 0.5%, |dMz|/M0 0.8% (0-180 deg)")
        == "largest |ΔF|/F0 0.5%, |ΔMz|/M0 0.8% (0–180°)"
    )


# ---------------------------------------------------------------- Figures 1-2 and the patch plan
@pytest.fixture(scope="module")
def disc(tmp_path_factory):
    from fepost.analysis import analyse
    from fepost.synthetic import write_map

    path = write_map(tmp_path_factory.mktemp("disc") / "s.vtu", "tire", radius=0.15, peak=6e5, n_rings=16)
    return analyse(path)


def test_outlines_are_drawn_above_the_pressure_in_one_colour_scale(disc):
    """The circle, the ellipse and the contact edge are on the layer above the surface (never
    hidden under it); the legend draws line samples; the patch plan's colour range is
    Figure 1's."""
    import matplotlib.pyplot as plt
    import pyvista

    from fepost.figures import plot_patch_plan
    from fepost.figures.patchplan import pressure_colour_range
    from fepost.figures.render import overlay_renderer, pressure_surface

    pyvista.OFF_SCREEN = True
    patch = disc.static_patch
    clim = pressure_colour_range(patch)
    pl = pressure_surface(patch, clim=clim, symbol="σ₀")
    try:
        top = overlay_renderer(pl)
        assert top.GetLayer() == 1 and pl.render_window.GetNumberOfLayers() >= 2
        assert top.GetActiveCamera() is pl.renderer.GetActiveCamera()
        assert top.GetActors().GetNumberOfItems() == 3  # edge, r_max circle, ellipse
        for actor in pl.renderer.GetActors():
            assert not top.HasViewProp(actor)
        props = [
            pl.renderer.GetViewProps().GetItemAsObject(i)
            for i in range(pl.renderer.GetViewProps().GetNumberOfItems())
        ]
        texts = [a.GetInput() for a in props if hasattr(a, "GetInput")]
        assert any(t.startswith("contact edge, σ₀ = 2") for t in texts)
        assert "σ₀/P*" in texts and pl.scalar_bar.GetTitle() == "σ₀ (kPa)"
        lines = [a for a in props if a.IsA("vtkActor2D") and not a.IsA("vtkTextActor") and a.GetMapper()]
        assert len(lines) >= 3  # a line sample per legend entry
        bar_top = pl.scalar_bar.GetLookupTable().GetRange()[1]
    finally:
        pl.close()
    fig = plot_patch_plan(patch, clim=clim)
    mesh = next(c for c in fig.axes[0].collections if c.get_gid() == "pressure")
    assert mesh.get_clim() == (0.0, bar_top) == clim
    assert clim[1] >= patch.values.max() / 1e3
    plt.close(fig)


def test_load_trend_legends_lie_below_their_panels_and_k_x_says_its_maps(tmp_path):
    import matplotlib.pyplot as plt

    from fepost.figures.sweep import plot_load_trends
    from fepost.report.rollinglabel import kind_of_rolling_maps
    from fepost.sweep.trends import load_trends

    loads = [5e4, 1e5, 2e5, 3e5]
    rows = [
        {"status": "ok", "N": n, "R": 0.1 * (n / 1e5) ** 0.4, "M0": 3e3 * (n / 1e5) ** 1.4,
         "aR2": 0.02 * n / 1e5, "m_over_R2": 300 * 1e5 / n, "k_x": 0.24 if n == 2e5 else None}
        for n in loads
    ]  # fmt: skip
    fig = plot_load_trends(rows, load_trends(rows), k_x_kind="sliding stand-in")
    fig.canvas.draw()
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert any(ax.get_title() == "$k_x$ (sliding stand-in)" for ax in panels)
    for ax in panels:
        legend = ax.get_legend()
        if legend is not None:
            assert legend.get_window_extent().y1 < ax.get_window_extent().y0, ax.get_title()
            assert all("-" not in t.get_text().split("$")[-1] for t in legend.get_texts())  # true minus
    plt.close(fig)
    stand_in, rolled = MESHES / "aircraft" / "rolling_100.vtu", MESHES / "rig-aircraft" / "roll_free.vtu"
    assert kind_of_rolling_maps([str(stand_in), str(stand_in)]) == "sliding stand-in"
    assert kind_of_rolling_maps([str(stand_in), str(rolled)]) == "rolling maps of several kinds"
    assert kind_of_rolling_maps([None, ""]) is None


# ---------------------------------------------------------------- numba's cache
def test_numba_caches_outside_the_source_tree(monkeypatch, tmp_path):
    from fepost.friction import compiled

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert compiled.cache_folder() == str(tmp_path / "fepost" / "numba")
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/somewhere/else")
    assert compiled.cache_folder() == "/somewhere/else"
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    numba = pytest.importorskip("numba")
    monkeypatch.setattr(numba.config, "CACHE_DIR", "")
    namespace = {"twice": lambda x: 2 * x}
    compiled.compile_functions(namespace, ("twice",), set())  # compiles lazily: nothing built yet
    assert numba.config.CACHE_DIR == str(tmp_path / "fepost" / "numba")
    assert not Path(numba.config.CACHE_DIR).resolve().is_relative_to(REPO)


# ---------------------------------------------------------------- the Makefile's system packages
def _fake_apt(folder: Path, upgrade: bool) -> Path:
    """A bin folder with apt-get and update-alternatives stand-ins that log their arguments."""
    bin_ = folder / "bin"
    bin_.mkdir()
    log = folder / "apt.log"
    inst = (
        "Inst libglapi-mesa [22.3.6-1+deb12u1] (22.3.6-1+deb12u2 Debian:12 [amd64])"
        if upgrade
        else "Inst fepost-test-package (1.0 Debian:12 [amd64])"
    )
    (bin_ / "apt-get").write_text(
        f'#!/bin/sh\necho "apt-get $*" >> {log}\ncase "$*" in *-s*) echo "{inst}";; esac\n'
    )
    (bin_ / "update-alternatives").write_text(f'#!/bin/sh\necho "update-alternatives $*" >> {log}\n')
    (bin_ / "sudo").write_text('#!/bin/sh\nexec "$@"\n')  # never the real sudo (no password prompt)
    for f in bin_.iterdir():
        f.chmod(0o755)
    return log


@pytest.mark.skipif(
    shutil.which("make") is None or shutil.which("dpkg") is None, reason="needs make and dpkg"
)
@pytest.mark.parametrize(("apt", "upgrade"), [("no", True), ("yes", True), ("yes", False)])
def test_make_never_upgrades_system_packages_unasked(tmp_path, apt, upgrade):
    log = _fake_apt(tmp_path, upgrade)
    env = {**os.environ, "PATH": f"{tmp_path / 'bin'}:{os.environ['PATH']}"}
    proc = subprocess.run(
        [
            "make",
            "-s",
            "-C",
            str(REPO),
            "system-deps-demo",
            "GL_PACKAGES=fepost-no-such-package",
            f"APT={apt}",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    calls = log.read_text() if log.exists() else ""
    assert "system packages needed (make demo): fepost-no-such-package" in proc.stdout
    if apt == "no":
        assert proc.returncode == 0 and calls == ""
        assert "APT=no: not installing the missing fepost-no-such-package" in proc.stdout
    elif upgrade:
        assert proc.returncode != 0 and "install -y" not in calls
        assert "libglapi-mesa 22.3.6-1+deb12u1 -> 22.3.6-1+deb12u2 (UPGRADE" in proc.stdout
        assert "make system-deps-demo APT=no" in proc.stdout
    else:
        assert proc.returncode == 0 and "--no-upgrade fepost-no-such-package" in calls


def test_make_lists_the_system_packages_and_chromium_is_optional():
    if shutil.which("make") is None:
        pytest.skip("needs make")

    def packages(*extra):
        out = subprocess.run(
            ["make", "-s", "-C", str(REPO), "system-packages", *extra],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        return dict(line.split(": ", 1) for line in out.splitlines())

    assert "chromium" in packages()["test"].split() and "libgl1" in packages()["demo"].split()
    assert "chromium" not in packages("CHROMIUM=no")["test"].split()
    assert np.all([p in packages()["test"].split() for p in packages()["demo"].split()])
