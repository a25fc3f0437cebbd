"""Resultants of given kinematics by the three models: exact integrals, paper, generalised.

Input CSV (header row, one row per kinematic point, other columns ignored;
blank lines and lines starting with ``#`` skipped):

======== ==============================================================
``vx``   sliding velocity of the patch origin against the road, m/s
``vy``   (patch frame: x rolling direction, y lateral)
``wz``   spin about the road normal, rad/s
======== ==============================================================

Output CSV, same rows in the same order: ``vx, vy, wz``, then ``Fx, Fy, Mz``
(forces on the tire in N, torque about the patch origin in N·m) of

* ``*_exact``: the exact Coulomb integrals over the FE map,
* ``*_paper``: the paper's closed forms (1.3)/(1.7) with F0, M0, a, m (and k_x),
* ``*_model``: the generalised model built from the map (`fepost.friction.build`).

With a rolling map the kinematics are those of the rolling tire: the exact
integrals and the generalised model use the rolling map (in the static patch's
frame), the closed forms add F⊥ with k_x. Without one, the static map and
k_x = 0. The CSV is read by `fepost.csvtable`, as the measured data of
``fepost diagnose`` are: every problem with it is a one-line
`DataError` naming the file, the line and the column.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np

from .._arrays import frozen
from ..coefficients import Coefficients
from ..csvtable import CsvFormat, CsvTable, parse_table, read_table
from ..errors import ArgumentError
from ..polar import PolarMap
from .closed_form import components
from .exact import Resultants, friction_resultants
from .law import FrictionLaw
from .model import GeneralisedModel
from .quadrature import PressureQuadrature

COLUMNS = ("vx", "vy", "wz")
OUTPUT_COLUMNS = COLUMNS + tuple(f"{q}_{m}" for m in ("exact", "paper", "model") for q in ("Fx", "Fy", "Mz"))


@dataclass(frozen=True)
class Kinematics:
    """Kinematic points read from a CSV: ``vx``, ``vy`` (m/s), ``wz`` (rad/s) and the
    1-based ``lines`` they came from."""

    vx: np.ndarray
    vy: np.ndarray
    wz: np.ndarray
    lines: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        for name in ("vx", "vy", "wz"):
            object.__setattr__(self, name, frozen(getattr(self, name)))
        object.__setattr__(self, "lines", frozen(self.lines, dtype=int))

    def __len__(self) -> int:
        return int(self.vx.size)


#: The kinematics CSV format (module docstring).
KINEMATICS = CsvFormat(required=COLUMNS, what="kinematics")


def _kinematics(table: CsvTable) -> Kinematics:
    return Kinematics(vx=table["vx"], vy=table["vy"], wz=table["wz"], lines=table.lines, source=table.source)


def parse_kinematics(text: str, source: str = "") -> Kinematics:
    """Parse the kinematics CSV ``text`` (module docstring); ``source`` names it in messages."""
    return _kinematics(parse_table(text, KINEMATICS, source))


def read_kinematics(path) -> Kinematics:
    """Read a kinematics CSV file (module docstring)."""
    return _kinematics(read_table(path, KINEMATICS))


@dataclass(frozen=True)
class Prediction:
    """The three models' resultants at the same kinematic points (module docstring).

    ``map`` says which pressure map the exact integrals and the generalised model
    used (``"static"`` or ``"rolling"``); ``model`` is that generalised model.
    """

    vx: np.ndarray
    vy: np.ndarray
    wz: np.ndarray
    exact: Resultants
    paper: Resultants
    generalised: Resultants
    model: GeneralisedModel
    map: str

    def __post_init__(self) -> None:
        for name in ("vx", "vy", "wz"):
            object.__setattr__(self, name, frozen(getattr(self, name)))

    def columns(self) -> dict[str, np.ndarray]:
        """The output columns, in the order of `OUTPUT_COLUMNS`."""
        out = {"vx": self.vx, "vy": self.vy, "wz": self.wz}
        for tag, res in (("exact", self.exact), ("paper", self.paper), ("model", self.generalised)):
            out[f"Fx_{tag}"], out[f"Fy_{tag}"], out[f"Mz_{tag}"] = res.Fx, res.Fy, res.Mz
        return out

    def to_csv(self) -> str:
        """The output CSV text (repr-exact floats)."""
        cols = self.columns()
        buf = io.StringIO()
        buf.write(",".join(OUTPUT_COLUMNS) + "\n")
        table = np.column_stack([cols[c] for c in OUTPUT_COLUMNS])
        for row in table:
            buf.write(",".join(repr(float(v)) for v in row) + "\n")
        return buf.getvalue()


def predict(
    vx,
    vy,
    wz,
    *,
    pmap: PolarMap,
    coefficients: Coefficients,
    law: FrictionLaw,
    rolling: bool = False,
    model: GeneralisedModel | None = None,
) -> Prediction:
    """Exact, paper and generalised resultants for the kinematics (vx, vy in m/s, wz in rad/s).

    Parameters
    ----------
    vx, vy, wz : array_like
        The kinematic points (broadcast together).
    pmap : PolarMap
        The pressure map the exact integrals and the generalised model use: the
        rolling map (in the static patch's frame) of a rolling tire, else the
        static map.
    coefficients : Coefficients
        The paper's coefficients (F0, M0, a, m, R and k_x).
    law : FrictionLaw
        The friction law.
    rolling : bool
        ``pmap`` is the rolling map: the closed forms add F⊥ with k_x.
    model : GeneralisedModel, optional
        The generalised model to use (default: built from ``pmap``, see
        ``fepost.friction.summary.map_model``).

    Examples
    --------
    >>> import fepost
    >>> from fepost.friction.law import FrictionLaw
    >>> from fepost.friction.predict import predict
    >>> an = fepost.analyse("meshes/static.vtu")
    >>> pred = predict([0.1, 0.0], [0.0, 0.0], [0.0, 1.0], pmap=an.static_map,
    ...                coefficients=an.coefficients, law=FrictionLaw(f=0.3))
    >>> pred.map
    'static'
    >>> round(float(pred.exact.Fx[0] / an.coefficients.F0), 6)   # pure sliding: exactly −f N
    -1.0
    >>> round(float(pred.exact.Mz[1] / an.coefficients.M0), 6)   # pure spin: exactly −M0
    -1.0
    """
    from .summary import check_map_values, map_model, paper_k_x

    check_map_values(pmap, coefficients, law)
    vx, vy, wz = (np.atleast_1d(np.asarray(a, float)) for a in np.broadcast_arrays(vx, vy, wz))
    c = coefficients
    if model is None:
        model = map_model(pmap, c, law, rolling=rolling)
    elif not isinstance(model, GeneralisedModel):
        raise ArgumentError(f"model must be a GeneralisedModel, got {type(model).__name__}")
    exact = friction_resultants(PressureQuadrature.from_polar(pmap), vx, vy, wz, law)
    k_x = paper_k_x(c, rolling=rolling)
    paper = Resultants(*components(vx, vy, wz, F0=c.F0, M0=c.M0, a=c.a, m=c.m, k_x=k_x, radius=c.R))
    return Prediction(
        vx=vx,
        vy=vy,
        wz=wz,
        exact=exact,
        paper=paper,
        generalised=model.resultants(vx, vy, wz),
        model=model,
        map="rolling" if rolling else "static",
    )
