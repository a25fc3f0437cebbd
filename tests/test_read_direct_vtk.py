"""The direct decoder of serial VTK XML files gives what VTK's readers give, bit for bit.

Every file is read in-process twice, by `fepost.reader.vtkdirect` and by VTK's own
readers (the direct path switched off), and the two contact fields must be identical
in every field; the raw meshes too (points, blocks, every point array, loaded or left
for later). Files the decoder does not take (ASCII arrays, LZ4) must go to VTK, files it
takes must not import VTK at all. Corrupt data is one `InputFileError` naming the file
and the array. The answer of the reading child travels through a shared memory file;
the same arrays must arrive with the file and without it (`fepost.reader.transfer`).
"""

from __future__ import annotations

import dataclasses
import itertools
import subprocess
import sys
import zlib
from pathlib import Path

import meshio
import numpy as np
import pytest
import pyvista as pv
from vtk_writers import both_ways, same_fields, xml_file

from fepost.errors import InputFileError
from fepost.reader import contact, isolate, read_contact, transfer, vtkdirect
from fepost.reader.vtkfile import read_vtk

pv.OFF_SCREEN = True

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "aircraft" / "static_100.vtu"
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def grids():
    grid = pv.read(SAMPLE)
    rng = np.random.default_rng(5)
    grid.point_data["S"] = rng.normal(size=(grid.n_points, 6))
    grid.point_data["T"] = rng.normal(size=grid.n_points).astype(np.float32)
    grid.cell_data["ID"] = np.arange(grid.n_cells, dtype=np.int32)
    return {"ug": grid, "pd": grid.extract_surface(algorithm=None)}


def _write(grids, out: Path, kind: str, mode: str, encode: bool, compressor: str, **extra) -> Path:
    return xml_file(grids[kind], out, mode, encode, compressor, **extra)


def _both(path: Path, **kw):
    """(direct, VTK) results of `read_here`: the field, or an error's (type, message)."""
    return both_ways(lambda: contact.read_here(path, **kw), vtkdirect, "DIRECT_SUFFIXES")


_same = same_fields


def _same_raw(path: Path, **kw) -> None:
    """The raw meshes of both paths: points, blocks, cell data and every point array."""
    direct = vtkdirect.read_direct(path, **kw)
    assert direct is not None
    general = read_vtk(path, select=False, **kw)
    assert np.array_equal(direct.points, general.points) and direct.points.dtype == general.points.dtype
    assert [(b.label, b.cell_type, b.first_cell, b.body) for b in direct.blocks] == [
        (b.label, b.cell_type, b.first_cell, b.body) for b in general.blocks
    ]
    for bd, bg in zip(direct.blocks, general.blocks, strict=True):
        assert np.array_equal(bd.conn, bg.conn)
        assert list(bd.cell_data) == list(bg.cell_data)
        for name in bg.cell_data:
            assert bd.cell_data[name].dtype == bg.cell_data[name].dtype
            assert np.array_equal(bd.cell_data[name], bg.cell_data[name]), name
    assert list(direct.point_data) == list(general.point_data)
    for name in general.point_data:  # the lazy ones are decoded here
        assert direct.point_data[name].dtype == general.point_data[name].dtype, name
        assert np.array_equal(direct.point_data[name], general.point_data[name]), name
    assert direct.components == general.components
    assert direct.format == general.format and direct.skipped == general.skipped
    assert direct.connectivity_size == general.connectivity_size


TAKEN = [
    (kind, mode, encode, comp)
    for kind, (mode, encode), comp in itertools.product(
        ("ug", "pd"),
        (("binary", True), ("appended", True), ("appended", False)),
        ("none", "zlib", "lzma"),
    )
]


@pytest.mark.parametrize(("kind", "mode", "encode", "compressor"), TAKEN)
def test_every_binary_layout_decodes_as_vtk_reads_it(grids, tmp_path, kind, mode, encode, compressor):
    suffix = ".vtu" if kind == "ug" else ".vtp"
    path = _write(grids, tmp_path / f"map{suffix}", kind, mode, encode, compressor, block=4096)
    assert vtkdirect.read_direct(path) is not None  # the direct path takes it
    _same(*_both(path))
    _same_raw(path)


@pytest.mark.parametrize(
    "extra", [{"big_endian": True}, {"uint64": True}, {"big_endian": True, "uint64": True}], ids=str
)
@pytest.mark.parametrize("compressor", ["none", "zlib"])
def test_byte_order_and_header_words(grids, tmp_path, extra, compressor):
    path = _write(grids, tmp_path / "map.vtu", "ug", "appended", False, compressor, **extra)
    text = path.read_bytes()[:400]
    assert (b"BigEndian" in text) == bool(extra.get("big_endian"))
    _same(*_both(path))
    _same_raw(path)


@pytest.mark.parametrize(
    "options",
    [{}, {"field": "S"}, {"field": "S[2]"}, {"displacement": None}, {"displacement": "S"}, {"field": "ID"}],
    ids=str,
)
def test_reader_options_choose_the_same_arrays(grids, tmp_path, options):
    path = _write(grids, tmp_path / "map.vtu", "ug", "binary", True, "zlib")
    _same(*_both(path, **options))


@pytest.mark.parametrize(("mode", "compressor"), [("ascii", "none"), ("binary", "lz4"), ("appended", "lz4")])
def test_files_the_decoder_does_not_take_go_to_vtk(grids, tmp_path, mode, compressor):
    path = _write(grids, tmp_path / "map.vtu", "ug", mode, True, compressor)
    assert vtkdirect.read_direct(path) is None
    _same(*_both(path))


@pytest.mark.parametrize("binary", [True, False], ids=["binary", "ascii"])
@pytest.mark.parametrize("compression", ["zlib", "lzma", None])
def test_meshio_files(tmp_path, binary, compression):
    m = meshio.read(SAMPLE)
    path = tmp_path / "m.vtu"
    meshio.write(path, m, binary=binary, compression=compression if binary else None)
    if binary:
        _same_raw(path)
    _same(*_both(path))


def test_the_lazy_arrays_are_decoded_on_demand_and_refused_after_a_change(grids, tmp_path):
    path = _write(grids, tmp_path / "map.vtu", "ug", "appended", False, "zlib")
    raw = vtkdirect.read_direct(path)
    assert set(raw.ncomp) == {"S", "T"}  # the pressure and the displacement only were decoded
    assert raw.point_data["S"].shape == (grids["ug"].n_points, 6)
    np.testing.assert_array_equal(raw.point_data["S"], grids["ug"].point_data["S"])
    again = vtkdirect.read_direct(path)
    path.write_bytes(path.read_bytes() + b"\n")  # the file changes after the read
    with pytest.raises(InputFileError, match=r"map\.vtu: point array 'T': the file changed"):
        again.point_data["T"]


def _corrupt_first_block(path: Path) -> None:
    data = bytearray(path.read_bytes())
    mark = data.index(b"_", data.index(b"<AppendedData")) + 1
    first = data.index(b"x\x9c", mark)  # the zlib stream of the first array's first block
    data[first + 2 : first + 40] = b"\xff" * 38
    path.write_bytes(bytes(data))


def _inflater(name: str):
    """The zlib module the direct decoder inflates with: the standard one or ISA-L's."""
    return zlib if name == "zlib" else pytest.importorskip("isal.isal_zlib")


INFLATERS = ["zlib", "isal"]


@pytest.mark.parametrize("inflater", INFLATERS)
def test_both_zlib_inflaters_decode_as_vtk_reads_it(grids, tmp_path, monkeypatch, inflater):
    monkeypatch.setattr(vtkdirect, "ZLIB", _inflater(inflater))
    for kind, mode, encode in (("ug", "binary", True), ("ug", "appended", False), ("pd", "appended", True)):
        suffix = ".vtu" if kind == "ug" else ".vtp"
        path = _write(grids, tmp_path / f"{kind}-{mode}{suffix}", kind, mode, encode, "zlib", block=4096)
        _same_raw(path)


def test_isal_inflates_where_installed(monkeypatch):
    pytest.importorskip("isal")
    assert vtkdirect.ZLIB.__name__ == "isal.isal_zlib"

    def missing(name):
        raise ImportError(name)

    monkeypatch.setattr(vtkdirect.importlib, "import_module", missing)
    assert vtkdirect._zlib_module() is zlib


@pytest.mark.parametrize("inflater", INFLATERS)
def test_a_corrupt_block_is_one_line_naming_the_file_and_the_array(grids, tmp_path, monkeypatch, inflater):
    monkeypatch.setattr(vtkdirect, "ZLIB", _inflater(inflater))
    path = _write(grids, tmp_path / "bad.vtu", "ug", "appended", False, "zlib")
    _corrupt_first_block(path)
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    msg = str(err.value)
    assert msg.startswith(f"{path}: ") and "\n" not in msg
    assert "array" in msg and "decompress" in msg


@pytest.mark.parametrize("inflater", INFLATERS)
def test_a_block_of_the_wrong_size_is_refused(tmp_path, monkeypatch, inflater):
    """A block that inflates to less than its header says, or to more (a zip bomb: 64 MB
    of zeros in 64 kB), is refused naming the array; the bomb is never inflated whole."""
    import tracemalloc

    monkeypatch.setattr(vtkdirect, "ZLIB", _inflater(inflater))

    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    good = zlib.compress(pts.tobytes())
    short = zlib.compress(pts.tobytes()[:-8])
    bomb = zlib.compress(bytes(64 << 20), 9)
    assert len(bomb) < 100_000
    for name, block in (("good", good), ("short", short), ("bomb", bomb)):
        head = np.array([1, pts.nbytes, pts.nbytes, len(block)], "<u4").tobytes()
        conn = np.array([0, 1, 2], "<i8").tobytes()
        body = b""
        offsets = {}
        for key, raw in (
            ("Points", head + block),
            ("connectivity", _zblock(conn)),
            ("offsets", _zblock(np.array([3], "<i8").tobytes())),
            ("types", _zblock(np.array([5], "u1").tobytes())),
            ("CPRESS", _zblock(np.array([1.0, 2.0, 3.0]).tobytes())),
        ):
            offsets[key] = len(body)
            body += raw
        xml = (
            (
                '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" '
                'byte_order="LittleEndian" header_type="UInt32" compressor="vtkZLibDataCompressor">\n'
                '<UnstructuredGrid><Piece NumberOfPoints="3" NumberOfCells="1">\n'
                '<PointData><DataArray type="Float64" Name="CPRESS" format="appended" '
                f'offset="{offsets["CPRESS"]}"/></PointData>\n'
                '<Points><DataArray type="Float64" NumberOfComponents="3" format="appended" '
                f'offset="{offsets["Points"]}"/></Points>\n<Cells>'
                '<DataArray type="Int64" Name="connectivity" format="appended" '
                f'offset="{offsets["connectivity"]}"/>'
                f'<DataArray type="Int64" Name="offsets" format="appended" offset="{offsets["offsets"]}"/>'
                f'<DataArray type="UInt8" Name="types" format="appended" offset="{offsets["types"]}"/>'
                "</Cells>\n</Piece></UnstructuredGrid>\n"
            ).encode()
            + b'<AppendedData encoding="raw">\n_'
            + body
            + b"\n</AppendedData>\n</VTKFile>\n"
        )
        path = tmp_path / f"{name}.vtu"
        path.write_bytes(xml)
        if name == "good":
            raw = vtkdirect.read_direct(path)
            np.testing.assert_array_equal(raw.points, pts)
            _same(*_both(path))
        else:
            tracemalloc.start()
            try:
                with pytest.raises(InputFileError, match=rf"{name}\.vtu: array 'Points': block 1") as err:
                    vtkdirect.read_direct(path)
                peak = tracemalloc.get_traced_memory()[1]
            finally:
                tracemalloc.stop()
            assert ("more than 72 bytes" in str(err.value)) == (name == "bomb")
            assert peak < 8 << 20  # the 64 MB were never held


def _zblock(raw: bytes) -> bytes:
    packed = zlib.compress(raw)
    return np.array([1, len(raw), len(raw), len(packed)], "<u4").tobytes() + packed


def test_reading_an_xml_file_imports_no_vtk(grids, tmp_path):
    path = _write(grids, tmp_path / "map.vtu", "ug", "binary", True, "zlib")
    code = (
        "import sys\nfrom fepost.reader import read_contact\n"
        f"f = read_contact({str(path)!r})\n"
        "print(f.field, sorted(m for m in sys.modules if m.startswith(('vtkmodules', 'pyvista'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.split() == ["CPRESS", "[]"]


def _arrays(n: int) -> dict:
    rng = np.random.default_rng(n)
    return {
        "a": rng.normal(size=(n, 3)),
        "b": np.arange(n, dtype=np.int64),
        "c": rng.normal(size=7).astype(np.float32),
        "d": np.empty((0, 3)),
    }


@pytest.mark.parametrize("shared", [True, False], ids=["memory-file", "copied"])
def test_the_answer_arrives_whole_with_and_without_the_shared_file(monkeypatch, shared):
    if not shared:
        monkeypatch.setattr(transfer, "shared_file", lambda: None)
    elif transfer.shared_file() is None:
        pytest.skip("no memfd_create on this system: the answer is always copied")
    got = isolate.call(_arrays, 300_001, what="test")
    want = _arrays(300_001)
    assert got.keys() == want.keys()
    for k in want:
        assert got[k].dtype == want[k].dtype and np.array_equal(got[k], want[k])
        assert got[k].flags.writeable
    got["a"][0, 0] = 1.0  # the caller owns its arrays


def test_a_surface_mesh_reserves_about_its_answer_and_a_volume_mesh_nothing(grids, tmp_path, monkeypatch):
    """The decoder asks for its answer's memory early (`fepost.reader.transfer.reserve`): for a
    surface mesh about the bytes of the field's arrays; for a volume mesh, whose answer is its
    boundary, nothing."""
    asked: list[int] = []
    monkeypatch.setattr(vtkdirect, "reserve", asked.append)
    surface = _write(grids, tmp_path / "surface.vtu", "ug", "binary", True, "zlib")
    fld = contact.read_here(surface)
    held = (
        fld.points.nbytes
        + fld.triangles.nbytes
        + fld.values.nbytes
        + sum(c.nbytes for c in fld.faces.values())
    )
    assert len(asked) == 1 and 0.5 * held <= asked[0] <= 2.0 * held, (asked, held)
    volume = pv.ImageData(dimensions=(6, 6, 4)).cast_to_unstructured_grid()
    volume.point_data["CPRESS"] = np.where(volume.points[:, 2] == 0, 1e5, 0.0)
    asked.clear()
    contact.read_here(xml_file(volume, tmp_path / "volume.vtu", "binary", True, "zlib"))
    assert asked == [0]


def test_the_memory_file_is_closed_after_the_answer(monkeypatch):
    made: list[int] = []
    real = transfer.shared_file

    def spy():
        fd = real()
        if fd is not None:
            made.append(fd)
        return fd

    monkeypatch.setattr(transfer, "shared_file", spy)
    isolate.call(_arrays, 1000, what="test")
    if not made:
        pytest.skip("no memfd_create on this system")
    import os

    with pytest.raises(OSError):
        os.fstat(made[0])


@pytest.mark.parametrize("compressor", ["none", "zlib"])
def test_base64_broken_into_lines(grids, tmp_path, compressor):
    """Base64 text wrapped at 76 characters a line decodes as one stream: the same field as
    the file unwrapped. (VTK's reader misreads such files: uncompressed, the connectivity
    comes out wrong and the file is refused; the direct decoder reads them right.)"""
    import re

    plain = _write(grids, tmp_path / "plain.vtu", "ug", "binary", True, compressor)
    text = plain.read_bytes()
    path = tmp_path / "map.vtu"

    def wrap(m: re.Match) -> bytes:
        body = m.group(2).strip()
        lines = b"\n          ".join(body[i : i + 76] for i in range(0, len(body), 76))
        return m.group(1) + b"\n          " + lines + b"\n        "

    wrapped = re.sub(rb"(<DataArray[^>]*format=\"binary\"[^>]*>)([A-Za-z0-9+/=\s]+)", wrap, text)
    assert wrapped.count(b"\n") > text.count(b"\n") + 100
    path.write_bytes(wrapped)
    raw = vtkdirect.read_direct(path)
    assert raw is not None
    np.testing.assert_array_equal(raw.points, np.asarray(grids["ug"].points, float))
    wrapped_field = contact.read_here(path)
    plain_field = contact.read_here(plain)
    _same(dataclasses.replace(wrapped_field, source=plain_field.source), plain_field)


def test_a_file_refused_by_the_check_is_named_once(grids, tmp_path):
    """The pre-read check's refusal passes through as it is (one file name, one reason)."""
    whole = _write(grids, tmp_path / "whole.vtu", "ug", "binary", True, "zlib").read_bytes()
    path = tmp_path / "cut.vtu"
    path.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(InputFileError) as err:
        vtkdirect.read_direct(path)
    assert str(err.value).count(str(path)) == 1
    assert str(err.value).startswith(f"{path}: corrupt or truncated .vtu file")


def test_strict_base64_goes_to_the_fast_decoder_and_the_rest_to_binascii(grids, tmp_path, monkeypatch):
    """Strict base64 (every writer's inline arrays) is decoded by pybase64, without binascii;
    text broken into lines falls back to binascii's lenient decoding. Both give VTK's field."""
    import binascii
    from types import SimpleNamespace

    lenient = []

    def counted(text):
        lenient.append(len(text))
        return binascii.a2b_base64(text)

    monkeypatch.setattr(vtkdirect, "binascii", SimpleNamespace(a2b_base64=counted, Error=binascii.Error))
    plain = _write(grids, tmp_path / "plain.vtu", "ug", "binary", True, "zlib")
    assert vtkdirect.read_direct(plain) is not None
    _same(*_both(plain))
    assert lenient == []
    wrapped = tmp_path / "wrapped.vtu"
    body = plain.read_bytes()
    start = body.index(b'format="binary"')
    start = body.index(b">", start) + 1
    wrapped.write_bytes(body[: start + 40] + b"\n" + body[start + 40 :])
    assert vtkdirect.read_direct(wrapped) is not None
    assert lenient  # the broken array went to binascii
    _same(dataclasses.replace(contact.read_here(wrapped), source=str(plain)), contact.read_here(plain))


@pytest.mark.parametrize(
    "text",
    [b"QUJDREVG", b"QUJDREU=", b"QUJDRA==", b"QUJD\nREVG", b"  QUJDREVG\n", b"QQ==QkM=", b"", b"+/+/"],
)
def test_both_base64_decoders_give_the_same_bytes(text):
    import binascii

    assert vtkdirect._b64(_fmt(), memoryview(text), "Points") == binascii.a2b_base64(text)


def test_base64_that_no_decoder_takes_is_one_line_naming_the_file_and_the_array():
    with pytest.raises(InputFileError, match=r"^map\.vtu: array 'Points': invalid base64 data$"):
        vtkdirect._b64(_fmt(), memoryview(b"QUJDR"), "Points")


def _fmt():
    """A decoding format of a little-endian zlib file named map.vtu (only its path is read by `_b64`)."""
    return vtkdirect._Format(
        path=Path("map.vtu"),
        endian="<",
        header=4,
        inflate=vtkdirect._INFLATE["vtkZLibDataCompressor"],
        appended=None,
    )


def test_a_repeated_block_is_inflated_once(tmp_path, monkeypatch):
    """A run of one value (the cell types of a mesh of one cell type, 64-bit as meshio writes
    them) compresses to the same small block again and again: it is inflated once and copied,
    and the mesh is the one every block inflated gives, and VTK's, bit for bit."""
    from fepost.synthetic import write_map

    path = tmp_path / "disc.vtu"
    write_map(path, "hertz", radius=0.1, n_rings=40)  # 22 374 triangles: 179 kB of types, 6 blocks
    real = vtkdirect._INFLATE["vtkZLibDataCompressor"]

    def read(same_max: int):
        blocks = []

        def counted(block, limit):
            blocks.append(bytes(block))
            return real(block, limit)

        monkeypatch.setitem(vtkdirect._INFLATE, "vtkZLibDataCompressor", counted)
        monkeypatch.setattr(vtkdirect, "_SAME_MAX", same_max)
        return vtkdirect.read_direct(path), blocks

    default = vtkdirect._SAME_MAX
    every, all_blocks = read(0)
    once, inflated = read(default)
    assert len(inflated) == len(set(inflated)) < len(all_blocks) - 3  # the types' repeats skipped
    (a,), (b,) = every.blocks, once.blocks
    assert a.conn.shape == (22374, 3)
    np.testing.assert_array_equal(a.conn, b.conn)
    np.testing.assert_array_equal(every.points, once.points)
    monkeypatch.undo()
    _same_raw(path)
