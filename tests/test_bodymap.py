"""``fepost map``: a body's contact-pressure map, checked against statics and closed forms.

The maps are read back with meshio and integrated by hand (independent of fepost's
reader), then through ``fepost coefficients`` and ``fepost predict``:
pure sliding gives F = f N; pure spin about the reference point gives
M = f Σ N_i ⟨|r|⟩_i for point supports (a disc's mean lever arm, by scipy's
quadrature here) and f ∬ σ |r| dA in closed form for a uniform triangle.
"""

from __future__ import annotations

import csv
import json
import math

import meshio
import numpy as np
import pytest
from scipy import integrate

from fepost.cli import main

F = 0.3  # fepost's default friction coefficient
G = 9.81
MASS = 1.518
W = MASS * G
#: Identities: statics loads and the exact load of a linear field, to round-off.
ROUND_OFF = 1e-12
#: A polar grid the map command recommends carries the load within this (fepost.bodymap.grid).
GRID_TOL = 5e-3


def write_body(path, **keys):
    body = {"mass": MASS, "gravity": G, "centre_of_mass": [0.05, 0.05], "reference_point": [0.05, 0.05]}
    body.update(keys)
    path.write_text(json.dumps(body))
    return path


#: Three legs, loaded unequally (centre of mass off their centroid), discs big enough for the
#: default polar grid.
LEGS = {"supports": [[0.02, 0.02], [0.10, 0.03], [0.03, 0.10]], "support_radius": 0.006}
#: The real block's flat base.
TRIANGLE = {"base": [[0.0, 0.0], [0.15, 0.0], [0.0, 0.15]]}


def statics_loads(supports, com):
    a = np.vstack([np.ones(3), np.array(supports).T])
    return np.linalg.solve(a, W * np.array([1.0, com[0], com[1]]))


def read_map(path):
    m = meshio.read(path)
    xy = m.points[:, :2]
    tri = m.cells_dict["triangle"]
    p = m.point_data["pressure"]
    return xy, tri, p


def hand_load(xy, tri, p):
    """N and the first moments of a linear field: 3-point (edge-midpoint) rule, exact for it."""
    a, b, c = (xy[tri[:, k]] for k in range(3))
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    pa, pb, pc = (p[tri[:, k]] for k in range(3))
    mids = [((a + b) / 2, (pa + pb) / 2), ((b + c) / 2, (pb + pc) / 2), ((c + a) / 2, (pc + pa) / 2)]
    n = sum(float(np.sum(area * q)) / 3 for _, q in mids)
    first = sum((area * q) @ x for x, q in mids) / 3  # the midpoint rule is exact for quadratics
    return n, first / n


@pytest.fixture(scope="module")
def maps(tmp_path_factory):
    d = tmp_path_factory.mktemp("bodymap")
    legs = write_body(
        d / "legs_body.json", centre_of_mass=[0.045, 0.05], reference_point=[0.045, 0.05], **LEGS
    )
    base = write_body(d / "base_body.json", **TRIANGLE)
    out = {}
    for name, body in (("legs", legs), ("base", base)):
        assert main(["map", str(body), "--out", str(d / f"{name}.vtu")]) == 0
        out[name] = d / f"{name}.vtu"
    assert main(["map", str(legs), "--out", str(d / "legs_uniform.vtu"), "--profile", "uniform"]) == 0
    out["legs_uniform"] = d / "legs_uniform.vtu"
    out["dir"] = d
    return out


def test_support_map_carries_the_statics_loads(maps):
    xy, tri, p = read_map(maps["legs"])
    n, cop = hand_load(xy, tri, p)
    assert n == pytest.approx(W, rel=ROUND_OFF), "total load = m g"
    assert np.hypot(*cop) < ROUND_OFF * 0.1, (
        f"centre of pressure at the reference point (= centre of mass): {cop}"
    )
    loads = statics_loads(LEGS["supports"], [0.045, 0.05])
    ref = np.array([0.045, 0.05])
    for (sx, sy), load in zip(LEGS["supports"], loads, strict=True):
        near = np.hypot(xy[:, 0] - (sx - ref[0]), xy[:, 1] - (sy - ref[1])) <= 0.006 * (1 + 1e-9)
        disc = tri[np.all(near[tri], axis=1)]
        n_i, c_i = hand_load(xy, disc, p)
        assert n_i == pytest.approx(load, rel=ROUND_OFF), f"support at ({sx}, {sy})"
        assert np.allclose(c_i, [sx - ref[0], sy - ref[1]], atol=1e-15), "disc centre of pressure"
    side = json.loads(maps["legs"].with_suffix(".json").read_text())
    assert side["separate_patches"] == 3 and side["reaction_z"] == pytest.approx(W, rel=ROUND_OFF)
    assert [s["load"] for s in side["supports"]] == pytest.approx(loads, rel=ROUND_OFF)


def test_base_map_is_uniform_and_balanced(maps):
    xy, tri, p = read_map(maps["base"])
    n, cop = hand_load(xy, tri, p)
    assert n == pytest.approx(W, rel=ROUND_OFF)
    assert np.hypot(*cop) < 1e-15, "the triangle's centroid is the centre of mass (0.05, 0.05)"
    assert np.ptp(p) == 0.0 and p[0] == pytest.approx(W / (0.5 * 0.15**2), rel=ROUND_OFF)
    # frame: the body frame moved to the reference point
    assert xy.min(axis=0) == pytest.approx([-0.05, -0.05]) and xy.max(axis=0) == pytest.approx([0.10, 0.10])


def grid_options(path):
    """The ``--nr``/``--nphi`` the map's sidecar recommends (the grid that carries its load)."""
    grid = json.loads(path.with_suffix(".json").read_text())["grid"]
    assert abs(grid["load_carried"] - 1) <= GRID_TOL
    return ["--nr", str(grid["nr"]), "--nphi", str(grid["nphi"])]


def coefficients(path, tmp_path, *extra):
    out = tmp_path / f"{path.stem}.coefficients.json"
    assert main(["coefficients", str(path), "--json", str(out), *grid_options(path), *extra]) == 0
    return json.loads(out.read_text())


def triangle_r_integral(vertices):
    """∬ |r| dA over a triangle about the origin, in closed form: over the three triangles
    (origin, edge), ∫ r dA = h³/6 [t√(h²+t²)/h² + asinh(t/h)] between the edge's ends, with h
    the origin's distance from the edge and t the coordinate along it from the foot."""
    total = 0.0
    v = np.asarray(vertices, float)
    for i in range(3):
        p, q = v[i], v[(i + 1) % 3]
        e = (q - p) / np.hypot(*(q - p))
        h = abs(p[0] * e[1] - p[1] * e[0])
        t0, t1 = float(p @ e), float(q @ e)

        def prim(t, h=h):
            return h**3 / 6 * (t * math.sqrt(h * h + t * t) / h**2 + math.asinh(t / h))

        total += prim(t1) - prim(t0)
    return total


def test_base_map_through_fepost_coefficients(maps, tmp_path):
    c = coefficients(maps["base"], tmp_path)
    assert c["N_fe"] == pytest.approx(W, rel=1e-12), "fepost's exact integral over the faces"
    assert c["N"] == pytest.approx(W, rel=GRID_TOL), "the polar grid's load"
    assert c["patch"]["centre"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12), "origin = reference point"
    tri = np.array(TRIANGLE["base"]) - 0.05
    m0 = F * W / (0.5 * 0.15**2) * triangle_r_integral(tri)
    assert c["M0"] == pytest.approx(m0, rel=GRID_TOL), "pure-spin torque of a uniform triangle"
    assert c["F0"] == pytest.approx(F * W, rel=GRID_TOL)
    assert c["patch"]["circular"] is False


def mean_lever_arm(d, a, hertz):
    """⟨|r|⟩ over a disc of radius a whose centre is d from the origin (weights: Hertz or uniform)."""

    def w(rho):
        return math.sqrt(max(0.0, 1 - (rho / a) ** 2)) if hertz else 1.0

    def f(phi, rho, g):
        return g(rho, phi) * w(rho) * rho

    def arm(rho, phi):
        return math.hypot(d + rho * math.cos(phi), rho * math.sin(phi))

    num = integrate.dblquad(lambda phi, rho: f(phi, rho, arm), 0, a, 0, 2 * math.pi, epsabs=1e-13)[0]
    den = integrate.dblquad(lambda phi, rho: f(phi, rho, lambda *_: 1.0), 0, a, 0, 2 * math.pi)[0]
    return num / den


def predict(path, tmp_path, rows, *extra):
    kin = tmp_path / "kin.csv"
    kin.write_text("vx,vy,wz\n" + "".join(f"{vx},{vy},{wz}\n" for vx, vy, wz in rows))
    out = tmp_path / "pred.csv"
    argv = ["predict", str(path), "--kinematics", str(kin), "--out", str(out), *grid_options(path), *extra]
    assert main(argv) == 0
    with out.open() as fh:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(fh)]


def test_support_map_through_fepost_predict(maps, tmp_path):
    c = coefficients(maps["legs"], tmp_path)
    assert c["N_fe"] == pytest.approx(W, rel=1e-12)
    assert c["patch"]["centre"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    slide, spin = predict(maps["legs"], tmp_path, [(0.01, 0.0, 0.0), (0.0, 0.0, 1.0)])
    assert slide["Fx_exact"] == pytest.approx(-F * W, rel=GRID_TOL), "pure sliding: F = f N"
    assert abs(slide["Fy_exact"]) < 1e-9 * W
    ref = np.array([0.045, 0.05])
    loads = statics_loads(LEGS["supports"], ref)
    arms = [np.array(s) - ref for s in LEGS["supports"]]
    d = [float(np.hypot(*r)) for r in arms]
    # pure spin (w_z > 0): each support slides along e_theta; torque f sum N_i <|r|>_i
    m_points = F * sum(n * di for n, di in zip(loads, d, strict=True))
    m_discs = F * sum(n * mean_lever_arm(di, 0.006, True) for n, di in zip(loads, d, strict=True))
    assert spin["Mz_exact"] == pytest.approx(-m_discs, rel=GRID_TOL), "pure spin: M = f sum N_i <|r|>_i"
    assert abs(m_discs / m_points - 1) < 0.01, "the discs' size moves the torque by under 1 %"
    fx = -F * sum(n * -r[1] / np.hypot(*r) for n, r in zip(loads, arms, strict=True))
    fy = -F * sum(n * r[0] / np.hypot(*r) for n, r in zip(loads, arms, strict=True))
    assert [spin["Fx_exact"], spin["Fy_exact"]] == pytest.approx([fx, fy], abs=GRID_TOL * F * W)


def test_disc_profile_hardly_matters(maps, tmp_path):
    """Hertz against uniform discs: the torque at pure spin differs by ~a²/(40 d), under 1e-3."""
    ref = np.array([0.045, 0.05])
    d = [float(np.hypot(*(np.array(s) - ref))) for s in LEGS["supports"]]
    for di in d:
        gap = mean_lever_arm(di, 0.006, False) - mean_lever_arm(di, 0.006, True)
        assert gap == pytest.approx(0.006**2 / (40 * di), rel=0.05), "second-order estimate"
    hertz = coefficients(maps["legs"], tmp_path)
    uniform = coefficients(maps["legs_uniform"], tmp_path)
    assert uniform["N_fe"] == pytest.approx(hertz["N_fe"], rel=1e-12)
    assert abs(uniform["M0"] / hertz["M0"] - 1) < 2 * GRID_TOL


def test_split_maps_stay_refused_without_the_declaration(maps, tmp_path, capsys):
    side = json.loads(maps["legs"].with_suffix(".json").read_text())
    bare = tmp_path / "bare.vtu"
    bare.write_bytes(maps["legs"].read_bytes())
    assert main(["coefficients", str(bare)]) == 2
    assert "3 separate contact patches" in capsys.readouterr().err
    wrong = tmp_path / "wrong.vtu"
    wrong.write_bytes(maps["legs"].read_bytes())
    wrong.with_suffix(".json").write_text(json.dumps({**side, "separate_patches": 2}))
    assert main(["coefficients", str(wrong)]) == 2
    assert "3 separate contact patches" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"supports": [[0.0, 0.0], [0.1, 0.0], [0.2, 0.0]], "support_radius": 0.002}, "collinear"),
        ({"supports": [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]]}, "missing key 'support_radius'"),
        ({"base": [[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]]}, "outside the base polygon"),
        ({}, "give either 'supports'"),
    ],
)
def test_bad_body_files(tmp_path, capsys, keys, message):
    body = write_body(tmp_path / "body.json", **keys)
    assert main(["map", str(body), "--out", str(tmp_path / "m.vtu")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err and str(body) in err, err
    assert list(tmp_path.iterdir()) == [body], "nothing written"


def test_unreadable_body_and_unwritable_outputs(tmp_path, capsys):
    body = tmp_path / "body.json"
    body.write_text('{"mass": 1.5,')
    assert main(["map", str(body), "--out", str(tmp_path / "m.vtu")]) == 2
    assert "unreadable body JSON" in capsys.readouterr().err
    good = write_body(tmp_path / "good.json", **TRIANGLE)
    for out, message in (
        (tmp_path / "m.csv", "a map is written as a .vtu file"),
        (tmp_path / "missing" / "m.vtu", "does not exist"),
        ("-", "not standard output"),
    ):
        assert main(["map", str(good), "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and message in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["body.json", "good.json"]
