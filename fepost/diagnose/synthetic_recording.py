"""Synthetic rig recordings: test points held for seconds, ramps between them, autocorrelated noise.

`synthetic_recording` turns the noise-free test points of a
`fepost.diagnose.synthetic.SyntheticData` (a hidden effect already in
them) into what a rig writes: each point held for ``hold`` s at ``rate`` Hz,
joined by linear ramps of ``ramp`` s (kinematics and forces both ramp), with
AR(1) noise (lag-1 correlation ``rho``, stationary SD ``sd`` per force channel)
added to every sample. Every length is in seconds, so one test can be written
at any logging rate: ``tau`` gives the noise's correlation time in seconds
instead of ``rho`` (ρ = exp(−1/(rate·τ)), the same noise in time at every rate),
``cutoff`` passes the force channels through a logger's anti-alias filter (a
causal second-order Butterworth low-pass, Hz, started at rest on the first
sample; the commanded kinematics are digital and are written as they are), and
``repeat`` holds each written value of every channel for that many samples (a
logger that writes faster than its converter and the controller update).
`write_recording` writes it as CSV, Parquet, MATLAB v5 or v7.3, or TYDEX, with
the rig's own channel names and units when asked (so the reading side's mapping
is exercised).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import signal

from ..errors import ArgumentError
from .synthetic import SyntheticData

CHANNELS = ("time", "vx", "vy", "wz", "Fx", "Fy", "Mz")
#: MATLAB v7.3 files are HDF5 files with this 128-byte text at the front (in a 512-byte user block).
MAT73_HEADER = (
    b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Thu Jan  1 00:00:00 1970 HDF5 schema 1.00 ."
)


def synthetic_recording(
    syn: SyntheticData,
    *,
    rate: float = 200.0,
    hold: float = 3.0,
    ramp: float = 1.0,
    sd=(0.0, 0.0, 0.0),
    rho: float = 0.9,
    seed: int = 0,
    tau: float | None = None,
    cutoff: float | None = None,
    repeat: int = 1,
) -> dict[str, np.ndarray]:
    """The recording of ``syn``'s test points in file order (module docstring); channel -> array (SI).

    Also returns ``hold_id`` (the test point of each sample, −1 on ramps).
    """
    if tau is not None:
        if not tau > 0:
            raise ArgumentError(f"need tau > 0 (s), got {tau}")
        rho = float(np.exp(-1.0 / (rate * tau))) if rate > 0 else rho
    if not (rate > 0 and hold > 0 and ramp >= 0 and -1 < rho < 1):
        got = f"{rate}, {hold}, {ramp}, {rho}"
        raise ArgumentError(f"need rate, hold > 0, ramp >= 0 and |rho| < 1, got {got}")
    if not (isinstance(repeat, (int, np.integer)) and repeat >= 1):
        raise ArgumentError(f"need repeat >= 1 (an integer), got {repeat!r}")
    if cutoff is not None and not 0 < cutoff < rate / 2:
        raise ArgumentError(f"need 0 < cutoff < rate / 2 = {rate / 2:g} Hz, got {cutoff}")
    d = syn.data
    clean = np.asarray(syn.clean)
    pts = np.column_stack([d.vx, d.vy, d.wz, clean])
    nh, nr = int(round(hold * rate)), int(round(ramp * rate))
    m = pts.shape[0]
    blocks, ids = [], []
    for i in range(m):
        blocks.append(np.repeat(pts[i : i + 1], nh, axis=0))
        ids.append(np.full(nh, i))
        if i + 1 < m and nr:
            w = (np.arange(1, nr + 1) / (nr + 1))[:, None]
            blocks.append((1 - w) * pts[i] + w * pts[i + 1])
            ids.append(np.full(nr, -1))
    values = np.concatenate(blocks)
    n = values.shape[0]
    rng = np.random.default_rng([seed, 31])
    noise = signal.lfilter([np.sqrt(1 - rho**2)], [1, -rho], rng.normal(size=(n, 3)), axis=0)
    values[:, 3:] += noise * np.asarray(sd, float)
    if cutoff is not None:
        sos = signal.butter(2, cutoff, fs=rate, output="sos")
        zi = signal.sosfilt_zi(sos)[:, :, None] * values[0, 3:][None, None, :]
        values[:, 3:] = signal.sosfilt(sos, values[:, 3:], axis=0, zi=zi)[0]
    if repeat > 1:
        values = values[(np.arange(n) // repeat) * repeat]
    out = {"time": np.arange(n) / rate}
    for k, name in enumerate(CHANNELS[1:]):
        out[name] = values[:, k]
    out["hold_id"] = np.concatenate(ids)
    return out


def _renamed(rec: dict, names: dict | None, factors: dict | None) -> dict[str, np.ndarray]:
    names, factors = names or {}, factors or {}
    out = {}
    for k, v in rec.items():
        if k != "hold_id":
            out[names.get(k, k)] = np.asarray(v, float) / factors.get(k, 1.0)
    return out


def write_recording(rec: dict, path, *, names: dict | None = None, factors: dict | None = None,
                    units: dict | None = None) -> Path:  # fmt: skip
    """Write ``rec`` to ``path`` by suffix; ``names``/``factors``: the rig's column names and SI per unit.

    A channel is written as value / factor under names.get(channel, channel);
    ``units`` (channel -> unit text) goes into the TYDEX channel table.
    """
    path = Path(path)
    cols = _renamed(rec, names, factors)
    suffix = path.suffix.lower()
    if suffix in (".csv", ".parquet"):
        import pyarrow as pa

        table = pa.table(cols)
        if suffix == ".csv":
            from pyarrow import csv

            csv.write_csv(table, path)
        else:
            import pyarrow.parquet as pq

            pq.write_table(table, path, row_group_size=250_000)
    elif suffix == ".mat":
        from scipy import io as sio

        sio.savemat(path, {k: v[:, None] for k, v in cols.items()})
    elif suffix == ".mat73":
        import h5py

        path = path.with_suffix(".mat")
        with h5py.File(path, "w", userblock_size=512) as f:
            for k, v in cols.items():
                f.create_dataset(k, data=v[None, :])
        with path.open("r+b") as fh:
            fh.write(MAT73_HEADER.ljust(116) + b"\x00" * 8 + b"\x00\x02IM")
    elif suffix == ".tdx":
        _write_tdx(cols, path, names or {}, units or {})
    else:
        raise ArgumentError(f"unknown recording suffix {suffix!r}")
    return path


def _write_tdx(cols: dict, path: Path, names: dict, units: dict) -> None:
    back = {v: k for k, v in names.items()}
    with path.open("w") as fh:
        fh.write("**HEADER\nRELEASE   1.3\nMEASID    synthetic\n**COMMENTS\nsynthetic rig recording\n")
        fh.write("**CONSTANTS\n**MEASURCHANNELS\n! name     description                    unit  factor\n")
        for k in cols:
            unit = units.get(back.get(k, k), "-")
            fh.write(f"{k:<10}{'channel ' + k:<30}{unit:<10}1.0 0.0 0.0\n")
        fh.write("**MEASURDATA\n")
        table = np.column_stack(list(cols.values()))
        np.savetxt(fh, table, fmt="%.9g", delimiter="  ")
        fh.write("**END\n")
