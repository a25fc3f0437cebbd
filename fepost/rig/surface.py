"""Integrals of a rig export's shear traction over its contact faces: the check of the reactions.

The export holds, per node, the shear traction of the road on the tire
(``shear``, Pa, a 3-vector), the contact pressure (``CPRESS``) and the nodal
displacement (``displacement``, m; the faces are integrated in their deformed
position). The faces are the solver's bilinear quadrilaterals (or linear
triangles); the nodal fields are interpolated with the faces' own shape
functions and integrated by Gauss quadrature (2 x 2 points on a quadrilateral,
3 on a triangle), which is exact for a bilinear field on a flat parallelogram
and the accurate choice on the solver's faces. Written here rather than taken
from ``fepost.facesums`` because that one works on triangles with linear data:
splitting the quadrilaterals would change the interpolation the solver used.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import DataError, InputFileError
from .resultants import Resultants

_G = np.array([-1.0, 1.0]) / np.sqrt(3.0)


def _quad_rule():
    """Shape functions and their derivatives at the 2 x 2 Gauss points of the unit square."""
    out = []
    for a in _G:
        for b in _G:
            n = 0.25 * np.array([(1 - a) * (1 - b), (1 + a) * (1 - b), (1 + a) * (1 + b), (1 - a) * (1 + b)])
            da = 0.25 * np.array([-(1 - b), (1 - b), (1 + b), -(1 + b)])
            db = 0.25 * np.array([-(1 - a), -(1 + a), (1 + a), (1 - a)])
            out.append((n, da, db, 1.0))
    return out


def _tri_rule():
    """Shape functions at the 3-point (degree 2) rule of the unit triangle."""
    out = []
    for bary in ([2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]):
        da = np.array([-1.0, 1.0, 0.0])
        db = np.array([-1.0, 0.0, 1.0])
        out.append((np.array(bary), da, db, 1 / 6))
    return out


def face_integrals(points: np.ndarray, faces: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Integral of each column of the nodal ``values`` (n, k) over the faces (f, 3 or 4) at ``points``."""
    rule = _quad_rule() if faces.shape[1] == 4 else _tri_rule()
    x = points[faces]  # (f, c, 3)
    v = values[faces]  # (f, c, k)
    total = np.zeros(values.shape[1])
    for n, da, db, w in rule:
        ta = np.einsum("c,fcj->fj", da, x)
        tb = np.einsum("c,fcj->fj", db, x)
        jac = np.linalg.norm(np.cross(ta, tb), axis=1)
        total += w * np.einsum("f,fk->k", jac, np.einsum("c,fck->fk", n, v))
    return total


def _point_array(mesh, path: Path, name: str, width: int) -> np.ndarray:
    a = np.asarray(mesh.point_data[name], dtype=float)
    a = a.reshape(a.shape[0], -1)
    if a.shape[1] < width:
        raise DataError(f"{path}: array {name!r} has {a.shape[1]} components, expected {width}")
    if not np.isfinite(a).all():
        raise DataError(f"{path}: array {name!r} has non-finite values")
    return a[:, :width]


def shear_resultants(path, origin: tuple[float, float]) -> Resultants | None:
    """Fx, Fy, Mz (about ``origin``) of the ``shear`` traction and N of ``CPRESS``; None without ``shear``."""
    import meshio

    path = Path(path)
    try:
        mesh = meshio.read(path)
    except Exception as exc:  # noqa: BLE001 - meshio raises many kinds; one line for the user
        raise InputFileError(f"{path}: cannot read the rig export ({type(exc).__name__}: {exc})") from None
    if "shear" not in mesh.point_data:
        return None
    for name in ("CPRESS", "displacement"):
        if name not in mesh.point_data:
            raise DataError(f"{path}: the export has 'shear' but no {name!r} point array")
    x = np.asarray(mesh.points, dtype=float) + _point_array(mesh, path, "displacement", 3)
    tau = _point_array(mesh, path, "shear", 2)
    cp = _point_array(mesh, path, "CPRESS", 1)[:, 0]
    dx, dy = x[:, 0] - origin[0], x[:, 1] - origin[1]
    cols = np.column_stack([tau[:, 0], tau[:, 1], dx * tau[:, 1] - dy * tau[:, 0], cp])
    total = np.zeros(4)
    for block in mesh.cells:
        if block.type in ("quad", "triangle"):
            total += face_integrals(x, np.asarray(block.data), cols)
    if total[3] <= 0.0:
        raise DataError(f"{path}: no contact pressure on the export's faces")
    return Resultants(Fx=float(total[0]), Fy=float(total[1]), Mz=float(total[2]), N=float(total[3]))
