"""Damaged files are refused naming the file and what is damaged, never read to a quiet wrong number.

Built here from the sample map (meshes/static.vtu, 2961 nodes) written by VTK's own writers,
or from small generated meshes, then damaged byte by byte:

* ``.vtu`` base64 (inline and appended, UInt32 and UInt64 headers, raw and zlib): a character
  outside the alphabet, ``=`` padding or a space written into the pressure array. VTK's reader
  stops at such a character and leaves the rest of the array zero (or, for whitespace, shifts
  it): refused by the direct decoder and by the check before VTK, naming the array; a length
  header encoded on its own (padding *between* two valid streams) is valid and read to the
  clean file's numbers by both paths;
* ``.frd`` (an ASCII/binary writer of the record layout below, a 4 × 4 block of 25 mm bricks
  pressed with a uniform CPRESS p, so N_fe = p · (0.1 m)², exact for bilinear faces): ``-5``
  flags that declare fewer stored values than the records hold, a node twice in a CONTACT
  block, two CONTACT blocks in one increment, a file cut inside its last step, and a last step
  without contact output (read from the last step that has it, with a note);
* ``.pvtu``: a piece listed twice, pieces that are a directory or a FIFO, and UTF-8 piece
  names (valid: read to the serial file's numbers);
* ``.xdmf``: an ``.h5`` reaching its data through an HDF5 external link outside the folder
  (refused; inside the folder: read), a directory or FIFO for the ``.h5``, damaged HDF5 chunk
  and superblock, inline values that are not numbers.

Every refusal through the CLI: exit 2, one ``fepost: error:`` line naming the file.
"""

from __future__ import annotations

import os
import re
import shutil
import struct
import warnings
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest
import pyvista as pv
from test_reader_parallel import write_parallel
from vtk_writers import both_ways, xml_file

from fepost.cli import main
from fepost.errors import FieldError, InputFileError, ReaderWarning
from fepost.patch import build_patch
from fepost.reader import contact, read_contact, vtkdirect

pv.OFF_SCREEN = True

SAMPLE = Path(__file__).resolve().parents[1] / "meshes" / "static.vtu"
#: N_fe of two reads of the same numbers (the same doubles, the same faces).
SAME = 1e-12
#: N_fe of a map split into pieces and joined again (float32 points of the piece writer).
JOINED = 1e-6


@pytest.fixture(autouse=True)
def _bounded(monkeypatch):
    monkeypatch.setenv("FEPOST_READ_TIMEOUT", "20")  # a FIFO must not hang a read


@pytest.fixture(scope="module")
def grid():
    return pv.read(SAMPLE)


@pytest.fixture(scope="module")
def reference(grid):
    return build_patch(read_contact(SAMPLE)).N_fe


def _n_fe(path: Path, **kw) -> float:
    return build_patch(read_contact(path, **kw)).N_fe


def _cli_refuses(path: Path, capsys, *extra: str) -> str:
    """Exit 2 and one ``fepost: error:`` line naming ``path``; the line."""
    assert main(["coefficients", str(path), "--nr", "12", "--nphi", "24", *extra]) == 2
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("fepost: error: ")]
    assert len(errors) == 1 and str(path) in errors[0], lines
    assert "Traceback" not in "\n".join(lines)
    return errors[0]


# ----------------------------------------------------------------------------- VTK base64


LAYOUTS = [
    pytest.param(mode, comp, uint64, id=f"{mode}-{comp}-{'UInt64' if uint64 else 'UInt32'}")
    for mode in ("binary", "appended")
    for comp in ("none", "zlib")
    for uint64 in (False, True)
]
#: What is written over the middle of the pressure array's text.
DAMAGE = {"invalid": b"!", "padding": b"=", "pad-pair": b"==", "space": b" ", "newline": b"\n"}


def _text_of(data: bytes, name: str) -> tuple[int, int]:
    """(start, end) of the base64 text of array ``name`` (inline, or appended: up to the next offset)."""
    tag = re.search(rb'<DataArray[^>]*Name="' + name.encode() + rb'"[^>]*>', data)
    assert tag is not None
    attrs = tag.group(0)
    if b'format="appended"' not in attrs:
        return tag.end(), data.index(b"<", tag.end())
    base = data.index(b"_", data.index(b"<AppendedData")) + 1
    offsets = sorted({int(v) for v in re.findall(rb'offset="(\d+)"', data)})
    off = int(re.search(rb'offset="(\d+)"', attrs).group(1))
    later = [o for o in offsets if o > off]
    return base + off, (base + later[0] if later else data.index(b"<", base))


def _damaged(src: Path, out: Path, damage: bytes, name: str = "CPRESS") -> Path:
    data = src.read_bytes()
    start, end = _text_of(data, name)
    mid = (start + end) // 2
    out.write_bytes(data[:mid] + damage + data[mid + len(damage) :])
    return out


def _both(path: Path):
    """(direct decoder, VTK's reader): each the field or its error's (type, message)."""
    return both_ways(lambda: contact.read_here(path), vtkdirect, "DIRECT_SUFFIXES")


@pytest.mark.parametrize(("mode", "comp", "uint64"), LAYOUTS)
@pytest.mark.parametrize("damage", list(DAMAGE))
def test_damaged_base64_is_refused_naming_the_array(grid, tmp_path, mode, comp, uint64, damage):
    clean = xml_file(grid, tmp_path / "clean.vtu", mode, True, comp, uint64=uint64)
    path = _damaged(clean, tmp_path / "map.vtu", DAMAGE[damage])
    direct, general = _both(path)
    for way, got in (("direct", direct), ("VTK", general)):
        if damage == "newline" and way == "direct" and not isinstance(got, tuple):
            # a line break inside inline text is passed over by the decoder: the clean numbers
            assert mode == "binary" and np.array_equal(got.values, contact.read_here(clean).values)
            continue
        assert isinstance(got, tuple), (way, damage)
        kind, message = got
        assert kind is InputFileError, (way, message)
        assert message.startswith(f"{path}: ") and "\n" not in message
        assert "array 'CPRESS'" in message and "base64" in message, (way, message)
        assert "zero everywhere" not in message


def _damaged_at(src: Path, out: Path, damage: bytes, where: str, position: int, name: str = "CPRESS") -> Path:
    """``damage`` written at ``position`` (0-3) of a 4-character base64 group of the array's text:
    its first group, the one in its middle, or its last (where the padding is)."""
    data = src.read_bytes()
    start, end = _text_of(data, name)
    text = data[start:end]
    chars = [i for i, c in enumerate(text) if c not in b" \t\r\n"]
    groups = len(chars) // 4
    group = {"first": 0, "middle": groups // 2, "last": groups - 1}[where]
    at = start + chars[4 * group + position]
    return out.write_bytes(data[:at] + damage + data[at + len(damage) :]) and out


@pytest.mark.parametrize(("mode", "comp", "uint64"), [LAYOUTS[0], LAYOUTS[3], LAYOUTS[5]])
@pytest.mark.parametrize("where", ["first", "middle", "last"])
@pytest.mark.parametrize("damage", ["invalid", "padding"])
def test_damage_at_every_position_of_a_group_is_refused(grid, tmp_path, mode, comp, uint64, where, damage):
    """The damage of `test_damaged_base64_is_refused_naming_the_array` at each of the four
    positions of a group, at the text's start, middle and end: "=" inside a group is never a
    stream boundary that decodes to fewer bytes without a word."""
    clean = xml_file(grid, tmp_path / "clean.vtu", mode, True, comp, uint64=uint64)
    reference = contact.read_here(clean).values
    for position in range(4):
        path = _damaged_at(clean, tmp_path / f"map{position}.vtu", DAMAGE[damage], where, position)
        if path.read_bytes() == clean.read_bytes():
            continue  # the character was already there (padding over padding): nothing damaged
        for way, got in zip(("direct", "VTK"), _both(path), strict=True):
            if not isinstance(got, tuple):
                # read without a word: only if the numbers are the clean ones
                assert np.array_equal(got.values, reference), (way, where, position)
                continue
            kind, message = got
            assert kind is InputFileError, (way, where, position, message)
            assert message.startswith(f"{path}: ") and "\n" not in message
            # "=" closing the first group early leaves a header of too few bytes: "truncated"
            assert "array 'CPRESS'" in message, (way, where, position, message)
            assert "base64" in message or "truncated" in message, (way, where, position, message)


def _reencoded(src: Path, out: Path) -> Path:
    """``src`` (inline, uncompressed) with every array's length word encoded on its own, as some
    writers do: padding sits between two valid base64 streams."""
    import base64

    data = src.read_bytes()

    def split(m: re.Match) -> bytes:
        raw = base64.b64decode(m.group(2))
        return m.group(1) + base64.b64encode(raw[:4]) + base64.b64encode(raw[4:]) + m.group(3)

    text = re.sub(rb'(<DataArray[^>]*format="binary"[^>]*>\s*)([A-Za-z0-9+/=]+)(\s*<)', split, data)
    assert text.count(b"==") > data.count(b"==")
    out.write_bytes(text)
    return out


def test_a_length_word_encoded_on_its_own_reads_as_the_clean_file_both_ways(grid, tmp_path, reference):
    clean = xml_file(grid, tmp_path / "clean.vtu", "binary", True, "none")
    path = _reencoded(clean, tmp_path / "split.vtu")
    direct, general = _both(path)
    want = contact.read_here(clean)
    for got in (direct, general):
        assert not isinstance(got, tuple), got
        assert np.array_equal(got.values, want.values) and np.array_equal(got.points, want.points)
    assert _n_fe(path) == pytest.approx(reference, rel=SAME)


def test_the_vtk_path_refuses_damage_the_direct_decoder_never_sees(grid, tmp_path):
    """LZ4 files go to VTK: damaged base64 is refused by the check before it, naming the array;
    whitespace inside the text too (VTK shifts the values after it)."""
    clean = xml_file(grid, tmp_path / "clean.vtu", "binary", True, "lz4")
    for damage, why in ((b"!", "invalid character '!'"), (b" ", "whitespace"), (b"==", "'=' padding")):
        path = _damaged(clean, tmp_path / "map.vtu", damage)
        with pytest.raises(InputFileError) as err:
            read_contact(path)
        message = str(err.value)
        assert message.startswith(
            f"{path}: corrupt or truncated .vtu file (array 'CPRESS': damaged base64 data ("
        )
        assert why in message


def test_a_damaged_piece_is_refused_naming_the_piece_and_the_array(grid, tmp_path):
    path = write_parallel(grid, tmp_path / "map.pvtu", pieces=2, ghosts=0)
    pieces = re.findall(r'Source="([^"]+)"', path.read_text())
    piece = path.parent / pieces[1]
    _damaged(piece, piece, b"=")
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    message = str(err.value)
    assert message.startswith(f"{path}: piece {pieces[1]!r} refused: {piece.resolve()}: ")
    assert "array 'CPRESS': damaged base64 data" in message


def test_damaged_base64_through_the_cli(grid, tmp_path, capsys):
    clean = xml_file(grid, tmp_path / "clean.vtu", "binary", True, "none")
    line = _cli_refuses(_damaged(clean, tmp_path / "map.vtu", b"="), capsys)
    assert "array 'CPRESS'" in line and "base64" in line


# ----------------------------------------------------------------------------- .frd

#: Bricks per side, brick size (m), the pressure (Pa).
CELLS, SIZE, PRESSURE = 4, 0.025, 2.0e5
COMPONENTS = ("COPEN", "CSLIP1", "CSLIP2", "CPRESS", "CSHEAR1", "CSHEAR2")


def _block():
    """(node ids, coordinates, brick node lists, bottom node ids) of a CELLS × CELLS × 1 block."""
    n = CELLS + 1
    ijk = np.array([(i, j, k) for k in range(2) for j in range(n) for i in range(n)])
    ids = np.arange(1, len(ijk) + 1)
    number = {tuple(p): int(q) for p, q in zip(ijk, ids, strict=True)}
    bricks = []
    for j in range(CELLS):
        for i in range(CELLS):
            quad = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            bricks.append([number[(a, b, 0)] for a, b in quad] + [number[(a, b, 1)] for a, b in quad])
    return ids, ijk * SIZE, bricks, ids[ijk[:, 2] == 0]


class _Frd:
    """An ``.frd`` file written record by record, ASCII (``*CONTACT FILE``) or binary."""

    def __init__(self, binary: bool = False):
        self.binary, self.out, self.kode = binary, bytearray(), 0

    def line(self, text: str) -> None:
        self.out += text.encode("latin-1") + b"\n"

    def mesh(self, ids, xyz, bricks) -> None:
        self.line("    1C")
        self.line(f"    2C{len(ids):30d}{3 if self.binary else 1:37d}")
        for node, p in zip(ids, xyz, strict=True):
            if self.binary:
                self.out += struct.pack("<i3d", int(node), *p)
            else:
                self.line(f" -1{int(node):10d}" + "".join(f"{v:12.5E}" for v in p))
        if not self.binary:
            self.line(" -3")
        self.line(f"    3C{len(bricks):30d}{2 if self.binary else 1:37d}")
        for e, nodes in enumerate(bricks, 1):
            if self.binary:
                self.out += struct.pack("<4i8i", e, 1, 0, 1, *nodes)
            else:
                self.line(f" -1{e:10d}{1:5d}{0:5d}{1:5d}")
                self.line(" -2" + "".join(f"{v:10d}" for v in nodes))
        if not self.binary:
            self.line(" -3")

    def block(self, name, comps, nodes, values, time, derived=()) -> None:
        self.line(f"    1PSTEP{self.kode + 1:25d}{1:12d}{1:12d}")
        fmt = 2 if self.binary else 1
        self.line(f"  100CL  101{time:12.9f}{len(nodes):12d}{'':20}{0:2d}{self.kode + 1:5d}{'':11}{fmt}")
        self.line(f" -4  {name:<8s}{len(comps) + len(derived):5d}    1")
        for c in comps:
            self.line(f" -5  {c:<8s}    1    4    1    0")
        for c in derived:
            self.line(f" -5  {c:<8s}    1    2    0    0    1ALL")
        for node, row in zip(nodes, values, strict=True):
            if self.binary:
                self.out += struct.pack(f"<i{len(row)}f", int(node), *row)
            else:
                self.line(f" -1{int(node):10d}" + "".join(f"{v:12.5E}" for v in row))
        if not self.binary:
            self.line(" -3")

    def step(self, time: float, pressure: float | None, nodes, bottom) -> None:
        """One increment: DISP at every node, CONTACT at the bottom nodes (none when ``pressure`` is None)."""
        self.block("DISP", ("D1", "D2", "D3"), nodes, np.zeros((len(nodes), 3)), time, derived=("ALL",))
        if pressure is not None:
            self.block("CONTACT", COMPONENTS, bottom, _contact(len(bottom), pressure), time)
        self.kode += 1

    def end(self) -> None:
        self.line(" 9999")


def _contact(n: int, pressure: float) -> np.ndarray:
    values = np.zeros((n, len(COMPONENTS)))
    values[:, 0], values[:, 3] = -1e-6, pressure
    return values


def write_frd(path: Path, steps, binary: bool = False, end: bool = True) -> Path:
    """The block pressed at each (time, pressure or None) of ``steps``."""
    ids, xyz, bricks, bottom = _block()
    frd = _Frd(binary)
    frd.mesh(ids, xyz, bricks)
    for time, pressure in steps:
        frd.step(time, pressure, ids, bottom)
    if end:
        frd.end()
    path.write_bytes(bytes(frd.out))
    return path


def _load(pressure: float) -> float:
    return pressure * (CELLS * SIZE) ** 2


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary"])
def test_the_written_frd_reads_to_the_closed_form(tmp_path, binary):
    path = write_frd(tmp_path / "block.frd", [(0.5, PRESSURE / 2), (1.0, PRESSURE)], binary=binary)
    assert _n_fe(path) == pytest.approx(_load(PRESSURE), rel=SAME)
    assert _n_fe(path, step=0) == pytest.approx(_load(PRESSURE / 2), rel=SAME)


def _derived_flag(path: Path, component: str) -> Path:
    """``path`` with IEXIST = 1 (derived: no values stored) on ``component``'s -5 line."""
    data = path.read_bytes()
    at = data.index(f" -5  {component:<8s}".encode())
    eol = data.index(b"\n", at)
    path.write_bytes(data[:at] + data[at:eol].ljust(33) + b"    1" + data[eol:])
    return path


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary"])
def test_fewer_stored_components_than_the_records_hold_is_refused(tmp_path, binary, capsys):
    path = _derived_flag(write_frd(tmp_path / "flag.frd", [(1.0, PRESSURE)], binary=binary), "CSLIP2")
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    if binary:
        want = (
            f"{path}: corrupt or truncated .frd file (result block CONTACT: its records do not end where "
            "its -5 lines say (25 nodes, 5 stored components of 4 bytes each): a component flagged as "
            "derived (IEXIST = 1) that has values, or the reverse?)"
        )
    else:
        want = (
            f"{path}: corrupt or truncated .frd file (result block CONTACT: a record holds 6 values, "
            "its -5 lines declare 5 stored components (a component flagged as derived, IEXIST = 1, "
            "that has values?))"
        )
    assert str(err.value) == want
    _cli_refuses(path, capsys)


def _with_records(path: Path, extra: list[tuple[int, float]]) -> Path:
    """``path`` (ASCII, one increment) with CONTACT records (node, CPRESS) added, the count raised."""
    text = path.read_text(encoding="latin-1")
    head = text.index("  100C", text.index(" -4  CONTACT") - 200)
    eol = text.index("\n", head)
    line = text[head:eol]
    count = int(line[24:36]) + len(extra)
    close = text.index(" -3\n", head)
    rows = "".join(
        f" -1{node:10d}" + "".join(f"{v:12.5E}" for v in _contact(1, p)[0]) + "\n" for node, p in extra
    )
    text = text[:head] + line[:24] + f"{count:12d}" + line[36:] + text[eol:close] + rows + text[close:]
    path.write_text(text, encoding="latin-1")
    return path


def test_a_node_twice_in_a_contact_block(tmp_path):
    _, _, _, bottom = _block()
    node = int(bottom[7])
    same = _with_records(write_frd(tmp_path / "same.frd", [(1.0, PRESSURE)]), [(node, PRESSURE)])
    assert _n_fe(same) == pytest.approx(_load(PRESSURE), rel=SAME)  # the same record twice: read once
    path = _with_records(write_frd(tmp_path / "twice.frd", [(1.0, PRESSURE)]), [(node, 3 * PRESSURE)])
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: result block CONTACT at step 0 (t = 1) holds node {node} twice, with different values "
        "(CPRESS 200000 and CPRESS 600000); fepost cannot tell which to read (corrupt file?)"
    )


def test_two_contact_blocks_in_one_increment(tmp_path):
    path = write_frd(tmp_path / "two.frd", [(1.0, PRESSURE)])
    text = path.read_text(encoding="latin-1")
    start = text.rindex("    1PSTEP", 0, text.index(" -4  CONTACT"))
    stop = text.index(" -3\n", start) + 4
    block = text[start:stop]
    doubled = tmp_path / "doubled.frd"
    doubled.write_text(text[:stop] + block + text[stop:], encoding="latin-1")
    assert _n_fe(doubled) == pytest.approx(_load(PRESSURE), rel=SAME)  # the same block twice
    other = block.replace("2.00000E+05", "1.00000E+05")
    path.write_text(text[:start] + other + block + text[stop:], encoding="latin-1")
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: step 0 (t = 1) holds 2 CONTACT blocks with different values (corrupt file, or two runs "
        "written into one file?); fepost cannot tell which to read"
    )


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary"])
def test_a_file_cut_inside_its_last_step_is_called_truncated(tmp_path, binary, capsys):
    whole = write_frd(tmp_path / "whole.frd", [(0.5, PRESSURE / 2), (1.0, PRESSURE)], binary=binary)
    data = whole.read_bytes()
    last = data.rindex(b" -4  CONTACT")
    cut = data.rindex(b"    1PSTEP", 0, last)  # the last step's DISP written, its CONTACT not
    path = tmp_path / "cut.frd"
    path.write_bytes(data[:cut])
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: truncated .frd file: it ends at byte {cut} without CalculiX's closing 9999 line, in "
        "step 1 (t = 1), before its contact output (cut off while written?); contact output is complete "
        "at step(s) 0 (t = 0.5): choose one with --step"
    )
    assert "CONTACT FILE" not in _cli_refuses(path, capsys)
    assert _n_fe(path, step=0) == pytest.approx(_load(PRESSURE / 2), rel=SAME)


def test_a_last_step_without_contact_output_reads_the_last_that_has_it(tmp_path, capsys):
    path = write_frd(tmp_path / "unload.frd", [(0.5, PRESSURE / 2), (1.0, PRESSURE), (2.0, None)])
    note = (
        "step 2 (t = 2), the last, holds no contact output: read step 1 (t = 1), the last with a "
        "CONTACT block; choose another with --step"
    )
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        fld = read_contact(path)
    assert fld.step == 1 and fld.time == 1.0 and note in fld.notes
    assert [str(w.message) for w in seen if issubclass(w.category, ReaderWarning)] == [f"{path}: {note}"]
    assert build_patch(fld).N_fe == pytest.approx(_load(PRESSURE), rel=SAME)
    with pytest.raises(FieldError) as err:
        read_contact(path, step=2)
    assert str(err.value) == (
        f"{path}: no CONTACT block at step 2 (t = 2); contact output is at step(s) 0 (t = 0.5), "
        "1 (t = 1): choose one with --step"
    )
    _cli_refuses(path, capsys, "--step", "-1")


# ----------------------------------------------------------------------------- .pvtu and .vtm


@pytest.fixture
def parallel(grid, tmp_path):
    path = write_parallel(grid, tmp_path / "map.pvtu", pieces=2, ghosts=0)
    return path, re.findall(r'Source="([^"]+)"', path.read_text())


def _sources(path: Path, names: list[str], declaration: str | None = "") -> Path:
    """``path`` listing ``names`` as its pieces, with the XML declaration given (None: without one)."""
    text = path.read_text(encoding="utf-8")
    body = text[text.index("<VTKFile") :]
    pieces = iter(names)
    body = re.sub(r"<Piece [^>]*/>\s*", "", body)
    body = body.replace(
        "</PUnstructuredGrid>", "".join(f'<Piece Source="{n}"/>\n' for n in pieces) + "</PUnstructuredGrid>"
    )
    head = "" if declaration is None else f'<?xml version="1.0"{declaration}?>\n'
    out = path.with_name("named.pvtu")
    out.write_text(head + body, encoding="utf-8")
    return out


def test_a_piece_listed_twice_is_refused_naming_it(parallel, capsys):
    path, pieces = parallel
    twice = _sources(path, [*pieces, pieces[0]])
    with pytest.raises(InputFileError) as err:
        read_contact(twice)
    assert str(err.value) == (
        f"{twice}: refused .pvtu file (piece {pieces[0]!r} is listed twice; its nodes would count twice)"
    )
    _cli_refuses(twice, capsys)


@pytest.mark.parametrize("declaration", [' encoding="UTF-8"', "", None], ids=["utf8", "plain", "none"])
@pytest.mark.parametrize("name", ["pièce.vtu", "piece one é.vtu"])
def test_utf8_piece_names_are_read(parallel, declaration, name):
    path, pieces = parallel
    first = path.parent / pieces[0]
    renamed = path.parent / name
    shutil.copy(first, renamed)
    named = _sources(path, [name, pieces[1]], declaration)
    assert _n_fe(named) == pytest.approx(_n_fe(path), rel=SAME)


def test_utf8_block_names_in_a_multiblock_file_are_read(grid, tmp_path, reference):
    folder = tmp_path / "dossier é"
    folder.mkdir()
    grid.save(folder / "bloc é.vtu")
    vtm = tmp_path / "map.vtm"
    vtm.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="vtkMultiBlockDataSet" version="1.0">\n<vtkMultiBlockDataSet>\n'
        '<DataSet index="0" file="dossier é/bloc é.vtu"/>\n</vtkMultiBlockDataSet>\n</VTKFile>\n',
        encoding="utf-8",
    )
    assert _n_fe(vtm) == pytest.approx(reference, rel=JOINED)


@pytest.mark.parametrize("kind", ["directory", "FIFO"])
def test_a_piece_that_is_not_a_regular_file(parallel, kind, capsys):
    path, pieces = parallel
    odd = path.parent / "odd.vtu"
    odd.mkdir() if kind == "directory" else os.mkfifo(odd)
    named = _sources(path, [pieces[0], "odd.vtu"])
    with pytest.raises(InputFileError) as err:
        read_contact(named)
    assert (
        str(err.value) == f"{named}: refused .pvtu file (piece 'odd.vtu' is not a regular file but a {kind})"
    )
    _cli_refuses(named, capsys)


# ----------------------------------------------------------------------------- .xdmf


@pytest.fixture
def xdmf(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    path = folder / "map.xdmf"
    meshio.write(path, meshio.read(SAMPLE))
    return path


def _linked(h5: Path, target: str) -> None:
    """The pressure dataset of ``h5`` replaced by an external link to ``target``:/data2."""
    with h5py.File(h5, "a") as f:
        del f["data2"]
        f["data2"] = h5py.ExternalLink(target, "/data2")


def _tripled(src: Path, out: Path) -> None:
    with h5py.File(src) as f, h5py.File(out, "w") as g:
        g["data2"] = f["data2"][()] * 3


def test_heavy_data_reached_through_an_external_link_outside_the_folder_is_refused(xdmf, reference, capsys):
    h5 = xdmf.with_suffix(".h5")
    outside = xdmf.parent.parent / "far.h5"
    _tripled(h5, outside)
    inside = xdmf.parent / "near.h5"
    _tripled(h5, inside)
    _linked(h5, "near.h5")
    assert _n_fe(xdmf) == pytest.approx(3 * reference, rel=SAME)  # inside the folder: read
    for target in ("../far.h5", str(outside)):
        with h5py.File(h5, "a") as f:
            del f["data2"]
            f["data2"] = h5py.ExternalLink(target, "/data2")
        with pytest.raises(InputFileError) as err:
            read_contact(xdmf)
        assert str(err.value) == (
            f"{xdmf}: refused .xdmf file (heavy-data file 'map.h5': dataset '/data2' reaches {target!r} "
            "through an HDF5 external link, which lies outside the file's folder)"
        )
    _cli_refuses(xdmf, capsys)


@pytest.mark.parametrize("kind", ["directory", "FIFO"])
def test_an_h5_that_is_not_a_regular_file(xdmf, kind):
    odd = xdmf.with_name("odd.h5")
    odd.mkdir() if kind == "directory" else os.mkfifo(odd)
    xdmf.write_text(xdmf.read_text().replace("map.h5", "odd.h5"))
    with pytest.raises(InputFileError) as err:
        read_contact(xdmf)
    assert (
        str(err.value)
        == f"{xdmf}: refused .xdmf file (heavy-data file 'odd.h5' is not a regular file but a {kind})"
    )


def test_damaged_hdf5_names_the_file_and_the_dataset(tmp_path):
    path = tmp_path / "map.xdmf"
    meshio.write(path, meshio.read(SAMPLE), compression="gzip")
    h5 = path.with_suffix(".h5")
    with h5py.File(h5) as f:
        chunk = f["data2"].id.get_chunk_info(0)
    data = bytearray(h5.read_bytes())
    middle = chunk.byte_offset + chunk.size // 2
    data[middle : middle + 64] = b"\xff" * 64
    h5.write_bytes(bytes(data))
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: heavy-data file 'map.h5': the values of dataset '/data2' cannot be read (damaged HDF5 data)"
    )
    data[8:48] = b"\0" * 40  # the superblock
    h5.write_bytes(bytes(data))
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: corrupt or truncated .xdmf file (heavy-data file 'map.h5' is damaged: HDF5 cannot open it "
        "(its superblock))"
    )


def test_inline_values_that_are_not_numbers_name_the_item_and_the_token(tmp_path):
    path = tmp_path / "map.xdmf"
    meshio.write(path, meshio.read(SAMPLE), data_format="XML")
    text = path.read_text()
    at = text.index(">", text.index("<DataItem", text.index('Name="CPRESS"'))) + 1
    first = text[at:].split()[0]
    path.write_text(text[:at] + text[at:].replace(first, "1.0x0", 1))
    with pytest.raises(InputFileError) as err:
        read_contact(path)
    assert str(err.value) == (
        f"{path}: corrupt or truncated .xdmf file (the DataItem of Attribute 'CPRESS': inline value "
        "'1.0x0' is not a Float number)"
    )
