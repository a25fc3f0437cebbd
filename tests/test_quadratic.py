"""Element faces with their own shape functions: exact integrals on curved faces, the cut into triangles.

References are independent: scipy's adaptive quadrature of the defining
integrals over the true curved surface, and closed forms.
"""

import numpy as np
import pytest
from scipy import integrate

from fepost.field import ContactField
from fepost.patch import REFINE_TOL, build_patch
from fepost.reader import quadratic
from fepost.reader.quadratic import face_loads, reference_nodes, refine, shape, surface_integrals

TYPES = ("tri3", "tri6", "tri7", "quad4", "quad8", "quad9")
A_CURV = 0.4  # the face lies on z = A (x² + y²)
P0, RP = 1.0e5, 2.0  # a quadratic pressure: every quadratic face type reproduces it


def _sigma(x, y):
    return P0 * (1.0 - x**2 / RP**2 + 0.3 * y - 0.1 * x * y)


def _face(ftype: str, h: float = 0.5):
    """One face on the paraboloid z = A(x² + y²): nodes (k, 3) and nodal pressure (k,)."""
    ref = reference_nodes(ftype)
    xy = h * (ref if ftype.startswith("quad") else 2.0 * ref - 0.5)
    z = A_CURV * (xy**2).sum(axis=1)
    pts = np.column_stack([xy, z])
    return pts, _sigma(xy[:, 0], xy[:, 1])


@pytest.mark.parametrize("ftype", TYPES)
def test_shape_functions_interpolate_and_sum_to_one(ftype):
    ref = reference_nodes(ftype)
    N, dxi, deta = shape(ftype, ref[:, 0], ref[:, 1])
    np.testing.assert_allclose(N, np.eye(len(ref)), atol=1e-14)
    rng = np.random.default_rng(1)
    q = rng.uniform(0, 0.45, (20, 2)) if ftype.startswith("tri") else rng.uniform(-1, 1, (20, 2))
    N, dxi, deta = shape(ftype, q[:, 0], q[:, 1])
    np.testing.assert_allclose(N.sum(axis=1), 1.0, atol=1e-13)
    np.testing.assert_allclose(dxi.sum(axis=1), 0.0, atol=1e-12)
    h = 1e-7
    Nx, _, _ = shape(ftype, q[:, 0] + h, q[:, 1])
    Ny, _, _ = shape(ftype, q[:, 0], q[:, 1] + h)
    np.testing.assert_allclose((Nx - N) / h, dxi, atol=2e-6)
    np.testing.assert_allclose((Ny - N) / h, deta, atol=2e-6)


def _domain(ftype, h=0.5):
    """scipy dblquad limits of the face's footprint in (x, y)."""
    if ftype.startswith("quad"):
        return (-h, h, lambda x: -h, lambda x: h)
    # the reference triangle scaled by 2h, shifted by -h/2: corners (-h/2, -h/2), (3h/2, -h/2), (-h/2, 3h/2)
    lo = -0.5 * h
    return (lo, lo + 2 * h, lambda x: lo, lambda x: lo + 2 * h - (x - lo))


@pytest.mark.parametrize("ftype", ("tri6", "tri7", "quad8", "quad9"))
def test_exact_integrals_on_a_curved_quadratic_face(ftype):
    """A quadratic face on the paraboloid z = a(x² + y²) with a quadratic pressure: its shape
    functions reproduce both exactly, so ∬σ dA over the curved surface and the load normal to
    the plane, ∬σ dx dy, equal scipy's adaptive quadrature of the defining integrals."""
    pts, p = _face(ftype)
    conn = np.arange(len(pts))[None, :]
    x0, x1, y0, y1 = _domain(ftype)
    true_area_load = integrate.dblquad(
        lambda y, x: _sigma(x, y) * np.sqrt(1 + (2 * A_CURV * x) ** 2 + (2 * A_CURV * y) ** 2),
        x0,
        x1,
        y0,
        y1,
        epsabs=0,
        epsrel=1e-12,
    )[0]
    projected = integrate.dblquad(lambda y, x: _sigma(x, y), x0, x1, y0, y1, epsabs=0, epsrel=1e-13)[0]
    scalar, vec = surface_integrals(ftype, pts, conn, p)
    assert scalar == pytest.approx(true_area_load, rel=2e-7)  # a square root: Gauss 5 a side, not exact
    assert abs(vec[2]) == pytest.approx(projected, rel=1e-12)  # a polynomial: exact
    assert face_loads(ftype, pts[:, :2], conn, p, "point")[0] == pytest.approx(projected, rel=1e-12)


@pytest.mark.parametrize("ftype", ("tri6", "quad8", "quad9"))
def test_refinement_error_falls_as_the_square_of_the_level(ftype):
    """Linear sub-triangles of a quadratic face: the load error is O(L⁻²) (observed order 2)."""
    pts, p = _face(ftype)
    conn = np.arange(len(pts))[None, :]
    exact = face_loads(ftype, pts[:, :2], conn, p, "point")[0]
    errs = []
    levels = (4, 8, 16)
    for L in levels:
        q, tri, v = refine(ftype, pts, conn, p, L)
        x, y = q[:, 0][tri], q[:, 1][tri]
        area = 0.5 * np.abs(
            (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (y[:, 1] - y[:, 0]) * (x[:, 2] - x[:, 0])
        )
        errs.append(abs((area * v[tri].mean(axis=1)).sum() / exact - 1))
    order = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(order - 2.0) < 0.15), (errs, order)


def _hex20_top(n: int = 4, h: float = 0.25, curved: float = 0.0):
    """The top faces (quad8) of an n × n grid of HEX20 elements: points, faces, nodal pressure."""
    # the face nodes of an n×n quad8 surface: corner grid and mid-edge nodes
    xs = np.linspace(-n * h / 2, n * h / 2, 2 * n + 1)
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    keep = ~((np.arange(2 * n + 1)[:, None] % 2 == 1) & (np.arange(2 * n + 1)[None, :] % 2 == 1))
    idx = -np.ones(X.shape, int)
    idx[keep] = np.arange(keep.sum())
    pts = np.column_stack([X[keep], Y[keep], curved * (X[keep] ** 2 + Y[keep] ** 2)])
    faces = []
    for i in range(0, 2 * n, 2):
        for j in range(0, 2 * n, 2):
            c = [idx[i, j], idx[i + 2, j], idx[i + 2, j + 2], idx[i, j + 2]]
            m = [idx[i + 1, j], idx[i + 2, j + 1], idx[i + 1, j + 2], idx[i, j + 1]]
            faces.append(c + m)
    return pts, np.array(faces)


def test_quadratic_faces_keep_the_load_the_mid_side_nodes_carry():
    """A pressure p0(1 − r²/a²) on quad8 faces: N_fe is exact, the polar map carries it to the
    grid's accuracy, while the corner nodes alone (a linearised face) would miss ~1.6 % of it."""
    pts, faces = _hex20_top(n=4, h=0.25)
    a = 1.0
    p = P0 * (1 - (pts[:, 0] ** 2 + pts[:, 1] ** 2) / a**2)
    fld = ContactField("hex20-top", pts, np.empty((0, 3)), p, "point", "CPRESS", faces={"quad8": faces})
    patch = build_patch(fld)
    s = 0.5  # half side of the square
    exact = P0 * (4 * s * s - (8 / 3) * s**4 / a**2)
    assert patch.N_fe == pytest.approx(exact, rel=1e-12)
    assert abs(patch.refine_error) <= REFINE_TOL
    from fepost.moments import moments
    from fepost.resample import resample

    m = moments(resample(patch, radius=patch.r_max))
    assert m.N == pytest.approx(exact, rel=5e-3)  # a square patch on a polar grid (corners)
    corner = faces[:, :4]
    tri = np.concatenate([corner[:, [0, 1, 2]], corner[:, [0, 2, 3]]])
    lin = build_patch(ContactField("corners", pts, tri, p, "point", "CPRESS")).N_fe
    assert abs(lin / exact - 1) > 0.01


def test_negative_lobes_of_a_quadratic_face_are_not_a_sign_error():
    """Nodal pressures all >= 0 whose quadratic interpolant dips below zero between nodes (the
    contact front inside an element): accepted, kept as the element's field, noted."""
    pts, faces = _hex20_top(n=2, h=0.5)
    x = pts[:, 0]
    # loaded up to x = 0, zero beyond: the right elements' field along x is p0 ξ(ξ − 1)/2, < 0 past 0.25
    p = np.where(x <= 1e-9, P0, 0.0)
    fld = ContactField("lobes", pts, np.empty((0, 3)), p, "point", "CPRESS", faces={"quad8": faces})
    patch = build_patch(fld)
    assert any("dips below zero" in n and "not a sign error" in n for n in patch.notes)
    assert patch.N_fe > 0
    assert patch.N_fe == pytest.approx(sum(face_loads("quad8", pts[:, :2], faces, p, "point")), rel=1e-12)


def test_gauss_rules_are_exact_to_degree_eight():
    for kind in ("tri", "quad"):
        xi, eta, w = quadratic.gauss_rule(kind)
        for a in range(9):
            for b in range(9 - a):
                got = np.sum(w * xi**a * eta**b)
                if kind == "quad":
                    ref = (1 - (-1) ** (a + 1)) / (a + 1) * (1 - (-1) ** (b + 1)) / (b + 1)
                else:
                    from math import factorial

                    ref = factorial(a) * factorial(b) / factorial(a + b + 2)
                assert got == pytest.approx(ref, abs=1e-14), (kind, a, b)
