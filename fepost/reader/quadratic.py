"""Element faces with their own shape functions: exact load and a refinement into triangles.

Face types (node order of `fepost.reader.cells`): ``tri3``, ``tri6``,
``tri7`` on the reference triangle (ξ, η ≥ 0, ξ + η ≤ 1) and ``quad4``
(bilinear), ``quad8`` (serendipity), ``quad9`` (Lagrange) on [−1, 1]². The
same shape functions carry the geometry (isoparametric: a quadratic face is
curved) and the pressure.

* `face_loads` – the exact load of each face in a given plane,
  ∬ σ (n·z) dA = ∬ σ(ξ, η) det ∂(x, y)/∂(ξ, η) dξ dη with in-plane x, y: a
  polynomial for these elements, integrated exactly by Gauss rules of
  `GAUSS_POINTS` points a side (tensor rule on quads, collapsed
  conical-product rule on triangles: degree ≥ 8).
* `surface_integrals` – ∬ σ dA and ∬ σ n dA over the curved surface
  (3-D Jacobian), for checks.
* `refine` – each face cut into linear triangles whose nodes are
  evaluated with the shape functions (position and pressure): ``level`` L cuts
  a quad into L × L sub-quads, each split along a diagonal into two triangles,
  and a triangle into L² sub-triangles. The error of the linear sub-triangles
  falls as L⁻² (measured in the tests), and `fepost.patch.build_patch`
  doubles L until the triangles carry the exact element load to
  `fepost.patch.REFINE_TOL` (a ``quad4`` mesh of near-parallelograms
  stops at L = 1: the plain two-triangle split).

A quadratic interpolant of non-negative nodal pressures may dip below zero
between nodes; those negative lobes belong to the element's field and are
kept (they are not a sign-convention error).

Why hand-written: the library readers (VTK, meshio) hand quadratic faces on
as their corner polygons, which linearises away the load the mid-side nodes
carry; the shape functions are the textbook ones (Zienkiewicz & Taylor).
"""

from __future__ import annotations

from functools import cache

import numpy as np

#: Gauss points a side of the exact integration rules.
GAUSS_POINTS = 5


def _tri_shape(xi: np.ndarray, eta: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    L1, L2, L3 = 1.0 - xi - eta, xi, eta
    one = np.ones_like(xi)
    zero = np.zeros_like(xi)
    if k == 3:
        N = np.stack([L1, L2, L3], axis=-1)
        dxi = np.stack([-one, one, zero], axis=-1)
        deta = np.stack([-one, zero, one], axis=-1)
        return N, dxi, deta
    # quadratic: corners L(2L−1), mid-edges 4 Li Lj on edges (0,1), (1,2), (2,0)
    N = np.stack(
        [L1 * (2 * L1 - 1), L2 * (2 * L2 - 1), L3 * (2 * L3 - 1), 4 * L1 * L2, 4 * L2 * L3, 4 * L3 * L1], -1
    )
    # dL/dξ = (−1, 1, 0), dL/dη = (−1, 0, 1)
    dxi = np.stack(
        [-(4 * L1 - 1), 4 * L2 - 1, zero, 4 * (L1 - L2), 4 * L3, -4 * L3],
        -1,
    )
    deta = np.stack(
        [-(4 * L1 - 1), zero, 4 * L3 - 1, -4 * L2, 4 * L2, 4 * (L1 - L3)],
        -1,
    )
    if k == 6:
        return N, dxi, deta
    # tri7: add the cubic bubble b = 27 L1 L2 L3 (centre node), corrected so N stays interpolatory
    b = 27.0 * L1 * L2 * L3
    db_xi = 27.0 * (L2 * L3 * -1 + L1 * L3)
    db_eta = 27.0 * (L2 * L3 * -1 + L1 * L2)
    corr_c, corr_m = 1.0 / 9.0, -4.0 / 9.0
    N7 = np.concatenate(
        [N[..., :3] + corr_c * b[..., None], N[..., 3:] + corr_m * b[..., None], b[..., None]], -1
    )
    dxi7 = np.concatenate(
        [
            dxi[..., :3] + corr_c * db_xi[..., None],
            dxi[..., 3:] + corr_m * db_xi[..., None],
            db_xi[..., None],
        ],
        -1,
    )
    deta7 = np.concatenate(
        [
            deta[..., :3] + corr_c * db_eta[..., None],
            deta[..., 3:] + corr_m * db_eta[..., None],
            db_eta[..., None],
        ],
        -1,
    )
    return N7, dxi7, deta7


_QC = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
_QM = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])


def _lagrange(s: np.ndarray, node: float) -> tuple[np.ndarray, np.ndarray]:
    """1-D quadratic Lagrange polynomial of node −1, 0 or 1 and its derivative."""
    if node < 0:
        return 0.5 * s * (s - 1.0), s - 0.5
    if node > 0:
        return 0.5 * s * (s + 1.0), s + 0.5
    return 1.0 - s * s, -2.0 * s


def _quad_shape(xi: np.ndarray, eta: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if k == 4:
        a, b = _QC[:, 0], _QC[:, 1]
        x, e = xi[..., None], eta[..., None]
        N = 0.25 * (1 + a * x) * (1 + b * e)
        return N, 0.25 * a * (1 + b * e), 0.25 * b * (1 + a * x)
    if k == 8:
        x, e = xi[..., None], eta[..., None]
        a, b = _QC[:, 0], _QC[:, 1]
        Nc = 0.25 * (1 + a * x) * (1 + b * e) * (a * x + b * e - 1)
        dcx = 0.25 * a * (1 + b * e) * (2 * a * x + b * e)
        dce = 0.25 * b * (1 + a * x) * (a * x + 2 * b * e)
        ma, mb = _QM[:, 0], _QM[:, 1]
        # mid-edge nodes: on ξ = 0 edges (ma = 0) and on η = 0 edges (mb = 0)
        Nm = np.where(ma == 0, 0.5 * (1 - x * x) * (1 + mb * e), 0.5 * (1 + ma * x) * (1 - e * e))
        dmx = np.where(ma == 0, -x * (1 + mb * e), 0.5 * ma * (1 - e * e))
        dme = np.where(ma == 0, 0.5 * mb * (1 - x * x), -e * (1 + ma * x))
        return (
            np.concatenate([Nc, Nm], -1),
            np.concatenate([dcx, dmx], -1),
            np.concatenate([dce, dme], -1),
        )
    nodes = np.vstack([_QC, _QM, [[0.0, 0.0]]])
    Ns, dx, de = [], [], []
    for a, b in nodes:
        la, dla = _lagrange(xi, a)
        lb, dlb = _lagrange(eta, b)
        Ns.append(la * lb)
        dx.append(dla * lb)
        de.append(la * dlb)
    return np.stack(Ns, -1), np.stack(dx, -1), np.stack(de, -1)


def shape(ftype: str, xi, eta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shape functions N (…, k) and their derivatives ∂N/∂ξ, ∂N/∂η of face type ``ftype``."""
    xi = np.asarray(xi, float)
    eta = np.asarray(eta, float)
    k = int(ftype[-1])
    if ftype.startswith("tri"):
        return _tri_shape(xi, eta, k)
    return _quad_shape(xi, eta, k)


def reference_nodes(ftype: str) -> np.ndarray:
    """Reference coordinates (k, 2) of the nodes of ``ftype`` (where N_i = δ_ij)."""
    if ftype.startswith("tri"):
        corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        mids = 0.5 * (corners + corners[[1, 2, 0]])
        pts = {3: corners, 6: np.vstack([corners, mids]), 7: np.vstack([corners, mids, [[1 / 3, 1 / 3]]])}
        return pts[int(ftype[-1])]
    pts = {4: _QC, 8: np.vstack([_QC, _QM]), 9: np.vstack([_QC, _QM, [[0.0, 0.0]]])}
    return pts[int(ftype[-1])]


@cache
def gauss_rule(kind: str, n: int = GAUSS_POINTS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (ξ, η) and weights of an n-a-side rule on the reference ``tri`` or ``quad``."""
    x, w = np.polynomial.legendre.leggauss(n)
    if kind == "quad":
        xi, eta = np.meshgrid(x, x, indexing="ij")
        return xi.ravel(), eta.ravel(), np.outer(w, w).ravel()
    # collapsed square: ξ = u, η = v (1 − u), dξ dη = (1 − u) du dv, u, v ∈ [0, 1]
    u, v = 0.5 * (x + 1.0), 0.5 * (x + 1.0)
    U, V = np.meshgrid(u, v, indexing="ij")
    W = 0.25 * np.outer(w, w) * (1.0 - U)
    return U.ravel(), (V * (1.0 - U)).ravel(), W.ravel()


def _in_plane(ftype: str, xy: np.ndarray, conn: np.ndarray):
    """Shape functions N (q, k) and weights w (q,) at the Gauss points of ``ftype``, the faces'
    in-plane node coordinates X, Y (m, k) and their Jacobian det ∂(x, y)/∂(ξ, η) (m, q)."""
    xi, eta, w = gauss_rule("tri" if ftype.startswith("tri") else "quad")
    N, dxi, deta = shape(ftype, xi, eta)
    X, Y = xy[:, 0][conn], xy[:, 1][conn]  # (m, k)
    det = (X @ dxi.T) * (Y @ deta.T) - (X @ deta.T) * (Y @ dxi.T)  # (m, q)
    return N, w, X, Y, det


def face_loads(ftype: str, xy: np.ndarray, conn: np.ndarray, values: np.ndarray, location: str) -> np.ndarray:
    """Exact load of each face projected on the plane of the in-plane coordinates ``xy`` (N).

    ``xy`` (n, 2) node coordinates in the patch plane (m); ``conn`` (m, k);
    ``values`` per node (``location="point"``) or per face (Pa).
    """
    N, w, _, _, det = _in_plane(ftype, xy, conn)
    jac = np.abs(det) * w
    if location == "point":
        return np.einsum("mq,mq->m", np.asarray(values, float)[conn] @ N.T, jac)
    return np.asarray(values, float) * jac.sum(axis=1)


def folded(ftype: str, xy: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """True for faces whose map onto the plane of ``xy`` folds over (its Jacobian changes sign)."""
    det = _in_plane(ftype, xy, conn)[4]
    scale = np.max(np.abs(det), axis=1)
    return (det.min(axis=1) < -1e-9 * scale) & (det.max(axis=1) > 1e-9 * scale)


def face_moments(
    ftype: str, xy: np.ndarray, conn: np.ndarray, values: np.ndarray, location: str
) -> np.ndarray:
    """Exact (load, ∬σx, ∬σy) of each face in the plane of ``xy``: an (m, 3) array."""
    N, w, X, Y, det = _in_plane(ftype, xy, conn)
    jac = np.abs(det) * w
    sig = np.asarray(values, float)[conn] @ N.T if location == "point" else np.asarray(values, float)[:, None]
    f = sig * jac
    return np.column_stack([f.sum(1), (f * (X @ N.T)).sum(1), (f * (Y @ N.T)).sum(1)])


def face_surface_loads(
    ftype: str, points: np.ndarray, conn: np.ndarray, values: np.ndarray, location: str = "point"
) -> np.ndarray:
    """∬ σ dA of each face over its curved surface in 3-D (N): an (m,) array."""
    xi, eta, w = gauss_rule("tri" if ftype.startswith("tri") else "quad")
    N, dxi, deta = shape(ftype, xi, eta)
    P = points[conn]
    dA = (
        np.linalg.norm(np.cross(np.einsum("qk,mkd->mqd", dxi, P), np.einsum("qk,mkd->mqd", deta, P)), axis=-1)
        * w
    )
    sig = np.asarray(values, float)[conn] @ N.T if location == "point" else np.asarray(values, float)[:, None]
    return np.sum(sig * dA, axis=1)


def surface_integrals(
    ftype: str, points: np.ndarray, conn: np.ndarray, values: np.ndarray, location: str = "point"
) -> tuple[float, np.ndarray]:
    """(∬ σ dA, ∬ σ n dA) over the curved faces in 3-D; n the face normal of the node order."""
    xi, eta, w = gauss_rule("tri" if ftype.startswith("tri") else "quad")
    N, dxi, deta = shape(ftype, xi, eta)
    P = points[conn]  # (m, k, 3)
    a = np.einsum("qk,mkd->mqd", dxi, P)
    b = np.einsum("qk,mkd->mqd", deta, P)
    cross = np.cross(a, b)
    dA = np.linalg.norm(cross, axis=-1) * w
    sig = np.asarray(values, float)[conn] @ N.T if location == "point" else np.asarray(values, float)[:, None]
    vec = np.einsum("mq,mqd->d", sig * w, cross)
    return float(np.sum(sig * dA)), vec


@cache
def _pattern(ftype: str, level: int) -> tuple[np.ndarray, np.ndarray]:
    """Reference points (p, 2) and triangles (t, 3) of one face cut at ``level``."""
    L = level
    if ftype.startswith("quad"):
        s = np.linspace(-1.0, 1.0, L + 1)
        gx, gy = np.meshgrid(s, s, indexing="ij")
        grid = np.column_stack([gx.ravel(), gy.ravel()])
        idx = np.arange((L + 1) ** 2).reshape(L + 1, L + 1)
        a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
        c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
        # each sub-quad split along its diagonal (0, 2), as VTK and the readers split a quad
        tris = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        return grid, tris
    pts: list[tuple[float, float]] = []
    index: dict[tuple[int, int], int] = {}
    for i in range(L + 1):
        for j in range(L + 1 - i):
            index[(i, j)] = len(pts)
            pts.append((i / L, j / L))
    tri_list: list[tuple[int, int, int]] = []
    for i in range(L):
        for j in range(L - i):
            tri_list.append((index[(i, j)], index[(i + 1, j)], index[(i, j + 1)]))
            if i + j < L - 1:
                tri_list.append((index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]))
    return np.array(pts), np.array(tri_list, np.int64)


def refine(
    ftype: str, points: np.ndarray, conn: np.ndarray, values: np.ndarray | None, level: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Cut each face into linear triangles at ``level``.

    Returns the new points (m·p, 3), the triangles (m·t, 3) indexing them
    (0-based within the new points, face by face), and the nodal values at the
    new points (``values`` per node) or None (face data: each triangle takes
    its face's value, t triangles per face in order).
    """
    ref, tris = _pattern(ftype, level)
    N, _, _ = shape(ftype, ref[:, 0], ref[:, 1])  # (p, k)
    m, p = len(conn), len(ref)
    new_pts = np.einsum("pk,mkd->mpd", N, points[conn]).reshape(m * p, 3)
    new_tri = (tris[None, :, :] + (np.arange(m) * p)[:, None, None]).reshape(-1, 3)
    new_vals = None if values is None else (np.asarray(values, float)[conn] @ N.T).reshape(m * p)
    return new_pts, new_tri, new_vals


def triangles_per_face(ftype: str, level: int) -> int:
    return len(_pattern(ftype, level)[1])
