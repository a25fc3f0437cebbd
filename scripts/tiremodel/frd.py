"""Read the blocks we need from a CalculiX .frd file with ccx2paraview's parser.

ccx2paraview (PyPI, GPL-3.0) provides a maintained, step-by-step .frd reader.
Only its parsing classes are used here; results become numpy arrays indexed by
the CalculiX node numbers.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, field

import numpy as np


@dataclass
class FrdResults:
    node_ids: np.ndarray  # CalculiX node numbers, sorted
    coords: np.ndarray  # (n, 3) undeformed coordinates
    steps: list[tuple[int, float]] = field(default_factory=list)  # (step, time) of stored increments
    # last stored increment of each step: {step: {block name: (components, (n, k) array)}}
    last: dict[int, dict[str, tuple[list[str], np.ndarray]]] = field(default_factory=dict)
    # every stored increment (only with read_frd(..., every=True)): [(time, blocks)]
    every: list[tuple[float, dict[str, tuple[list[str], np.ndarray]]]] = field(default_factory=list)

    def field(self, step: int, name: str) -> tuple[list[str], np.ndarray]:
        if step not in self.last or name not in self.last[step]:
            raise KeyError(f"no {name} results for step {step} in the .frd file")
        return self.last[step][name]


def read_frd(path, every: bool = False) -> FrdResults:
    """Parse mesh coordinates and, per step, the last increment's nodal blocks.

    With ``every`` the blocks of every stored increment are kept too (in
    ``FrdResults.every``), e.g. for output at several time points of one step.
    """
    try:
        from ccx2paraview import common as c2p
    except ImportError as exc:  # pragma: no cover - import guard
        raise RuntimeError("ccx2paraview is not installed (pip install ccx2paraview)") from exc

    logging.getLogger().setLevel(max(logging.getLogger().level, logging.WARNING))
    with open(path, encoding="latin-1") as fh:
        frd = c2p.FRD(fh)
        frd.parse_mesh()
        ids = np.array(frd.node_block.get_node_numbers(), dtype=np.int64)
        pts = frd.node_block.points
        coords = np.array([pts.GetPoint(int(c2p.renumbered_nodes[i])) for i in ids])
        res = FrdResults(node_ids=ids, coords=coords)
        frd.count_increments()
        # ccx2paraview keys result sets by (global increment counter, time);
        # the analysis step of each counter is in the '1PSTEP' records.
        incs = list(frd.steps_increments)  # [(counter, time)]
        step_of = _step_of_counter(path)
        last_cnt: dict[int, int] = {}
        for cnt, _ in incs:
            last_cnt[step_of.get(cnt, 1)] = cnt
        for cnt, t in incs:
            blocks = frd.parse_results(cnt, t)
            step = step_of.get(cnt, 1)
            res.steps.append((step, t))
            if cnt != last_cnt[step] and not every:
                continue
            store: dict[str, tuple[list[str], np.ndarray]] = {}
            if cnt == last_cnt[step]:
                res.last[step] = store
            if every:
                res.every.append((float(t), store))
            for b in blocks:
                if not getattr(b, "results", None) or b.name is None:
                    continue
                k = len(b.components)
                arr = np.zeros((ids.size, k))
                for row, nid in enumerate(ids):
                    vals = b.results.get(int(nid))
                    if vals is not None:
                        arr[row, :] = vals[:k]
                store[b.name] = (list(b.components), arr)
    return res


def _step_of_counter(path) -> dict[int, int]:
    """Map the .frd result-set counter to the analysis step.

    Each result block is preceded by a '1PSTEP' record (block counter,
    increment within the step, analysis step); the following '100C' record
    carries the global counter that ccx2paraview uses as its key.
    """
    from ccx2paraview.common import get_inc_step

    out: dict[int, int] = {}
    step = 1
    with open(path, encoding="latin-1") as fh:
        for line in fh:
            if line.startswith("    1PSTEP"):
                f = line.split()
                if len(f) >= 4:
                    step = int(f[3])
            elif line[:5].strip() == "100":
                _, cnt = get_inc_step(line)
                out[cnt] = step
    return out


_TOTAL = re.compile(r"total force \(fx,fy,fz\) for set (\S+) and time\s+(\S+)\s*\n\s*(\S+)\s+(\S+)\s+(\S+)")


def read_dat_totals(path) -> list[tuple[str, float, np.ndarray]]:
    """All 'total force' records of a .dat file: (set name, time, (fx, fy, fz))."""
    with open(path, encoding="latin-1") as fh:
        text = fh.read()
    out = []
    for m in _TOTAL.finditer(text):
        out.append((m.group(1), float(m.group(2)), np.array([float(m.group(i)) for i in (3, 4, 5)])))
    return out


_BLOCK = re.compile(r"^ ([a-z ]+) \(([a-z,]+)\) for set (\S+) and time\s+(\S+)\s*$")


def read_dat_blocks(path) -> list[tuple[str, str, float, np.ndarray]]:
    """All printed blocks of a .dat file, in file order.

    Each is (kind, set name, time, rows): ``kind`` is the block title
    ('total force', 'displacements', 'forces', ...); ``rows`` holds the numbers
    of each printed line (a node number first, except for totals).
    """
    out: list[tuple[str, str, float, np.ndarray]] = []
    cur: tuple[str, str, float] | None = None
    rows: list[list[float]] = []

    def flush():
        if cur is not None:
            out.append((*cur, np.array(rows, dtype=float)))

    with open(path, encoding="latin-1") as fh:
        for line in fh:
            m = _BLOCK.match(line.rstrip("\n"))
            if m:
                flush()
                cur, rows = (m.group(1).strip(), m.group(3), float(m.group(4))), []
                continue
            f = line.split()
            if cur is not None and f:
                try:
                    rows.append([float(v) for v in f])
                except ValueError:
                    flush()
                    cur, rows = None, []
    flush()
    return out
