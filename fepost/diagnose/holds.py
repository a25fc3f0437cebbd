"""Steady holds of a rig recording, each reduced to one test point with its standard error.

A rig holds each kinematic point for a few seconds and ramps between points.
`find_holds` reads the recording chunk by chunk
(`fepost.diagnose.recording.read_chunks`) and keeps one chunk and the
current hold in memory.

**The rule** (`HoldRule`). Sample i is *steady* when over the trailing
window of ``window`` samples (i − window + 1 … i) each commanded kinematic
channel c of vx, vy, wz spans at most its tolerance,

    max − min ≤ abs_c + rel · max |c|   (abs: 1 mm/s for vx, vy, 0.001 rad/s for wz; rel 1 %),

so the first window − 1 samples of a hold are left out as settling; so are its
last window − 1 (a ramp that starts slowly stays within the tolerance for up to
that many samples). A **hold**
is a run of steady samples lasting at least ``min_seconds`` and ``min_samples``.
With a ``point`` column (the rig's own test-point number, ``--point-column``)
the holds are instead the runs of one finite point number, as long as above.
Every other row is a **transition** and is left out; the diagnosis reports how
many and the time spans.

**Each hold** becomes one row: the mean of every channel (``time``: the
hold's mid time), and per force channel the standard error of the mean by
**batch means**: with τ = (1 + ρ₁)/(1 − ρ₁) the correlation time (in samples)
from the lag-1 autocorrelation ρ₁ of the hold's samples, the hold is cut into b
consecutive batches of at least `TAU_BATCHES` × τ samples (and at least
`MIN_BATCH`; at most `BATCHES` batches, at least 2), and
SE² = var(batch means)/b with b − 1 degrees of freedom. Batches ten correlation
times long are nearly independent (for AR(1) noise the batch-means variance is
then a few % low), so the SE accounts for autocorrelated samples, where σ/√n
would be too small by √τ.

The lack-of-fit test (`fepost.diagnose.lackfit`) uses them pooled per
channel (`Holds.pure_error`): κ_c = Σ ν_i n_i SE_ic² / Σ ν_i is the
long-run variance of one sample, the same in every hold when the rig's noise
is, and a hold of n_i samples has SE_ic = √(κ_c/n_i) on Σ ν_i degrees of
freedom (a per-hold SE on a few degrees of freedom would make Σ (r/SE)²
heavy-tailed).

Written by hand rather than with pandas' rolling windows (not a dependency):
numpy's ``sliding_window_view`` gives the windowed range over a chunk and its
carried-over tail.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .._arrays import frozen
from ..errors import DataError
from .measured import MeasuredData
from .recording import Chunk, Columns, read_chunks

#: Most batches per hold, fewest samples per batch, and batch length in correlation times.
BATCHES = 20
MIN_BATCH = 5
TAU_BATCHES = 10.0
#: Most samples kept for the recording figure (decimated evenly).
TRACE_POINTS = 5_000
#: Left-out spans listed in the report (the count is always complete).
MAX_SPANS = 200
KINEMATICS = ("vx", "vy", "wz")
FORCES = ("Fx", "Fy", "Mz")


@dataclass(frozen=True)
class HoldRule:
    """Tolerances (m/s, rad/s, relative), the trailing window (samples) and the shortest hold."""

    abs_v: float = 1e-3
    abs_w: float = 1e-3
    rel: float = 0.01
    window: int = 10
    min_seconds: float = 0.5
    min_samples: int = 20
    use_point: bool = False

    def describe(self) -> str:
        if self.use_point:
            return (
                f"runs of one value of the point column lasting >= {self.min_seconds:g} s "
                f"and >= {self.min_samples} samples"
            )
        return (
            f"vx, vy within {self.abs_v:g} m/s + {self.rel:.0%}, wz within {self.abs_w:g} rad/s + "
            f"{self.rel:.0%} over a trailing window of {self.window} samples; holds of >= "
            f"{self.min_seconds:g} s and >= {self.min_samples} samples"
        )


@dataclass(frozen=True)
class Holds:
    """The holds of one recording: ``data`` (one row per hold, SI), their SEs and what was left out.

    ``se`` (m, 3): standard errors of the hold means of Fx, Fy, Mz (N, N, N·m);
    ``dof`` (m,): their degrees of freedom (the least of the three channels');
    ``spans`` (m, 2): first and last time of each hold (s);
    ``row_spans`` (m, 2): first and last row (0-based);
    ``left_out``: (first time, last time, rows) of each transition;
    ``trace``: a decimated copy of the recording for the figure.
    """

    data: MeasuredData
    se: np.ndarray
    dof: np.ndarray
    spans: np.ndarray
    row_spans: np.ndarray
    rows_total: int
    rows_used: int
    left_out: tuple[tuple[float, float, int], ...]
    rule: str
    trace: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        for name in ("se", "spans"):
            object.__setattr__(self, name, frozen(getattr(self, name)))
        for name in ("dof", "row_spans"):
            object.__setattr__(self, name, frozen(getattr(self, name), dtype=int))

    @property
    def count(self) -> int:
        return int(self.dof.size)

    @property
    def samples(self) -> np.ndarray:
        """Samples in each hold."""
        return self.row_spans[:, 1] - self.row_spans[:, 0] + 1

    def pure_error(self) -> tuple[np.ndarray, np.ndarray]:
        """(pooled SEs (m, 3) in N, N, N·m; degrees of freedom (m,)) for the lack-of-fit test (docstring)."""
        n = self.samples.astype(float)
        ok = (self.dof > 0) & np.all(np.isfinite(self.se), axis=1)
        nu = np.where(ok, self.dof, 0).astype(float)
        if not np.any(ok):
            return np.zeros_like(self.se), np.zeros(self.count)
        kappa = np.sum((nu * n)[:, None] * np.where(ok[:, None], self.se, 0.0) ** 2, axis=0) / nu.sum()
        return np.sqrt(kappa[None, :] / n[:, None]), nu

    def to_dict(self) -> dict:
        return {
            "count": self.count,
            "rows": self.rows_total,
            "rows_used": self.rows_used,
            "rows_left_out": self.rows_total - self.rows_used,
            "left_out_spans": [{"time": [a, b], "rows": n} for a, b, n in self.left_out[:MAX_SPANS]],
            "left_out_span_count": len(self.left_out),
            "rule": self.rule,
            "standard_error": (
                f"batch means, batches of >= {TAU_BATCHES:g} correlation times (and >= {MIN_BATCH} "
                f"samples; 2 to {BATCHES} per hold), pooled per channel for the lack-of-fit test"
            ),
        }


def correlation_time(x: np.ndarray) -> float:
    """τ = (1 + ρ₁)/(1 − ρ₁) from the lag-1 autocorrelation of ``x`` (samples), within [1, n/4]."""
    u = x - x.mean()
    den = float(u @ u)
    rho = float(u[1:] @ u[:-1]) / den if den > 0 else 0.0
    rho = min(max(rho, 0.0), 0.999)
    return float(np.clip((1 + rho) / (1 - rho), 1.0, max(x.size / 4.0, 1.0)))


def batch_means(x: np.ndarray) -> tuple[float, float, int]:
    """(mean, standard error by batch means, degrees of freedom) of the samples ``x`` (module docstring)."""
    n = x.size
    size = max(MIN_BATCH, int(np.ceil(TAU_BATCHES * correlation_time(x))))
    b = min(BATCHES, max(2, n // size))
    if n < 2 * MIN_BATCH:
        return float(np.mean(x)), float("nan"), 0
    m = n // b
    means = x[: b * m].reshape(b, m).mean(axis=1)
    return float(np.mean(x)), float(np.std(means, ddof=1) / np.sqrt(b)), b - 1


class _Builder:
    """Streaming state: the open hold's samples, closed holds, left-out spans, the trace."""

    def __init__(self, rule: HoldRule, source: str) -> None:
        self.rule, self.source = rule, source
        self.rows: list[dict] = []
        self.open: list[dict[str, np.ndarray]] = []
        self.open_start = -1
        self.last_end = -1  # last row of the last closed hold
        self.left: list[tuple[float, float, int]] = []
        self.t_first = self.t_last = self.t_end = np.nan  # recording's first, last; last hold's end
        self.tail: dict[str, np.ndarray] = {}
        self.prev_point = np.nan
        self.stride = 1
        self.trace: dict[str, list[np.ndarray]] = {}
        self.total = 0

    def steady(self, chunk: Chunk) -> tuple[np.ndarray, np.ndarray]:
        """Per row of ``chunk``: steady by the rule, or the start of a new point (point mode: run ids)."""
        rule = self.rule
        if rule.use_point:
            p = chunk.values["point"]
            prev = np.concatenate([[self.prev_point], p[:-1]])
            self.prev_point = p[-1]
            ok = np.isfinite(p)
            return ok, ok & (p != prev)
        w = rule.window
        flags = np.ones(len(chunk), bool)
        for c in KINEMATICS:
            x = np.concatenate([self.tail.get(c, np.empty(0)), chunk.values[c]])
            self.tail[c] = x[-(w - 1) :] if w > 1 else np.empty(0)
            lead = x.size - len(chunk)
            if x.size < w:
                flags[:] = False
                continue
            win = sliding_window_view(x, w)
            span = win.max(axis=1) - win.min(axis=1)
            top = np.abs(win).max(axis=1)
            tol = (rule.abs_w if c == "wz" else rule.abs_v) + rule.rel * top
            ok = span <= tol  # ok[k]: window ending at x[k + w - 1]
            got = np.zeros(x.size, bool)
            got[w - 1 :] = ok
            flags &= got[lead:]
        return flags, np.zeros(len(chunk), bool)

    def feed(self, chunk: Chunk) -> None:
        flags, starts = self.steady(chunk)
        self._trace(chunk)
        t = chunk.values["time"]
        if np.isnan(self.t_first):
            self.t_first = self.t_end = float(t[0])
        self.t_last = float(t[-1])
        n = len(chunk)
        self.total += n
        # runs of equal flag (and in point mode, breaks where the point changes)
        edges = np.flatnonzero((np.diff(flags.astype(np.int8)) != 0) | starts[1:]) + 1
        bounds = np.concatenate([[0], edges, [n]])
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            if flags[a]:
                if starts[a]:  # point mode: a new test point begins here
                    self._close()
                if not self.open:
                    self.open_start = chunk.start + a
                self.open.append({k: v[a:b] for k, v in chunk.values.items()})
            else:
                self._close()

    def _close(self) -> None:
        if not self.open:
            return
        block = {k: np.concatenate([o[k] for o in self.open]) for k in self.open[0]}
        self.open = []
        trim = 0 if self.rule.use_point else self.rule.window - 1
        if trim:  # a ramp stays within the tolerance for up to window - 1 samples: leave them out too
            block = {k: v[:-trim] for k, v in block.items()}
        t = block["time"]
        n = t.size
        start = self.open_start
        if n < self.rule.min_samples or t[-1] - t[0] < self.rule.min_seconds:
            return
        row: dict = {k: float(np.mean(v)) for k, v in block.items() if k != "point"}
        dofs = []
        for c in FORCES:
            _, row[f"se_{c}"], dof = batch_means(block[c])
            dofs.append(dof)
        row["dof"] = min(dofs)
        row["span"] = (float(t[0]), float(t[-1]))
        row["rows"] = (start, start + n - 1)
        if start > self.last_end + 1:
            self.left.append((self.t_end, float(t[0]), start - self.last_end - 1))
        self.last_end, self.t_end = start + n - 1, float(t[-1])
        self.rows.append(row)

    def _trace(self, chunk: Chunk) -> None:
        keep = {k: chunk.values[k] for k in ("time", *KINEMATICS, *FORCES)}
        offset = (-chunk.start) % self.stride
        for k, v in keep.items():
            self.trace.setdefault(k, []).append(v[offset :: self.stride])
        if sum(a.size for a in self.trace["time"]) > 2 * TRACE_POINTS:
            self.trace = {k: [np.concatenate(v)[::2]] for k, v in self.trace.items()}
            self.stride *= 2

    def finish(self) -> Holds:
        self._close()
        src = self.source
        if not self.rows:
            raise DataError(f"{src}: no steady hold found ({self.rule.describe()}); see --point-column")
        if self.total > self.last_end + 1:
            self.left.append((self.t_end, self.t_last, self.total - self.last_end - 1))
        rows = self.rows
        col = {k: np.array([r[k] for r in rows]) for k in rows[0] if k not in ("span", "rows")}
        spans = np.array([r["span"] for r in rows])
        roll = np.rint(col["roll"]).astype(int) if "roll" in col else None
        data = MeasuredData(
            vx=col["vx"], vy=col["vy"], wz=col["wz"], Fx=col["Fx"], Fy=col["Fy"], Mz=col["Mz"],
            N=col.get("N"), roll=roll, source=src, time=col["time"],
        )  # fmt: skip
        trace = {k: np.concatenate(v) for k, v in self.trace.items()}
        used = int(sum(r["rows"][1] - r["rows"][0] + 1 for r in rows))
        se = np.column_stack([col[f"se_{c}"] for c in FORCES])
        return Holds(
            data, se, col["dof"].astype(int), spans, np.array([r["rows"] for r in rows]),
            self.total, used, tuple(self.left), self.rule.describe(), trace,
        )  # fmt: skip


def find_holds(path, columns: Columns | None = None, rule: HoldRule | None = None) -> Holds:
    """Read the recording at ``path`` and reduce it to its holds (module docstring)."""
    rule = rule or HoldRule()
    builder = _Builder(rule, str(path))
    prev_t = -np.inf
    for chunk in read_chunks(path, columns):
        if rule.use_point and "point" not in chunk.values:
            raise DataError(f"{path}: no point column (name it with --point-column or --columns point=NAME)")
        t = chunk.values["time"]
        dt = np.diff(np.concatenate([[prev_t], t]))
        if np.any(dt <= 0):
            i = int(np.flatnonzero(dt <= 0)[0])
            raise DataError(f"{path}: row {chunk.start + i + 1}, column time: time must increase")
        prev_t = t[-1]
        builder.feed(chunk)
    return builder.finish()
