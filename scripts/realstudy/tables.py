"""The study's tables, as Markdown lines."""

from __future__ import annotations

from .layouts import NAMES, SHORT, SURFACES


def _ci(v: float, ci, fmt: str = ".3f") -> str:
    return f"{v:{fmt}} ({ci[0]:{fmt}} – {ci[1]:{fmt}})"


def table_friction(held: dict, checks: dict) -> list[str]:
    lines = [
        "| layout | exact integrals | paper's closed forms | generalised model | point sums (check) "
        "| exact vs point sums (RMS, of N) |",
        "|---|---|---|---|---|---|",
    ]
    for name, h in held.items():
        cells = [_ci(h[k]["fit"]["f"], h[k]["fit"]["ci95"]) for k in ("exact", "paper", "model", "points")]
        lines.append(f"| {SHORT[name]} | " + " | ".join(cells) + f" | {checks[name]:.1%} |")
    return lines


def table_held_out(held: dict) -> list[str]:
    lines = [
        "| layout | model | parameters | held-out \\|ΔF\\| RMS | held-out \\|ΔM\\| RMS | wrench angle |",
        "|---|---|---|---|---|---|",
    ]
    for name, h in held.items():
        for key in (
            "exact",
            "paper",
            "model",
            "turn",
            *(("fe",) if "fe" in h else ()),
            "ellipsoid",
            "quartic",
        ):
            s = h[key]["test"]
            k = h[key]["fit"].get("n_params", 1)
            lines.append(
                f"| {SHORT[name]} | {NAMES[key]} | {k} | {s['force_rms_N']:.2f} N ({s['force_rel']:.0%}) | "
                f"{s['torque_rms_Nmm']:.1f} N·mm ({s['torque_rel']:.0%}) | {s['angle_deg']:.1f}° |"
            )
    return lines


def table_across(across: dict) -> list[str]:
    lines = [
        "| predicted layout | f from the other four | exact: \\|ΔF\\|, \\|ΔM\\| "
        "| ellipsoid: \\|ΔF\\|, \\|ΔM\\| "
        "| quartic: \\|ΔF\\|, \\|ΔM\\| |",
        "|---|---|---|---|---|",
    ]
    for name, row in across.items():
        cells = [
            f"{row[k]['test']['force_rel']:.0%}, {row[k]['test']['torque_rel']:.0%}"
            for k in ("exact", *SURFACES)
        ]
        lines.append(f"| {SHORT[name]} | {row['exact']['f']:.3f} | " + " | ".join(cells) + " |")
    return lines


def table_table1(t1: dict) -> list[str]:
    lines = ["| layout | f = F0/N | F0 (N) | M0 (N·mm) | a | m |", "|---|---|---|---|---|---|"]
    for name, rows in t1.items():
        cells = []
        for key, scale, fmt in (
            ("f", 1, ".3f"),
            ("F0", 1, ".2f"),
            ("M0", 1000, ".0f"),
            ("a", 1, ".2f"),
            ("m", 1, ".2f"),
        ):
            r = rows[key]
            lo, hi = (scale * v for v in r["ci95"])
            cells.append(
                f"{scale * r['fitted']:{fmt}} ({lo:{fmt}} – {hi:{fmt}}); map {scale * r['map']:{fmt}}"
            )
        lines.append(f"| {SHORT[name]} | " + " | ".join(cells) + " |")
    return lines


def table_diagnosis(per_log: dict) -> list[str]:
    lines = [
        "| layout | named | parameters (95 %) | held-out RMSE before → after | ΔBIC | lack of fit |",
        "|---|---|---|---|---|---|",
    ]
    for name, d in per_log.items():
        pars = "; ".join(f"{k} = {_ci(v['value'], v['ci95'], '.4g')}" for k, v in d["parameters"].items())
        g = d["gain"]
        lof = (
            "yes: " + d["lack_of_fit"]["message"].split(":")[1].strip()[:90]
            if d["lack_of_fit"]["detected"]
            else "no"
        )
        lines.append(
            f"| {SHORT[name]} | {' + '.join(d['causes'])}{' ¹' if d['failed_with_every_cause'] else ''} "
            f"| {pars or '–'} | {g['rmse_before']:.3f} → "
            f"{g['rmse_after']:.3f} | {g['delta_bic']:.1f} | {lof} |"
        )
    return lines


def table_pooled(pooled: dict) -> list[str]:
    lines = ["| cause | ΔBIC summed over the five logs | admissible in |", "|---|---|---|"]
    for r in pooled["candidates"]:
        where = ", ".join(SHORT[g] for g in r["admissible_in"]) or "none"
        lines.append(f"| {r['name']} | {r['delta_bic_sum']:.1f} | {where} |")
    return lines


def table_extras(ex: dict) -> list[str]:
    lines = [
        "| layout | model | parameters | ΔBIC vs Coulomb | held-out \\|ΔF\\|, \\|ΔM\\| |",
        "|---|---|---|---|---|",
    ]
    for name, rows in ex.items():
        for key, r in rows.items():
            extra = {k: v for k, v in r.items() if k in ("mu", "h_m", "lambda_m", "f")}
            shown = ", ".join(
                f"{k} = " + (", ".join(f"{x:.3f}" for x in v) if isinstance(v, list) else f"{v:.4g}")
                for k, v in extra.items()
            )
            s = r["test"]
            lines.append(
                f"| {SHORT[name]} | {key.replace('_', ' ')} | {r['k']}{': ' + shown if shown else ''} | "
                f"{r['delta_bic']:.1f} | {s['force_rel']:.0%}, {s['torque_rel']:.0%} |"
            )
    return lines


# -- the study --------------------------------------------------------------------------------
