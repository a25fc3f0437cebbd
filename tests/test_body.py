"""The body JSON contract (`fepost.body`): validation, one-line errors, the supports' statics loads."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from fepost.body import load_body, support_loads
from fepost.errors import DataError, InputFileError, ScaleError

BODIES = Path(__file__).resolve().parents[1].parent / "shared" / "real" / "planar-sliding" / "bodies"

LEGS = {
    "mass": 1.5,
    "gravity": 9.81,
    "centre_of_mass": [0.05, 0.05],
    "reference_point": [0.05, 0.05],
    "supports": [[0.01, 0.01], [0.13, 0.01], [0.01, 0.13]],
    "support_radius": 0.002,
    "log": {
        "format": "planar-push",
        "sensor_to_world": [[0.0, 1.0], [1.0, 0.0]],
        "body_origin_in_mocap": [50, 50, 0],
        "length_unit": 0.001,
    },
    "board": {"E": 3e9},
}
FLAT = {k: v for k, v in LEGS.items() if k not in ("supports", "support_radius")} | {
    "base": [[0.0, 0.0], [0.15, 0.0], [0.0, 0.15]]
}


def _write(tmp_path: Path, data, name="body.json") -> Path:
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return p


def _loads_by_moments(pts, com, w):
    """Independent statics: each load from the moment balance about the line through the other two
    supports (lever arm of the weight over lever arm of the support)."""
    pts = np.asarray(pts, float)
    out = []
    for i in range(3):
        a, b = pts[(i + 1) % 3], pts[(i + 2) % 3]
        n = np.array([-(b - a)[1], (b - a)[0]])
        out.append(w * np.dot(np.asarray(com) - a, n) / np.dot(pts[i] - a, n))
    return np.array(out)


def test_legs_and_flat_read(tmp_path):
    b = load_body(_write(tmp_path, LEGS))
    assert b.kind == "supports" and b.weight == pytest.approx(1.5 * 9.81, rel=1e-15)
    assert b.supports == ((0.01, 0.01), (0.13, 0.01), (0.01, 0.13)) and b.support_radius == 0.002
    assert b.log is not None and b.log.length_unit == 0.001
    assert b.log.matrix().tolist() == [[0.0, 1.0], [1.0, 0.0]]
    assert dict(b.extra) == {"board": {"E": 3e9}}
    assert b.name == "body"  # no name key: the file's stem
    f = load_body(_write(tmp_path, FLAT, "flat.json"))
    assert f.kind == "base" and f.base_area() == pytest.approx(0.5 * 0.15**2, rel=1e-12)
    with pytest.raises(DataError, match="flat base"):
        support_loads(f)


def test_body_is_frozen(tmp_path):
    b = load_body(_write(tmp_path, LEGS))
    with pytest.raises(AttributeError):
        b.mass = 2.0  # type: ignore[misc]
    loads = support_loads(b)
    with pytest.raises(ValueError):
        loads[0] = 0.0


@pytest.mark.parametrize(
    "supports, com",
    [
        ([[0.01, 0.01], [0.13, 0.01], [0.01, 0.13]], [0.05, 0.05]),  # the centroid: equal thirds
        ([[0.01, 0.01], [0.09, 0.03], [0.01, 0.13]], [0.05, 0.05]),
        ([[0.03, 0.03], [0.06333, 0.04333], [0.04333, 0.06333]], [0.05, 0.05]),
        ([[0.0, 0.0], [0.2, 0.0], [0.0, 0.1]], [0.15, 0.02]),
    ],
)
def test_support_loads_match_moment_balance(tmp_path, supports, com):
    data = copy.deepcopy(LEGS) | {"supports": supports, "centre_of_mass": com}
    b = load_body(_write(tmp_path, data))
    loads = support_loads(b)
    np.testing.assert_allclose(loads, _loads_by_moments(supports, com, b.weight), rtol=1e-12)
    assert loads.sum() == pytest.approx(b.weight, rel=1e-14)
    moment = np.asarray(supports).T @ loads
    np.testing.assert_allclose(moment, b.weight * np.asarray(com), rtol=1e-12)


def test_shared_bodies():
    if not BODIES.is_dir():
        pytest.skip(f"{BODIES} is absent: the real measurements live in ../shared/real/planar-sliding")
    w = 1.518 * 9.81
    b = load_body(BODIES / "10_130_10_10_10_130.json")
    np.testing.assert_allclose(support_loads(b), [w / 3] * 3, rtol=1e-12)
    # legs (10,10), (90,30), (10,130), CoM (50,50): by hand, N2 = W/2 and N1 = N3 = W/4
    b = load_body(BODIES / "10_90_10_10_30_130.json")
    np.testing.assert_allclose(support_loads(b), [w / 4, w / 2, w / 4], rtol=1e-12)
    assert load_body(BODIES / "patch.json").kind == "base"


def _edit(data, key, value):
    out = copy.deepcopy(data)
    if value is _DROP:
        del out[key]
    else:
        out[key] = value
    return out


_DROP = object()


@pytest.mark.parametrize(
    "data, error, message",
    [
        (_edit(LEGS, "mass", _DROP), DataError, "missing key 'mass'"),
        (_edit(LEGS, "mass", -1), DataError, "key 'mass' must be positive, got -1"),
        (_edit(LEGS, "gravity", "9.81"), DataError, "key 'gravity' must be a number, got '9.81'"),
        (
            _edit(LEGS, "centre_of_mass", [0.05]),
            DataError,
            "key 'centre_of_mass' must be a list of 2 numbers",
        ),
        (
            _edit(LEGS, "supports", [[0, 0], [0.1, 0]]),
            DataError,
            "key 'supports' must be a list of 3 [x, y] points",
        ),
        (
            _edit(LEGS, "supports", [[0, 0], [0.1, 0.1], [0.2, 0.2]]),
            DataError,
            "key 'supports': the three supports are collinear",
        ),
        (_edit(LEGS, "centre_of_mass", [0.2, 0.2]), DataError, "lies outside the supports' triangle"),
        (_edit(LEGS, "support_radius", _DROP), DataError, "missing key 'support_radius'"),
        (
            _edit(LEGS, "support_radius", 0.07),
            DataError,
            "key 'support_radius': 0.07 m makes the supports' discs",
        ),
        (_edit(LEGS, "base", [[0, 0], [1, 0], [0, 1]]), DataError, "not both"),
        (_edit(FLAT, "base", _DROP), DataError, "not neither"),
        (_edit(FLAT, "base", [[0, 0], [0.2, 0], [0, 0.1], [0.1, 0.1]]), DataError, "of the polygon cross"),
        (_edit(FLAT, "centre_of_mass", [0.1, 0.1]), DataError, "outside the base polygon"),
        (_edit(LEGS, "supports", [[10, 10], [130, 10], [10, 130]]), ScaleError, "are the lengths in metres?"),
        (_edit(LEGS, "log", {"format": "csv"}), DataError, "key 'log.format' must be one of planar-push"),
        (
            _edit(LEGS, "log", LEGS["log"] | {"sensor_to_world": [[1, 1], [1, 1]]}),
            DataError,
            "key 'log.sensor_to_world' is singular",
        ),
        (
            _edit(LEGS, "log", LEGS["log"] | {"length_unit": 0}),
            DataError,
            "key 'log.length_unit' must be positive",
        ),
        (
            _edit(LEGS, "log", {k: v for k, v in LEGS["log"].items() if k != "body_origin_in_mocap"}),
            DataError,
            "missing key 'log.body_origin_in_mocap'",
        ),
        ("[1, 2]", InputFileError, "body JSON must be an object, got list"),
        ('{"mass": NaN}', InputFileError, "unreadable body JSON"),
        ("{", InputFileError, "unreadable body JSON"),
    ],
)
def test_refusals_are_one_line_naming_file_and_key(tmp_path, data, error, message):
    p = _write(tmp_path, data)
    with pytest.raises(error) as info:
        load_body(p)
    text = str(info.value)
    assert text.startswith(f"{p}: ") and "\n" not in text
    assert message in text


def test_missing_file(tmp_path):
    with pytest.raises(InputFileError, match="body file not found"):
        load_body(tmp_path / "none.json")
