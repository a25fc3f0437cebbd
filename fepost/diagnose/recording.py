"""Rig recordings: long time series in the rig's own files, channels and units, read in chunks.

A recording has one row per sample: ``time`` (s), the kinematics ``vx``, ``vy``
(m/s), ``wz`` (rad/s), the channels ``Fx``, ``Fy`` (N), ``Mz`` (N·m), and
optionally ``N`` (N), ``roll`` and ``point`` (a test-point number given by the
rig: `fepost.diagnose.holds` then takes the holds from it). Formats, by
suffix:

========================= ==========================================================
``.csv``, ``.txt``        header row, comma-separated (``#`` comment lines only
                          before the header); pyarrow's streaming CSV reader
``.parquet``, ``.pq``     pyarrow, row group batches
``.mat``                  MATLAB v5 (scipy.io.loadmat: one vector per channel, at
                          the top level or as fields of one struct; v5 cannot be
                          read in parts, so its channels are loaded whole) and
                          v7.3 (HDF5, h5py: read in slices)
``.tdx``                  TYDEX: the ``**MEASURCHANNELS`` section names the
                          columns (name first, then description and unit; numbers
                          at the end of a line are the conversion Factor, MeasOffset,
                          PhysOffset: value = (stored − MeasOffset)·Factor +
                          PhysOffset), ``**MEASURDATA`` holds whitespace-separated
                          rows up to ``**END``; ``!`` lines are comments
========================= ==========================================================

**Column mapping** (`Columns`): ``--columns Fx=FX_N,Mz=MZ_Nm`` names the
source column of a channel; without it each channel is found under its own name
or a common alias (`ALIASES`, matched without regard to case, e.g.
``FX``, ``Force_X``, ``RUNTIME``; ``Fz``/``FZ`` for ``N``, whose sign is dropped:
rigs record the load as a compressive, often negative, Fz). **Units**: each
channel is converted to SI with a factor from `UNITS` (``--channel-units
Fx=kN,wz=deg/s``); TYDEX files state their units, which are used when no unit
is given. Unknown units and missing channels are one-line
`fepost.errors.DataError` naming the file and the column. Non-finite values
(empty cells, ``nan``, ``inf``: a channel that dropped out) are passed on as NaN;
`fepost.diagnose.gaps` finds them and the holds leave them out.

Reading streams `CHUNK_ROWS` rows at a time (Parquet batches, CSV blocks,
HDF5 slices), so the caller (`fepost.diagnose.holds.find_holds`) holds one
chunk and one hold in memory, not the recording.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ArgumentError, DataError

#: Rows per chunk read.
CHUNK_ROWS = 1_000_000
#: The channels a recording may give; the first seven are needed (``N``, ``roll``, ``point`` optional).
NEEDED = ("time", "vx", "vy", "wz", "Fx", "Fy", "Mz")
OPTIONAL = ("N", "roll", "point")
SUFFIXES = (".csv", ".txt", ".parquet", ".pq", ".mat", ".tdx")

#: Common source names of each channel (compared in lower case, after the channel's own name).
ALIASES: dict[str, tuple[str, ...]] = {
    "time": ("t", "time_s", "runtime", "timestamp", "zeit"),
    "vx": ("v_x", "vx_ms", "vslip_x", "slip_velocity_x", "sliding_velocity_x"),
    "vy": ("v_y", "vy_ms", "vslip_y", "slip_velocity_y", "sliding_velocity_y"),
    "wz": ("w_z", "omega_z", "omegaz", "spin", "yaw_rate", "wz_rads"),
    "Fx": ("fx_n", "force_x", "forcex"),
    "Fy": ("fy_n", "force_y", "forcey"),
    "Mz": ("mz_nm", "moment_z", "torque_z", "momentz"),
    "N": ("fz", "fz_n", "normal_load", "load", "force_z"),
    "roll": ("rolling", "roll_direction"),
    "point": ("point_id", "test_point", "step", "point_no"),
}
#: Source names whose sign is dropped (a compressive Fz recorded as negative).
ABSOLUTE = ("fz", "fz_n", "force_z")

_FORCE = {"N": 1.0, "kN": 1e3, "daN": 10.0, "lbf": 4.4482216152605, "kgf": 9.80665}
_MOMENT = {"N·m": 1.0, "Nm": 1.0, "N*m": 1.0, "N.m": 1.0, "kNm": 1e3, "kN·m": 1e3, "kN*m": 1e3,
           "lbf·ft": 1.3558179483314, "lbf*ft": 1.3558179483314, "Nmm": 1e-3, "N*mm": 1e-3}  # fmt: skip
_SPEED = {"m/s": 1.0, "km/h": 1.0 / 3.6, "kph": 1.0 / 3.6, "mm/s": 1e-3, "mph": 0.44704}
_RATE = {"rad/s": 1.0, "1/s": 1.0, "deg/s": np.pi / 180.0, "rpm": 2.0 * np.pi / 60.0, "rev/s": 2.0 * np.pi}
_TIME = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "min": 60.0}
#: Accepted units of each channel and their factor to SI.
UNITS: dict[str, dict[str, float]] = {
    "time": _TIME, "vx": _SPEED, "vy": _SPEED, "wz": _RATE, "Fx": _FORCE, "Fy": _FORCE, "Mz": _MOMENT,
    "N": _FORCE, "roll": {"1": 1.0, "-": 1.0}, "point": {"1": 1.0, "-": 1.0},
}  # fmt: skip


def _parse_pairs(text: str | None, what: str) -> dict[str, str]:
    out: dict[str, str] = {}
    if not text:
        return out
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise ArgumentError(f"{what}: expected NAME=VALUE pairs separated by commas, got {item!r}")
        if key not in UNITS:
            raise ArgumentError(f"{what}: unknown channel {key!r} (one of {', '.join(UNITS)})")
        out[key] = value
    return out


@dataclass(frozen=True)
class Columns:
    """Where each channel is in the source (``names``) and its unit (``units``); empty = defaults."""

    names: dict[str, str] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for ch, unit in self.units.items():
            if ch not in UNITS:
                raise ArgumentError(f"--channel-units: unknown channel {ch!r} (one of {', '.join(UNITS)})")
            if unit not in UNITS[ch]:
                raise ArgumentError(
                    f"--channel-units: unit {unit!r} of {ch} is not one of {', '.join(UNITS[ch])}"
                )

    @classmethod
    def parse(cls, columns: str | None = None, units: str | None = None) -> Columns:
        """From the command line's ``--columns Fx=FX_N,...`` and ``--channel-units Fx=kN,...``."""
        return cls(_parse_pairs(columns, "--columns"), _parse_pairs(units, "--channel-units"))

    def resolve(self, available: list[str], source: str) -> dict[str, str]:
        """channel -> source column for the ``available`` names; a needed channel missing is an error."""
        lower = {a.lower(): a for a in available}
        found: dict[str, str] = {}
        for ch in NEEDED + OPTIONAL:
            if ch in self.names:
                name = self.names[ch]
                if name not in available:
                    raise DataError(
                        f"{source}: column {name!r} (given for {ch} by --columns) is not in the file"
                    )
                found[ch] = name
                continue
            for cand in (ch.lower(), *ALIASES.get(ch, ())):
                if cand in lower:
                    found[ch] = lower[cand]
                    break
        missing = [ch for ch in NEEDED if ch not in found]
        if missing:
            raise DataError(
                f"{source}: no column for {', '.join(missing)} (columns: {', '.join(available[:20])}); "
                "name them with --columns, e.g. --columns Fx=FX_N"
            )
        return found


@dataclass(frozen=True)
class Chunk:
    """One block of rows in SI: channel -> array (float64); ``start`` its first row (0-based);
    ``names``: channel -> its column in the source (for messages)."""

    start: int
    values: dict[str, np.ndarray]
    names: dict[str, str] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(next(iter(self.values.values())).size)


def recording_suffix(path) -> str:
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        raise DataError(f"{path}: unknown recording format {suffix!r} (one of {', '.join(SUFFIXES)})")
    return suffix


def _leading_comments(path: Path) -> int:
    n = 0
    with path.open("r", encoding="utf-8", errors="replace") as fh:
        for line in fh:
            s = line.strip()
            if s and not s.startswith("#"):
                return n
            n += 1
    return n


def _csv_batches(path: Path, wanted) -> Iterator[tuple[dict, Any]]:
    import pyarrow as pa
    from pyarrow import csv

    skip = _leading_comments(path)
    opts = csv.ReadOptions(skip_rows=skip, block_size=64 << 20)
    header = csv.open_csv(path, read_options=csv.ReadOptions(skip_rows=skip, block_size=1 << 16))
    names = header.schema.names
    cols = wanted(names)
    conv = csv.ConvertOptions(include_columns=list(cols.values()),
                              column_types={c: pa.float64() for c in cols.values()})  # fmt: skip
    try:
        reader = csv.open_csv(path, read_options=opts, convert_options=conv)
        for batch in reader:
            yield cols, batch
    except pa.ArrowInvalid as exc:
        msg = str(exc).splitlines()[0]
        raise DataError(f"{path}: not a numeric CSV recording ({msg})") from None


def _parquet_batches(path: Path, wanted) -> Iterator[tuple[dict, Any]]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        pf = pq.ParquetFile(path)
    except (pa.ArrowInvalid, OSError) as exc:
        raise DataError(f"{path}: not a Parquet file ({str(exc).splitlines()[0]})") from None
    cols = wanted(pf.schema_arrow.names)
    for batch in pf.iter_batches(batch_size=CHUNK_ROWS, columns=list(cols.values())):
        yield cols, batch


def _tdx_layout(path: Path) -> tuple[list[str], dict[str, tuple[str, float, float, float]], int]:
    """TYDEX channels (name, unit, factor, offsets) and the line where MEASURDATA begins."""
    names: list[str] = []
    info: dict[str, tuple[str, float, float, float]] = {}
    section = ""
    with path.open("r", encoding="utf-8", errors="replace") as fh:
        for lineno, line in enumerate(fh, 1):
            s = line.strip()
            if s.startswith("**"):
                section = s[2:].upper()
                if section == "MEASURDATA":
                    return names, info, lineno
                continue
            if section != "MEASURCHANNELS" or not s or s.startswith("!"):
                continue
            tokens = s.split()
            nums: list[float] = []
            while len(tokens) > 1 and re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", tokens[-1]):
                nums.insert(0, float(tokens.pop()))
            unit = tokens[-1] if len(tokens) > 1 else ""
            factor, meas_off, phys_off = (
                (nums + [1.0, 0.0, 0.0][len(nums) :])[:3] if nums else (1.0, 0.0, 0.0)
            )
            names.append(tokens[0])
            info[tokens[0]] = (unit, factor, meas_off, phys_off)
    raise DataError(f"{path}: no **MEASURDATA section: not a TYDEX file")


def _tdx_batches(path: Path, wanted) -> Iterator[tuple[dict, Any]]:
    import pyarrow as pa
    from pyarrow import csv

    names, info, start = _tdx_layout(path)
    cols = wanted(names)
    ropts = csv.ReadOptions(column_names=names, block_size=64 << 20)
    popts = csv.ParseOptions(delimiter=" ", ignore_empty_lines=True)
    conv = csv.ConvertOptions(include_columns=list(cols.values()),
                              column_types={c: pa.float64() for c in cols.values()})  # fmt: skip
    text = _tdx_rows(path, start)
    try:
        for batch in csv.open_csv(text, read_options=ropts, parse_options=popts, convert_options=conv):
            yield cols, batch
    except pa.ArrowInvalid as exc:
        raise DataError(
            f"{path}: **MEASURDATA is not a table of numbers ({str(exc).splitlines()[0]})"
        ) from None


def _tdx_rows(path: Path, start: int):
    """A file-like object of the MEASURDATA rows with runs of blanks made single (pyarrow splits on one)."""
    import io

    class Rows(io.RawIOBase):
        def __init__(self) -> None:
            self.fh = path.open("rb")
            self.buf = b""
            self.done = False
            for _ in range(start):
                self.fh.readline()

        def readable(self) -> bool:
            return True

        def readinto(self, b) -> int:
            while len(self.buf) < len(b) and not self.done:
                lines = self.fh.readlines(1 << 20)
                if not lines:
                    self.done = True
                    break
                out = []
                for ln in lines:
                    s = ln.strip()
                    if not s or s.startswith((b"!", b"**")):
                        if s.upper().startswith(b"**END"):
                            self.done = True
                            break
                        continue
                    out.append(b" ".join(s.split()))
                if out:
                    self.buf += b"\n".join(out) + b"\n"
            n = min(len(b), len(self.buf))
            b[:n] = self.buf[:n]
            self.buf = self.buf[n:]
            return n

        def close(self) -> None:
            self.fh.close()
            super().close()

    return io.BufferedReader(Rows(), buffer_size=1 << 20)


def _mat_columns(path: Path, wanted) -> Iterator[tuple[dict, dict]]:
    with path.open("rb") as fh:
        head = fh.read(128)
    if head[:19] == b"MATLAB 7.3 MAT-file" or head.startswith(b"\x89HDF"):
        yield from _mat73_columns(path, wanted)
        return
    from scipy import io as sio

    try:
        top = sio.whosmat(path)
    except (ValueError, OSError) as exc:
        raise DataError(f"{path}: not a MATLAB .mat file ({exc})") from None
    names = [n for n, _shape, _cls in top]
    structs = [n for n, _shape, cls in top if cls == "struct"]
    if len(structs) == 1 and len(names) == 1:
        mat = sio.loadmat(path, variable_names=structs, squeeze_me=True, struct_as_record=False)
        obj = mat[structs[0]]
        fields = list(obj._fieldnames)
        cols = wanted(fields)
        yield cols, {name: np.asarray(getattr(obj, name), float).ravel() for name in cols.values()}
        return
    cols = wanted(names)
    mat = sio.loadmat(path, variable_names=list(cols.values()), squeeze_me=True)
    yield cols, {name: np.asarray(mat[name], float).ravel() for name in cols.values()}


def _mat73_columns(path: Path, wanted) -> Iterator[tuple[dict, dict]]:
    try:
        import h5py
    except ImportError:
        raise DataError(f"{path}: MATLAB v7.3 files need h5py (pip install h5py)") from None
    with h5py.File(path, "r") as f:
        group = f
        top = [k for k in f if not k.startswith("#")]
        if len(top) == 1 and isinstance(f[top[0]], h5py.Group):
            group = f[top[0]]
            top = list(group.keys())
        cols = wanted(top)
        sets = {name: group[name] for name in cols.values()}
        n = max(int(np.prod(d.shape)) for d in sets.values())
        for start in range(0, n, CHUNK_ROWS):
            stop = min(start + CHUNK_ROWS, n)
            block = {}
            for name, d in sets.items():
                if d.ndim == 2 and d.shape[0] == 1:
                    block[name] = np.asarray(d[0, start:stop], float)
                elif d.ndim == 2:
                    block[name] = np.asarray(d[start:stop, 0], float)
                else:
                    block[name] = np.asarray(d[start:stop], float)
            yield cols, block


def read_chunks(path, columns: Columns | None = None) -> Iterator[Chunk]:
    """The recording at ``path`` as SI chunks (module docstring)."""
    path = Path(path)
    if not path.is_file():
        raise DataError(f"{path}: no such file")
    columns = columns or Columns()
    suffix = recording_suffix(path)
    units = dict(columns.units)
    source = str(path)

    def wanted(names):
        return columns.resolve(list(names), source)

    if suffix == ".tdx":
        _, info, _ = _tdx_layout(path)
        batches = _tdx_batches(path, wanted)
    elif suffix in (".parquet", ".pq"):
        info, batches = {}, _parquet_batches(path, wanted)
    elif suffix == ".mat":
        info, batches = {}, _mat_columns(path, wanted)
    else:
        info, batches = {}, _csv_batches(path, wanted)
    start = 0
    for cols, batch in batches:
        values = {}
        for ch, name in cols.items():
            raw = (
                batch[name] if isinstance(batch, dict) else batch.column(name).to_numpy(zero_copy_only=False)
            )
            values[ch] = _to_si(np.asarray(raw, float), ch, name, units, info.get(name), source)
        if values and len(next(iter(values.values()))):
            chunk = Chunk(start, values, dict(cols))
            start += len(chunk)
            yield chunk
    if start == 0:
        raise DataError(f"{path}: no data rows")


def _to_si(raw, ch, name, units, tdx, source) -> np.ndarray:
    """One column in SI: TYDEX conversion, then the unit's factor; absolute value for Fz sources.

    Non-finite values stay non-finite (NaN or ±inf; module docstring).
    """
    if tdx is not None:
        unit, factor, meas_off, phys_off = tdx
        raw = (raw - meas_off) * factor + phys_off
        if ch not in units and unit in UNITS[ch]:
            units = {**units, ch: unit}
        elif ch not in units and unit and ch not in ("roll", "point"):
            raise DataError(
                f"{source}: column {name}: unit {unit!r} of {ch} is not one of {', '.join(UNITS[ch])}"
            )
    out = raw * UNITS[ch][units.get(ch, next(iter(UNITS[ch])))]
    if ch == "N" and name.lower() in ABSOLUTE:
        out = np.abs(out)
    return out
