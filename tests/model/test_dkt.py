"""The DKT element against facts that do not depend on our code: three rigid-body modes of zero
energy, symmetry, the patch test (constant-curvature states give exact moments, element by
element and on an assembled patch of distorted triangles), and exact statics of its loads."""

from __future__ import annotations

import numpy as np
import pytest

from plateqp.model.elements import DKT, ELEMENTS, bending_matrix

TRI = np.array([[0.1, 0.0], [1.3, 0.2], [0.4, 0.9]])
D, NU = 2.7, 0.3


def dofs(xy, w, wx, wy):
    return np.array([[w(*p), wx(*p), wy(*p)] for p in xy]).ravel()


# w = a x² + b x y + c y² (+ linear): curvature (2a, 2c, 2b), the same everywhere
A, B, C = 0.5, 0.3, -1.0
QUAD = (lambda x, y: A * x * x + B * x * y + C * y * y + 0.2 * x - 0.1,
        lambda x, y: 2 * A * x + B * y + 0.2,
        lambda x, y: B * x + 2 * C * y)


def test_registered():
    assert ELEMENTS["dkt"] is DKT and DKT.ndof == 9 and DKT.dof_names == ("w", "wx", "wy")


def test_three_zero_eigenvalues_and_symmetry():
    K = DKT().stiffness(TRI, D, NU)[0]
    assert np.array_equal(K, K.T)
    ev = np.linalg.eigvalsh(K)
    assert np.all(np.abs(ev[:3]) < 1e-12 * ev[-1]) and ev[3] > 1e-3 * ev[-1]


@pytest.mark.parametrize("mode", [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)])
def test_rigid_body_modes_have_zero_energy(mode):
    a, b, c = mode
    u = dofs(TRI, lambda x, y: a + b * x + c * y, lambda x, y: b, lambda x, y: c)
    K = DKT().stiffness(TRI, D, NU)[0]
    assert np.abs(K @ u).max() < 1e-12 * np.abs(K).max()


def test_constant_curvature_gives_exact_moments():
    el = DKT()
    lam = np.array([[1.0, 0.0, 0.0], [0.2, 0.3, 0.5], [0.0, 0.5, 0.5]])
    M = el.moments(TRI, dofs(TRI, *QUAD), lam, D, NU)[0]
    kappa = np.array([2 * A, 2 * C, 2 * B])
    assert np.allclose(M, -bending_matrix(D, NU) @ kappa, rtol=1e-12, atol=1e-12)
    # and the element's cubic deflection reproduces the quadratic w
    N = el.shape(TRI, lam)[0]
    p = lam @ TRI
    assert np.allclose(N @ dofs(TRI, *QUAD), QUAD[0](p[:, 0], p[:, 1]), rtol=1e-12, atol=1e-13)


def test_assembled_patch_test():
    """A patch of distorted triangles, boundary dofs from a quadratic w: the interior node's dofs
    solve exactly to the quadratic's (the patch test of Irons, for the assembled element)."""
    xy = np.array([[0, 0], [2, 0], [2.2, 1.7], [0.1, 2], [0.9, 0.8]], float)  # node 4 inside
    tris = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    K = np.zeros((15, 15))
    for t, Ke in zip(tris, DKT().stiffness(xy[tris], D, NU)):
        d = (t[:, None] * 3 + np.arange(3)).ravel()
        K[np.ix_(d, d)] += Ke
    exact = dofs(xy, *QUAD)
    inner = np.arange(12, 15)
    outer = np.arange(12)
    u = np.linalg.solve(K[np.ix_(inner, inner)], -K[np.ix_(inner, outer)] @ exact[outer])
    assert np.allclose(u, exact[inner], rtol=1e-10, atol=1e-12)


def test_uniform_load_is_statically_exact():
    """Lumped load of a unit pressure: the w-loads add to the area, and their moment about the
    origin to the area's first moment (the centroid), exactly."""
    f = DKT().load(TRI)[0]
    area = 0.5 * abs((TRI[1, 0] - TRI[0, 0]) * (TRI[2, 1] - TRI[0, 1]) - (TRI[2, 0] - TRI[0, 0]) * (TRI[1, 1] - TRI[0, 1]))
    assert f[0::3].sum() == pytest.approx(area, rel=1e-13)
    # ∫ w dA for w = x: Σ f_i · (dof values of x) = area · x̄
    ux = dofs(TRI, lambda x, y: x, lambda x, y: 1.0, lambda x, y: 0.0)
    assert f @ ux == pytest.approx(area * TRI[:, 0].mean(), rel=1e-13)
