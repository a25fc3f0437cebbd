"""The planar-push reader (`fepost.pushes`): a synthetic rig's logs read back exactly, a real log
against an independent calculation and the physics, and damaged logs refused in one line each."""

from __future__ import annotations

import cmath
import json
import math
from pathlib import Path

import numpy as np
import pytest
from test_body import LEGS

from fepost.body import load_body
from fepost.errors import DataError, InputFileError
from fepost.pushes import read_log, read_pushes
from fepost.pushes.wrench import Settings

REAL = Path(__file__).resolve().parents[1].parent / "shared" / "real" / "planar-sliding"
NO_REAL = f"{REAL} is absent: the real push logs live in ../shared/real/planar-sliding"
C = math.sqrt(0.5)
SENSOR = [[C, C], [C, -C]]
#: Identities of the exact synthetic round trip (only rounding in the log's 12 digits).
EXACT = 1e-9


def _rot(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def _quat(yaw: float) -> list[float]:
    return [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]


def _body(tmp_path: Path, origin=(0.5, -0.3, 0.0)) -> Path:
    """test_body's three-leg body, logged with the rig's sensor matrix and ``origin``."""
    data = {k: v for k, v in LEGS.items() if k != "board"} | {
        "log": {
            "format": "planar-push",
            "sensor_to_world": SENSOR,
            "body_origin_in_mocap": list(origin),
            "length_unit": 0.001,
        }
    }
    p = tmp_path / "body.json"
    p.write_text(json.dumps(data))
    return p


class SyntheticPush:
    """A push the test makes: the block's reference point and yaw move linearly from the impact to the
    end, the finger moves linearly at a fixed yaw and presses with a constant world force."""

    def __init__(self, *, ref0, ref1, th0, th1, psi, force, zero, origin=(0.5, -0.3, 0.0), n=300, impact=60):
        self.ref0, self.ref1 = np.array(ref0, float), np.array(ref1, float)  # mm, world
        self.th0, self.th1, self.psi = th0, th1, psi
        self.force = np.array(force, float)  # N, the finger's force on the block, world axes
        self.zero = np.array(zero, float)
        self.n, self.impact = n, impact
        self.t = 1000.0 + 0.01 * np.arange(n)
        self.m_ref = np.array([50.0, 50.0]) + np.array(origin[:2])  # the reference point, mocap frame (mm)
        self.finger0 = self.ref0 + np.array([-60.0, 10.0])
        self.finger_v = np.array([2.0, 1.0])  # mm/s

    def pose(self, ref, th) -> list[float]:
        p = ref - _rot(th) @ self.m_ref
        return [p[0], p[1], 10.0, *_quat(th)]

    def lines(self) -> list[str]:
        out = [" ".join(f"{x:.12g}" for x in self.pose(self.ref0, self.th0))]
        out.append(" ".join(f"{x:.12g}" for x in self.pose(self.ref1, self.th1)))
        on = np.arange(self.n) >= self.impact
        reading = np.linalg.solve(np.array(SENSOR), _rot(self.psi).T @ -self.force)  # the sensor reads -F
        out.append(str(self.n))
        for t, loaded in zip(self.t, on, strict=True):
            f = self.zero + (reading if loaded else 0.0)
            out.append(f"{t:.9f} {f[0]:.12g} {f[1]:.12g}")
        tf = self.t[0] + 0.03 * np.arange(int((self.t[-1] - self.t[0]) / 0.03) + 2)
        out.append(str(len(tf)))
        for t in tf:
            x, y = self.finger0 + self.finger_v * (t - self.t[0])
            out.append(f"{t:.9f} {x:.12g} {y:.12g} 20 " + " ".join(f"{q:.12g}" for q in _quat(self.psi)))
        return out

    def expected(self, settings: Settings) -> tuple[np.ndarray, np.ndarray]:
        """(wrench, displacement) as the module docstring defines them, computed here forward."""
        t = self.t - self.t[0]
        ti = t[self.impact]
        keep = t >= ti + settings.settle
        s = (t[keep] - ti) / (t[-1] - ti)
        ref = (self.ref0 + s[:, None] * (self.ref1 - self.ref0)) * 1e-3
        finger = (self.finger0 + self.finger_v * t[keep][:, None]) * 1e-3
        r = finger - ref
        torque = np.mean(r[:, 0] * self.force[1] - r[:, 1] * self.force[0])
        f_start = _rot(self.th0).T @ -self.force
        d = _rot(self.th0).T @ (self.ref1 - self.ref0) * 1e-3
        turn = math.remainder(self.th1 - self.th0, 2 * math.pi)
        return np.array([*f_start, -torque]), np.array([*d, turn])


PUSHES = [
    dict(ref0=[600, 30], ref1=[610, 36], th0=0.3, th1=0.38, psi=0.25, force=[3.0, 1.2], zero=[0.02, -0.03]),
    dict(
        ref0=[610, 36], ref1=[605, 30], th0=0.38, th1=0.31, psi=-2.9, force=[-2.5, -1.9], zero=[0.025, -0.031]
    ),
    dict(ref0=[605, 30], ref1=[605, 40], th0=3.1, th1=-3.1, psi=1.6, force=[0.2, 3.9], zero=[0.022, -0.028]),
]


def write_log(path: Path, pushes, header: int | None = None) -> Path:
    lines = [str(len(pushes) if header is None else header)]
    for p in pushes:
        lines += p.lines()
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pushes")
    pushes = [SyntheticPush(**k) for k in PUSHES]
    return write_log(folder / "synthetic.txt", pushes), load_body(_body(folder)), pushes


def test_synthetic_log_reads_back_exactly(synthetic):
    log, body, pushes = synthetic
    table = read_pushes([log], body)
    assert len(table.pushes) == 3 and not table.left_out
    for got, made in zip(table.pushes, pushes, strict=True):
        wrench, disp = made.expected(Settings())
        np.testing.assert_allclose(got.wrench, wrench, rtol=0, atol=EXACT)
        np.testing.assert_allclose(got.displacement, disp, rtol=0, atol=EXACT)
        np.testing.assert_allclose(got.zero, made.zero, rtol=0, atol=EXACT)
        assert got.impact_time == pytest.approx(0.6, abs=1e-9) and not got.zero_from_log
    # the third push turns through the ±π cut: dθ is the short way round
    assert table.pushes[2].displacement[2] == pytest.approx(2 * math.pi - 6.2, abs=EXACT)


def test_synthetic_friction_signs(synthetic):
    """The support's friction opposes the finger: Fx, Fy are minus the finger's force (start frame)."""
    log, body, pushes = synthetic
    p = read_pushes([log], body).pushes[0]
    finger = _rot(-0.3) @ np.array([3.0, 1.2])
    np.testing.assert_allclose(p.wrench[:2], -finger, atol=EXACT)


def test_loaded_start_takes_the_log_median_zero(tmp_path, synthetic):
    _, body, _ = synthetic
    loaded = dict(PUSHES[0], zero=[0.4, -0.9])  # the finger already pressing: its own zero is wrong
    pushes = [SyntheticPush(**PUSHES[0]), SyntheticPush(**PUSHES[1]), SyntheticPush(**loaded)]
    pushes[2].zero = np.array([0.4, -0.9])
    log = write_log(tmp_path / "loaded.txt", pushes)
    table = read_pushes([log], body)
    third = table.pushes[2]
    assert third.zero_from_log and table.checks[0].zero_replaced == (3,)
    np.testing.assert_allclose(third.zero, np.median([[0.02, -0.03], [0.025, -0.031], [0.4, -0.9]], axis=0))


def test_a_push_that_hardly_moved_is_left_out(tmp_path, synthetic):
    _, body, _ = synthetic
    still = SyntheticPush(**dict(PUSHES[0], ref1=[600.2, 30.1], th1=0.3 + 1e-4))
    log = write_log(tmp_path / "still.txt", [SyntheticPush(**PUSHES[0]), still])
    table = read_pushes([log], body)
    assert [p.index for p in table.pushes] == [1]
    assert len(table.left_out) == 1 and table.left_out[0].reason.startswith("hardly moved")
    assert "left out: push 2: hardly moved" in "\n".join(table.lines())


def test_pushes_without_a_wrench_are_left_out_and_counted(tmp_path, synthetic):
    _, body, _ = synthetic
    short = SyntheticPush(**PUSHES[0], n=10, impact=3)
    idle = SyntheticPush(**dict(PUSHES[1], force=[0.0, 0.0]))
    log = write_log(tmp_path / "idle.txt", [short, SyntheticPush(**PUSHES[0]), idle])
    table = read_pushes([log], body)
    assert [p.index for p in table.pushes] == [2]
    assert [(o.index, o.reason) for o in table.left_out] == [
        (1, "10 force samples (fewer than 20)"),
        (3, "no contact force (plateau 0 N, under 0.1 N)"),
    ]
    assert table.lines()[0] == f"{log}: 3 pushes, 1 kept, 2 left out"
    assert table.to_csv().count("\n") == 2  # the header and push 2


def test_reader_streams_one_push_at_a_time(synthetic):
    log, _, _ = synthetic
    it = read_log(log)
    first = next(it)
    assert first.index == 1 and first.line == 2 and first.force_line == 5
    assert first.force.shape == (300, 3) and not first.force.flags.writeable
    assert first.where(0) == f"{log}: push 1, line 5"


# --- damaged logs: one line naming the push and the line ------------------------------------------


def _damage(tmp_path: Path, log: Path, edit) -> Path:
    lines = log.read_text().splitlines()
    out = tmp_path / "damaged.txt"
    out.write_text("\n".join(edit(lines)) + "\n")
    return out


# line numbers of the synthetic log: 1 header; push 1: 2-3 poses, 4 n_ft, 5-304 force, 305 n_robot,
# 306-406 finger (101 poses, every 0.03 s over 3 s); push 2 starts at line 407, push 3 at 812
CASES = [
    (
        "truncated mid-push",
        lambda ls: ls[:150],
        "the log ends in push 1 after line 150: expected force sample",
    ),
    (
        "truncated in push 2",
        lambda ls: ls[:420],
        "the log ends in push 2 after line 420: expected force sample",
    ),
    (
        "not a number",
        lambda ls: ls[:99] + ["1000.940000000 0.02 abc"] + ls[100:],
        "push 1, line 100: 'abc' is not a number",
    ),
    (
        "nan",
        lambda ls: ls[:99] + ["1000.940000000 nan 0.1"] + ls[100:],
        "push 1, line 100: 'nan' is not a finite number",
    ),
    (
        "count too large",
        lambda ls: ls[:3] + ["301"] + ls[4:],
        "push 1, line 305: expected 3 numbers (force sample: t fx fy), got 1",
    ),
    (
        "count too small",
        lambda ls: ls[:3] + ["299"] + ls[4:],
        "push 1, line 304: expected one whole number (the number of finger poses",
    ),
    (
        "count not whole",
        lambda ls: ls[:3] + ["300.5"] + ls[4:],
        "push 1, line 4: '300.5' is not a whole number",
    ),
    (
        "header too large",
        lambda ls: ["4"] + ls[1:],
        "the log ends in push 4 after line 1216: expected block's pose before the push",
    ),
    ("header too small", lambda ls: ["2"] + ls[1:], "line 812: data after the last of the 2 pushes"),
    (
        "quaternion",
        lambda ls: ls[:1] + [" ".join(ls[1].split()[:3] + ["0.9", "0.3", "0.2", "0.5"])] + ls[2:],
        "push 1, line 2: the quaternion of the block's pose before the push has norm 1.091, not 1",
    ),
    (
        "finger quaternion",
        lambda ls: ls[:309] + [" ".join(ls[309].split()[:4] + ["0", "0", "0", "0"])] + ls[310:],
        "push 1, line 310: the quaternion of the finger's pose has norm 0, not 1",
    ),
    ("time goes back", lambda ls: ls[:10] + [ls[11], ls[10]] + ls[12:], "push 1, line 12: time"),
    ("wrong width", lambda ls: ls[:1] + [ls[1] + " 7"] + ls[2:], "push 1, line 2: expected 7 numbers"),
]


@pytest.mark.parametrize("name, edit, message", CASES, ids=[c[0] for c in CASES])
def test_damaged_log_one_line(tmp_path, synthetic, name, edit, message):
    log, body, _ = synthetic
    bad = _damage(tmp_path, log, edit)
    with pytest.raises(DataError) as info:
        read_pushes([bad], body)
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"{bad}: ")
    assert message in text, text


def test_empty_and_missing_logs(tmp_path, synthetic):
    _, body, _ = synthetic
    empty = tmp_path / "empty.txt"
    empty.write_text("\n \n")
    with pytest.raises(DataError, match=r"empty\.txt: the push log is empty$"):
        read_pushes([empty], body)
    with pytest.raises(InputFileError, match="push log not found"):
        read_pushes([tmp_path / "none.txt"], body)
    binary = tmp_path / "binary.txt"
    binary.write_bytes(b"3\n\xff\xfe\x00")
    with pytest.raises(DataError, match="not a text log"):
        read_pushes([binary], body)


def test_body_without_log_block(tmp_path, synthetic):
    log, _, _ = synthetic
    data = json.loads(_body(tmp_path).read_text())
    del data["log"]
    p = tmp_path / "nolog.json"
    p.write_text(json.dumps(data))
    with pytest.raises(DataError, match=r"nolog\.json: missing key 'log'"):
        read_pushes([log], load_body(p))


# --- a real log against an independent calculation ----------------------------------------------

LAYOUT = "10_130_10_10_10_130"


def excerpt(log: Path, count: int, out: Path) -> Path:
    """The first ``count`` pushes of ``log``, written to ``out`` (the logs stay in ../shared)."""
    lines = log.read_text().splitlines()
    i = 1
    for _ in range(count):
        i += 2
        i += int(lines[i]) + 1
        i += int(lines[i]) + 1
    out.write_text("\n".join([str(count), *lines[1:i]]) + "\n")
    return out


def _hamilton(a, b):
    aw, av = a[0], np.array(a[1:])
    bw, bv = b[0], np.array(b[1:])
    return np.array([aw * bw - av @ bv, *(aw * bv + bw * av + np.cross(av, bv))])


def _turn(q, v):
    """v (3-vector) turned by the unit quaternion q, as q (0, v) q*."""
    conj = np.array([q[0], -q[1], -q[2], -q[3]])
    return _hamilton(_hamilton(q, [0.0, *v]), conj)[1:]


def _independent(lines: list[str], first: int, body, settings: Settings):
    """One push from its raw lines: complex numbers for the plane, Hamilton products for the poses.

    Returns (wrench, displacement, next line index)."""
    pre, post = (np.array(lines[first + k].split(), float) for k in (0, 1))
    n = int(lines[first + 2])
    ft = np.array([ln.split() for ln in lines[first + 3 : first + 3 + n]], float)
    m = int(lines[first + 3 + n])
    rb = np.array([ln.split() for ln in lines[first + 4 + n : first + 4 + n + m]], float)
    # S f = e^{iπ/4} conj(f) for S = √½ [[1, 1], [1, -1]]; the tool's yaw from the x axis it turns
    f = ft[:, 1] + 1j * ft[:, 2]
    psi = np.array([np.angle(complex(*_turn(q, [1, 0, 0])[:2])) for q in rb[:, 4:8]])
    spin = np.exp(1j * np.interp(ft[:, 0], rb[:, 0], np.unwrap(psi)))
    world = lambda g: spin * cmath.exp(1j * math.pi / 4) * np.conj(g)  # noqa: E731
    t = ft[:, 0] - ft[0, 0]
    size = np.abs(world(f - f[0]))
    plateau = np.median(size[n // 2 :])
    i0 = int(np.argmax(size >= 0.5 * plateau))
    quiet = (t <= t[i0] - settings.zero_guard) | (np.arange(n) == 0)
    on_block = -world(f - f[quiet].mean())
    keep = (t >= t[i0] + settings.settle) & (np.abs(on_block) >= 0.5 * plateau)

    def place(pose):  # the reference point (complex, m) and the yaw
        q = pose[3:] / np.linalg.norm(pose[3:])
        local = np.array(body.log.body_origin_in_mocap) + np.array([*body.reference_point, 0]) / 1e-3
        p = (pose[:3] + _turn(q, local)) * 1e-3
        return complex(p[0], p[1]), np.angle(complex(*_turn(q, [1, 0, 0])[:2]))

    (z0, a0), (z1, a1) = place(pre), place(post)
    turn = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
    s = np.clip((t[keep] - t[i0]) / (t[-1] - t[i0]), 0, 1)
    z = z0 + s * (z1 - z0)
    finger = (
        np.interp(ft[keep, 0], rb[:, 0], rb[:, 1]) + 1j * np.interp(ft[keep, 0], rb[:, 0], rb[:, 2])
    ) * 1e-3
    g = on_block[keep]
    torque = np.mean(np.imag(np.conj(finger - z) * g))  # r × F
    force = np.mean(-g) * cmath.exp(-1j * a0)
    d = (z1 - z0) * cmath.exp(-1j * a0)
    wrench = np.array([force.real, force.imag, -torque])
    return wrench, np.array([d.real, d.imag, turn]), first + 4 + n + m


@pytest.fixture(scope="module")
def real(tmp_path_factory):
    if not REAL.is_dir():
        pytest.skip(NO_REAL)
    folder = tmp_path_factory.mktemp("real")
    log = excerpt(REAL / f"hardboard_{LAYOUT}.txt", 8, folder / "excerpt.txt")
    body = load_body(REAL / "bodies" / f"{LAYOUT}.json")
    return log, body, read_pushes([log], body)


def test_real_log_against_an_independent_calculation(real):
    log, body, table = real
    lines = log.read_text().splitlines()
    assert len(table.pushes) == 8 and not any(p.zero_from_log for p in table.pushes)
    at = 1
    for p in table.pushes:
        wrench, disp, at = _independent(lines, at, body, Settings())
        np.testing.assert_allclose(p.wrench, wrench, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(p.displacement, disp, rtol=1e-9, atol=1e-12)


def test_real_log_physics(real):
    """What the frames must give: friction against the sliding, torque against the spin, a friction level
    near the authors' 0.28, and the finger's contact on the block's edges (x = 0, y = 0, x + y = 150 mm)."""
    _, body, table = real
    w = np.array([p.wrench for p in table.pushes])
    d = np.array([p.displacement for p in table.pushes])
    cos = -np.sum(w[:, :2] * d[:, :2], axis=1) / np.hypot(*w[:, :2].T) / np.hypot(*d[:, :2].T)
    assert cos.min() > 0.8
    assert np.all(w[:, 2] * d[:, 2] < 0)
    level = np.hypot(*w[:, :2].T) / body.weight
    assert 0.15 < level.min() and level.max() < 0.36
    for p in table.pushes:
        x, y = p.contact * 1e3
        edge = min(abs(x), abs(y), abs(x + y - 150) / math.sqrt(2))
        assert edge < 2.5, (p.index, x, y)
