"""Malformed and hostile ``.frd`` files through ``fepost coefficients``: one-line error or the right load.

Base files: the small contact model of tests/test_reader_frd_decks.py solved by ``ccx``
(skipped without it), ASCII and binary, one and four increments. Seeded and
bounded: truncations at many points, byte mutations, huge declared counts,
text in binary, missing blocks, and NaN in some increments. Every case ends in

* exit 2 with exactly one ``fepost: error:`` line naming the file and no
  traceback; or
* exit 0 with N_fe equal to the unmutated file's (the mutation hit bytes that
  carry no data: the header, a displacement of a node off the contact, …)
  or, where it changed a contact value or a coordinate, N_fe finite and the
  result complete.
"""

from __future__ import annotations

import json
import random
import re
import time
from pathlib import Path

import numpy as np
import pytest
from test_reader_frd import HAVE_CCX, solve

from fepost.cli import main

pytestmark = [
    pytest.mark.ccx,
    pytest.mark.skipif(not HAVE_CCX, reason="CalculiX 'ccx' is not on PATH"),
    pytest.mark.usefixtures("small_accuracy_grid"),  # the checks are N_fe and the errors (conftest.py)
]
SEED = 20261125
ARGS = ("--nr", "16", "--nphi", "32")
#: A read of these small files takes well under a second; a hang would take the reader's deadline.
SLOW = 20.0


@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    root = tmp_path_factory.mktemp("frdfuzz")
    out = {}
    for name, kw in {
        "ascii": {},
        "binary": {"binary": True},
        "ascii4": {"increments": 4},
        "binary4": {"increments": 4, "binary": True},
    }.items():
        out[name] = solve(root / name, **kw)[0]
    return out


def _run(path: Path, capsys, extra=()) -> tuple[int, list[str], dict | None]:
    out = path.with_name(path.name + ".json")
    t0 = time.perf_counter()
    code = main(["coefficients", str(path), *ARGS, *extra, "--json", str(out)])
    assert time.perf_counter() - t0 < SLOW, path
    cap = capsys.readouterr()
    lines = [ln for ln in cap.err.splitlines() if ln.strip() and not re.search(r"Warning|warning:", ln)]
    result = json.loads(out.read_text()) if code == 0 and out.exists() else None
    return code, lines, result


def _one_line_error(path: Path, code: int, lines: list[str]) -> str:
    assert code == 2, (path, code, lines)
    assert len(lines) == 1, lines
    assert lines[0].startswith("fepost: error:") and str(path) in lines[0], lines[0]
    assert "Traceback" not in lines[0]
    return lines[0]


def _verdict(path: Path, capsys, reference: float) -> str:
    code, lines, result = _run(path, capsys)
    if code == 0:
        assert result is not None and np.isfinite(result["N_fe"]), (path, result)
        return "same" if result["N_fe"] == pytest.approx(reference, rel=1e-9) else "changed"
    return _one_line_error(path, code, lines)


def _reference(path: Path, capsys) -> float:
    code, lines, result = _run(path, capsys)
    assert code == 0 and result is not None, lines
    return float(result["N_fe"])


@pytest.mark.parametrize("name", ["ascii", "binary", "binary4"])
def test_truncated(bases, tmp_path, capsys, name):
    data = bases[name].read_bytes()
    reference = _reference(bases[name], capsys)
    rng = random.Random(SEED)
    cuts = sorted({1, 10, 100, len(data) - 6, len(data) - 1, *(rng.randrange(len(data)) for _ in range(14))})
    errors = 0
    for k, cut in enumerate(cuts):
        path = tmp_path / f"cut{k}.frd"
        path.write_bytes(data[:cut])
        verdict = _verdict(path, capsys, reference)
        errors += verdict.startswith("fepost: error:")
        if cut < len(data) - 10:
            assert verdict != "same" or cut > data.rfind(b"CONTACT"), (cut, verdict)
    assert errors >= len(cuts) - 3


def _second_reading(path: Path, tmp_path: Path) -> float | None:
    """N_fe of the mutated ASCII file as ccx2paraview parses it (its VTU read by fepost), or None."""
    from ccx2paraview.common import Converter

    work = tmp_path / f"c2p_{path.stem}"
    work.mkdir()
    copy = work / "job.frd"
    copy.write_bytes(path.read_bytes())
    try:
        Converter(str(copy), ["vtu"]).run()
    except Exception:  # ccx2paraview stops on what it cannot parse (SyntaxError, ValueError, ...)
        return None
    vtus = sorted(work.glob("*.vtu"))
    if not vtus:
        return None
    from fepost.patch import build_patch
    from fepost.reader import read_contact

    try:
        return build_patch(read_contact(vtus[-1])).N_fe
    except Exception:  # the converted file is refused by fepost's VTU path: no second value
        return None


@pytest.mark.parametrize("name", ["ascii", "binary"])
def test_mutated(bases, tmp_path, capsys, name):
    """Mutated files: refused in one line, or the clean file's N_fe, or (ASCII, a changed value)
    the N_fe of the same bytes parsed by ccx2paraview, to its float32 round-off. Besides random
    bytes, ASCII files get single digits of numbers changed (the format intact), to be read."""
    pytest.importorskip("ccx2paraview.common", reason="ccx2paraview is not installed")
    data = bytearray(bases[name].read_bytes())
    reference = _reference(bases[name], capsys)
    rng = random.Random(SEED + len(name))
    seen: dict[str, int] = {}
    digits = [m.start() for m in re.finditer(rb"\d(?=\.\d{5}E)", bytes(data))]  # leading digits (ASCII)
    for k in range(25 + (8 if digits else 0)):
        mutated = bytearray(data)
        if k >= 25:  # a number changed, the format intact: a value of the contact or a coordinate
            mutated[rng.choice(digits)] = ord(str(rng.randrange(1, 10)))
        for _ in range(rng.choice((1, 4, 32)) if k < 25 else 0):
            mutated[rng.randrange(len(mutated))] = rng.randrange(256)
        path = tmp_path / f"mut{k}.frd"
        path.write_bytes(bytes(mutated))
        verdict = _verdict(path, capsys, reference).split(":")[0]
        if verdict == "changed" and name == "ascii":
            code, _, result = _run(path, capsys)
            second = _second_reading(path, tmp_path)
            if second is not None:
                assert result["N_fe"] == pytest.approx(second, rel=1e-6), path
                verdict = "changed, confirmed by ccx2paraview"
        seen[verdict] = seen.get(verdict, 0) + 1
    assert seen.get("fepost", 0) >= 10, seen  # most mutations are refused; none crash or hang
    assert seen.get("changed", 0) <= 2, seen  # results that differ are confirmed by a second parser
    if name == "ascii":
        assert seen.get("changed, confirmed by ccx2paraview", 0) >= 1, seen


def _replace_count(data: bytes, key: bytes, new: int) -> bytes:
    i = data.index(key)
    line_end = data.index(b"\n", i)
    line = data[i:line_end]
    return data[:i] + line[:24] + f"{new:12d}".encode() + line[36:] + data[line_end:]


@pytest.mark.parametrize("name", ["ascii", "binary"])
@pytest.mark.parametrize("key", [b"    2C", b"    3C", b"  100C"])
@pytest.mark.parametrize("count", [999_999_999_999, 2**31, -5, 0])
def test_huge_and_wrong_counts(bases, tmp_path, capsys, name, key, count):
    data = _replace_count(bases[name].read_bytes(), key, count)
    path = tmp_path / "count.frd"
    path.write_bytes(data)
    code, lines, _ = _run(path, capsys)
    msg = _one_line_error(path, code, lines)
    assert "memory" not in msg  # refused from the header, before anything is allocated


def test_text_in_binary_and_binary_in_text(bases, tmp_path, capsys):
    binary = bases["binary"].read_bytes()
    start = binary.index(b"\n", binary.index(b"    2C")) + 1
    text = (
        binary[:start]
        + b" -1         1 1.00000E+00 2.00000E+00 3.00000E+00\n" * 200
        + binary[start + 200 * 51 :]
    )
    (tmp_path / "t.frd").write_bytes(text)
    _one_line_error(tmp_path / "t.frd", *_run(tmp_path / "t.frd", capsys)[:2])
    ascii_ = bases["ascii"].read_bytes()
    start = ascii_.index(b"\n", ascii_.index(b"    3C")) + 1
    garbage = (
        ascii_[:start]
        + bytes(random.Random(SEED).randrange(256) for _ in range(3000))
        + ascii_[start + 3000 :]
    )
    (tmp_path / "g.frd").write_bytes(garbage)
    _one_line_error(tmp_path / "g.frd", *_run(tmp_path / "g.frd", capsys)[:2])


def _without(data: bytes, key: bytes) -> bytes:
    i = data.index(key)
    end = data.index(b"\n -3\n", i) + 5
    return data[:i] + data[end:]


def test_missing_blocks(bases, tmp_path, capsys):
    data = bases["ascii"].read_bytes()
    cases = {
        "nonodes": (_without(data, b"    2C"), "no node block"),
        "noelements": (_without(data, b"    3C"), "no mesh"),
        "empty": (b"    1C\n 9999\n", "no node block"),
        "notfrd": (b"hello world\n" * 10, "corrupt or truncated .frd"),
    }
    i = data.index(b"    1PSTEP", data.index(b"CONTACT") - 400)
    cases["nocontact"] = (data[:i] + data[data.index(b" 9999", i) :], "*CONTACT FILE")
    cases["noresults"] = (data[: data.index(b"    1PSTEP")] + b" 9999\n", "no results")
    for name, (content, words) in cases.items():
        path = tmp_path / f"{name}.frd"
        path.write_bytes(content)
        msg = _one_line_error(path, *_run(path, capsys)[:2])
        assert words in msg, (name, msg)


def test_nan_in_some_increments(bases, tmp_path, capsys):
    """NaN contact values in increments 2 and 3 of 4: those are refused or read by the NaN rules,
    the others give the clean file's loads."""
    src = bases["ascii4"]
    text = src.read_text(encoding="latin-1")
    blocks = [m.start() for m in re.finditer(r" -4  CONTACT", text)]
    assert len(blocks) == 4
    out = text[: blocks[1]]
    for k, start in enumerate(blocks[1:], start=1):
        stop = blocks[k + 1] if k + 1 < len(blocks) else len(text)
        part = text[start:stop]
        if k in (1, 2):
            part = re.sub(
                r"(?m)^( -1\s+\d+)(.{36}).{12}", lambda m: m.group(1) + m.group(2) + "         NaN", part
            )
        out += part
    path = tmp_path / "nan.frd"
    path.write_text(out, encoding="latin-1")
    for step in range(4):
        clean = _run(src, capsys, ("--step", str(step)))
        code, lines, result = _run(path, capsys, ("--step", str(step)))
        if step in (0, 3):
            assert code == 0 and result["N_fe"] == pytest.approx(clean[2]["N_fe"], rel=1e-12)
        elif code == 0:
            assert np.isfinite(result["N_fe"]) and result["N_fe"] < clean[2]["N_fe"]
        else:
            msg = _one_line_error(path, code, lines)
            assert "NaN" in msg or "nan" in msg, msg


def test_duplicate_and_unknown_nodes(bases, tmp_path, capsys):
    data = bases["ascii"].read_text(encoding="latin-1")
    node_line = re.search(r"(?m)^ -1         2(.{36})$", data)
    dup = data.replace(node_line.group(0), " -1         1" + node_line.group(1), 1)
    (tmp_path / "dup.frd").write_text(dup, encoding="latin-1")
    msg = _one_line_error(tmp_path / "dup.frd", *_run(tmp_path / "dup.frd", capsys)[:2])
    assert "defined twice" in msg
    i = data.index(" -4  CONTACT")
    j = data.index("\n -1", i) + 1
    unknown = data[:j] + " -1     99999" + data[j + 13 :]
    (tmp_path / "unknown.frd").write_text(unknown, encoding="latin-1")
    msg = _one_line_error(tmp_path / "unknown.frd", *_run(tmp_path / "unknown.frd", capsys)[:2])
    assert "node 99999" in msg


def test_hostile_headers(bases, tmp_path, capsys):
    data = bases["binary4"].read_bytes()
    head = data.index(b"  100C")
    line = data[head : data.index(b"\n", head)]
    minus4 = data.index(b" -4  ", head)
    minus4_end = data.index(b"\n", minus4)
    cases = {
        "nan_time": (data.replace(line, line[:12] + b"         nan" + line[24:], 1), "not a finite number"),
        "inf_time": (data.replace(line, line[:12] + b"         inf" + line[24:], 1), "not a finite number"),
        "format9": (data.replace(line, line[:74] + b"9" + line[75:], 1), "format 9"),
        "components": (data[:minus4] + b" -4  DISP     9999    1" + data[minus4_end:], "components"),
        "unknown_key": (data[:head] + b"    7C  what is this\n" + data[head:], "unexpected line"),
        "long_line": (data[:head] + b"x" * 5000 + data[head:], "no line break"),
    }
    for name, (content, words) in cases.items():
        path = tmp_path / f"{name}.frd"
        path.write_bytes(content)
        msg = _one_line_error(path, *_run(path, capsys)[:2])
        assert words in msg, (name, msg)
