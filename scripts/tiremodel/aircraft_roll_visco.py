"""What CalculiX 2.20 offers for a rate-dependent tread: three one-element decks.

A hyperelastic tire rolling quasi-statically has no hysteresis; the forward
pressure shift of a real rolling tire (k_x) comes mostly from the tread
rubber's loss. These decks test, on one Neo-Hooke cube of the tread rubber
(G = 1.5 MPa, K = 100 G), the ways CalculiX could add a rate:

- ``prony``: ``*VISCOELASTIC, TIME=PRONY`` (a Prony series, as other codes
  give rubber): CalculiX does not know the keyword; it warns that the card
  image cannot be interpreted and runs the cube purely hyperelastic;
- ``creep``: ``*CREEP, LAW=NORTON`` for a ``*VISCO`` step: CalculiX refuses
  it after ``*HYPERELASTIC`` (it must follow ``*ELASTIC``), and a Norton law
  is unbounded creep, not a relaxing solid;
- ``decay``: Rayleigh stiffness damping ``*DAMPING, ALPHA=0, BETA=beta`` in
  a ``*DYNAMIC`` step: a free shear vibration of the cube decays with the
  damping ratio beta*omega/2 it should have. This one works, in dynamic steps
  only (the rolling runs are ``*STATIC``: no rate, no damping).

``python -m scripts.tiremodel.aircraft_roll_visco`` runs the three and prints
what CalculiX said and the decay's damping ratio.
"""

from __future__ import annotations

import math
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .frd import read_dat_blocks

C10, D1 = 7.5e5, 1.333e-8  # the tread's Neo-Hooke constants (G = 1.5 MPa, K = 150 MPa)

CUBE = """*NODE, NSET=NALL
1, 0, 0, 0
2, 1, 0, 0
3, 1, 1, 0
4, 0, 1, 0
5, 0, 0, 1
6, 1, 0, 1
7, 1, 1, 1
8, 0, 1, 1
*ELEMENT, TYPE=C3D8, ELSET=EALL
1, 1, 2, 3, 4, 5, 6, 7, 8
*NSET, NSET=BOT
1, 2, 3, 4
*NSET, NSET=TOP
5, 6, 7, 8
*MATERIAL, NAME=TREAD
*HYPERELASTIC, NEO HOOKE
{c10:.6e}, {d1:.6e}
"""


def _cube(material_extra: str, rest: str) -> str:
    return (
        CUBE.format(c10=C10, d1=D1) + material_extra + "*SOLID SECTION, ELSET=EALL, MATERIAL=TREAD\n" + rest
    )


SHEAR_STATIC = """*BOUNDARY
BOT, 1, 3
*STEP, NLGEOM
{proc}
0.1, 1.0
*BOUNDARY
TOP, 1, 1, 0.1
*NODE PRINT, NSET=TOP, TOTALS=ONLY
RF
*END STEP
"""


def prony_deck() -> str:
    """A Prony-series relaxation (20 % of the modulus, 0.01 s) after the Neo-Hooke law."""
    return _cube("*VISCOELASTIC, TIME=PRONY\n0.2, 0.0, 0.01\n", SHEAR_STATIC.format(proc="*STATIC"))


def creep_deck() -> str:
    """A Norton creep law after the Neo-Hooke law, in a *VISCO step."""
    return _cube("*CREEP, LAW=NORTON\n1.0e-12, 1.0, 0.0\n", SHEAR_STATIC.format(proc="*VISCO, CETOL=1e-3"))


def decay_deck(beta: float, duration: float = 0.6, dt: float = 0.002) -> str:
    """Free shear vibration of the cube (top pushed at 0.5 m/s, bottom held) with Rayleigh ``beta``."""
    material = f"*DENSITY\n1100.\n*DAMPING, ALPHA=0.0, BETA={beta:.6e}\n"
    rest = (
        "*INITIAL CONDITIONS, TYPE=VELOCITY\nTOP, 1, 0.5\n*BOUNDARY\nBOT, 1, 3\n"
        f"*STEP, NLGEOM, INC=5000\n*DYNAMIC, DIRECT\n{dt}, {duration}\n"
        "*NODE PRINT, NSET=TOP\nU\n*END STEP\n"
    )
    return _cube(material, rest)


@dataclass(frozen=True)
class DeckRun:
    returncode: int
    log: str  # CalculiX's screen output
    dat: Path | None


def run_deck(exe: str, text: str, workdir: Path, name: str) -> DeckRun:
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / f"{name}.inp").write_text(text)
    proc = subprocess.run([exe, "-i", name], cwd=workdir, capture_output=True, text=True, timeout=300)
    dat = workdir / f"{name}.dat"
    return DeckRun(proc.returncode, proc.stdout + proc.stderr, dat if dat.exists() else None)


def solver_words(log: str) -> list[str]:
    """The warning/error lines CalculiX printed, each joined with its continuation lines."""
    lines = log.splitlines()
    out = []
    for i, ln in enumerate(lines):
        if "*WARNING" in ln or "*ERROR" in ln:
            block = [ln.strip()]
            for nxt in lines[i + 1 : i + 4]:
                if not nxt.strip() or "*WARNING" in nxt or "*ERROR" in nxt or "*INFO" in nxt:
                    break
                block.append(nxt.strip())
            out.append(" ".join(block))
    return out


def damping_ratio(dat: Path) -> tuple[float, float]:
    """(omega, zeta) of the top's free vibration: period from the peaks, log decrement."""
    blocks = [b for b in read_dat_blocks(dat) if b[0] == "displacements"]
    t = np.array([b[2] for b in blocks])
    u = np.array([b[3][:, 1].mean() for b in blocks])
    peaks = [i for i in range(1, len(u) - 1) if u[i] > u[i - 1] and u[i] >= u[i + 1] and u[i] > 0]
    if len(peaks) < 3:
        raise ValueError(f"{dat}: fewer than 3 vibration peaks")
    omega = 2.0 * math.pi * (len(peaks) - 1) / (t[peaks[-1]] - t[peaks[0]])
    decrement = math.log(u[peaks[0]] / u[peaks[-1]]) / (len(peaks) - 1)
    return omega, decrement / math.sqrt(4.0 * math.pi**2 + decrement**2)


def main() -> int:
    from .solve import find_ccx

    exe = find_ccx()
    with tempfile.TemporaryDirectory(prefix="roll-visco-") as tmp:
        for name, text in (("prony", prony_deck()), ("creep", creep_deck())):
            run = run_deck(exe, text, Path(tmp), name)
            print(f"{name}: exit {run.returncode}")
            for w in solver_words(run.log):
                print(f"  {w}")
        for beta in (0.0, 1.0e-3):
            run = run_deck(exe, decay_deck(beta), Path(tmp), f"decay{beta:g}")
            if run.dat is None:
                print(f"decay beta={beta:g}: no .dat (exit {run.returncode})")
                continue
            omega, zeta = damping_ratio(run.dat)
            expected = beta * omega / 2
            print(
                f"decay beta={beta:g}: omega {omega:.1f} rad/s, zeta {zeta:.4f}, beta omega/2 {expected:.4f}"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
