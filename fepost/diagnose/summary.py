"""The words of a diagnosis: ``summary.txt`` of ``fepost diagnose``."""

from __future__ import annotations

import math

from .causes import MEANING
from .measured import CHANNELS


def _cause_lines(diag) -> list[str]:
    lines = [f"cause: {diag.cause}"]
    if len(diag.causes) > 1:
        lines.append(f"causes: {', '.join(diag.causes)} (primary first; one model holds them all)")
    if diag.cause == "none":
        lines.append("no extension earns its parameters: the misfit is within the noise")
        return lines
    for c in diag.causes:
        lines.append(f"  {c}: {MEANING.get(c, '')}")
    for name, p in diag.parameters.items():
        unit = "" if p.unit in ("", "1") else f" {p.unit}"  # dimensionless: no unit written
        lines.append(
            f"  {name} = {p.value:.6g}{unit}  (95 % CI {p.ci95[0]:.6g} .. {p.ci95[1]:.6g})"
            + (f"  [{p.cause}]" if len(diag.causes) > 1 else "")
        )
    return lines


def _outlier_lines(diag) -> list[str]:
    rule = diag.robust
    if diag.outliers:
        rows = ", ".join(str(i) for i in diag.outliers)
        lines = diag.data.lines
        at = ", ".join(str(int(lines[i])) for i in diag.outliers) if lines is not None else ""
        return [
            f"outliers: {len(diag.outliers)} row(s) no candidate explains "
            f"(data rows {rows}; file lines {at}): "
            f"beyond {rule.get('threshold', float('nan')):.3g} noise SDs under every robust fit; "
            "left out of every fit and test"
        ]
    if rule.get("widespread"):
        return [
            f"outliers: none removed: {len(rule['beyond_threshold'])} rows lie beyond the outlier "
            "threshold, too many to be isolated glitches (see lack of fit)"
        ]
    return ["outliers: none (no row lies beyond the outlier threshold under every candidate)"]


def _recording_lines(holds) -> list[str]:
    """How a recording became test points: holds, the rule in seconds, dropouts, resets, splits."""
    rate = holds.rate
    known = math.isfinite(rate)
    at = f" at {rate:.4g} Hz" if known else ""
    lines = [
        f"recording: {holds.count} steady holds from {holds.rows_total} rows{at} ({holds.rows_used} rows "
        f"used, {holds.rows_total - holds.rows_used} left out as transitions"
        + (f", {holds.segments} segments" if holds.segments > 1 else "")
        + ")"
    ]
    samples = f" ({holds.window * rate:.3g} samples at {rate:.4g} Hz)" if known else ""
    lines.append(f"  hold rule: {holds.rule}; window {holds.window:g} s{samples}")
    gaps = holds.gaps_text()
    lines.append(f"  gaps: {gaps}" if gaps else "  gaps: no dropouts, clock resets or drifting holds")
    return lines


def summary_text(diag) -> str:
    g = diag.gain
    lines = _recording_lines(diag.holds) if diag.holds is not None else []
    lines += _cause_lines(diag)
    lines.append(
        f"held-out RMSE (scaled, {diag.info.get('folds', 5)}-fold): before {g['rmse_before']:.4g}, "
        f"after {g['rmse_after']:.4g}; delta BIC vs the simulation {g['delta_bic']:.1f}"
    )
    lof = diag.lack_of_fit
    if lof:
        verdict = "DETECTED" if lof["detected"] else "none"
        lines.append(
            f"lack of fit: {verdict}: {lof['message']}. "
            f"Strongest test: {lof['test']}, Holm p = {lof['p_value']:.2g}"
        )
    lines += _outlier_lines(diag)
    if diag.noise:
        parts = [
            f"{ch} {diag.noise[ch]['model']} (s0 {diag.noise[ch]['s0']:.3g}, s1 {diag.noise[ch]['s1']:.3g})"
            for ch in CHANNELS
            if ch in diag.noise
        ]
        lines.append("noise model (scaled, sd^2 = s0^2 + (s1 |F|)^2, chosen by BIC): " + "; ".join(parts))
    pairs = diag.pairs
    if pairs is not None:
        tried = [t for t in pairs["trials"]]
        fitted = [t["second"] for t in tried if t["fitted"]]
        lines.append(
            f"second cause on top of {pairs['primary']}: "
            + (f"{pairs['chosen']} admitted" if pairs["chosen"] else "none admitted")
            + f" ({len(tried)} screened by score test, fitted: {', '.join(fitted) or 'none'})"
        )
        ft = pairs.get("friction_level") or {}
        if ft:
            lines.append(
                f"friction level inside the chosen model: f = {ft['f']:.4g} vs nominal {ft['f0']:.4g} "
                + ("(admitted as a second cause)" if ft.get("admissible") else "(consistent with nominal)")
            )
    for note in diag.separation:
        lines.append(f"cannot separate: {note}")
    if diag.indistinguishable:
        lines.append(
            "indistinguishable on these data (delta BIC < 10, both pass the nesting tests): "
            + ", ".join(diag.indistinguishable)
        )
    for note in diag.design_notes:
        lines.append(f"design: {note}")
    for key, title in (("before", "simulation"), ("after", "chosen model")):
        parts = []
        for ch in CHANNELS:
            st = diag.residuals[key][ch]
            parts.append(
                f"{ch} {st['verdict']} (rmse {st['rmse']:.3g}, worst: {st['strongest']}, "
                f"p={st['p_adjusted']:.2g})"
            )
        lines.append(f"residuals of the {title}: " + "; ".join(parts))
    cf = diag.closed_form
    lines.append(
        f"paper closed forms: RMSE vs data {cf['rmse_vs_data']:.4g}, vs exact integrals "
        f"{cf['rmse_vs_exact']:.4g} (exact vs data {cf['exact_rmse_vs_data']:.4g}), scaled"
    )
    lines.append("candidates (BIC, lower is better; admissible first):")
    for s in diag.candidates:
        mark = "*" if s.admissible else " "
        lines.append(
            f" {mark} {s.name:<29} BIC {s.fit.bic:11.1f}  dBIC {s.delta_bic:9.1f}  cv-rmse {s.cv.rmse:.4g}"
        )
    return "\n".join(lines) + "\n"
