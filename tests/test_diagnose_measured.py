"""The measured-data CSV: parsing, validation, plausibility checks."""

from __future__ import annotations

import numpy as np
import pytest

from fepost.diagnose.measured import (
    MIN_ROWS,
    MeasuredData,
    UnitsWarning,
    check_plausible,
    parse_csv,
    read_measured,
    write_csv,
)
from fepost.errors import DataError, FepostError

GOOD = """# rig run 12, 2024-03-01
# units SI

vx,vy,wz,Fx,Fy,Mz,temperature
0.1,0,0,-900,1.5,0.2,21
  # a comment inside the data
0,0.1,0,2,-898,0.1,21

0,0,5,1,-2,-60,22
"""


def test_parse_skips_comments_and_blank_lines_and_ignores_other_columns():
    d = parse_csv(GOOD, "run12.csv")
    assert len(d) == 3
    assert d.vx.tolist() == [0.1, 0.0, 0.0]
    assert d.Mz.tolist() == [0.2, 0.1, -60.0]
    assert d.lines.tolist() == [5, 7, 9]
    assert d.N is None
    assert d.roll.tolist() == [0, 0, 0]
    assert d.forces.shape == (3, 3)


def test_optional_load_and_roll_columns():
    d = parse_csv("roll,N,vx,vy,wz,Fx,Fy,Mz\n1,4000,0.1,0,0,-1,0,0\n-1,5000,0,0,1,0,0,-1\n")
    assert d.roll.tolist() == [1, -1]
    assert d.N.tolist() == [4000.0, 5000.0]
    assert d.loads(1234.0).tolist() == [4000.0, 5000.0]


def test_arrays_are_read_only():
    d = parse_csv(GOOD)
    with pytest.raises(ValueError):
        d.Fx[0] = 1.0


def test_missing_columns_are_named():
    with pytest.raises(DataError) as exc:
        parse_csv("vx,vy,Fx,Fy\n1,2,3,4\n", "m.csv")
    assert str(exc.value) == "m.csv: missing column(s) wz, Mz in the header (found 'vx', 'vy', 'Fx', 'Fy')"


def test_non_numeric_cell_names_line_and_column():
    text = "vx,vy,wz,Fx,Fy,Mz\n0.1,0,0,-900,1,0\n0.2,0,0,abc,1,0\n"
    with pytest.raises(DataError) as exc:
        parse_csv(text, "m.csv")
    assert str(exc.value) == "m.csv: line 3, column Fx: not a number: 'abc'"


def test_empty_and_non_finite_cells():
    with pytest.raises(DataError, match=r"^m.csv: line 2, column Fy: not a number: 'an empty cell'$"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz\n0.1,0,0,-900,,0\n", "m.csv")
    with pytest.raises(DataError, match=r"^m.csv: line 2, column Mz: not a finite number: 'nan'$"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz\n0.1,0,0,-900,1,nan\n", "m.csv")


def test_short_row_and_bad_roll_and_bad_load():
    with pytest.raises(DataError, match=r"^line 2, column Fy: missing \(4 fields, the header has 6\)$"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz\n1,2,3,4\n")
    with pytest.raises(DataError, match=r"^line 2, column roll: must be -1, 0 or 1, got 2$"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz,roll\n1,0,0,-1,0,0,2\n")
    with pytest.raises(DataError, match=r"^line 2, column N: load must be positive \(N\), got -5.0$"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz,N\n1,0,0,-1,0,0,-5\n")


def test_empty_file_and_header_only():
    with pytest.raises(DataError, match="no header row"):
        parse_csv("# nothing\n\n")
    with pytest.raises(DataError, match="no data rows after the header"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz\n# none\n")


def test_duplicate_column():
    with pytest.raises(DataError, match=r"column 'Fx' appears twice"):
        parse_csv("vx,vy,wz,Fx,Fy,Mz,Fx\n1,0,0,-1,0,0,3\n")


def test_read_measured_missing_file(tmp_path):
    with pytest.raises(DataError, match=r"nope.csv: no such file$") as exc:
        read_measured(tmp_path / "nope.csv")
    assert isinstance(exc.value, FepostError) and isinstance(exc.value, ValueError)


def _data(n=40, scale=1.0, **over):
    rng = np.random.default_rng(0)
    ang = rng.uniform(0, 2 * np.pi, n)
    fields = {
        "vx": np.cos(ang), "vy": np.sin(ang), "wz": rng.choice([-5.0, 0.0, 5.0], n),
        "Fx": -900 * np.cos(ang) * scale,
        "Fy": -900 * np.sin(ang) * scale,
        "Mz": rng.normal(0, 20, n) * scale,
    }  # fmt: skip
    fields.update(over)
    return MeasuredData(**fields, source="m.csv")


def test_plausible_data_pass():
    check_plausible(_data(), friction=0.3, load=3000.0, radius=0.1, has_rolling=False)


def test_too_few_rows():
    with pytest.raises(DataError) as exc:
        check_plausible(_data(n=MIN_ROWS - 1), friction=0.3, load=3000.0, radius=0.1, has_rolling=False)
    assert str(exc.value) == (
        f"m.csv: {MIN_ROWS - 1} test points are too few: the candidate models and the 5-fold check "
        f"need at least {MIN_ROWS}"
    )


def test_all_zero_channel():
    with pytest.raises(
        DataError,
        match=r"^m.csv: column Mz is zero in every row: a dead channel cannot be diagnosed$",
    ):
        check_plausible(_data(Mz=np.zeros(40)), friction=0.3, load=3000.0, radius=0.1, has_rolling=False)


def test_roll_without_rolling_map_is_an_error():
    roll = np.zeros(40, int)
    roll[:3] = 1
    with pytest.raises(DataError, match=r"column roll: 3 rows have roll = ±1 but no rolling map was given"):
        check_plausible(_data(roll=roll), friction=0.3, load=3000.0, radius=0.1, has_rolling=False)
    check_plausible(_data(roll=roll), friction=0.3, load=3000.0, radius=0.1, has_rolling=True)


def test_forces_far_above_fN_name_the_column():
    # kN-sized numbers in N columns: |F| = 1000 x 900 N = 1000 x f N
    with pytest.raises(DataError, match=r"^m.csv: line \d+, column Fx: \|Fx\| is .* x f·N .*wrong units\?$"):
        check_plausible(_data(scale=1000.0), friction=0.3, load=3000.0, radius=0.1, has_rolling=False)
    big_mz = _data(Mz=np.linspace(4000.0, 5000.0, 40))
    with pytest.raises(DataError, match=r"column Mz: \|Mz\| is .* x f·N·R"):
        check_plausible(big_mz, friction=0.3, load=3000.0, radius=0.1, has_rolling=False)


def test_forces_far_below_fN_warn():
    with pytest.warns(UnitsWarning, match=r"columns Fx, Fy: the largest sliding force is 0.001 x f·N"):
        check_plausible(_data(scale=1e-3), friction=0.3, load=3000.0, radius=0.1, has_rolling=False)


def test_write_csv_round_trip(tmp_path):
    d = _data(N=np.full(40, 3000.0), roll=np.resize([0, 1, -1], 40))
    write_csv(d, tmp_path / "x.csv", comment="two\nlines")
    text = (tmp_path / "x.csv").read_text()
    assert text.startswith("# two\n# lines\nvx,vy,wz,Fx,Fy,Mz,N,roll\n")
    back = read_measured(tmp_path / "x.csv")
    for name in ("vx", "vy", "wz", "Fx", "Fy", "Mz", "N"):
        np.testing.assert_allclose(getattr(back, name), getattr(d, name), rtol=1e-9)
    assert back.roll.tolist() == d.roll.tolist()
