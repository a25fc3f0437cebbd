"""``load_transfer`` on a map of a few small supports stays finite where its fixed point does not contract.

Three 2 mm legs 40 mm apart (`fepost.bodymap`): the force turns sharply as the centre
of rotation passes a leg, so the fixed point d = h F(d)/N of the centre of pressure's
shift diverged for heights of a few centimetres (`fepost diagnose` stopped with
"vx must be finite"). The shifts are now kept finite and within the patch radius.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fepost.body import load_body
from fepost.bodymap import body_map, write_map
from fepost.diagnose.causes import Predictor, build_candidates
from fepost.diagnose.measured import parse_csv
from fepost.diagnose.simulation import load_simulation

BODY = {
    "mass": 1.5,
    "gravity": 9.81,
    "centre_of_mass": [0.05, 0.05],
    "reference_point": [0.05, 0.05],
    "supports": [[0.03, 0.03], [0.0633, 0.0433], [0.0433, 0.0633]],
    "support_radius": 0.002,
}


@pytest.fixture(scope="module")
def candidate(tmp_path_factory):
    folder = tmp_path_factory.mktemp("legs")
    (folder / "body.json").write_text(json.dumps(BODY))
    write_map(body_map(load_body(folder / "body.json")), folder / "legs.vtu")
    sim = load_simulation(folder / "legs.vtu", None, friction=0.3)
    rng = np.random.default_rng(3)
    n = 40
    u = rng.uniform(0.0, 4.0, n)  # spin ratio about the patch radius: the centre of rotation
    phi = rng.uniform(0.0, 2 * np.pi, n)  # passes near every leg
    rows = ["vx,vy,wz,Fx,Fy,Mz"] + [
        f"{1e-3 * np.cos(p):.9g},{1e-3 * np.sin(p):.9g},{k * 1e-3 / sim.radius:.9g},0,0,0"
        for k, p in zip(u, phi, strict=True)
    ]
    data = parse_csv("\n".join(rows) + "\n")
    pred = Predictor(sim, data)
    return build_candidates(pred)["load_transfer"], sim


@pytest.mark.parametrize("height", [0.005, 0.05, 0.2, -0.2])
def test_predictions_stay_finite_for_any_height(candidate, height):
    cand, sim = candidate
    names = [p.name for p in cand.parameters]
    values = np.array([0.3 if n == "f" else height if n in ("h_x", "h_y") else 0.0 for n in names])
    got = cand.predict(values)
    assert np.all(np.isfinite(got)), height
    # forces within the friction limit (scaled by f0 N): a bounded shift moves the map, not the load
    assert np.max(np.hypot(got[:, 0], got[:, 1])) <= 1.0 + 1e-9


def test_a_small_height_is_a_small_change(candidate):
    """Where the fixed point contracts the model is as before: continuous in h from no effect."""
    cand, _ = candidate
    names = [p.name for p in cand.parameters]

    def at(h):
        return cand.predict(np.array([0.3 if n == "f" else h if n in ("h_x", "h_y") else 0.0 for n in names]))

    base = at(0.0)
    assert np.max(np.abs(at(1e-5) - base)) < 1e-2 * np.max(np.abs(base))
