"""Load trends of a sweep: power laws y = c·N^α fitted with 95 % intervals.

The fit is ordinary least squares of log y on log N (``scipy.stats.linregress``;
scatter taken as multiplicative, i.e. constant in log space). The exponent's
95 % interval is α ± t₀.₉₇₅,ₙ₋₂ · se(α) with Student's t for n − 2 degrees of
freedom; the band drawn around the fitted line is the 95 % confidence band of
the mean, s·√(1/n + (log N − mean log N)²/Sxx).

Reference exponents are those of a Hertz contact (pressure √(1 − ρ²), radius
R ∝ N^(1/3)): M0 = (3π/16) f N R ∝ N^(4/3); a and m do not depend on the load,
so aR² ∝ N^(2/3) and m/R² ∝ N^(−2/3). A tire is not a Hertz contact (its
inflation pressure carries most of the load, so R grows faster); the Hertz
column says how far it departs.

Rows of unpaired rolling maps (role ``rolling``) are left out: a rolling map is
not a static load point. Rows are grouped by inflation pressure when the sidecars give it, so an
inflation sweep gives one load trend per pressure.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np

#: Fitted quantities: column, label, unit, Hertz exponent (None: no reference).
QUANTITIES: tuple[tuple[str, str, str, float | None], ...] = (
    ("R", "R", "m", 1.0 / 3.0),
    ("M0", "M0", "N m", 4.0 / 3.0),
    ("aR2", "a R²", "m²", 2.0 / 3.0),
    ("m_over_R2", "m / R²", "1/m²", -2.0 / 3.0),
    ("k_x", "k_x", "1", None),
)
#: Fewest loads for a fit with an interval (n − 2 ≥ 1 degrees of freedom).
MIN_POINTS = 3
#: Smallest spread of the loads, max/min, for a load trend to mean anything.
MIN_SPREAD = 1.05
#: Confidence level of every interval.
LEVEL = 0.95


@dataclass(frozen=True)
class PowerLaw:
    """y = c·N^α fitted in log space, or the reason it was not fitted.

    Attributes
    ----------
    quantity, label, unit : str
        Table column, printable name and unit of y.
    group : str
        Which rows: ``"all"`` or ``"inflation_pressure = … Pa"``.
    n : int
        Points used (ok rows with finite, positive N and y).
    exponent, ci95 : float, (float, float)
        α and its 95 % interval (None when not fitted).
    prefactor : float
        c, in the unit of y per N^α.
    r2 : float
        Coefficient of determination in log space.
    hertz : float or None
        The Hertz exponent for reference.
    note : str
        Why the fit is missing, empty otherwise.
    """

    quantity: str
    label: str
    unit: str
    group: str
    n: int
    exponent: float | None = None
    ci95: tuple[float, float] | None = None
    prefactor: float | None = None
    r2: float | None = None
    hertz: float | None = None
    note: str = ""
    # for the confidence band: mean and Sxx of log N, residual s, t quantile
    _lx_mean: float = math.nan
    _sxx: float = math.nan
    _s: float = math.nan
    _t: float = math.nan

    @property
    def fitted(self) -> bool:
        return self.exponent is not None

    def predict(self, N) -> np.ndarray:
        """Fitted y at loads ``N`` (N)."""
        return self.prefactor * np.asarray(N, float) ** self.exponent  # type: ignore[operator]

    def band(self, N) -> tuple[np.ndarray, np.ndarray]:
        """95 % confidence band of the fitted mean at loads ``N``: (lower, upper)."""
        lx = np.log(np.asarray(N, float))
        half = self._t * self._s * np.sqrt(1.0 / self.n + (lx - self._lx_mean) ** 2 / self._sxx)
        y = self.predict(N)
        return y * np.exp(-half), y * np.exp(half)

    def to_dict(self) -> dict:
        return {
            "quantity": self.quantity,
            "unit": self.unit,
            "group": self.group,
            "n": self.n,
            "exponent": self.exponent,
            "ci95": None if self.ci95 is None else list(self.ci95),
            "prefactor": self.prefactor,
            "r2": self.r2,
            "hertz_exponent": self.hertz,
            "note": self.note,
            "method": "OLS of log y on log N (scipy.stats.linregress), Student t 95 % interval",
        }


def fit_power_law(
    N: Sequence[float] | np.ndarray,
    y: Sequence[float] | np.ndarray,
    *,
    quantity: str = "y",
    label: str = "",
    unit: str = "",
    group: str = "all",
    hertz: float | None = None,
) -> PowerLaw:
    """Fit y = c·N^α by least squares in log space, with the exponent's 95 % interval.

    Non-finite points are dropped; non-positive ones make the fit impossible
    (the ``note`` says so) rather than being dropped silently.
    """
    from scipy import stats

    x_all = np.asarray(N, float)
    y_all = np.asarray(y, float)
    keep = np.isfinite(x_all) & np.isfinite(y_all)
    x, yv = x_all[keep], y_all[keep]
    label = label or quantity
    unfitted = partial(PowerLaw, quantity, label, unit, group, int(x.size), hertz=hertz)
    if x.size < MIN_POINTS:
        return unfitted(note=f"{x.size} load{'s' if x.size != 1 else ''}: a fit needs {MIN_POINTS}")
    if np.any(x <= 0) or np.any(yv <= 0):
        return unfitted(note=f"{label} or N is zero or negative: no power law")
    if x.max() / x.min() < MIN_SPREAD:
        return unfitted(note=f"the loads span less than {MIN_SPREAD - 1:.0%}: no load trend")
    lx, ly = np.log(x), np.log(yv)
    fit = stats.linregress(lx, ly)
    dof = x.size - 2
    t = float(stats.t.ppf(0.5 + LEVEL / 2.0, dof))
    sxx = float(np.sum((lx - lx.mean()) ** 2))
    resid = ly - (fit.intercept + fit.slope * lx)
    s = float(math.sqrt(np.sum(resid**2) / dof))
    se = s / math.sqrt(sxx)
    alpha = float(fit.slope)
    return unfitted(
        exponent=alpha,
        ci95=(alpha - t * se, alpha + t * se),
        prefactor=float(math.exp(fit.intercept)),
        r2=float(fit.rvalue**2),
        _lx_mean=float(lx.mean()),
        _sxx=sxx,
        _s=s,
        _t=t,
    )


def groups(rows: Sequence[Mapping]) -> dict[str, list[Mapping]]:
    """Ok rows of load points by inflation pressure (one group ``"all"`` when no sidecar
    gives it); rows of unpaired rolling maps (role ``rolling``) are no load points."""
    ok = [r for r in rows if r.get("status") == "ok" and r.get("role") != "rolling"]
    pressures = sorted({r["inflation_pressure"] for r in ok if r.get("inflation_pressure") is not None})
    if len(pressures) <= 1:
        return {"all": ok} if ok else {}
    out: dict[str, list[Mapping]] = {}
    for p in pressures:
        out[f"inflation_pressure = {p:.4g} Pa"] = [r for r in ok if r.get("inflation_pressure") == p]
    rest = [r for r in ok if r.get("inflation_pressure") is None]
    if rest:
        out["inflation pressure not given"] = rest
    return out


def load_trends(rows: Sequence[Mapping]) -> list[PowerLaw]:
    """Every power law of `QUANTITIES` for every group of ``rows``."""
    fits = []
    for name, members in groups(rows).items():
        N = [r.get("N") for r in members]
        for q, label, unit, hertz in QUANTITIES:
            y = [r.get(q) for r in members]
            if all(v is None for v in y):
                continue
            fits.append(
                fit_power_law(
                    [math.nan if v is None else v for v in N],
                    [math.nan if v is None else v for v in y],
                    quantity=q,
                    label=label,
                    unit=unit,
                    group=name,
                    hertz=hertz,
                )
            )
    return fits


def _fraction(value: float) -> str:
    """A Hertz exponent as the fraction it is (1/3, 4/3, -2/3), else to 3 decimals."""
    for den in (1, 2, 3, 4, 6):
        if abs(value * den - round(value * den)) < 1e-12:
            num = round(value * den)
            return f"{num}/{den}" if den > 1 else f"{num}"
    return f"{value:.3f}"


def trend_lines(fits: Sequence[PowerLaw]) -> list[str]:
    """One plain-text line per fit, for a console: y ~ N^alpha, its 95 % interval, R² in log
    space, the Hertz exponent; or why it was not fitted."""
    lines = []
    for f in fits:
        label = f.label.replace("²", "^2")
        where = "" if f.group == "all" else f" ({f.group})"
        if not f.fitted or f.ci95 is None:
            lines.append(f"trend{where}: {label}: no fit, {f.note}")
            continue
        hertz = "" if f.hertz is None else f", Hertz {_fraction(f.hertz)}"
        lines.append(
            f"trend{where}: {label} ~ N^{f.exponent:.3f}  (95 % {f.ci95[0]:.3f} to {f.ci95[1]:.3f}, "
            f"r^2 = {f.r2:.4f}, {f.n} loads{hertz})"
        )
    return lines
