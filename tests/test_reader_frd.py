"""CalculiX ``.frd`` files read directly, checked against the solver's own reaction and ccx2paraview.

Each case solves a small contact model with the ``ccx`` on PATH (a soft block
pressed on a steel plate, tests/test_reader_frd_decks.py; under 2 s each) and compares

* fepost's load from the ``.frd`` (N_fe: the exact integral of the nodal CPRESS
  over the recovered contact faces) with the total reaction CalculiX prints for
  the plate's fixed bottom (``*NODE PRINT, TOTALS=ONLY``), and
* the same file converted by ccx2paraview to ``.vtu`` and read by fepost's VTU
  path: the same numbers to round-off.

Tolerances. Linear elements, node-to-surface penalty: CalculiX's CPRESS is
each slave node's spring force over its tributary area, which for linear faces
is the integral of the node's shape function, so the integral of the
interpolated CPRESS is the sum of the spring forces: measured 7.0e-6 (ASCII)
and 7.1e-6 (binary) from the reaction, so not the rounding of the ASCII values
but CalculiX's own small difference between its spring areas and the faces;
bound 5e-5.
Quadratic tetrahedra and wedges: the springs sit at the mid-side nodes (the
corners of a 6-node triangle have no tributary area); measured 0.08 % and
0.3 %, bound 1 %. Surface-to-surface contact: CPRESS is extrapolated from the
integration points (measured 0.6 % on 8-node bricks, 0.015 % on 20-node
bricks); bound 1 %. fepost's N (the polar-grid integral) meets the pressure
jump along the square patch's edges: measured 0.4 %, bound 1 % as for the
square patches of tests/test_external.py.
"""

from __future__ import annotations

import json
import re
import shutil
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from test_reader_frd_decks import write_deck

from fepost import analyse
from fepost.cli import main
from fepost.errors import FieldError, PressureWarning, ReaderWarning
from fepost.patch import build_patch
from fepost.reader import read_contact, time_steps

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:  # scripts/ is a plain folder at the repository root
    sys.path.insert(0, str(REPO))

HAVE_CCX = shutil.which("ccx") is not None
pytestmark = [pytest.mark.ccx, pytest.mark.skipif(not HAVE_CCX, reason="CalculiX 'ccx' is not on PATH")]
ASCII_TOL = 5e-5
QUADRATIC_TOL = 1e-2
S2S_TOL = 1e-2
GRID_TOL = 1e-2
ROUND_OFF = 1e-6  # float32 points in the converted file


def solve(folder: Path, etype: str = "C3D8", **kw) -> tuple[Path, list[tuple[float, float]]]:
    """Solve the deck in ``folder``; return the .frd and the (time, reaction z) of every increment."""
    from scripts.tiremodel.frd import read_dat_totals
    from scripts.tiremodel.solve import find_ccx, run_ccx

    folder.mkdir(parents=True, exist_ok=True)
    inp = write_deck(folder / "job.inp", etype, **kw)
    run_ccx(find_ccx(), inp, threads=1, timeout=300)
    totals = [(t, float(f[2])) for name, t, f in read_dat_totals(folder / "job.dat") if name == "PBOT"]
    return folder / "job.frd", totals


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    root = tmp_path_factory.mktemp("frd")
    return {
        "ascii": solve(root / "ascii"),
        "binary": solve(root / "binary", binary=True),
        "steps": solve(root / "steps", increments=4, binary=True),
    }


def _n_fe(path, **kw) -> float:
    return build_patch(read_contact(path, **kw)).N_fe


@pytest.mark.parametrize("kind", ["ascii", "binary"])
def test_load_equals_the_solver_reaction(cases, kind):
    path, totals = cases[kind]
    reaction = totals[-1][1]
    fld = read_contact(path)
    assert fld.format == f"CalculiX .frd ({'ASCII' if kind == 'ascii' else 'binary'})"
    assert fld.field == "CONTACT:CPRESS"
    assert set(fld.arrays) == {"CONTACT", "DISP"}
    patch = build_patch(fld)
    assert patch.face_types == ("quad4",) and patch.n_element_faces == 16  # the block's 4 × 4 bottom faces
    assert patch.N_fe == pytest.approx(reaction, rel=ASCII_TOL)
    res = analyse(path)
    assert res.coefficients.N == pytest.approx(reaction, rel=GRID_TOL)


def test_ascii_and_binary_agree(cases):
    a, b = (read_contact(cases[k][0]) for k in ("ascii", "binary"))
    np.testing.assert_allclose(a.points, b.points, rtol=0, atol=1e-9)  # ASCII: 6 digits of 5e-2 m
    np.testing.assert_allclose(a.values, b.values, rtol=1e-5)  # ASCII: 6 significant digits
    assert _n_fe(cases["ascii"][0]) == pytest.approx(_n_fe(cases["binary"][0]), rel=1e-5)


def test_same_numbers_as_the_ccx2paraview_vtu(cases, tmp_path):
    Converter = pytest.importorskip("ccx2paraview.common", reason="ccx2paraview is not installed").Converter

    frd = tmp_path / "job.frd"
    shutil.copy(cases["ascii"][0], frd)
    Converter(str(frd), ["vtu"]).run()
    vtu = tmp_path / "job.vtu"
    assert vtu.exists()
    direct, converted = read_contact(frd), read_contact(vtu)
    assert converted.field == "CONTACT:CPRESS"
    # ccx2paraview stores the points in float32 (VTK's default): round-off of 6e-8 relative
    assert build_patch(direct).N_fe == pytest.approx(build_patch(converted).N_fe, rel=ROUND_OFF)
    a, b = analyse(frd).coefficients, analyse(vtu).coefficients
    for key in ("N", "M0", "R", "F0"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=ROUND_OFF), key


@pytest.mark.parametrize(
    ("etype", "contact", "faces", "tol", "binary"),
    [
        ("C3D8I", "NODE TO SURFACE", "quad4", ASCII_TOL, False),
        ("C3D6", "NODE TO SURFACE", "tri3", ASCII_TOL, True),  # wedges and the plate's bricks: mixed records
        ("C3D4", "NODE TO SURFACE", "tri3", ASCII_TOL, False),
        ("C3D10", "NODE TO SURFACE", "tri6", QUADRATIC_TOL, True),
        ("C3D15", "NODE TO SURFACE", "tri6", QUADRATIC_TOL, False),
        ("C3D20", "SURFACE TO SURFACE", "quad8", S2S_TOL, True),
        ("C3D8", "SURFACE TO SURFACE", "quad4", S2S_TOL, False),
    ],
)
def test_element_types(tmp_path, etype, contact, faces, tol, binary):
    path, totals = solve(tmp_path, etype, contact=contact, binary=binary)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ReaderWarning)
        fld = read_contact(path)
    patch = build_patch(fld)
    assert patch.face_types == (faces,)  # the bottom faces; quadratic faces keep their mid-side nodes
    assert patch.N_fe == pytest.approx(totals[-1][1], rel=tol)


def test_quadratic_node_to_surface_is_flagged(tmp_path):
    path, _ = solve(tmp_path, "C3D20")
    with pytest.warns(ReaderWarning, match="node-to-surface contact on quadratic hexahedra"):
        fld = read_contact(path)
    assert build_patch(fld).face_types == ("quad8",)


def test_every_increment_is_a_time_step(cases, tmp_path, capsys):
    path, totals = cases["steps"]
    steps = time_steps(path)
    assert [s.index for s in steps] == [0, 1, 2, 3]
    np.testing.assert_allclose([s.time for s in steps], [0.25, 0.5, 0.75, 1.0])
    np.testing.assert_allclose([t for t, _ in totals], [0.25, 0.5, 0.75, 1.0])
    loads = [_n_fe(path, step=k) for k in range(4)]
    for (_, reaction), n in zip(totals, loads, strict=True):
        assert n == pytest.approx(reaction, rel=ASCII_TOL)
    assert loads[0] < loads[1] < loads[2] < loads[3]  # the push grows with the increments
    assert read_contact(path).step == 3 and _n_fe(path) == loads[3]  # the last by default
    assert read_contact(path, step=-3).time == pytest.approx(0.5)
    out = tmp_path / "c.json"
    assert main(["coefficients", str(path), "--step", "1", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["N_fe"] == pytest.approx(loads[1], rel=1e-9)
    assert main(["coefficients", str(path), "--step", "7"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("fepost: error:") and "--step 7 out of range (file has 4 time steps)" in err[-1]


def test_contact_components_kept(cases):
    from fepost.reader.frd import read_frd

    raw = read_frd(cases["binary"][0], None)
    try:
        assert raw.components["CONTACT"] == ("COPEN", "CSLIP1", "CSLIP2", "CPRESS", "CSHEAR1", "CSHEAR2")
        contact = raw.point_data["CONTACT"]
        assert contact.shape == (len(raw.points), 6)
        slave = np.any(contact != 0, axis=1)
        assert slave.sum() == 25  # the block's 5 × 5 bottom nodes, all in contact here
        assert np.all(contact[slave, 3] > 0)
        assert np.all(contact[slave, 0] < 0)  # and penetrating (penalty): COPEN < 0
        assert np.all(contact[slave, 1:3] == 0)  # frictionless: no slip recorded, no shear
        assert np.all(contact[slave, 4:] == 0)
        assert raw.point_data["DISP"].shape == (len(raw.points), 3)
    finally:
        raw.close()


def test_no_contact_output_is_a_clear_error(cases, tmp_path):
    text = cases["ascii"][0].read_text(encoding="latin-1")
    cut = text.index(" -4  CONTACT")
    head = text.rfind("    1PSTEP", 0, cut)
    end = text.index(" -3\n", cut) + 4
    path = tmp_path / "nocontact.frd"
    path.write_text(text[:head] + text[end:], encoding="latin-1")
    with pytest.raises(FieldError, match=r"\*CONTACT FILE .* \*CONTACT OUTPUT .* CSTR"):
        read_contact(path)


def test_displacement_missing_at_contact_nodes(cases, tmp_path):
    """A DISP block written for a node set that leaves out contact nodes: refused, unless not used."""
    text = cases["ascii"][0].read_text(encoding="latin-1")
    head = text.index("  100C", text.index("    1PSTEP"))
    line = text[head : text.index("\n", head)]
    count = int(line[24:36])
    first = text.index("\n -1         1", head) + 1
    cut = text[:first] + text[text.index("\n", first) + 1 :]
    cut = cut.replace(line, line[:24] + f"{count - 1:12d}" + line[36:], 1)
    path = tmp_path / "partial.frd"
    path.write_text(cut, encoding="latin-1")
    with pytest.raises(
        FieldError, match=r"DISP block has no values at 1 of the \d+ nodes.*--displacement none"
    ):
        read_contact(path)
    fld = read_contact(path, displacement=None)
    clean = read_contact(cases["ascii"][0], displacement=None)
    assert build_patch(fld).N_fe == build_patch(clean).N_fe  # the undeformed faces, as in the clean file


def test_double_precision_results(cases, tmp_path):
    """Format 3 (float64 records, as CalculiX writes with its double-precision binary option):
    the float32 file rewritten in doubles reads to the same field."""
    from fepost.reader.frdparse import open_frd, scan

    src = cases["binary"][0]
    data = src.read_bytes()
    mapped = open_frd(src)
    try:
        blocks = scan(src, mapped).blocks
    finally:
        mapped.close()
    out, pos = bytearray(), 0
    for b in blocks:
        head = data.rfind(b"  100C", 0, b.start)
        eol = data.index(b"\n", head)
        out += data[pos:head] + data[head : head + 74] + b"3" + data[head + 75 : b.start]
        rec = np.frombuffer(
            data, np.dtype([("id", "<i4"), ("v", "<f4", (len(b.components),))]), b.count, b.start
        )
        dbl = np.empty(b.count, np.dtype([("id", "<i4"), ("v", "<f8", (len(b.components),))]))
        dbl["id"], dbl["v"] = rec["id"], rec["v"]
        out += dbl.tobytes()
        pos = b.end
        assert eol < b.start
    out += data[pos:]
    path = tmp_path / "double.frd"
    path.write_bytes(bytes(out))
    a, b = read_contact(src), read_contact(path)
    np.testing.assert_array_equal(a.values, b.values)
    np.testing.assert_array_equal(a.points, b.points)


@pytest.mark.slow
def test_sample_tire_frd_against_its_reaction_and_export(coarse_static_tire):
    """The coarse sample tire of scripts/tiremodel (8-node bricks, node-to-surface penalty contact,
    8 increments; ~20 s): its .frd read directly against CalculiX's reaction and against the VTU
    the scripts export from the same file. Measured: N_fe 2.0e-4 from the reaction (the bilinear
    interpolation of CPRESS over the half-open faces at the contact rim, bound 1e-3); N, M0, R, F0
    within 2e-6 of the export (both read the same five-digit values; bound 1e-5).

    The deck lets the contact carry a tension of up to 1 Pa (CONTACT_TENSION) at a node just
    off the road: a few such CPRESS values at the contact rim are read as zero with a warning
    (the export clips them silently), and that is the only warning allowed."""
    out, keep, _ = coarse_static_tire  # solved once per session (tests/conftest.py), as test_e2e_ccx's
    frd = keep / "static" / "static.frd"
    side = json.loads((out / "static.json").read_text())
    steps = time_steps(frd)
    assert len(steps) > 1 and steps[-1].time == max(s.time for s in steps)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert build_patch(read_contact(frd)).N_fe == pytest.approx(side["reaction_z"], rel=1e-3)
        a, b = analyse(frd).coefficients, analyse(out / "static.vtu").coefficients
    for key in ("N", "M0", "R", "F0"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=1e-5), key
    tension = re.compile(r"static\.frd: \d+ small negative pressures \(>= (\S+) Pa, under 1% of the peak\)")
    for w in seen:
        found = tension.search(str(w.message))
        assert issubclass(w.category, PressureWarning) and found, w.message
        assert float(found.group(1)) >= -1.0, w.message


def _without_last_contact(path: Path, out: Path) -> Path:
    """The file with the CONTACT block of its last increment taken out (its DISP kept), as a
    last step without contact output writes it (CalculiX's ``contact10`` example)."""
    data = path.read_bytes()
    last = data.rindex(b" -4  CONTACT")
    start = data.rindex(b"    1PSTEP", 0, last)
    end = data.index(b" 9999", last)
    out.write_bytes(data[:start] + data[end:])
    return out


def test_a_last_step_without_contact_output_reads_the_last_with_it(cases, tmp_path):
    """No --step: the last increment holding a CONTACT block is read, with a note, and its load
    is CalculiX's reaction at that increment; an asked-for step without one is refused."""
    path, totals = cases["steps"]
    cut = _without_last_contact(path, tmp_path / "unloaded.frd")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        fld = read_contact(cut)
    assert fld.step == 2 and fld.time == pytest.approx(0.75)
    assert any("the last with a CONTACT block" in n for n in fld.notes)
    assert any(
        issubclass(w.category, ReaderWarning) and "holds no contact output" in str(w.message) for w in seen
    )
    assert build_patch(fld).N_fe == pytest.approx(totals[2][1], rel=ASCII_TOL)
    with pytest.raises(
        FieldError, match=r"no CONTACT block at step 3 \(t = 1\); contact output is at step\(s\) 0"
    ):
        read_contact(cut, step=3)


def test_a_binary_file_cut_inside_its_last_step_is_called_truncated(cases, tmp_path, capsys):
    path, totals = cases["steps"]
    data = path.read_bytes()
    cut = data.rindex(b"    1PSTEP", 0, data.rindex(b" -4  CONTACT"))
    short = tmp_path / "cut.frd"
    short.write_bytes(data[:cut])
    assert main(["coefficients", str(short)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith(f"fepost: error: {short}: truncated .frd file: it ends at byte {cut}")
    assert "*CONTACT FILE" not in err[-1]
    assert _n_fe(short, step=2) == pytest.approx(totals[2][1], rel=ASCII_TOL)


@pytest.mark.parametrize("into", [0, 5, 30, 60])
def test_a_binary_file_cut_in_the_step_line_before_its_first_contact_block_is_called_truncated(
    cases, tmp_path, capsys, into
):
    """A one-increment binary file cut at, or in the middle of, the ``1PSTEP`` line that opens
    its CONTACT block holds no CONTACT block at all: the file is called truncated (it has no
    closing 9999 line), not blamed on the deck's output requests."""
    data = cases["binary"][0].read_bytes()
    cut = data.rindex(b"    1PSTEP", 0, data.rindex(b" -4  CONTACT")) + into
    assert data[cut : cut + 1] != b"\n"  # inside the line
    short = tmp_path / "cut.frd"
    short.write_bytes(data[:cut])
    assert main(["coefficients", str(short)]) == 2
    err = [ln for ln in capsys.readouterr().err.strip().splitlines() if ln.strip()]
    assert err == [
        f"fepost: error: {short}: truncated .frd file: it ends at byte {cut} without CalculiX's closing "
        "9999 line (cut off while written?), in step 0 (t = 1), before its contact output"
    ]
