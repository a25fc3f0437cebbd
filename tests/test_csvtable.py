"""The CSV reader shared by the measured data (diagnose) and the kinematics (predict)."""

from __future__ import annotations

import csv
import re

import numpy as np
import pytest

from fepost.csvtable import MAX_CELL, CsvFormat, parse_table, read_table
from fepost.diagnose.measured import MEASURED, parse_csv, read_measured
from fepost.errors import DataError, FepostError
from fepost.friction.predict import KINEMATICS, parse_kinematics, read_kinematics

FMT = CsvFormat(required=("a", "b"), optional=("c",), what="test data", kind="test CSV file")


def test_columns_by_name_comments_blank_lines_and_other_columns():
    text = "# head\n\nname,b,a\n# between\nx,2,1\n\n y ,4.5, -3e2 \n"
    t = parse_table(text, FMT, "t.csv")
    assert t["a"].tolist() == [1.0, -300.0] and t["b"].tolist() == [2.0, 4.5]
    assert t.get("c") is None and "c" not in t.values and len(t) == 2
    assert t.lines.tolist() == [5, 7] and t.where(1) == "t.csv: line 7"
    with pytest.raises(ValueError):
        t["a"][0] = 0.0
    with pytest.raises(TypeError):
        t.values["a"] = np.zeros(2)  # type: ignore[index]


def test_values_agree_with_numpy_loadtxt(tmp_path):
    rng = np.random.default_rng(3)
    table = rng.normal(size=(50, 3)) * 10.0 ** rng.integers(-8, 8, size=(50, 3))
    path = tmp_path / "n.csv"
    np.savetxt(path, table, delimiter=",", header="a,c,b", comments="", fmt="%.17g")
    t = read_table(path, FMT)
    again = np.loadtxt(path, delimiter=",", skiprows=1)
    assert np.array_equal(np.column_stack([t["a"], t["c"], t["b"]]), again)
    assert t.lines.tolist() == list(range(2, 52)) and t.source == str(path)


def test_bom_and_crlf_files_read_like_plain_ones(tmp_path):
    plain, variant = tmp_path / "p.csv", tmp_path / "v.csv"
    plain.write_text("a,b\n1,2\n3,4\n")
    variant.write_bytes("\ufeffa,b\r\n\r\n1,2\r\n3,4\r\n".encode())
    p, v = read_table(plain, FMT), read_table(variant, FMT)
    assert p["a"].tolist() == v["a"].tolist() == [1.0, 3.0] and v.lines.tolist() == [3, 4]


BAD = [
    ("", "no header row: the file is empty or only comments"),
    ("# c\n\n  # c\n", "no header row: the file is empty or only comments"),
    ("a,b\n# none\n", "no data rows after the header"),
    ("a,x\n1,2\n", "missing column(s) b in the header (found 'a', 'x')"),
    (",\n1,2\n", "missing column(s) a, b in the header (found none)"),
    ("a,b,a\n1,2,3\n", "line 1: column 'a' appears twice in the header"),
    ("a,b\n1,2\n3\n", "line 3, column b: missing (1 fields, the header has 2)"),
    ("a,b\n1,x\n", "line 2, column b: not a number: 'x'"),
    ("a,b\n1, \n", "line 2, column b: not a number: 'an empty cell'"),
    ("a,b\n1,nan\n", "line 2, column b: not a finite number: 'nan'"),
    ("a,b\n-1e999,1\n", "line 2, column a: not a finite number: '-1e999'"),
    (
        "a,b\n1,2\n" + "1," + "9" * (MAX_CELL + 1) + "\n",
        f"line 3: a cell is longer than {MAX_CELL} characters",
    ),
]


@pytest.mark.parametrize("text,message", BAD)
def test_bad_tables_one_line_naming_file_line_and_column(text, message):
    with pytest.raises(DataError) as exc:
        parse_table(text, FMT, "t.csv")
    assert str(exc.value) == f"t.csv: {message}"
    assert isinstance(exc.value, FepostError) and isinstance(exc.value, ValueError)
    with pytest.raises(DataError) as exc:
        parse_table(text, FMT)
    assert str(exc.value) == message


def test_unread_columns_may_hold_anything_and_duplicates_there_are_allowed():
    t = parse_table("note,a,note,b\nfast,1,slow,2\n", FMT)
    assert t["a"].tolist() == [1.0] and t["b"].tolist() == [2.0]


def test_cell_limit_does_not_depend_on_the_csv_modules_limit():
    previous = csv.field_size_limit(10 * MAX_CELL)
    try:
        with pytest.raises(DataError, match=rf"^t.csv: line 2: a cell is longer than {MAX_CELL} characters$"):
            parse_table("a,b\n1," + "9" * (MAX_CELL + 1) + "\n", FMT, "t.csv")
    finally:
        csv.field_size_limit(previous)


def test_a_line_the_csv_module_refuses_is_named(monkeypatch):
    def refuse(lines):
        raise csv.Error("bad quoting")

    monkeypatch.setattr("fepost.csvtable.csv.reader", refuse)
    with pytest.raises(DataError, match=r"^t.csv: line 1: not a CSV line \(bad quoting\)$"):
        parse_table("a,b\n1,2\n", FMT, "t.csv")


def test_row_limit_counted_before_parsing():
    fmt = CsvFormat(required=("a",), max_rows=3, too_many_rows="at most 3 here")
    assert len(parse_table("a\n1\n# c\n2\n\n3\n", fmt)) == 3
    with pytest.raises(DataError, match=r"^t.csv: 4 data rows: at most 3 here$"):
        parse_table("a\n1\n2\n3\nnot a number\n", fmt, "t.csv")


def test_files_missing_folder_binary_undecodable_and_too_large(tmp_path):
    fmt = CsvFormat(required=("a",), what="test data", kind="test CSV file", max_bytes=100, too_large="tests")
    cases = {
        tmp_path / "none.csv": "no such file",
        tmp_path: "is a folder, not a test CSV file",
    }
    (tmp_path / "bin.csv").write_bytes(b"a\n1\x00\n")
    cases[tmp_path / "bin.csv"] = "not a text CSV file (binary data)"
    (tmp_path / "latin.csv").write_bytes("a\n1\xe9\n".encode("latin-1"))
    cases[tmp_path / "latin.csv"] = "cannot read the test data (UnicodeDecodeError)"
    (tmp_path / "big.csv").write_text("a\n" + "1\n" * 100)
    cases[tmp_path / "big.csv"] = "0 MB is too large for tests"
    for path, message in cases.items():
        with pytest.raises(DataError) as exc:
            read_table(path, fmt)
        assert str(exc.value) == f"{path}: {message}"
    (tmp_path / "small.csv").write_text("a\n" + "1\n" * 49)
    assert len(read_table(tmp_path / "small.csv", fmt)) == 49


# --- the two formats read through it -----------------------------------------------------------


def test_both_formats_refuse_the_same_fault_with_the_same_message(tmp_path):
    faults = {
        "short": ("1,2\n", "line 3, column wz: missing (2 fields, the header has {n})"),
        "text": ("1,x,3,4,5,6\n", "line 3, column vy: not a number: 'x'"),
        "nan": ("1,2,nan,4,5,6\n", "line 3, column wz: not a finite number: 'nan'"),
        "long": ("1," + "9" * (MAX_CELL + 1) + "\n", f"line 3: a cell is longer than {MAX_CELL} characters"),
    }
    for name, (row, message) in faults.items():
        for head, reader in (("vx,vy,wz", read_kinematics), ("vx,vy,wz,Fx,Fy,Mz", read_measured)):
            path = tmp_path / f"{name}-{reader.__name__}.csv"
            path.write_text(f"{head}\n{','.join(['0.5'] * len(head.split(',')))}\n{row}")
            with pytest.raises(DataError) as exc:
                reader(path)
            assert str(exc.value) == f"{path}: " + message.format(n=len(head.split(","))), name


def test_format_words_in_file_messages(tmp_path):
    for reader, what, kind in (
        (read_kinematics, "kinematics", "CSV file"),
        (read_measured, "measured data", "measured-data CSV file"),
    ):
        with pytest.raises(DataError, match=rf"^{re.escape(str(tmp_path))}: is a folder, not a {kind}$"):
            reader(tmp_path)
        bad = tmp_path / "latin.csv"
        bad.write_bytes("vx\n1\xe9\n".encode("latin-1"))
        with pytest.raises(
            DataError, match=rf"^{re.escape(str(bad))}: cannot read the {what} \(UnicodeDecodeError\)$"
        ):
            reader(bad)
    assert KINEMATICS.max_rows is None and KINEMATICS.max_bytes is None
    assert MEASURED.max_rows == 5000 and MEASURED.max_bytes == 64 * 2**20


def test_kinematics_and_measured_keep_their_columns_and_lines():
    k = parse_kinematics("# k\nwz,vx,other,vy\n3,1,abc,2\n\n6,4,,5\n", "k.csv")
    assert (k.vx.tolist(), k.vy.tolist(), k.wz.tolist(), k.lines.tolist()) == ([1, 4], [2, 5], [3, 6], [3, 5])
    m = parse_csv("time,Mz,Fy,Fx,wz,vy,vx,roll\n0,6,5,4,3,2,1,-1\n1,1,1,1,1,1,1,0\n", "m.csv")
    assert m.forces.tolist() == [[4, 5, 6], [1, 1, 1]] and m.roll.tolist() == [-1, 0]
    assert m.time.tolist() == [0, 1] and m.N is None and m.lines.tolist() == [2, 3]
