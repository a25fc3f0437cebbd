"""A second, independent computation of contact loads from FE files (no fepost code).

Files are read with netCDF4 (Exodus) or meshio (VTU); the contact faces are
found geometrically (element faces whose nodes all lie in the contact plane,
found from the loaded nodes), not through element face tables; the fields are
integrated with textbook bilinear / serendipity shape functions and tensor
Gauss rules written out here.
"""

from __future__ import annotations

import netCDF4
import numpy as np


def exodus(path, step=-1):
    """Reference coordinates (n, 3), displacement (n, 3), blocks [(elem_type, (m, k))], nodal and globals."""
    ds = netCDF4.Dataset(str(path))
    ds.set_auto_mask(False)
    try:
        nd = len(ds.dimensions["num_dim"])
        x = np.zeros((len(ds.dimensions["num_nodes"]), 3))
        for k, c in enumerate("xyz"[:nd]):
            x[:, k] = ds.variables[f"coord{c}"][:]
        names = [bytes(r).split(b"\0")[0].decode() for r in ds.variables["name_nod_var"][:]]
        nodal = {
            n: np.asarray(ds.variables[f"vals_nod_var{i + 1}"][step], float) for i, n in enumerate(names)
        }
        blocks = []
        for k in range(len(ds.dimensions["num_el_blk"])):
            v = ds.variables[f"connect{k + 1}"]
            blocks.append((v.elem_type, np.asarray(v[:], np.int64) - 1))
        glob = {}
        if "vals_glo_var" in ds.variables:
            gn = [bytes(r).split(b"\0")[0].decode() for r in ds.variables["name_glo_var"][:]]
            vals = ds.variables["vals_glo_var"][step]
            glob = {n: float(v) for n, v in zip(gn, vals, strict=True)}
    finally:
        ds.close()
    disp = np.zeros_like(x)
    for k, c in enumerate("xyz"):
        for name in (f"disp_{c}", f"displ_{c}"):
            if name in nodal:
                disp[:, k] = nodal[name]
    return x, disp, blocks, nodal, glob


def planar_faces(x, conn, axis, value, tol=1e-9):
    """Faces of the elements ``conn`` lying in the plane x[axis] = value.

    Returns (corners (m, 4), mids (m, 4) or None): corners counter-clockwise
    around the face centre; mid-edge node k between corners k and k+1.
    """
    corners, mids = [], []
    ncorner = 8  # hexahedra: the corners come first
    for el in conn:
        on = [n for n in el if abs(x[n, axis] - value) < tol]
        c = [n for n in el[:ncorner] if abs(x[n, axis] - value) < tol]
        if len(c) != 4:
            continue
        others = [a for a in range(3) if a != axis]
        cen = x[c][:, others].mean(axis=0)
        ang = np.arctan2(*(x[c][:, others] - cen).T[::-1])
        c = [c[i] for i in np.argsort(ang)]
        corners.append(c)
        m = [n for n in on if n not in c]
        if m:
            order = []
            for k in range(4):
                mid = 0.5 * (x[c[k]] + x[c[(k + 1) % 4]])
                order.append(min(m, key=lambda n, mid=mid: np.linalg.norm(x[n] - mid)))
            mids.append(order)
    return np.array(corners), (np.array(mids) if mids else None)


_G = np.polynomial.legendre.leggauss(4)


def _shape(xi, eta, quadratic):
    a = np.array([-1.0, 1.0, 1.0, -1.0])
    b = np.array([-1.0, -1.0, 1.0, 1.0])
    if not quadratic:
        N = 0.25 * (1 + a * xi) * (1 + b * eta)
        return N, 0.25 * a * (1 + b * eta), 0.25 * b * (1 + a * xi)
    Nc = 0.25 * (1 + a * xi) * (1 + b * eta) * (a * xi + b * eta - 1)
    dcx = 0.25 * a * (1 + b * eta) * (2 * a * xi + b * eta)
    dce = 0.25 * b * (1 + a * xi) * (a * xi + 2 * b * eta)
    # mid-edge nodes at (0,-1), (1,0), (0,1), (-1,0)
    Nm = np.array(
        [
            0.5 * (1 - xi**2) * (1 - eta),
            0.5 * (1 + xi) * (1 - eta**2),
            0.5 * (1 - xi**2) * (1 + eta),
            0.5 * (1 - xi) * (1 - eta**2),
        ]
    )
    dmx = np.array([-xi * (1 - eta), 0.5 * (1 - eta**2), -xi * (1 + eta), -0.5 * (1 - eta**2)])
    dme = np.array([-0.5 * (1 - xi**2), -eta * (1 + xi), 0.5 * (1 - xi**2), -eta * (1 - xi)])
    return np.r_[Nc, Nm], np.r_[dcx, dmx], np.r_[dce, dme]


def integrate(points, p, corners, mids=None, normal_axis=2, centre=None, cut=16):
    """Integrals over the faces of the field p, projected on the plane normal to ``normal_axis``:
    {N, area, Mx, My (first moments), Mxx (∬σ x² dA), spin (∬σ r dA about ``centre``, or about
    the centre of pressure)}.

    Each face is cut into ``cut`` × ``cut`` cells with a 4 × 4 Gauss rule each: the distance r has a
    kink at the centre, which a single Gauss rule per face would miss.
    """
    others = [a for a in range(3) if a != normal_axis]
    nodes = corners if mids is None else np.concatenate([corners, mids], axis=1)
    tot = {"N": 0.0, "area": 0.0, "Mx": 0.0, "My": 0.0, "Mxx": 0.0}
    samples = []
    edges = np.linspace(-1.0, 1.0, cut + 1)
    gx = (0.5 * (edges[:-1, None] + edges[1:, None]) + 0.5 * (edges[1] - edges[0]) * _G[0][None, :]).ravel()
    gw = np.tile(_G[1] * 0.5 * (edges[1] - edges[0]), cut)
    for xi, wx in zip(gx, gw, strict=True):
        for eta, we in zip(gx, gw, strict=True):
            N, dx, de = _shape(xi, eta, mids is not None)
            X = points[nodes][:, :, others]  # (m, k, 2)
            xy = np.einsum("k,mkd->md", N, X)
            jx = np.einsum("k,mkd->md", dx, X)
            je = np.einsum("k,mkd->md", de, X)
            det = np.abs(jx[:, 0] * je[:, 1] - jx[:, 1] * je[:, 0]) * wx * we
            s = p[nodes] @ N
            tot["N"] += float(s @ det)
            tot["area"] += float(det.sum())
            tot["Mx"] += float((s * xy[:, 0]) @ det)
            tot["My"] += float((s * xy[:, 1]) @ det)
            tot["Mxx"] += float((s * xy[:, 0] ** 2) @ det)
            samples.append((xy, s * det))
    c = np.array([tot["Mx"], tot["My"]]) / tot["N"] if centre is None else np.asarray(centre)
    tot["spin"] = float(sum((np.hypot(*(xy - c).T) * sd).sum() for xy, sd in samples))
    tot["centre"] = c
    return tot
