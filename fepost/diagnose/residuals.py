"""Is the misfit noise or structure? Residuals against the kinematic variables.

For each channel and each kinematic variable the residuals are grouped (bins of
equal count for the continuous variables) and a one-way ANOVA F-test asks
whether the group means differ; a t-test asks whether the overall mean is zero.
Noise gives p-values spread on [0, 1]; a systematic misfit gives tiny ones.
The verdict is ``structure`` when any p-value, Bonferroni-corrected over all the
tests of the channel, is below `LEVEL`, else ``noise``.

Variables: sliding speed |v| (m/s); ε/(1+ε) with ε = |v|/(|ω|R) (0 = pure spin,
1 = pure sliding); sliding direction atan2(vy, vx) (8 sectors); spin sign; load
N (when it varies); roll (when it varies).
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from .measured import CHANNELS

#: Family-wise level of the structure verdict per channel: 0.001, so that pure
#: noise is called "structure" in any of the three channels of a data set about
#: 0.3 % of the time (at 0.01 it was ~3 %, too often for a yes/no verdict).
LEVEL = 0.001
#: Bins of the continuous variables.
BINS = 6


def kinematic_variables(vx, vy, wz, radius: float, loads, roll) -> dict[str, np.ndarray]:
    """The variables the residuals are plotted and tested against (see the module docstring)."""
    v = np.hypot(vx, vy)
    u = np.abs(wz) * radius
    # ε/(1+ε) = v/(v+u): 0 at pure spin, 1 at pure sliding (nan at rest)
    total = v + u
    compressed = np.divide(v, total, out=np.full_like(v, np.nan), where=total > 0)
    return {
        "sliding speed |v| (m/s)": v,
        "speed ratio eps/(1+eps)": compressed,
        "sliding direction (deg)": np.where(v > 0, np.degrees(np.arctan2(vy, vx)), np.nan),
        "spin sign": np.sign(wz),
        "load N (N)": np.asarray(loads, float),
        "roll": np.asarray(roll, float),
    }


def _groups(name: str, x: np.ndarray) -> np.ndarray | None:
    """Group labels (−1 = left out), or None when the variable does not vary."""
    ok = np.isfinite(x)
    if np.unique(x[ok]).size < 2:
        return None
    if name.startswith("sliding direction"):
        lab = np.floor(np.mod(x + 22.5, 360.0) / 45.0)
    elif np.unique(x[ok]).size <= BINS:
        lab = np.searchsorted(np.unique(x[ok]), x)
    else:
        edges = np.quantile(x[ok], np.linspace(0, 1, BINS + 1)[1:-1])
        lab = np.searchsorted(edges, x, side="right")
    return np.where(ok, lab, -1).astype(int)


def binned_means(r: np.ndarray, name: str, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Residual mean per group of the ANOVA test and its 95 % t-interval half-width.

    Returns (x-position, mean of ``r``, half-width), one entry per group with at
    least two points, in increasing x, or None when ``x`` does not vary. The
    x-position is the mean of x in the group, or for the sliding direction the
    centre of its 45° sector (the ±180° sector sits at 180°). These are the
    group means the F-test compares, drawn over the scatter.
    """
    x = np.asarray(x, float)
    lab = _groups(name, x)
    if lab is None:
        return None
    xs, ms, hw = [], [], []
    for g in np.unique(lab[lab >= 0]):
        sel = lab == g
        n = int(sel.sum())
        if n < 2:
            continue
        rg = r[sel]
        if name.startswith("sliding direction"):
            xs.append(float(45.0 * g if 45.0 * g <= 180.0 else 45.0 * g - 360.0))
        else:
            xs.append(float(np.mean(x[sel])))
        ms.append(float(np.mean(rg)))
        hw.append(float(stats.t.ppf(0.975, n - 1) * np.std(rg, ddof=1) / np.sqrt(n)))
    order = np.argsort(xs)
    return np.array(xs)[order], np.array(ms)[order], np.array(hw)[order]


def residual_structure(res: np.ndarray, variables: dict[str, np.ndarray]) -> dict:
    """Per-channel RMSE, mean test and ANOVA p-values, and the verdict (see the module docstring)."""
    out = {}
    for c, ch in enumerate(CHANNELS):
        r = res[:, c]
        tests = {"mean": float(stats.ttest_1samp(r, 0.0).pvalue)}
        for name, x in variables.items():
            lab = _groups(name, np.asarray(x, float))
            if lab is None:
                continue
            parts = [r[lab == g] for g in np.unique(lab[lab >= 0])]
            parts = [p for p in parts if p.size >= 2]
            if len(parts) >= 2:
                tests[name] = float(stats.f_oneway(*parts).pvalue)
        worst = min(tests, key=tests.__getitem__)
        p_adj = min(1.0, tests[worst] * len(tests))
        out[ch] = {
            "rmse": float(np.sqrt(np.mean(r**2))),
            "mean": float(np.mean(r)),
            "p_values": tests,
            "verdict": "structure" if p_adj < LEVEL else "noise",
            "strongest": worst,
            "p_adjusted": p_adj,
        }
    return out
