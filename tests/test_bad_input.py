"""Bad input to `fepost coefficients`: one line on stderr naming the file and the
problem, exit status 2, no traceback, no JSON written."""

import json
import re

import meshio
import numpy as np
import pytest

from fepost.cli import main
from fepost.synthetic import disc_mesh, write_map


def run_bad(capsys, tmp_path, args, pattern):
    out = tmp_path / "out.json"
    code = main(["coefficients", *map(str, args), "--json", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    errors = [line for line in err if line.startswith("fepost: error:")]
    assert code == 2
    assert len(errors) == 1, err
    assert "Traceback" not in "\n".join(err)
    assert re.search(pattern, errors[0]), errors[0]
    assert not out.exists()
    assert not list(tmp_path.glob(".out.json*"))
    return errors[0]


def disc(path, values_fn=None, z_fn=None, field="CPRESS", extra=None, location="point"):
    p2, tri = disc_mesh(12)
    p2 = 0.1 * p2
    z = np.zeros(len(p2)) if z_fn is None else z_fn(p2)
    val = 1e5 * (1 - (p2**2).sum(1) / 0.01) if values_fn is None else values_fn(p2)
    pd = {field: val} if location == "point" else {}
    cd = {field: [val[tri].mean(axis=1)]} if location == "cell" else {}
    pd.update(extra or {})
    meshio.write(
        path, meshio.Mesh(np.column_stack([p2, z]), [("triangle", tri)], point_data=pd, cell_data=cd)
    )
    return path


def test_missing_file(capsys, tmp_path):
    run_bad(capsys, tmp_path, [tmp_path / "nope.vtu"], r"nope\.vtu: no such file")


def test_unknown_suffix(capsys, tmp_path):
    p = tmp_path / "map.stl"
    p.write_text("solid x")
    run_bad(capsys, tmp_path, [p], r"map\.stl: unknown format '\.stl'; supported: \.vtu")


@pytest.mark.parametrize("suffix", [".vtu", ".vtk", ".vtp", ".e"])
def test_garbage_file(capsys, tmp_path, suffix):
    p = tmp_path / f"junk{suffix}"
    p.write_bytes(b"\x00\x01 this is not a mesh \xff" * 20)
    run_bad(capsys, tmp_path, [p], re.escape(str(p)) + r": (corrupt|cannot read|the file holds no mesh)")


def test_truncated_vtu(capsys, tmp_path):
    good = write_map(tmp_path / "good.vtu", "hertz", n_rings=10)
    bad = tmp_path / "trunc.vtu"
    bad.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    run_bad(capsys, tmp_path, [bad], r"trunc\.vtu: corrupt or truncated \.vtu file")


def test_empty_file(capsys, tmp_path):
    p = tmp_path / "empty.vtu"
    p.touch()
    run_bad(capsys, tmp_path, [p], r"empty\.vtu: empty file")


def test_no_pressure_array_lists_arrays(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu", field="temperature")
    run_bad(
        capsys,
        tmp_path,
        [p],
        r"m\.vtu: no contact-pressure array found .*arrays found: temperature \(point\)",
    )


def test_several_candidates(capsys, tmp_path):
    p = tmp_path / "m.vtu"
    p2, tri = disc_mesh(12)
    val = 1 - (p2**2).sum(1)
    meshio.write(
        p,
        meshio.Mesh(
            np.column_stack([p2, 0 * val]),
            [("triangle", tri)],
            point_data={"CPRESS": val, "ContactPressure": val},
        ),
    )
    run_bad(
        capsys,
        tmp_path,
        [p],
        r"m\.vtu: several candidate contact-pressure arrays: CPRESS \(point\), "
        r"ContactPressure \(point\); choose one with --field",
    )


def test_named_field_missing(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu")
    run_bad(
        capsys,
        tmp_path,
        [p, "--field", "PRESS"],
        r"m\.vtu: no array named 'PRESS'; arrays found: CPRESS \(point\)",
    )


def test_all_zero(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu", values_fn=lambda q: np.zeros(len(q)))
    run_bad(capsys, tmp_path, [p], r"m\.vtu: pressure array 'CPRESS' is zero everywhere \(no contact\)$")


def test_nan_inside_patch(capsys, tmp_path):
    def vals(q):
        v = 1e5 * (1 - (q**2).sum(1) / 0.01)
        v[0] = np.nan  # the centre node
        return v

    run_bad(
        capsys,
        tmp_path,
        [disc(tmp_path / "m.vtu", values_fn=vals)],
        r"m\.vtu: 1 NaN/inf pressure values inside the contact patch",
    )


def test_negative_pressure(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu", values_fn=lambda q: 1e5 * ((q**2).sum(1) / 0.01 - 0.5))
    run_bad(capsys, tmp_path, [p], r"m\.vtu: negative contact pressure down to -5e\+04 Pa")


def test_non_planar_patch(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu", z_fn=lambda q: 3.0 * (q**2).sum(1))
    run_bad(capsys, tmp_path, [p], r"m\.vtu: the contact patch is not planar")


def test_two_patches(capsys, tmp_path):
    p2, tri = disc_mesh(10)
    p2 = 0.1 * p2
    val = 1e5 * (1 - (p2**2).sum(1) / 0.01)
    pts = np.vstack([np.column_stack([p2, 0 * val]), np.column_stack([p2 + [0.5, 0.0], 0 * val])])
    cells = np.vstack([tri, tri + len(p2)])
    path = tmp_path / "dual.vtu"
    meshio.write(path, meshio.Mesh(pts, [("triangle", cells)], point_data={"CPRESS": np.r_[val, 0.8 * val]}))
    run_bad(
        capsys,
        tmp_path,
        [path],
        r"dual\.vtu: 2 separate contact patches \(load shares 56%, 44%\); dual wheels",
    )


def test_bad_friction_argument(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu")
    message = r"argument --friction: must be a friction coefficient in \[0.001, 10\], got '-1'"
    run_bad(capsys, tmp_path, [p, "--friction", "-1"], message)


def test_bad_step_for_vtu(capsys, tmp_path):
    p = disc(tmp_path / "m.vtu")
    run_bad(capsys, tmp_path, [p, "--step", "3"], r"m\.vtu: --step applies to Exodus time series")


def test_sentinels_are_masked_with_warning(capsys, tmp_path):
    """MOOSE-style -99999 means 'no contact data': masked to zero, with a warning."""

    def vals(q):
        v = 1e5 * np.clip(1 - (q**2).sum(1) / 0.0064, 0, None)  # contact radius 0.08 of 0.1
        v[v == 0] = -99999.0
        return v

    p = disc(tmp_path / "m.vtu", values_fn=vals)
    out = tmp_path / "c.json"
    assert main(["coefficients", str(p), "--json", str(out)]) == 0
    err = capsys.readouterr().err
    assert re.search(r"warning \(SentinelWarning\): .*m\.vtu: \d+ values equal to sentinel -99999", err)
    d = json.loads(out.read_text())
    assert d["N"] > 0 and d["patch"]["r_max"] < 0.095


def test_debug_shows_traceback(tmp_path):
    with pytest.raises(Exception, match="no such file"):
        main(["--debug", "coefficients", str(tmp_path / "nope.vtu")])


def test_rolling_map_off_the_static_plane(capsys, tmp_path):
    static = disc(tmp_path / "s.vtu")
    rolling = disc(tmp_path / "r.vtu", z_fn=lambda q: 0.05 + 0 * q[:, 0])  # 5 cm above the road
    out = tmp_path / "out.json"
    code = main(["coefficients", str(static), "--rolling", str(rolling), "--json", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and not out.exists()
    assert re.search(
        r"r\.vtu: the contact patch is not planar \(RMS distance from the given frame's plane", err[-1]
    )
