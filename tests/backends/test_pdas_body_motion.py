"""A floating plate's first solve on its held springs takes its move as a rigid body first
(``sparse._body_motion``): the same minimiser as SciPy's SuperLU gives for ``H u = b`` (an
independent factorisation), with reactions that balance the load along the rigid motions to the
rounding of the plate's deformation, however far the plate sinks or tilts as a body; solved as
it stands, the imbalance grows with the move (the solve's rounding is ε |H||u|, u the move)."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import plateqp as pq
from plateqp.backends.pdas import sparse as S
from plateqp.backends.pdas.factor import SpringFactor
from plateqp.backends.pdas.reduced import ReducedQP
from plateqp.contact.formulations import Primal
from plateqp.contact.scaling import Scaled
from plateqp.linalg import bindings
from plateqp.model.assembly import build_model

pytestmark = pytest.mark.skipif(not bindings(), reason="no CHOLMOD binding")


def sinking(n: int, g0: float, gx: float) -> ReducedQP:
    """A free plate on a bed that settles by g0 and tilts by gx: the plate follows as a body."""
    scene = pq.Scene(name="sink", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                     edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                     foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": g0, "gx": gx, "gy": 0.0}))
    return ReducedQP(Primal(Scaled.from_model(build_model(scene))).qp, None)


def first_solve(pb: ReducedQP, body: bool):
    W = 1.0 / pb.rho  # every spring held
    fac = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, 0.0, "auto")
    fac.set(W)
    b = pb.f + pb.B.T @ (W * pb.g)
    move = S._body_motion(pb, W, b) if body else None
    if move is None:
        return W, b, fac.solve(b)
    return W, b, fac.solve(b - pb.B.T @ (W * (pb.B @ move))) + move


def imbalance(pb: ReducedQP, W, u) -> float:
    """|Vᵀ(f − Bᵀλ)| against |V|ᵀ(|f| + |B|ᵀ|λ|), λ the held springs' forces, in units of ε."""
    V = pb.rigid()
    lam = W * (pb.B @ u - pb.g)
    size = (np.abs(V).T @ (np.abs(pb.f) + abs(pb.B).T @ np.abs(lam))).max()
    return float(np.abs(V.T @ (pb.f - pb.B.T @ lam)).max() / size / np.finfo(float).eps)


def test_the_body_first_solve_is_the_minimiser():
    pb = sinking(24, 1.0, 0.5)
    W, b, u = first_solve(pb, body=True)
    H = sp.csc_matrix(pb.K + pb.B.T @ sp.diags(W) @ pb.B)
    ref = spla.spsolve(H, b)
    assert np.abs(u - ref).max() <= 1e-9 * np.abs(ref).max()


def test_its_reactions_balance_the_load_however_far_the_plate_moves_as_a_body():
    still, far = sinking(24, 0.0, 0.0), sinking(24, 100.0, 0.5)
    body_still = imbalance(still, *first_solve(still, True)[::2])
    body_far = imbalance(far, *first_solve(far, True)[::2])
    plain_far = imbalance(far, *first_solve(far, False)[::2])
    assert body_far <= 10.0 * max(body_still, 1.0)  # the move's size does not enter
    assert body_far <= 1e4  # to rounding of the deformation (tens to thousands of ε by the mesh)
    assert plain_far >= 1e3 * body_far  # as it stands, the move's rounding is in the balance


def test_no_body_motion_where_the_springs_do_not_hold_the_plate():
    pb = sinking(12, 0.0, 0.0)
    W = np.zeros(pb.m)
    W[:2] = 1.0 / pb.rho[:2]  # two springs: a line the plate turns about
    assert S._body_motion(pb, W, pb.f) is None
