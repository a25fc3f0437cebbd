"""Is a slide/spin run steady? Every force component and the load over the last fifth of its path.

A run is steady when, over the increments in the last ``share`` (default 1/5) of its
reference path, each of Fx and Fy (the road's force on the tire in the tire's frame)
moves by less than ``tol`` (default 0.005) times f N and the load N = Fz by less than
``tol`` times N (N and f from the run itself). The older check on |F| / (f N) alone
passes runs whose force turns at the Coulomb ceiling or whose load drifts (the sector's
``long/d090_a40p``: |F| steady, Fx moving 0.0096 f N and N 1.1 %).

``python -m scripts.tiremodel.steadiness RUN.json ...`` prints each run's motions and
verdict; exit status 1 if any run is not steady.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

TOL = 0.005
SHARE = 0.2


@dataclass(frozen=True)
class Motion:
    """Peak-to-peak motions over the tail of the path: Fx, Fy in f N, N in N, |F| in f N."""

    fx: float
    fy: float
    n: float
    f_abs: float
    increments: int  # increments in the tail

    def steady(self, tol: float = TOL) -> bool:
        return max(self.fx, self.fy, self.n) < tol


def tail_motion(history: dict, friction: float, share: float = SHARE) -> Motion:
    """The motions of a sidecar's ``history`` over the last ``share`` of its path."""
    path = np.asarray(history["path"], dtype=float)
    if path.size < 2 or not path[-1] > 0.0:
        raise ValueError("history: fewer than two increments or no path")
    tail = path >= (1.0 - share) * path[-1] - 1e-12
    if tail.sum() < 2:
        raise ValueError(f"history: fewer than two increments in the last {share:g} of the path")
    fx, fy, fz = (np.asarray(history[k], dtype=float)[tail] for k in ("Fx", "Fy", "Fz"))
    # a frictionless run (friction 0) has no Coulomb scale: its forces are judged against N
    fn = (friction if friction > 0.0 else 1.0) * float(fz[-1])
    return Motion(
        fx=float(np.ptp(fx)) / fn,
        fy=float(np.ptp(fy)) / fn,
        n=float(np.ptp(fz)) / float(fz[-1]),
        f_abs=float(np.ptp(np.hypot(fx, fy) / (fn / float(fz[-1]) * fz))),
        increments=int(tail.sum()),
    )


def run_motion(sidecar: Path, share: float = SHARE) -> Motion:
    """``tail_motion`` of a run's sidecar (its ``history`` and ``friction``)."""
    side = json.loads(Path(sidecar).read_text())
    return tail_motion(side["history"], float(side["friction"]), share)


def main(argv: list[str] | None = None) -> int:
    paths = [Path(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not paths:
        print("usage: python -m scripts.tiremodel.steadiness RUN.json ...", file=sys.stderr)
        return 2
    print(f"{'run':<28} {'Fx/fN':>8} {'Fy/fN':>8} {'N/N':>8} {'|F|/fN':>8}  steady (all < {TOL:g})")
    bad = 0
    for p in paths:
        side = json.loads(p.read_text())
        if "history" not in side:
            print(f"{p!s:<28} not a slide/spin run (no history): skipped")
            continue
        m = tail_motion(side["history"], float(side["friction"]))
        bad += not m.steady()
        print(f"{p!s:<28} {m.fx:8.4f} {m.fy:8.4f} {m.n:8.4f} {m.f_abs:8.4f}  {'yes' if m.steady() else 'NO'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
