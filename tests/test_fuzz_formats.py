"""Hostile and mutated parallel VTK, structured VTK and XDMF files through ``fepost coefficients``.

As in `test_fuzz_files`: every case ends in exit 2 with one ``fepost: error:`` line naming
the file given, or in exit 0 with a correct N_fe. Structural cases (a ``.pvtu`` pointing at
missing, hostile or outside pieces; an ``.xdmf`` pointing at a missing, foreign or
inconsistent ``.h5``; structured grids whose ``Extent`` disagrees with their arrays) must be
refused with the stated reason. Seeded mutations of a ``.pvtu``'s own XML and of an
``.xdmf`` (their heavy data untouched) must be refused or give the unmutated N_fe; seeded
mutations of the ``.h5`` must be refused or give the N_fe of the same mutated file
converted to ``.vtu`` by meshio (in a forked child) and read by VTK.
"""

from __future__ import annotations

import random
import re
from pathlib import Path

import meshio
import pytest
import pyvista as pv
from test_fuzz_files import LAUGHS, SEED, _check_error, _mutate, _run
from test_reader_parallel import write_parallel

from fepost.synthetic import write_map

MUTATIONS = 16


@pytest.fixture(autouse=True)
def _bounded(monkeypatch, small_accuracy_grid):
    monkeypatch.setenv("FEPOST_READ_TIMEOUT", "20")


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    d = tmp_path_factory.mktemp("base")
    return write_map(d / "map.vtu", "hertz", radius=0.1, peak=1e6, n_rings=8)


@pytest.fixture(scope="module")
def reference(base):
    from fepost import analyse

    return analyse(base).static_patch.N_fe


def _refused(path: Path, capsys, pattern: str) -> None:
    code, lines, _ = _run(path, capsys)
    err = _check_error(path, code, lines)
    assert re.search(pattern, err), err


def _mutated_copies(path: Path, seed: int, capsys, reference) -> dict[str, int]:
    """Read `MUTATIONS` mutated copies of ``path`` beside it: how many were read right
    ("ok") and how many refused (`_ok_or_refused` fails the test on anything else)."""
    text = path.read_bytes()
    rng = random.Random(seed)
    seen = {"ok": 0, "refused": 0}
    for k in range(MUTATIONS):
        _, data = _mutate(text, rng)
        bad = path.with_name(f"mut{k}{path.suffix}")
        bad.write_bytes(data)
        seen[_ok_or_refused(bad, capsys, reference)] += 1
    return seen


def _ok_or_refused(path: Path, capsys, expected: float) -> str:
    code, lines, result = _run(path, capsys)
    if code != 0:
        _check_error(path, code, lines)
        return "refused"
    assert result["N_fe"] == pytest.approx(expected, rel=1e-9), (path, lines)
    return "ok"


# ------------------------------------------------------------------------------ parallel files


def _parallel(base, d: Path) -> Path:
    d.mkdir(exist_ok=True)
    return write_parallel(pv.read(base), d / "map.pvtu", 2, 0)


def test_parallel_file_structure(base, tmp_path, capsys):
    path = _parallel(base, tmp_path / "p")
    text = path.read_text()
    first = re.search(r'Source="([^"]+)"', text).group(1)
    outside = tmp_path / "outside.vtu"
    outside.write_bytes((path.parent / first).read_bytes())
    cases = [
        ("missing", text.replace(first, "nope.vtu"), r"piece 'nope\.vtu' not found"),
        (
            "parent",
            text.replace(first, "../outside.vtu"),
            r"refused \.pvtu file \(piece '\.\./outside\.vtu' lies outside",
        ),
        (
            "absolute",
            text.replace(first, "/etc/passwd"),
            r"piece '/etc/passwd' lies outside the file's folder",
        ),
        ("suffix", text.replace(first, "map.pvtu"), r"piece 'map\.pvtu' is not a \.vtu file"),
        ("none", re.sub(r"<Piece [^>]*/>", "", text), "a parallel file that lists no pieces"),
        ("nosource", text.replace(f'Source="{first}"', ""), "a Piece without its Source file"),
        (
            "many",
            text.replace("</PUnstructuredGrid>", '<Piece Source="a.vtu"/>' * 5000 + "</PUnstructuredGrid>"),
            r"refused: 5002 pieces|refused \.pvtu file \(5002 pieces",
        ),
    ]
    for name, body, pattern in cases:
        bad = path.with_name(f"{name}.pvtu")
        bad.write_text(body)
        _refused(bad, capsys, pattern)
    # hostile pieces: entity expansion, truncation, a piece declaring more points than it holds
    piece = path.parent / first
    good = piece.read_bytes()
    for _name, data, pattern in (
        ("laughs", LAUGHS.encode(), r"piece '.*' refused: .*DOCTYPE/ENTITY"),
        ("truncated", good[: len(good) // 2], r"piece '.*' refused: .*(truncated|not closed)"),
        (
            "points",
            re.sub(
                rb'NumberOfPoints="(\d+)"', lambda m: b'NumberOfPoints="%d"' % (int(m.group(1)) + 7), good
            ),
            r"piece '.*' refused: .*the header disagrees with the data",
        ),
    ):
        piece.write_bytes(data)
        _refused(path, capsys, pattern)
    piece.write_bytes(good)


def test_mutated_parallel_headers(base, tmp_path, capsys):
    from fepost import analyse

    path = _parallel(base, tmp_path / "p")
    reference = analyse(path).static_patch.N_fe  # the pieces hold float32 coordinates
    assert _mutated_copies(path, SEED, capsys, reference)["refused"] > 0


# ------------------------------------------------------------------------------ structured grids


def test_structured_grid_structure(tmp_path, capsys):
    x = y = [-0.1, 0.0, 0.1]
    grid = pv.RectilinearGrid(x, y, [0.0, 0.05])
    grid.point_data["CPRESS"] = [1e5] * grid.n_points
    vtr = tmp_path / "g.vtr"
    grid.save(vtr, binary=False)
    vts = tmp_path / "g.vts"
    grid.cast_to_structured_grid().save(vts, binary=False)
    t_r, t_s = vtr.read_text(), vts.read_text()
    cases = [
        (
            "bigger.vtr",
            re.sub(r'Extent="0 2 0 2 0 1"', 'Extent="0 3 0 2 0 1"', t_r, count=2),
            "disagrees with the data",
        ),
        ("words.vts", re.sub(r'Extent="[^"]*"', 'Extent="0 2 0 x"', t_s), "is not six integers"),
        ("huge.vts", re.sub(r'Extent="[^"]*"', 'Extent="0 99999 0 99999 0 99999"', t_s), "out of range"),
        ("inverted.vts", re.sub(r'Extent="[^"]*"', 'Extent="2 0 0 2 0 1"', t_s), "out of range"),
        (
            "nocoords.vtr",
            re.sub(r"<Coordinates>.*</Coordinates>", "<Coordinates></Coordinates>", t_r, flags=re.S),
            "0 Coordinates arrays instead of 3",
        ),
        ("short.vts", t_s[: len(t_s) // 2], "not closed|disagrees|truncated"),
    ]
    for name, body, pattern in cases:
        path = tmp_path / name
        path.write_text(body)
        _refused(path, capsys, pattern)


# ------------------------------------------------------------------------------ XDMF


def _xdmf(base, d: Path) -> Path:
    d.mkdir(exist_ok=True)
    path = d / "map.xdmf"
    meshio.write(path, meshio.read(base))
    return path


def test_xdmf_structure(base, tmp_path, capsys):
    path = _xdmf(base, tmp_path / "x")
    text = path.read_text()
    h5 = path.with_suffix(".h5")
    dims = re.search(r'Dimensions="(\d+) 3"', text).group(1)
    junk = tmp_path / "x" / "junk.h5"
    junk.write_bytes(b"not an HDF5 file" * 10)
    cases = [
        ("missing", text.replace("map.h5:", "gone.h5:"), r"heavy-data file 'gone\.h5' not found"),
        (
            "parent",
            text.replace("map.h5:", "../map.h5:"),
            r"refused \.xdmf file \(heavy-data file '\.\./map\.h5' lies outside",
        ),
        ("absolute", text.replace("map.h5:", "/etc/passwd:"), "lies outside the file's folder"),
        ("junk", text.replace("map.h5:", "junk.h5:"), r"heavy-data file 'junk\.h5' is not an HDF5 file"),
        ("dataset", text.replace(":/data0", ":/data9"), r"holds no dataset '/data9'"),
        (
            "dims",
            text.replace(f'Dimensions="{dims} 3"', f'Dimensions="{int(dims) - 1} 3"', 1),
            "the header disagrees",
        ),
        (
            "words",
            text.replace(f'Dimensions="{dims} 3"', 'Dimensions="many 3"', 1),
            "is not a list of integers",
        ),
        ("huge", text.replace(f'Dimensions="{dims} 3"', 'Dimensions="99999999999 3"', 1), "out of range"),
        (
            "binary",
            text.replace('Format="HDF"', 'Format="Binary"', 1),
            r'refused: Format="Binary"|Format="Binary" data',
        ),
        (
            "include",
            text.replace(
                "<Domain>",
                '<Domain><xi:include xmlns:xi="http://www.w3.org/2001/XInclude" href="/etc/passwd"/>',
            ),
            "xi:include of another file",
        ),
        ("entity", '<?xml version="1.0"?><!DOCTYPE X [<!ENTITY a "aaaa">]>' + text, "ENTITY declarations"),
        ("deep", text.replace("<Domain>", "<Domain>" + "<N>" * 100 + "</N>" * 100), "nested more than"),
        ("broken", text[: len(text) // 2], "not well-formed XML"),
        ("version", text.replace('Version="3.0"', 'Version="9"'), "XDMF Version='9'"),
        ("root", text.replace("<Xdmf", "<Other").replace("</Xdmf>", "</Other>"), "not an XDMF file"),
    ]
    for name, body, pattern in cases:
        bad = path.with_name(f"{name}.xdmf")
        bad.write_text(body)
        _refused(bad, capsys, pattern)
    # the .h5 it names: missing, truncated
    saved = h5.read_bytes()
    h5.unlink()
    _refused(path, capsys, r"heavy-data file 'map\.h5' not found")
    h5.write_bytes(saved[: len(saved) // 3])
    _refused(path, capsys, "map.h5")
    h5.write_bytes(saved)


def test_mutated_xdmf_text(base, reference, tmp_path, capsys):
    path = _xdmf(base, tmp_path / "x")
    assert _mutated_copies(path, SEED + 1, capsys, reference)["refused"] > 0


def _converted(path: Path) -> Path:
    out = path.with_name(path.stem + "-converted.vtu")
    meshio.write(out, meshio.read(path))
    return out


def test_mutated_hdf5_data(base, tmp_path, capsys):
    from fepost import analyse
    from fepost.errors import InputFileError
    from fepost.reader import isolate

    path = _xdmf(base, tmp_path / "x")
    h5 = path.with_suffix(".h5")
    saved = h5.read_bytes()
    rng = random.Random(SEED + 2)
    seen = {"ok": 0, "refused": 0}
    for _ in range(MUTATIONS):
        _, data = _mutate(saved, rng)
        h5.write_bytes(data)
        code, lines, result = _run(path, capsys)
        if code != 0:
            _check_error(path, code, lines)
            seen["refused"] += 1
            continue
        try:  # the independent reading: meshio in a forked child, converted, read by VTK
            conv = isolate.call(_converted, path, what=str(path), nbytes=len(data))
        except InputFileError:
            conv = None
        if conv is not None:
            assert result["N_fe"] == pytest.approx(analyse(conv).static_patch.N_fe, rel=1e-9)
        seen["ok"] += 1
        path.with_name(path.name + ".json").unlink()
    h5.write_bytes(saved)
    assert seen["refused"] > 0


# ------------------------------------------------------------------------------ binary legacy FIELD blocks


def _legacy_fields(path: Path) -> Path:
    """A binary legacy file whose FIELD block holds several arrays, METADATA between them."""
    import numpy as np
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridWriter

    pts = np.array([[0, 0, 0], [0.2, 0, 0], [0.2, 0.2, 0], [0, 0.2, 0]], float)
    g = pv.UnstructuredGrid(np.r_[4, 0, 1, 2, 3], np.array([pv.CellType.QUAD]), pts)
    contact = np.zeros((4, 6))
    contact[:, 3] = 1e5
    g.point_data["CONTACT"] = contact
    g.point_data["extra"] = np.ones((4, 2))
    g.point_data["temp"] = np.ones(4)
    for name, comps in (
        ("CONTACT", ("COPEN", "CSLIP1", "CSLIP2", "CPRESS", "CSHEAR1", "CSHEAR2")),
        ("extra", "ab"),
    ):
        arr = g.GetPointData().GetArray(name)
        for k, c in enumerate(comps):
            arr.SetComponentName(k, c)
    w = vtkUnstructuredGridWriter()
    w.SetInputData(g)
    w.SetFileName(str(path))
    w.SetFileTypeToBinary()
    w.Write()
    return path


def test_binary_legacy_field_blocks(tmp_path, capsys):
    from fepost.reader import read_contact

    path = _legacy_fields(tmp_path / "fields.vtk")
    data = path.read_bytes()
    assert data.count(b"METADATA") >= 2 and re.search(rb"FIELD FieldData [2-9]", data)
    fld = read_contact(path)
    assert fld.field == "CONTACT:CPRESS"
    assert _ok_or_refused(path, capsys, 1e5 * 0.04) == "ok"
    count = int(re.search(rb"FIELD FieldData (\d)", data).group(1))
    name = re.search(rb"FIELD FieldData \d\n(\w+) (\d+) (\d+) (\w+)\n", data)
    n_comp, n_tup = int(name.group(2)), int(name.group(3))
    cases = [
        (
            "more_arrays",
            data.replace(b"FIELD FieldData %d" % count, b"FIELD FieldData %d" % (count + 1)),
            "FIELD arrays end early|bad FIELD array line|fewer bytes",
        ),
        (
            "more_tuples",
            data.replace(name.group(0), name.group(0).replace(b" %d " % n_tup, b" %d " % (n_tup + 1))),
            "fewer bytes than a section declares|binary data where a section keyword belongs"
            "|bad FIELD array line",
        ),
        (
            "fewer_tuples",
            data.replace(name.group(0), name.group(0).replace(b" %d " % n_tup, b" %d " % (n_tup - 1))),
            "binary data where a section keyword belongs|bad FIELD array line|disagrees",
        ),
        ("cut", data[: len(data) - 20], "fewer bytes than a section declares"),
        (
            "type",
            data.replace(name.group(0), name.group(0).replace(name.group(4), b"quaternion")),
            "unknown data type 'quaternion'",
        ),
    ]
    assert n_comp >= 1
    for case, body, pattern in cases:
        bad = tmp_path / f"{case}.vtk"
        bad.write_bytes(body)
        _refused(bad, capsys, pattern)
