"""The rig engineer's checks of one log's pushes, and the console summary they make.

`check_log` looks at what `fepost.pushes.wrench.form_push` made of a log:

* **the sensor's zero**: the offset of each push (the mean of the quiet samples before the
  impact, sensor axes), its drift over the log (the last push's minus the first's, and
  the range) set beside the median force, how far the first sample alone (the
  authors' zero) lies from it, and which pushes started loaded and took the log's
  median zero (these are left out of the drift);
* **pushes that hardly moved** or gave no wrench: left out, each with its reason;
* **the finger's impact**: when it comes (s and fraction of the push; how many pushes
  are hit after 30 % of their samples, where a fixed 30 % cut would keep unloaded
  samples) and its spike (the largest force of the settling window over the plateau);
* **outliers**, counted and named but kept (the analysis decides): a wrench that does
  not dissipate (friction power Fx dx + Fy dy + Mz dθ ≥ 0, impossible for friction); an
  unsteady force (the kept samples' scatter over `UNSTEADY`); a friction level |F|/N
  more than `OUTLIER_Z` robust standard deviations (1.4826 MAD) from the log's median;
* **the physics' signs**: the friction force against the sliding direction (the cosine
  of the angle between F and −(dx, dy)) and the torque against the spin;
* the friction level |F|/N and the spin ratio u = |dθ| R / |(dx, dy)|, R the patch
  radius about the reference point (the smallest circle about it that holds the support).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .wrench import LeftOut, Push

#: A push's force scatter (std/mean of |F| over its kept samples) above which it is unsteady.
UNSTEADY = 0.25
#: Robust z-score of |F|/N beyond which a push is an outlier of its log.
OUTLIER_Z = 3.5
#: The authors' fixed cut: the first 30 % of a push's samples.
FIXED_CUT = 0.3


@dataclass(frozen=True)
class LogChecks:
    """The checks of one log (module docstring); numbers in N, m, s, rad."""

    log: str
    logged: int
    kept: int
    left_out: tuple[tuple[int, str], ...]
    zero_first: tuple[float, float]
    zero_last: tuple[float, float]
    zero_range: tuple[float, float]
    zero_vs_first_sample: float
    zero_replaced: tuple[int, ...]
    median_force: float
    impact_time: tuple[float, float]
    impact_fraction: tuple[float, float]
    late_impacts: tuple[int, ...]
    impact_peak: tuple[float, float]
    samples_kept: tuple[int, int]
    not_dissipating: tuple[int, ...]
    unsteady: tuple[int, ...]
    far_level: tuple[int, ...]
    cos_force_sliding: tuple[float, float]
    torque_against_spin: int
    level: tuple[float, float, float]
    u: tuple[float, float]
    radius: float
    tilt: float

    def lines(self) -> list[str]:
        """The console summary, a few lines."""
        out = [f"{self.log}: {self.logged} pushes, {self.kept} kept, {len(self.left_out)} left out"]
        for index, why in self.left_out:
            out.append(f"  left out: push {index}: {why}")
        if not self.kept:
            return out
        drift = float(np.hypot(*np.subtract(self.zero_last, self.zero_first)))
        zf, zl, zr = self.zero_first, self.zero_last, self.zero_range
        share = 100 * drift / self.median_force
        when, frac, peak = self.impact_time, self.impact_fraction, self.impact_peak
        late = f"{len(self.late_impacts)} after {100 * FIXED_CUT:.0f} %{_named(self.late_impacts)}"
        cos = self.cos_force_sliding
        nd, un, far = self.not_dissipating, self.unsteady, self.far_level
        out += [
            f"  zero: ({zf[0]:+.3f}, {zf[1]:+.3f}) N at the first push, "
            f"({zl[0]:+.3f}, {zl[1]:+.3f}) N at the last: drift {drift:.3f} N",
            f"        ({share:.1f} % of the median force {self.median_force:.2f} N); "
            f"range {zr[0]:.3f}, {zr[1]:.3f} N (fx, fy)",
            f"        the first sample alone is off by up to {self.zero_vs_first_sample:.3f} N; "
            f"started loaded: {len(self.zero_replaced)}{_named(self.zero_replaced)}",
            f"  impact: {when[0]:.2f}-{when[1]:.2f} s into the push, "
            f"{100 * frac[0]:.0f}-{100 * frac[1]:.0f} % of its samples; {late}",
            f"          spike (peak while settling / plateau) median {peak[0]:.2f}, max {peak[1]:.2f}; "
            f"samples kept {self.samples_kept[0]}-{self.samples_kept[1]}",
            f"  outliers (kept): not dissipating {len(nd)}{_named(nd)}; "
            f"unsteady (scatter > {100 * UNSTEADY:.0f} %) {len(un)}{_named(un)}",
            f"                   |F|/N beyond {OUTLIER_Z:g} robust sd {len(far)}{_named(far)}",
            f"  signs: cos(F, -v) median {cos[0]:.3f}, min {cos[1]:.3f}; torque against the spin in "
            f"{self.torque_against_spin} of {self.kept}; tilt up to {math.degrees(self.tilt):.1f} deg",
            f"  |F|/N mean {self.level[0]:.3f} ({self.level[1]:.3f}-{self.level[2]:.3f}); u = |w| R/|v| "
            f"{self.u[0]:.2f}-{self.u[1]:.2f} (R = {1e3 * self.radius:.1f} mm about the reference point)",
        ]
        return out


def _named(indices: tuple[int, ...], most: int = 8) -> str:
    if not indices:
        return ""
    shown = ", ".join(map(str, indices[:most]))
    return f" (push {shown}{', ...' if len(indices) > most else ''})"


def check_log(log: str, results: list[Push | LeftOut], *, weight: float, radius: float) -> LogChecks:
    """The checks of one log's pushes (module docstring).

    Parameters
    ----------
    log : str
        The log's name.
    results : list of Push or LeftOut
        Its pushes in order, as `fepost.pushes.wrench.form_push` made them.
    weight : float
        The block's weight (N).
    radius : float
        The patch radius R (m) of the spin ratio u.
    """
    kept = [r for r in results if isinstance(r, Push)]
    left = tuple((r.index, r.reason) for r in results if isinstance(r, LeftOut))
    if not kept:
        return _empty(log, len(results), left, radius)
    w = np.array([p.wrench for p in kept])
    d = np.array([p.displacement for p in kept])
    idx = np.array([p.index for p in kept])
    force = np.hypot(w[:, 0], w[:, 1])
    slide = np.hypot(d[:, 0], d[:, 1])
    own = [p for p in kept if not p.zero_from_log] or kept
    zeros = np.array([p.zero for p in own])
    level = force / weight
    mad = 1.4826 * float(np.median(np.abs(level - np.median(level))))
    far = np.abs(level - np.median(level)) > OUTLIER_Z * mad if mad > 0 else np.zeros(len(kept), bool)
    moving = slide > 0
    cos = -(w[moving, 0] * d[moving, 0] + w[moving, 1] * d[moving, 1]) / (force[moving] * slide[moving])
    frac = np.array([p.impact_fraction for p in kept])
    peaks = np.array([p.impact_peak for p in kept])
    with np.errstate(divide="ignore"):
        u = np.where(slide > 0, np.abs(d[:, 2]) * radius / np.where(slide > 0, slide, 1.0), np.inf)
    return LogChecks(
        log=log,
        logged=len(results),
        kept=len(kept),
        left_out=left,
        zero_first=(float(zeros[0, 0]), float(zeros[0, 1])),
        zero_last=(float(zeros[-1, 0]), float(zeros[-1, 1])),
        zero_range=(float(np.ptp(zeros[:, 0])), float(np.ptp(zeros[:, 1]))),
        zero_vs_first_sample=float(max(np.hypot(*(p.first - p.zero)) for p in own)),
        zero_replaced=tuple(p.index for p in kept if p.zero_from_log),
        median_force=float(np.median(force)),
        impact_time=(min(p.impact_time for p in kept), max(p.impact_time for p in kept)),
        impact_fraction=(float(frac.min()), float(frac.max())),
        late_impacts=tuple(int(i) for i in idx[frac > FIXED_CUT]),
        impact_peak=(float(np.median(peaks)), float(peaks.max())),
        samples_kept=(min(p.kept for p in kept), max(p.kept for p in kept)),
        not_dissipating=tuple(int(i) for i in idx[(w * d).sum(axis=1) >= 0]),
        unsteady=tuple(p.index for p in kept if p.scatter > UNSTEADY),
        far_level=tuple(int(i) for i in idx[far]),
        cos_force_sliding=(float(np.median(cos)), float(cos.min())) if cos.size else (math.nan, math.nan),
        torque_against_spin=int(np.sum(w[:, 2] * d[:, 2] < 0)),
        level=(float(level.mean()), float(level.min()), float(level.max())),
        u=(float(u.min()), float(u.max())),
        radius=radius,
        tilt=max(p.tilt for p in kept),
    )


def _empty(log: str, logged: int, left, radius: float) -> LogChecks:
    nan2 = (math.nan, math.nan)
    return LogChecks(
        log=log,
        logged=logged,
        kept=0,
        left_out=left,
        zero_first=nan2,
        zero_last=nan2,
        zero_range=nan2,
        zero_vs_first_sample=math.nan,
        zero_replaced=(),
        median_force=math.nan,
        impact_time=nan2,
        impact_fraction=nan2,
        late_impacts=(),
        impact_peak=nan2,
        samples_kept=(0, 0),
        not_dissipating=(),
        unsteady=(),
        far_level=(),
        cos_force_sliding=nan2,
        torque_against_spin=0,
        level=(math.nan, math.nan, math.nan),
        u=nan2,
        radius=radius,
        tilt=math.nan,
    )
