"""What the whole tire's rolling runs say: free rolling, the slip curve's initial slope, k_x.

Free rolling is the state in which the axle puts no torque on the rim. A programme driven against
a reference radius R_ref (``aircraft_roll360_programme``) never rolls exactly there, so it is found
from the runs: their steady axle torques T_i against their turn per travel w_i = dtheta/dX. A
least-squares line T(w) through the runs nearest free rolling gives its zero w_0, the effective
rolling radius R_e = 1 / w_0, and every run's slip against it, kappa_i = R_e w_i - 1. The same
interpolation at w_0 gives Fx/N (about 0: rolling resistance aside) and fepost's k_x there.

The slip curve's initial slope C_kappa / N comes two ways from the same runs, each run's Fx/N
being its fitted steady value where its force was still building up (``RunPoint.slip_force``):

- ``secant``: the least-squares line of Fx/N against kappa (it falls short of the slope at 0 by
  the curve's bend, about theta = C kappa / (3 f N) for a brush tire);
- ``brush``: each run's Fx inverted through the brush curve of a parabolic pressure,
  Fx / (f N) = 3 theta - 3 theta^2 + theta^3 (|theta| < 1, sign of kappa), with the Coulomb f
  of the runs; the mean of the runs' C / N.

Both are compared with ``brush_slope``, the brush estimate from the static patch's strips and the
tread rubber's stiffness (no run needed). ``build_up`` fits the first-order build-up of
each run's force along its roll (scipy's ``curve_fit``). The brush curve's inverse is closed:
1 - theta = (1 - |Fx| / (f N))^(1/3).

k_x depends on the slip through the force: ``traction_shift`` fits each run's k_x against the
Fx/N of the same instant (the end of the roll).
"""

from __future__ import annotations

import json
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import aircraft_deck as ad

TREAD_DEPTH = 0.020  # m, the crown rubber (aircraft_geometry: rubber_thickness on the crown)
STATIC = "roll_static"


@dataclass(frozen=True)
class RunPoint:
    """One finished rolling run, reduced to what the slip curve needs (tail means)."""

    name: str
    turn_rate: float  # rad/m over the last fifth of the roll
    torque: float  # N m, axle on rim, tail mean
    fx_over_n: float  # tail means
    normal_load: float  # N, tail mean
    friction: float
    kx: float = math.nan  # fepost's k_x of the run's map against the static one
    #: Fx/N of the first-order build-up's limit (``build_up``): the steady value of a run
    #: that has not reached it; NaN where no build-up was fitted
    steady_fx_over_n: float = math.nan
    #: N m, the axle torque's build-up limit, likewise
    steady_torque_fit: float = math.nan
    #: Fx/N at the end of the roll, the instant of the run's map (and of its k_x)
    end_fx_over_n: float = math.nan

    @classmethod
    def from_sidecar(cls, side: dict, kx: float = math.nan, fit: BuildUp | None = None) -> RunPoint:
        """The run of ``side``; ``fit``: its force's ``build_up`` when the caller has it already."""
        tail = side["tail_means"]
        fit = fit or build_up(side)
        f_inf = math.nan if fit is None else fit.f_inf
        torque = None if fit is None else build_up(side, "axle_torque_Nm")
        return cls(
            side["case"],
            float(side["turn_per_travel_rad_per_m"]),
            float(side["axle_torque_tail_mean_Nm"]),
            float(tail["Fx"] / tail["Fz"]),
            float(tail["Fz"]),
            float(side["friction"]),
            kx,
            f_inf / float(tail["Fz"]),
            math.nan if torque is None else torque.f_inf,
            float(side["longitudinal_force_ratio"]),
        )

    @property
    def steady_torque(self) -> float:
        """The axle torque for free rolling: the fitted steady value where the run was still building
        up, else the tail mean (a steady run, a pre-wound one, or one at free rolling)."""
        return self.steady_torque_fit if math.isfinite(self.steady_torque_fit) else self.torque

    @property
    def slip_force(self) -> float:
        """Fx/N for the slip curve: the fitted steady value where there is one, else the tail mean."""
        return self.steady_fx_over_n if math.isfinite(self.steady_fx_over_n) else self.fx_over_n


@dataclass(frozen=True)
class FreeRolling:
    """Free rolling found from driven runs, and the slip curve's initial slope."""

    effective_radius: float  # m
    runs_used: tuple[str, ...]
    slips: dict[str, float]  # each run's slip against R_e
    fx_over_n_at_free: float
    kx_at_free: float
    secant_slope: float  # C_kappa / N, least-squares line of Fx/N against kappa
    brush_fit_slope: float  # C_kappa / N from the brush curve through each run
    bracketed: bool  # free rolling lies between the runs' turn rates (no extrapolation)


@dataclass(frozen=True)
class TractionShift:
    """k_x against the map's own longitudinal force: k_x = k0 + slope Fx/N (least squares)."""

    k0: float
    slope: float
    rms: float  # of the residuals
    runs: tuple[str, ...]


def traction_shift(points: list[RunPoint]) -> TractionShift | None:
    """The line of each run's k_x against its Fx/N at the same instant (the end of the roll), over
    every run with both; None with fewer than two distinct forces. A map and its force belong
    together whether the run is steady or not, so the line holds for building-up runs too: it is
    how k_x depends on the slip, through the force the slip curve gives."""
    use = [p for p in points if math.isfinite(p.kx) and math.isfinite(p.end_fx_over_n)]
    x = np.array([p.end_fx_over_n for p in use])
    if len(use) < 2 or np.ptp(x) <= 0:
        return None
    y = np.array([p.kx for p in use])
    slope, k0 = np.polyfit(x, y, 1)
    rms = float(np.sqrt(np.mean((y - (k0 + slope * x)) ** 2)))
    return TractionShift(float(k0), float(slope), rms, tuple(p.name for p in use))


def brush_theta(force_ratio: float) -> float:
    """theta in [0, 1] with 3 theta - 3 theta^2 + theta^3 = |Fx| / (f N) (brush tire, parabolic
    pressure; 1 at full sliding); NaN where the ratio is outside [0, 1]."""
    r = abs(force_ratio)
    if not 0.0 <= r <= 1.0:
        return math.nan
    # (1 - theta)^3 = 1 - r: one real root
    return 1.0 - (1.0 - r) ** (1.0 / 3.0)


def brush_slope_of(fx_over_n: float, kappa: float, friction: float) -> float:
    """C_kappa / N of one steady run: its Fx/N at slip ``kappa`` through the brush curve (parabolic
    pressure, Coulomb ``friction``); NaN at |kappa| <= 1e-3 (free rolling says nothing of it)."""
    if abs(kappa) <= 1e-3:
        return math.nan
    return 3.0 * friction * brush_theta(fx_over_n / friction) / abs(kappa)


def steady_brush_slopes(
    sides: list[dict], points: list[RunPoint], slips: dict[str, float]
) -> dict[str, float]:
    """C_kappa / N of every run that is steady over the last fifth of its roll (its sidecar's
    ``steadiness``) and slips (``slips``: against R_e): its own tail-mean Fx/N through the brush
    curve (`brush_slope_of`), no build-up fit in between."""
    out = {}
    for side, p in zip(sides, points, strict=True):
        if side["steadiness"]["steady"] and p.name in slips:
            c = brush_slope_of(p.fx_over_n, slips[p.name], p.friction)
            if math.isfinite(c):
                out[p.name] = c
    return out


def free_rolling(points: list[RunPoint], nearest: int = 3) -> FreeRolling:
    """Free rolling from the ``nearest`` runs of smallest steady |torque| (at least two of different
    turn rates): a least-squares line of the steady torque (``RunPoint.steady_torque``) against the
    turn rate; R_e = 1 / its zero."""
    if len(points) < 2:
        raise ValueError(f"free rolling needs at least two rolling runs, got {len(points)}")
    use = sorted(points, key=lambda p: abs(p.steady_torque))[: max(2, nearest)]
    w = np.array([p.turn_rate for p in use])
    if np.ptp(w) <= 0:
        raise ValueError("the runs nearest free rolling share one turn rate: no line through them")
    slope, icpt = np.polyfit(w, [p.steady_torque for p in use], 1)
    if slope == 0:
        raise ValueError("the axle torque does not change with the turn rate")
    w0 = -icpt / slope
    radius = 1.0 / w0
    kappa = {p.name: radius * p.turn_rate - 1.0 for p in points}
    fx_line = np.polyfit(w, [p.fx_over_n for p in use], 1)
    kxs = [(p.turn_rate, p.kx) for p in use if math.isfinite(p.kx)]
    kx0 = math.nan
    if len({q[0] for q in kxs}) >= 2:
        kx0 = float(np.polyval(np.polyfit(*zip(*kxs, strict=True), 1), w0))
    k = np.array([kappa[p.name] for p in use])
    secant = float(np.polyfit(k, [p.slip_force for p in use], 1)[0])
    brush = [c for p in use if math.isfinite(c := brush_slope_of(p.slip_force, kappa[p.name], p.friction))]
    return FreeRolling(
        effective_radius=float(radius),
        runs_used=tuple(p.name for p in use),
        slips={n: float(v) for n, v in kappa.items()},
        fx_over_n_at_free=float(np.polyval(fx_line, w0)),
        kx_at_free=kx0,
        secant_slope=secant,
        brush_fit_slope=float(np.nanmean(brush)) if brush else math.nan,
        bracketed=bool(w.min() <= w0 <= w.max()),
    )


@dataclass(frozen=True)
class BuildUp:
    """The first-order fit Fx(X) = F_inf (1 - exp(-X / sigma)) of a run's force along its roll,
    with the fit's standard errors (from its residuals: the FE history is not noisy, so they say
    how far the build-up is from first order) and the share of F_inf reached at the roll's end."""

    sigma: float  # m: the tire's longitudinal relaxation length (Pacejka, ch. 7)
    f_inf: float  # N
    sigma_se: float
    f_inf_se: float
    reached: float  # 1 - exp(-X_end / sigma)


def build_up(side: dict, quantity: str = "Fx") -> BuildUp | None:
    """``BuildUp`` of the run's printed longitudinal force (``quantity``: ``Fx``, or the axle torque
    ``axle_torque_Nm``; ``history``; X the axle travel), None where the force does not build up
    from 0 (no imposed slip: a free rim or a run at the reference radius; or wound up at its start:
    ``prewind_rad``) or too few records were printed."""
    from scipy.optimize import curve_fit

    if side.get("prewind_rad") or not side.get("imposed_slip"):
        return None

    h = side["history"]
    travel = np.asarray(h["axle_travel_m"], float)
    keep = travel > 1e-12
    x = np.concatenate([[0.0], travel[keep]])
    y, fx = (np.concatenate([[0.0], np.asarray(h[q], float)[keep]]) for q in (quantity, "Fx"))
    tail = x >= 0.8 * x.max()
    if x.size < 4 or abs(fx[tail].mean()) < 1e-3 * abs(side["tail_means"]["Fz"]):
        return None

    def model(xx, sigma, f_inf):
        return f_inf * -np.expm1(-xx / sigma)

    (sigma, f_inf), cov = curve_fit(model, x, y, p0=(0.1 * x.max(), float(y[tail].mean())), maxfev=5000)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return BuildUp(float(sigma), float(f_inf), float(se[0]), float(se[1]), float(-np.expm1(-x.max() / sigma)))


def brush_slope(side: dict) -> float:
    """C_kappa / N of the brush model from the run's static patch, strip by strip: a lateral strip
    of width dy and length 2 a carries bristles of stiffness G_t / h per unit area (tread rubber
    shear modulus G_t, tread depth h = 20 mm), and under a small slip kappa its force is
    (G_t / h) 2 a^2 kappa dy; summed over the strips, over N."""
    strips = side["static_patch_strips"]
    g = ad.RUBBER["TREAD"]["shear_modulus"]
    a = np.asarray(strips["length"]) / 2.0
    return float(g / TREAD_DEPTH * np.sum(2.0 * a**2 * np.asarray(strips["width"])) / side["static_load"])


def fepost_kx(out: Path, name: str) -> float:
    """k_x that ``fepost coefficients`` gives the run's map against ``roll_static``."""
    import contextlib
    import io

    from fepost.cli import main as fepost

    with tempfile.TemporaryDirectory(prefix="roll360-kx-") as tmp:
        js = Path(tmp) / "coef.json"
        static, rolled = out / f"{STATIC}.vtu", out / f"{name}.vtu"
        said = io.StringIO()
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            status = fepost(["coefficients", str(static), "--rolling", str(rolled), "--json", str(js)])
        if status != 0:
            raise RuntimeError(f"fepost coefficients failed on {rolled}: {said.getvalue().strip()[-300:]}")
        coef = json.loads(js.read_text())
    return float(coef.get("coefficients", coef)["k_x"])


def rolling_sidecars(out: Path) -> list[dict]:
    """The finished rolling runs' sidecars in ``out``, by name."""
    sides = [json.loads(p.read_text()) for p in sorted(out.glob("roll_*.json"))]
    return [s for s in sides if s.get("kind") == "rolling run"]


def table(out: Path, kx: bool = True, rig: Path | None = None) -> list[str]:
    """One line per finished run: slip, Fx/N (tail mean and the build-up's fitted limit), axle
    torque, steadiness, balance, fepost's k_x, relaxation length; then free rolling (from the
    torques where the runs are driven), the initial slope against the brush estimate, and the
    relaxation length against C_kappa / K_x with the rig's standstill stiffness K_x (``rig``: the
    folder of the rig's slides, `fepost.shimmy.brush.rig_stiffness`)."""
    lines = [
        f"{'run':<15} {'kappa':>7} {'Fx/N':>7} {'inf':>7} {'T kN m':>7} {'dFx/fN':>7} {'dFz/N':>7} "
        f"{'dT/fNR':>7} {'bal x/N':>8} {'bal z/N':>8} {'k_x':>7} {'sigma m':>7} {'CPU s/m':>7}"
    ]
    sides = rolling_sidecars(out)
    fits = [build_up(side) for side in sides]
    sig = [math.nan if fit is None else fit.sigma for fit in fits]
    points = []
    for side, fit, sigma in zip(sides, fits, sig, strict=True):
        st, bal = side["steadiness"], side["balance"]["residual_over_N"]
        kappa = side["longitudinal_slip"]
        k = fepost_kx(out, side["case"]) if kx else math.nan
        point = RunPoint.from_sidecar(side, k, fit)
        points.append(point)
        cpu = side["cpu_s_per_m"] or math.nan
        lines.append(
            f"{side['case']:<15} {kappa if kappa is not None else math.nan:7.4f} {point.fx_over_n:7.4f} "
            f"{point.steady_fx_over_n:7.4f} {point.torque / 1e3:7.3f} "
            f"{st['Fx_over_fN']:7.4f} {st['Fz_over_N']:7.4f} "
            f"{st['torque_over_fNR']:7.4f} {bal[0]:8.1e} {bal[2]:8.1e} {k:7.4f} "
            f"{sigma:7.3f} {cpu:7.0f}"
        )
    for side, fit in zip(sides, fits, strict=True):
        if fit is not None:
            n = side["tail_means"]["Fz"]
            lines.append(
                f"build-up of {side['case']}: sigma = {fit.sigma:.3f} +- {fit.sigma_se:.3f} m, "
                f"F_inf/N = {fit.f_inf / n:+.4f} +- {fit.f_inf_se / n:.4f}, {100 * fit.reached:.0f} % of it "
                "reached at the end of the roll"
            )
    if sides:
        lines.append(
            f"brush estimate of the initial slope C_kappa/N (strip by strip): {brush_slope(sides[-1]):.2f}"
        )
    if len({p.turn_rate for p in points}) >= 2:
        fr = free_rolling(points)
        where = "between the runs" if fr.bracketed else "EXTRAPOLATED beyond the runs"
        lines += [
            f"free rolling (axle torque 0, {where}: {', '.join(fr.runs_used)}): "
            f"R_e = {fr.effective_radius:.4f} m, Fx/N = {fr.fx_over_n_at_free:+.4f}, "
            f"k_x = {fr.kx_at_free:.4f}",
            "slips against R_e: " + ", ".join(f"{n} {v:+.4f}" for n, v in fr.slips.items()),
            f"slip curve: C_kappa/N = {fr.secant_slope:.2f} (least-squares line), "
            f"{fr.brush_fit_slope:.2f} (each run through the brush curve, f = {points[0].friction:g})",
        ]
        steady = steady_brush_slopes(sides, points, fr.slips)
        if steady:
            lines.append(
                "steady runs through the brush curve: C_kappa/N = "
                + ", ".join(f"{n} {c:.2f}" for n, c in steady.items())
                + f" (mean {np.mean(list(steady.values())):.2f})"
            )
        ts = traction_shift(points)
        if ts is not None:
            lines.append(
                f"k_x against each map's own Fx/N (end of roll): k_x = {ts.k0:+.4f} {ts.slope:+.3f} Fx/N "
                f"(rms {ts.rms:.4f} over {', '.join(ts.runs)})"
            )
        if rig is not None and any(math.isfinite(v) for v in sig):
            from fepost.shimmy.brush import rig_stiffness

            k_x = rig_stiffness(rig)["K_x"]
            n = float(np.mean([p.normal_load for p in points]))
            lines.append(
                f"relaxation length: sigma = {np.nanmean(sig):.3f} m (fitted, mean of the runs) against "
                f"C_kappa / K_x = {fr.secant_slope * n / k_x:.3f} m (line) .. "
                f"{fr.brush_fit_slope * n / k_x:.3f} m "
                f"(brush), K_x = {k_x:.4g} N/m ({rig}/d000_slide.json at standstill)"
            )
    return lines
