"""Steady holds of a rig recording, each reduced to one test point with its standard error.

A rig holds each kinematic point for a few seconds and ramps between points.
`find_holds` reads the recording chunk by chunk
(`fepost.diagnose.recording.read_chunks`) and keeps one chunk and the
current hold in memory. Every length of the rule is in **seconds**, so a test
logged at 100 Hz or at 10 kHz gives the same holds.

**Gaps** (`fepost.diagnose.gaps`): rows with a non-finite value (a channel
that dropped out) are left out, and they and clock resets (time going back) end a
*segment*; holds never span a segment's end. They are counted and reported;
``strict`` makes the first of them an error instead. A recording mostly
non-finite (more than `MOST_BAD` of its rows), or left without any hold, is refused.

**The rule** (`HoldRule`). Sample i is *steady* when over the trailing
window of ``window`` seconds (the samples of its segment with t_i − t_j < window)
each commanded kinematic channel c of vx, vy, wz spans at most its tolerance,

    max − min ≤ abs_c + rel · max |c|   (abs: 1 mm/s for vx, vy, 0.001 rad/s for wz; rel 1 %),

and its segment began at least ``window`` before t_i (`fepost.diagnose.steady`).
A run of steady samples from t_a to t_b becomes a hold after ``settle`` seconds of
settling are left out at each end: it keeps the samples from t_a − window + settle
(the kinematics came within the tolerance about one window before t_a) to
t_b − settle (a ramp that starts slowly stays within the tolerance for a while).
A hold whose kinematics **drift** over its whole length by more than the tolerance
(a slow ramp passes any short window) is cut into pieces each within it
(`fepost.diagnose.steady.drift_pieces`): never averaged across two set points.
A **hold** lasts at least ``min_seconds`` and ``min_samples``.
With a ``point`` column (the rig's own test-point number, ``--point-column``)
the holds are instead the runs of one finite point number within a segment (no
settling left out; the drift rule applies), as long as above.
Every other row is a **transition** and is left out; the diagnosis reports how
many and the time spans.

**Each hold** becomes one row: the mean of every channel (``time``: the
hold's mid time on the run clock, which is the time column unless the clock was
reset), and per force channel the standard error of the mean by
**batch means**: with τ = (1 + ρ₁)/(1 − ρ₁) the correlation time (in samples)
from the lag-1 autocorrelation ρ₁ of the hold's samples, the hold is cut into b
consecutive batches of at least `TAU_BATCHES` × τ samples (and at least
`MIN_BATCH`; at most `BATCHES` batches, at least 2), and
SE² = var(batch means)/b with b − 1 degrees of freedom. Batches ten correlation
times long are nearly independent (for AR(1) noise the batch-means variance is
then a few % low), so the SE accounts for autocorrelated samples, where σ/√n
would be too small by √τ. (τ in samples grows with the logging rate; the batches'
length in seconds does not.)

The lack-of-fit test (`fepost.diagnose.lackfit`) uses them pooled per
channel (`Holds.pure_error`): κ_c = Σ ν_i n_i SE_ic² / Σ ν_i is the
long-run variance of one sample, the same in every hold when the rig's noise
is, and a hold of n_i samples has SE_ic = √(κ_c/n_i) on Σ ν_i degrees of
freedom (a per-hold SE on a few degrees of freedom would make Σ (r/SE)²
heavy-tailed).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from .._arrays import frozen
from ..errors import ArgumentError, DataError
from .gaps import Dropout, GapTracker, RecordingWarning, Reset, Scan
from .measured import MeasuredData
from .recording import Chunk, Columns, read_chunks
from .steady import SLACK, drift_pieces, steady_flags

#: Most batches per hold, fewest samples per batch, and batch length in correlation times.
BATCHES = 20
MIN_BATCH = 5
TAU_BATCHES = 10.0
#: The steadiness window and the settling left out at each end of a hold (s).
WINDOW_SECONDS = 0.05
SETTLE_SECONDS = 0.05
#: A recording with more than this fraction of its rows non-finite is refused.
MOST_BAD = 0.5
#: Most samples kept for the recording figure (decimated evenly).
TRACE_POINTS = 5_000
#: Left-out spans, dropouts, resets and splits listed in the report (the counts are always complete).
MAX_SPANS = 200
KINEMATICS = ("vx", "vy", "wz")
FORCES = ("Fx", "Fy", "Mz")


@dataclass(frozen=True)
class HoldRule:
    """Tolerances (m/s, rad/s, relative), the window and settling (s), the shortest hold (module docstring).

    ``strict``: a non-finite value or a clock reset is an error, not a gap.
    """

    abs_v: float = 1e-3
    abs_w: float = 1e-3
    rel: float = 0.01
    window: float = WINDOW_SECONDS
    settle: float = SETTLE_SECONDS
    min_seconds: float = 0.5
    min_samples: int = 20
    use_point: bool = False
    strict: bool = False

    def __post_init__(self) -> None:
        for name in ("window", "settle", "min_seconds"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0) or (name == "window" and value == 0):
                need = "> 0" if name == "window" else ">= 0"
                raise ArgumentError(f"hold rule: {name} must be a number of seconds {need}, got {value!r}")

    @property
    def tolerance(self) -> np.ndarray:
        """The absolute tolerances of vx, vy, wz."""
        return np.array([self.abs_v, self.abs_v, self.abs_w])

    def describe(self) -> str:
        if self.use_point:
            return (
                f"runs of one value of the point column lasting >= {self.min_seconds:g} s "
                f"and >= {self.min_samples} samples, cut where vx, vy, wz drift beyond "
                f"{self.abs_v:g} m/s, {self.abs_w:g} rad/s + {self.rel:.0%}"
            )
        return (
            f"vx, vy within {self.abs_v:g} m/s + {self.rel:.0%}, wz within {self.abs_w:g} rad/s + "
            f"{self.rel:.0%} over a trailing window of {self.window:g} s and over the whole hold "
            f"(a drifting hold is cut); {self.settle:g} s of settling left out at each end; holds of "
            f">= {self.min_seconds:g} s and >= {self.min_samples} samples"
        )


@dataclass(frozen=True)
class Holds:
    """The holds of one recording: ``data`` (one row per hold, SI), their SEs and what was left out.

    ``se`` (m, 3): standard errors of the hold means of Fx, Fy, Mz (N, N, N·m);
    ``dof`` (m,): their degrees of freedom (the least of the three channels');
    ``spans`` (m, 2): first and last time of each hold (s, run clock);
    ``row_spans`` (m, 2): first and last row (0-based);
    ``left_out``: (first time, last time, rows) of each transition;
    ``trace``: a decimated copy of the recording for the figure;
    ``dropouts``, ``resets``: the gaps (`fepost.diagnose.gaps`); ``splits``: (first time,
    last time, pieces kept) of each hold cut for drifting; ``bad_rows``: rows with a
    non-finite value; ``segments``; ``rate``: samples per second; ``window``, ``settle`` (s).
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
    dropouts: tuple[Dropout, ...] = ()
    resets: tuple[Reset, ...] = ()
    splits: tuple[tuple[float, float, int], ...] = ()
    bad_rows: int = 0
    segments: int = 1
    rate: float = float("nan")
    window: float = WINDOW_SECONDS
    settle: float = SETTLE_SECONDS

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

    def gap_counts(self) -> dict[str, int]:
        """Rows per channel in dropouts (the channels that dropped out only)."""
        out: dict[str, int] = {}
        for d in self.dropouts:
            for c in d.channels:
                out[c] = out.get(c, 0) + d.rows
        return out

    def to_dict(self) -> dict:
        return {
            "count": self.count,
            "rows": self.rows_total,
            "rows_used": self.rows_used,
            "rows_left_out": self.rows_total - self.rows_used,
            "left_out_spans": [{"time": [a, b], "rows": n} for a, b, n in self.left_out[:MAX_SPANS]],
            "left_out_span_count": len(self.left_out),
            "rule": self.rule,
            "window_seconds": self.window,
            "settle_seconds": self.settle,
            "sampling_rate_hz": self.rate if np.isfinite(self.rate) else None,
            "segments": self.segments,
            "dropouts": {
                "count": len(self.dropouts),
                "rows": self.bad_rows,
                "channels": self.gap_counts(),
                "spans": [d.to_dict() for d in self.dropouts[:MAX_SPANS]],
            },
            "clock_resets": {
                "count": len(self.resets),
                "resets": [r.to_dict() for r in self.resets[:MAX_SPANS]],
            },
            "drift_splits": {
                "count": len(self.splits),
                "spans": [{"time": [a, b], "holds": k} for a, b, k in self.splits[:MAX_SPANS]],
            },
            "standard_error": (
                f"batch means, batches of >= {TAU_BATCHES:g} correlation times (and >= {MIN_BATCH} "
                f"samples; 2 to {BATCHES} per hold), pooled per channel for the lack-of-fit test"
            ),
        }

    def gaps_text(self) -> str:
        """The dropouts, resets and drift splits in words ("" when there are none)."""
        parts = []
        if self.dropouts:
            chans = ", ".join(f"{c} {n}" for c, n in self.gap_counts().items())
            parts.append(
                f"{len(self.dropouts)} dropout(s), {self.bad_rows} rows non-finite ({chans}) left out"
            )
        if self.resets:
            rows = ", ".join(str(r.row + 1) for r in self.resets[:5]) + (
                ", ..." if len(self.resets) > 5 else ""
            )
            parts.append(f"{len(self.resets)} clock reset(s) (rows {rows}) start new segments")
        if self.splits:
            parts.append(f"{len(self.splits)} drifting stretch(es) cut into holds within the tolerance")
        return "; ".join(parts)


def correlation_time(x: np.ndarray) -> float:
    """τ = (1 + ρ₁)/(1 − ρ₁) from the lag-1 autocorrelation of ``x`` (samples), within [1, n/4]."""
    u = x - x.mean()
    # einsum, not BLAS: a threaded dot product stalls for tens of ms on a loaded machine
    den = float(np.einsum("i,i->", u, u))
    rho = float(np.einsum("i,i->", u[1:], u[:-1])) / den if den > 0 else 0.0
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
    """Streaming state: the open hold's samples, closed holds, left-out spans, the trace, the gaps."""

    def __init__(self, rule: HoldRule, source: str) -> None:
        self.rule, self.source = rule, source
        self.gaps = GapTracker(source, rule.strict)
        self.rows: list[dict] = []
        self.splits: list[tuple[float, float, int]] = []
        self.open: list[dict[str, np.ndarray]] = []
        self.last_end = -1  # last row of the last closed hold
        self.left: list[tuple[float, float, int]] = []
        self.t_first = self.t_last = self.t_end = np.nan  # recording's first, last; last hold's end
        self.tail = (np.empty(0), np.empty((0, 3)), np.empty(0))  # times, kinematics, segment starts
        self.seg_t0 = -np.inf
        self.prev_point = np.nan
        self.stride = 1
        self.trace: dict[str, list[np.ndarray]] = {}
        self.total = 0

    def steady(self, values: dict, scan: Scan) -> tuple[np.ndarray, np.ndarray]:
        """Per row: steady by the rule, and where a hold must start afresh (a new point or segment)."""
        if self.rule.use_point:
            p = values["point"]
            prev = np.concatenate([[self.prev_point], p[:-1]])
            self.prev_point = p[-1]
            ok = scan.good & np.isfinite(p)
            return ok, ok & ((p != prev) | scan.breaks)
        g = np.flatnonzero(scan.good)
        flags = np.zeros(scan.good.size, bool)
        if g.size == 0:
            return flags, scan.breaks
        tg = values["time"][g]
        kin = np.column_stack([values[c][g] for c in KINEMATICS])
        t0 = np.maximum.accumulate(np.concatenate([[self.seg_t0], np.where(scan.breaks[g], tg, -np.inf)]))[1:]
        self.seg_t0 = float(t0[-1])
        tt, tk, t0t = self.tail
        t, k, s0 = np.concatenate([tt, tg]), np.concatenate([tk, kin]), np.concatenate([t0t, t0])
        rule = self.rule
        flags[g] = steady_flags(t, k, s0, tt.size, rule.window, rule.tolerance, rule.rel)
        keep = t > t[-1] - rule.window
        self.tail = (t[keep], k[keep], s0[keep])
        return flags, scan.breaks

    def feed(self, chunk: Chunk) -> None:
        scan = self.gaps.scan(chunk)
        values = {**chunk.values, "time": scan.clock}
        flags, starts = self.steady(values, scan)
        self._trace(values, chunk.start)
        t = scan.clock[np.isfinite(scan.clock)]
        if t.size and np.isnan(self.t_first):
            self.t_first = self.t_end = float(t[0])
        if t.size:
            self.t_last = float(t[-1])
        n = len(chunk)
        self.total += n
        # runs of equal flag, broken where a hold must start afresh
        edges = np.flatnonzero((np.diff(flags.astype(np.int8)) != 0) | starts[1:]) + 1
        bounds = np.concatenate([[0], edges, [n]])
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            if flags[a]:
                if starts[a]:
                    self._close()
                piece = {k: v[a:b] for k, v in values.items()}
                piece["row"] = np.arange(chunk.start + a, chunk.start + b)
                self.open.append(piece)
            else:
                self._close()

    def _settled(self, block: dict) -> dict:
        """The block without its settling at each end (module docstring); point mode: unchanged."""
        rule = self.rule
        if rule.use_point:
            return block
        t = block["time"]
        eps = SLACK * max(rule.window, rule.settle)
        keep = (t >= t[0] - rule.window + rule.settle - eps) & (t <= t[-1] - rule.settle + eps)
        return {k: v[keep] for k, v in block.items()}

    def _close(self) -> None:
        if not self.open:
            return
        block = self._settled({k: np.concatenate([o[k] for o in self.open]) for k in self.open[0]})
        self.open = []
        t, rule = block["time"], self.rule
        if t.size < rule.min_samples or t[-1] - t[0] < rule.min_seconds:
            return
        kin = np.column_stack([block[c] for c in KINEMATICS])
        pieces = drift_pieces(kin, rule.tolerance, rule.rel, rule.min_samples)
        if pieces != [(0, t.size)]:
            kept = [(a, b) for a, b in pieces if t[b - 1] - t[a] >= rule.min_seconds]
            self.splits.append((float(t[0]), float(t[-1]), len(kept)))
            pieces = kept
        for a, b in pieces:
            self._hold({k: v[a:b] for k, v in block.items()})

    def _hold(self, block: dict) -> None:
        t, rows = block["time"], block["row"]
        if t.size < self.rule.min_samples or t[-1] - t[0] < self.rule.min_seconds:
            return
        row: dict = {k: float(np.mean(v)) for k, v in block.items() if k not in ("point", "row")}
        dofs = []
        for c in FORCES:
            _, row[f"se_{c}"], dof = batch_means(block[c])
            dofs.append(dof)
        row["dof"] = min(dofs)
        row["span"] = (float(t[0]), float(t[-1]))
        start, end = int(rows[0]), int(rows[-1])
        row["rows"] = (start, end)
        if start > self.last_end + 1:
            self.left.append((self.t_end, float(t[0]), start - self.last_end - 1))
        self.last_end, self.t_end = end, float(t[-1])
        self.rows.append(row)

    def _trace(self, values: dict, start: int) -> None:
        offset = (-start) % self.stride
        for k in ("time", *KINEMATICS, *FORCES):
            self.trace.setdefault(k, []).append(values[k][offset :: self.stride])
        if sum(a.size for a in self.trace["time"]) > 2 * TRACE_POINTS:
            self.trace = {k: [np.concatenate(v)[::2]] for k, v in self.trace.items()}
            self.stride *= 2

    def _refuse(self) -> None:
        """Refuse a recording mostly non-finite or without a hold, in one line."""
        src, gaps = self.source, self.gaps
        if gaps.bad_rows > MOST_BAD * self.total:
            chans = sorted({c for d in gaps.dropouts for c in d.channels})
            raise DataError(
                f"{src}: {gaps.bad_rows} of {self.total} rows ({gaps.bad_rows / self.total:.0%}) have "
                f"non-finite values (channels {', '.join(chans)}): not a usable recording"
            )
        if not self.rows:
            found = []
            if gaps.dropouts:
                found.append(f"{len(gaps.dropouts)} dropout(s) of {gaps.bad_rows} rows")
            if gaps.resets:
                found.append(f"{len(gaps.resets)} clock reset(s)")
            cut = f"; {' and '.join(found)} cut the recording" if found else ""
            raise DataError(f"{src}: no steady hold found ({self.rule.describe()}){cut}; see --point-column")

    def finish(self) -> Holds:
        self._close()
        self.gaps.finish()
        self._refuse()
        gaps = self.gaps
        if self.total > self.last_end + 1:
            self.left.append((self.t_end, self.t_last, self.total - self.last_end - 1))
        rows = self.rows
        col = {k: np.array([r[k] for r in rows]) for k in rows[0] if k not in ("span", "rows")}
        roll = np.rint(col["roll"]).astype(int) if "roll" in col else None
        data = MeasuredData(
            vx=col["vx"], vy=col["vy"], wz=col["wz"], Fx=col["Fx"], Fy=col["Fy"], Mz=col["Mz"],
            N=col.get("N"), roll=roll, source=self.source, time=col["time"],
        )  # fmt: skip
        trace = {k: np.concatenate(v) for k, v in self.trace.items()}
        known = np.isfinite(trace["time"])
        trace = {k: v[known] for k, v in trace.items()}
        used = int(sum(r["rows"][1] - r["rows"][0] + 1 for r in rows))
        se = np.column_stack([col[f"se_{c}"] for c in FORCES])
        rule = self.rule
        return Holds(
            data, se, col["dof"].astype(int), np.array([r["span"] for r in rows]),
            np.array([r["rows"] for r in rows]), self.total, used, tuple(self.left), rule.describe(), trace,
            tuple(gaps.dropouts), tuple(gaps.resets), tuple(self.splits), gaps.bad_rows,
            max(gaps.segments, 1), gaps.rate, rule.window, rule.settle,
        )  # fmt: skip


def find_holds(path, columns: Columns | None = None, rule: HoldRule | None = None) -> Holds:
    """Read the recording at ``path`` and reduce it to its holds (module docstring).

    Warns (`fepost.diagnose.gaps.RecordingWarning`) when dropouts or clock resets were left out.
    """
    rule = rule or HoldRule()
    builder = _Builder(rule, str(path))
    for chunk in read_chunks(path, columns):
        if rule.use_point and "point" not in chunk.values:
            raise DataError(f"{path}: no point column (name it with --point-column or --columns point=NAME)")
        builder.feed(chunk)
    holds = builder.finish()
    if holds.dropouts or holds.resets:
        warnings.warn(f"{path}: {holds.gaps_text()}", RecordingWarning, stacklevel=2)
    return holds
