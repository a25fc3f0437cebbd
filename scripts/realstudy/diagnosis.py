"""fepost diagnose on each log, and the five pooled by summing each cause's ΔBIC."""

from __future__ import annotations

import numpy as np

from .layouts import NOMINAL_F, Layout


def diagnose_layout(lay: Layout) -> dict:
    """``fepost.diagnose`` on the layout's pushes, the map on its own grid, nominal f = `NOMINAL_F`."""
    from fepost.diagnose import diagnose
    from fepost.diagnose.measured import MeasuredData
    from fepost.diagnose.simulation import simulation_from_maps

    sim = simulation_from_maps(lay.pmap, friction=NOMINAL_F, nr=lay.grid[0], nphi=lay.grid[1])
    data = MeasuredData(
        vx=lay.kin[:, 0], vy=lay.kin[:, 1], wz=lay.kin[:, 2], Fx=lay.W[:, 0], Fy=lay.W[:, 1],
        Mz=lay.W[:, 2], N=None, roll=np.zeros(lay.n, int), source=lay.name,
        time=np.arange(1.0, lay.n + 1.0),
    )  # fmt: skip
    failed = None
    try:
        d = diagnose(sim, data, friction=NOMINAL_F)
    except (ArithmeticError, ValueError) as exc:  # fepost's errors subclass ValueError
        failed = f"{type(exc).__name__}: {exc}"
        d = _diagnose_without(sim, data, "load_transfer")
    return {
        "failed_with_every_cause": failed,
        "cause": d.cause,
        "causes": list(d.causes),
        "parameters": {
            k: {"value": v.value, "ci95": list(v.ci95), "unit": v.unit} for k, v in d.parameters.items()
        },
        "gain": {k: d.gain[k] for k in ("rmse_before", "rmse_after", "delta_bic")},
        "lack_of_fit": {"detected": bool(d.lack_of_fit["detected"]), "message": d.lack_of_fit["message"]},
        "candidates": [
            {k: v for k, v in plain(c.to_dict()).items() if k in CANDIDATE_KEYS} for c in d.candidates
        ],
        "outliers": list(d.outliers),
    }


CANDIDATE_KEYS = ("name", "delta_bic", "admissible", "cv_rmse", "reasons", "parameters", "n_params")


def _diagnose_without(sim, data, cause: str):
    """The diagnosis with one cause left out of the vocabulary (after that cause's fit failed)."""
    from unittest import mock

    from fepost.diagnose import causes, diagnose, pairs, pipeline

    def build(pred):
        return {k: v for k, v in causes.build_candidates(pred).items() if k != cause}

    kept = tuple(e for e in causes.EXTENSIONS if e != cause)
    with mock.patch.object(pipeline, "build_candidates", build), mock.patch.object(pairs, "EXTENSIONS", kept):
        return diagnose(sim, data, friction=NOMINAL_F)


def plain(obj):
    """JSON-ready copy of a diagnosis value (numpy scalars and arrays to Python)."""
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if hasattr(obj, "to_dict"):
        return plain(obj.to_dict())
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def pooled_diagnosis(per_log: dict) -> dict:
    """Each cause's ΔBIC summed over the logs (each log with its own parameters) and its spread."""
    names = sorted({c["name"] for d in per_log.values() for c in d["candidates"]})
    rows = []
    for name in names:
        got = {k: next((c for c in d["candidates"] if c["name"] == name), None) for k, d in per_log.items()}
        vals = [c["delta_bic"] for c in got.values() if c is not None]
        rows.append({
            "name": name, "delta_bic_sum": float(np.sum(vals)), "logs": len(vals),
            "admissible_in": [k for k, c in got.items() if c is not None and c["admissible"]],
            "per_log": {k: (None if c is None else c["delta_bic"]) for k, c in got.items()},
        })  # fmt: skip
    rows.sort(key=lambda r: r["delta_bic_sum"])
    return {"candidates": rows, "best": rows[0]["name"] if rows else None}


# -- physics beyond the vocabulary ---------------------------------------------------------------
