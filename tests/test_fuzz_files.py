"""Malformed and hostile FE files through ``fepost coefficients``: one-line error or a correct result.

Seeded and bounded: byte mutations and truncations of VTU (ASCII, binary,
zlib, appended raw and base64), legacy VTK (ASCII, binary) and Exodus
(netCDF-3 and netCDF-4/HDF5) files, the CalculiX samples in ``meshes/``,
hostile XML headers and structural edge cases. Every case runs the real CLI
in-process (the reader itself runs in a forked child, so a crash in VTK or
HDF5 cannot take the test process down; a few cases also run as a separate
process to show the exit status is never a signal). Each case must end in

* exit 2 with exactly one ``fepost: error:`` line naming the file, no
  traceback and no other output on stderr but fepost's own warnings; or
* exit 0 with N_fe equal to an independent integral of the mutated file as
  meshio (VTK) or netCDF4 (Exodus) reads it, under the documented rules
  (sentinels and NaN away from the patch zeroed, small negatives clipped,
  faces below the threshold not loaded); or, where meshio/netCDF4 cannot
  read the file, equal to the unmutated file's N_fe (the mutation hit bytes
  that carry no data).
"""

from __future__ import annotations

import contextlib
import io
import json
import random
import re
import subprocess
import sys
import time
from pathlib import Path

import meshio
import netCDF4
import numpy as np
import pytest
from exodus_files import write as write_exodus_classic

from fepost.cli import main
from fepost.synthetic import write_map

SEED = 20240611
MUTATIONS = 22  # per base file
MESHES = Path(__file__).resolve().parents[1] / "meshes"
SENTINELS = (-99999.0, -999999.0, -9999.0, -1.0e30, -1.0e20)
THRESHOLD = 1e-6
ARGS = ("--nr", "16", "--nphi", "32")  # N_fe does not depend on the polar grid; a small one is fast


# ----------------------------------------------------------------------------- base files


@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    import pyvista as pv
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    d = tmp_path_factory.mktemp("bases")
    out: dict[str, Path] = {}
    out["vtu_zlib"] = write_map(d / "zlib.vtu", "hertz", radius=0.1, peak=1e6, n_rings=8)
    quad = write_map(d / "quad.vtu", "hertz", radius=0.1, peak=1e6, n_rings=5, kind="quad")
    m = meshio.read(out["vtu_zlib"])
    meshio.write(d / "ascii.vtu", meshio.read(quad), binary=False)
    out["vtu_ascii_quads"] = d / "ascii.vtu"
    meshio.write(d / "binary.vtu", m, binary=True, compression=None)
    out["vtu_binary"] = d / "binary.vtu"
    grid = pv.read(out["vtu_zlib"])
    for name, b64, zlib in (("appended_raw", False, False), ("appended_b64_zlib", True, True)):
        w = vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(str(d / f"{name}.vtu"))
        w.SetDataModeToAppended()
        w.SetEncodeAppendedData(b64)
        w.SetCompressorTypeToZLib() if zlib else w.SetCompressorTypeToNone()
        w.Write()
        out[f"vtu_{name}"] = d / f"{name}.vtu"
    grid.save(d / "binary.vtk")
    out["vtk_binary"] = d / "binary.vtk"
    pv.read(quad).save(d / "ascii.vtk", binary=False)
    out["vtk_ascii_quads"] = d / "ascii.vtk"
    out["exodus_hdf5"] = write_map(d / "hdf5.e", "hertz", radius=0.1, peak=1e6, n_rings=6)
    p = m.points
    val = m.point_data["CPRESS"]
    out["exodus_classic"] = write_exodus_classic(
        d / "classic.e", p, [("TRI3", m.cells_dict["triangle"])], nodal={"CPRESS": val[None]}
    )
    out["sample_vtu"] = MESHES / "static.vtu"
    return out


# ----------------------------------------------------------------------------- independent N_fe


def _sanitise(p: np.ndarray) -> np.ndarray:
    p = np.where(np.isin(p, SENTINELS), 0.0, p)
    p = np.where(np.isfinite(p), p, 0.0)
    return np.clip(p, 0.0, None)


def _independent(path: Path, normal) -> float | None:
    """N_fe of the file as meshio/netCDF4 read it, projected on ``normal``; None if they cannot read it."""
    try:
        if path.suffix == ".e":
            pts, faces, p = _exodus(path)
        else:
            if path.suffix == ".vtk":  # meshio knows only some version numbers; VTK reads any 5.x alike
                data = path.read_bytes()
                head, _, rest = data.partition(b"\n")
                v = re.fullmatch(rb"# vtk DataFile Version (\d+)\.\d+", head)
                if v:
                    known = b"5.1" if int(v.group(1)) >= 5 else b"4.2"
                    path = path.with_name("indep-" + path.name)
                    path.write_bytes(b"# vtk DataFile Version " + known + b"\n" + rest)
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                m = meshio.read(path)
            pts = np.asarray(m.points, float)
            if "displacement" in m.point_data:
                pts = pts + m.point_data["displacement"]
            p = np.asarray(m.point_data["CPRESS"], float)
            faces = [c.data for c in m.cells if c.type in ("triangle", "quad")]
    except Exception:  # the independent reader gives up: no independent value
        return None
    if len(p) != len(pts) or not faces or pts.ndim != 2 or pts.shape[1] != 3:
        return None
    p = _sanitise(p)
    thr = THRESHOLD * p.max()
    n = np.asarray(normal, float)
    e1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    xy = np.column_stack([pts @ e1, pts @ e2])
    total = 0.0
    for f in faces:
        f = np.asarray(f)
        if f.size == 0 or f.min() < 0 or f.max() >= len(pts):
            return None
        f = f[(p[f] > thr).any(axis=1)]
        if f.shape[1] == 3:
            x = xy[f]
            u, w = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
            a = 0.5 * np.abs(u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0])
            total += float(a @ p[f].mean(axis=1))
        else:  # bilinear quads, 2 × 2 Gauss
            g = 1 / np.sqrt(3)
            for xi in (-g, g):
                for eta in (-g, g):
                    a, b = np.array([-1, 1, 1, -1.0]), np.array([-1, -1, 1, 1.0])
                    N = 0.25 * (1 + a * xi) * (1 + b * eta)
                    dx, de = 0.25 * a * (1 + b * eta), 0.25 * b * (1 + a * xi)
                    X = xy[f]
                    jx, je = np.einsum("k,mkd->md", dx, X), np.einsum("k,mkd->md", de, X)
                    total += float((p[f] @ N) @ np.abs(jx[:, 0] * je[:, 1] - jx[:, 1] * je[:, 0]))
    return total


def _exodus(path: Path):
    ds = netCDF4.Dataset(str(path))
    ds.set_auto_mask(False)
    try:
        n = len(ds.dimensions["num_nodes"])
        pts = np.column_stack([np.asarray(ds.variables[f"coord{c}"][:], float) for c in "xyz"])
        names = [bytes(np.asarray(r, "S1")).split(b"\0")[0].decode() for r in ds.variables["name_nod_var"][:]]
        last = len(ds.variables["time_whole"][:]) - 1
        nod = {k: np.asarray(ds.variables[f"vals_nod_var{i + 1}"][last], float) for i, k in enumerate(names)}
        if all(f"displacement{c}" in nod for c in "XYZ"):
            pts = pts + np.column_stack([nod[f"displacement{c}"] for c in "XYZ"])
        faces = [np.asarray(ds.variables["connect1"][:], np.int64) - 1]
        assert pts.shape == (n, 3)
        return pts, faces, nod["CPRESS"]
    finally:
        ds.close()


# ----------------------------------------------------------------------------- running a case


def _run(path: Path, capsys, extra=()) -> tuple[int, list[str], dict | None]:
    out = path.with_name(path.name + ".json")
    code = main(["coefficients", str(path), *ARGS, *extra, "--json", str(out)])
    cap = capsys.readouterr()
    lines = [ln for ln in cap.err.splitlines() if ln.strip()]
    result = json.loads(out.read_text()) if code == 0 and out.exists() else None
    return code, lines, result


def _check_error(path: Path, code: int, lines: list[str]) -> str:
    assert code == 2, (path, code, lines)
    errors = [ln for ln in lines if ln.startswith("fepost: error: ")]
    assert len(errors) == 1, lines
    assert all(ln.startswith("fepost: ") for ln in lines), lines  # no traceback, no foreign warning
    assert str(path) in errors[0], errors[0]
    assert not path.with_name(path.name + ".json").exists()
    return errors[0]


def _dropped_share(lines: list[str]) -> float:
    share = 0.0
    for ln in lines:
        m = re.search(r"dropped \d+ small loaded fragment\(s\) carrying ([\d.]+)% of the load", ln)
        if m:
            share += float(m.group(1)) / 100 + 1e-4
    return share


def _check(path: Path, capsys, reference: float):
    code, lines, result = _run(path, capsys)
    if code != 0:
        return _check_error(path, code, lines)
    assert all(ln.startswith("fepost: warning (") for ln in lines), lines
    n_fe = result["N_fe"]
    indep = _independent(path, result["patch"]["normal"])
    tol = 1e-6 + _dropped_share(lines)
    if indep is not None:
        assert n_fe == pytest.approx(indep, rel=tol), (path, n_fe, indep, lines)
    else:
        assert n_fe == pytest.approx(reference, rel=1e-9), (path, n_fe, reference, lines)
    return "ok"


def _mutate(data: bytes, rng: random.Random) -> tuple[str, bytes]:
    b = bytearray(data)
    kind = rng.choice(("truncate", "flip", "digit", "reverse", "insert", "delete"))
    if kind == "truncate":
        return kind, bytes(b[: rng.randrange(1, len(b))])
    if kind == "flip":
        for _ in range(rng.randint(1, 6)):
            i = rng.randrange(len(b))
            b[i] = rng.randrange(256)
    elif kind == "digit":
        digits = [i for i, c in enumerate(b) if 48 <= c <= 57]
        for i in rng.sample(digits, min(len(digits), rng.randint(1, 3))):
            b[i] = rng.randrange(48, 58)
    elif kind == "reverse":
        i = rng.randrange(len(b))
        j = min(len(b), i + rng.randint(2, 300))
        b[i:j] = b[i:j][::-1]
    elif kind == "insert":
        i = rng.randrange(len(b))
        b[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 64)))
    else:
        i = rng.randrange(len(b))
        del b[i : i + rng.randint(1, 200)]
    return kind, bytes(b)


@pytest.fixture(autouse=True)
def _bounded(monkeypatch, small_accuracy_grid):
    monkeypatch.setenv("FEPOST_READ_TIMEOUT", "20")  # a hang costs at most this, and fails the case


def test_mutated_files(bases, tmp_path, capsys):
    """Byte mutations and truncations of every base file (seeded)."""
    from fepost import analyse

    rng = random.Random(SEED)
    t0 = time.monotonic()
    outcomes: dict[str, int] = {}
    for name, base in bases.items():
        reference = analyse(base).static_patch.N_fe
        data = base.read_bytes()
        for k in range(MUTATIONS if name != "sample_vtu" else MUTATIONS // 2):
            kind, mutated = _mutate(data, rng)
            path = tmp_path / f"{name}-{k}-{kind}{base.suffix}"
            path.write_bytes(mutated)
            try:
                verdict = _check(path, capsys, reference)
            except AssertionError as exc:
                raise AssertionError(f"{name} mutation {k} ({kind}): {exc}") from None
            key = "ok" if verdict == "ok" else "error"
            outcomes[key] = outcomes.get(key, 0) + 1
            path.unlink()
    assert sum(outcomes.values()) >= 200
    assert outcomes.get("error", 0) > 0 and outcomes.get("ok", 0) > 0, outcomes
    assert time.monotonic() - t0 < 600


# ----------------------------------------------------------------------------- hostile and structural cases


def _ascii_vtu(bases) -> str:
    return bases["vtu_ascii_quads"].read_text()


def _sub(text: str, pattern: str, repl, count=1) -> str:
    new, n = re.subn(pattern, repl, text, count=count, flags=re.S)
    assert n, pattern
    return new


LAUGHS = (
    '<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
    + "".join(
        f'<!ENTITY lol{i} "{("&lol" + (str(i - 1) if i > 1 else "") + ";") * 10}">' for i in range(1, 10)
    )
    + ']>\n<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="1" NumberOfCells="0">'
    "&lol9;</Piece></UnstructuredGrid></VTKFile>\n"
)


def _hostile_cases(bases) -> list[tuple[str, str, str]]:
    """(file name, text, the pattern the one-line error must match; "" = a correct result)."""
    t = _ascii_vtu(bases)
    npts = int(re.search(r'NumberOfPoints="(\d+)"', t).group(1))
    ncells = int(re.search(r'NumberOfCells="(\d+)"', t).group(1))
    deep = _sub(t, r"<UnstructuredGrid>", "<UnstructuredGrid>" + "<Nest>" * 5000 + "</Nest>" * 5000)
    conn = re.search(r'(Name="connectivity"[^>]*>\s*)(\d+)', t)
    cases = [
        (
            "huge_points.vtu",
            _sub(t, r'NumberOfPoints="\d+"', 'NumberOfPoints="999999999999"'),
            "out of range",
        ),
        ("negative_points.vtu", _sub(t, r'NumberOfPoints="\d+"', 'NumberOfPoints="-5"'), "out of range"),
        (
            "fewer_cells.vtu",
            _sub(t, r'NumberOfCells="\d+"', f'NumberOfCells="{ncells // 8}"'),
            "the header disagrees with the data",
        ),
        (
            "more_cells.vtu",
            _sub(t, r'NumberOfCells="\d+"', f'NumberOfCells="{ncells + 3}"'),
            "the header disagrees with the data",
        ),
        ("fewer_points.vtu", _sub(t, r'NumberOfPoints="\d+"', f'NumberOfPoints="{npts - 1}"'), "disagrees"),
        ("laughs.vtu", LAUGHS, "refused .*DOCTYPE/ENTITY"),
        ("deep.vtu", deep, "nested more than"),
        ("wild_conn.vtu", t[: conn.start(2)] + "987654321" + t[conn.end(2) :], "connectivity refers to node"),
        ("nan_point.vtu", _sub(t, r'(Name="Points"[^>]*>\s*)(\S+)', r"\g<1>nan"), "NaN or infinite"),
        ("inf_point.vtu", _sub(t, r'(Name="Points"[^>]*>\s*)(\S+)', r"\g<1>inf"), "NaN or infinite"),
        (
            "short_array.vtu",
            _sub(t, r'(Name="CPRESS"[^>]*>\s*)(\S+\s+\S+)', r"\g<1>"),
            "the header disagrees with the data",
        ),
        ("bad_type.vtu", _sub(t, r'(Name="types"[^>]*>\s*)(\d+)', r"\g<1>200"), "VTK type 200 \\(an unknown"),
        (
            "bad_offsets.vtu",
            _sub(t, r'(Name="offsets"[^>]*>\s*)(\d+)', r"\g<1>7"),
            "offsets|cells with|corrupt",
        ),
        ("not_closed.vtu", t[: t.index("</Piece>")], "not closed"),
        ("junk.vtu", "\x00\x01garbage" * 40, "corrupt or truncated|not a VTK"),
        (
            "header_type.vtu",  # 64-bit length headers declared over 32-bit ones
            _sub(bases["vtu_binary"].read_text(), r"<VTKFile", '<VTKFile header_type="UInt64"'),
            "bytes announced",
        ),
    ]
    lines_only = (
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1">\n<UnstructuredGrid>\n'
        '<Piece NumberOfPoints="2" NumberOfCells="1">\n<Points><DataArray type="Float64" '
        'NumberOfComponents="3" format="ascii">0 0 0 1 0 0</DataArray></Points>\n<Cells>\n'
        '<DataArray type="Int64" Name="connectivity" format="ascii">0 1</DataArray>\n'
        '<DataArray type="Int64" Name="offsets" format="ascii">2</DataArray>\n'
        '<DataArray type="UInt8" Name="types" format="ascii">3</DataArray>\n</Cells>\n'
        '<PointData><DataArray type="Float64" Name="CPRESS" format="ascii">1 1</DataArray></PointData>\n'
        "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"
    )
    cases.append(("lines.vtu", lines_only, "only points or lines"))
    no_cells = _sub(
        _sub(lines_only, 'NumberOfCells="1"', 'NumberOfCells="0"'),
        r"<Cells>.*</Cells>",
        '<Cells><DataArray type="Int64" Name="connectivity" format="ascii"></DataArray>'
        '<DataArray type="Int64" Name="offsets" format="ascii"></DataArray>'
        '<DataArray type="UInt8" Name="types" format="ascii"></DataArray></Cells>',
    )
    cases.append(("no_cells.vtu", no_cells, "holds no mesh|no surface faces"))
    labels = (
        f'<PointData><DataArray type="String" Name="label" format="ascii">{"97 98 0 " * npts}</DataArray>'
    )
    cases.append(("strings.vtu", _sub(t, r"<PointData>", labels), ""))
    few = '<PointData><DataArray type="String" Name="label" format="ascii">97 0 98 0</DataArray>'
    cases.append(("few_strings.vtu", _sub(t, r"<PointData>", few), "disagrees with the data"))
    leg = bases["vtk_ascii_quads"].read_text()
    cases.append(
        (
            "legacy_cells.vtk",
            _sub(leg, r"CELL_TYPES (\d+)", lambda m: f"CELL_TYPES {int(m.group(1)) - 5}"),
            "disagrees",
        )
    )
    cases.append(
        (
            "legacy_points.vtk",
            _sub(leg, r"POINTS (\d+)", lambda m: f"POINTS {int(m.group(1)) + 2}"),
            "disagrees|fewer|more",
        )
    )
    cases.append(
        (
            "legacy_data.vtk",
            _sub(leg, r"POINT_DATA (\d+)", lambda m: f"POINT_DATA {int(m.group(1)) - 1}"),
            "disagrees",
        )
    )
    cases.append(("legacy_huge.vtk", _sub(leg, r"POINTS (\d+)", "POINTS 99999999999"), "out of range"))
    return cases


def test_hostile_and_structural_vtk_files(bases, tmp_path, capsys):
    from fepost import analyse

    reference = analyse(bases["vtu_ascii_quads"]).static_patch.N_fe
    for name, text, pattern in _hostile_cases(bases):
        path = tmp_path / name
        path.write_text(text)
        code, lines, result = _run(path, capsys)
        if pattern:
            err = _check_error(path, code, lines)
            assert re.search(pattern, err), (name, err)
        else:
            assert code == 0, (name, lines)
            assert result["N_fe"] == pytest.approx(reference, rel=1e-9), name


def _vtm(tmp_path, body: str) -> Path:
    path = tmp_path / "multi.vtm"
    path.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="vtkMultiBlockDataSet" version="1.0">\n'
        f"<vtkMultiBlockDataSet>{body}</vtkMultiBlockDataSet>\n</VTKFile>\n"
    )
    return path


def test_multiblock_references(bases, tmp_path, capsys):
    for body, pattern in (
        ('<DataSet index="0" file="missing.vtu"/>', "multi-block piece 'missing.vtu' not found"),
        ('<DataSet index="0" file="multi.vtm"/>', "refers to itself"),
        (
            '<DataSet index="0" file="/etc/passwd"/>',
            r"refused \.vtm file \(multi-block piece '/etc/passwd' lies outside the file's folder\)",
        ),
        ('<DataSet index="0" file="notes.txt"/>', "multi-block piece 'notes.txt' is not a VTK XML file"),
    ):
        path = _vtm(tmp_path, body)
        code, lines, _ = _run(path, capsys)
        assert re.search(pattern, _check_error(path, code, lines)), lines


def test_hostile_exodus_files(bases, tmp_path, capsys):
    m = meshio.read(bases["vtu_zlib"])
    pts, tri, val = m.points, m.cells_dict["triangle"], m.point_data["CPRESS"]
    cases = [
        (
            "conn.e",
            dict(points=pts, blocks=[("TRI3", np.where(tri == 3, 10**6, tri))], nodal={"CPRESS": val[None]}),
            "connectivity refers to node",
        ),
        (
            "nan.e",
            dict(
                points=np.where(np.arange(len(pts))[:, None] == 2, np.nan, pts),
                blocks=[("TRI3", tri)],
                nodal={"CPRESS": val[None]},
            ),
            "NaN or infinite",
        ),
        (
            "plane.e",
            dict(points=pts[:, :2], blocks=[("TRI3", tri)], nodal={"CPRESS": val[None]}),
            "2-D model",
        ),
        (
            "etype.e",
            dict(points=pts, blocks=[("SPAGHETTI", tri)], nodal={"CPRESS": val[None]}),
            "elements of type 'SPAGHETTI' with 3 nodes, which fepost cannot read",
        ),
        (
            "nopressure.e",
            dict(points=pts, blocks=[("TRI3", tri)], nodal={"temperature": val[None]}),
            "no contact-pressure array found",
        ),
    ]
    three = np.stack([val, val, val])
    for name, times, message in (
        ("inf_time.e", (0.0, np.inf, 2.0), "step 1 (t = inf) is not a finite number"),
        (
            "nan_times.e",
            (np.nan, 1.0, -np.inf),
            "step 0 (t = nan), step 2 (t = -inf) are not a finite number",
        ),
    ):
        kw = dict(points=pts, blocks=[("TRI3", tri)], nodal={"CPRESS": three}, times=times)
        cases.append((name, kw, re.escape(f"{tmp_path / name}: corrupt Exodus II time values: {message}")))
    for name, kw, pattern in cases:
        path = write_exodus_classic(tmp_path / name, **kw)
        code, lines, _ = _run(path, capsys)
        assert re.search(pattern, _check_error(path, code, lines)), (name, lines)
    # a netCDF header declaring far more nodes than the file holds
    raw = bytearray(bases["exodus_classic"].read_bytes())
    path = tmp_path / "short.e"
    path.write_bytes(bytes(raw[: len(raw) // 2]))
    code, lines, _ = _run(path, capsys)
    _check_error(path, code, lines)


@pytest.mark.parametrize(
    "name,maker",
    [
        ("trunc_hdf5.e", lambda b: b["exodus_hdf5"].read_bytes()[:3000]),
        ("noise.e", lambda b: random.Random(SEED).randbytes(50_000)),
        ("laughs.vtu", lambda b: LAUGHS.encode()),
        ("trunc_appended.vtu", lambda b: b["vtu_appended_raw"].read_bytes()[:-700]),
    ],
)
def test_a_separate_process_ends_with_exit_2_never_a_signal(bases, tmp_path, name, maker):
    path = tmp_path / name
    path.write_bytes(maker(bases))
    proc = subprocess.run(
        [sys.executable, "-m", "fepost", "coefficients", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"fepost: error: {path}"), proc.stderr


def test_symbolic_link_loop_and_dangling_link(tmp_path, capsys):
    loop = tmp_path / "loop.vtu"
    other = tmp_path / "other.vtu"
    loop.symlink_to(other)
    other.symlink_to(loop)
    dangling = tmp_path / "dangling.vtu"
    dangling.symlink_to(tmp_path / "gone.vtu")
    for path, message in (
        (loop, f"{loop}: a symbolic-link loop (the links never reach a file)"),
        (dangling, f"{dangling}: a symbolic link to {str(tmp_path / 'gone.vtu')!r}, which does not exist"),
        (tmp_path / "none.vtu", f"{tmp_path / 'none.vtu'}: no such file"),
    ):
        code, lines, _ = _run(path, capsys)
        assert code == 2 and lines == [f"fepost: error: {message}"], lines
