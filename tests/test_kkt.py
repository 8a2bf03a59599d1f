"""The KKT check of a contact answer (plateqp.contact.kkt), against exact references.

* the local stiffness of the natural residual bounds the exact condensed stiffness
  ``(M⁻¹)_ii``, ``M = B K⁻¹ Bᵀ + diag(ρ)`` (K⁻¹ by SciPy's SuperLU), on every mesh;
* an exact answer (Lemke on the dual, statics-checked elsewhere) passes a tight tolerance, and
  the same answer with one reaction moved by 1e-6 of the largest fails it (stationarity), and
  so does a reaction of that size at an open gap with the deflections kept in equilibrium
  (natural residual).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from plateqp.assembly import build_model
from plateqp.backends import get_backend
from plateqp.contact import Scaled
from plateqp.contact.formulations import ContactSolution, formulate
from plateqp.contact.kkt import kkt_report
from plateqp.families import family


@pytest.mark.parametrize("k", [3, 7])
def test_local_stiffness_bounds_the_exact_one_at_every_mesh(k):
    """The natural residual's stiffness k_i against the exact one, (M⁻¹)_ii with M = B K⁻¹ Bᵀ + ρ
    (support i pushed, every other contact point held): an upper bound on every mesh (the
    residual stays conservative) by a factor that does not grow as the mesh is refined (Σ B² diag K
    alone grows 4× per halving)."""
    import scipy.sparse.linalg as spla

    from plateqp.assembly import build_model
    from plateqp.families import family
    from plateqp.contact import Scaled
    from plateqp.contact.kkt import local_stiffness

    worst = {}
    for n in (16, 32, 64):
        d = Scaled.from_model(build_model(family("grid_rigid", n, k)))
        X = spla.splu(d.K.tocsc()).solve(d.B.T.toarray())
        exact = np.diag(np.linalg.inv(d.B @ X + np.diag(d.rho)))
        ratio = local_stiffness(d) / exact
        assert ratio.min() >= 1.0
        worst[n] = ratio.max()
    assert worst[64] <= 10.0 and worst[64] <= 1.5 * worst[16]


@pytest.mark.parametrize("family_name", ["grid_rigid", "grid_elastic"])
def test_exact_answer_passes_and_a_moved_reaction_fails(family_name):
    d = Scaled.from_model(build_model(family(family_name, 16, 5)))
    form = formulate(d, "dual")
    c = form.recover(get_backend("lemke").solve(form.problem(frozenset({"lcp"})), accuracy="high"))
    exact = kkt_report(d, c, 1e-10)
    assert exact.worst <= 1e-10
    on = np.flatnonzero(c.R > 0)
    assert 0 < on.size < d.m  # a real contact problem
    i = on[np.argmax(c.R[on])]
    for sign in (1.0, -1.0):
        R = c.R.copy()
        R[i] += sign * 1e-6 * c.R.max()
        moved = kkt_report(d, ContactSolution(c.u, R, d.rho * R), 1e-10)
        assert moved.stationarity > 1e-8, moved
    # a reaction at an open gap, the deflections kept in equilibrium with it (K⁻¹ by SuperLU):
    # only the complementarity conditions can see it, in force units (natural residual)
    j = np.flatnonzero(c.R == 0)[0]
    R = c.R.copy()
    R[j] = 1e-6 * c.R.max()
    u = c.u - spla.splu(d.K.tocsc()).solve(d.B[[j]].T.toarray().ravel() * R[j])
    pushed = kkt_report(d, ContactSolution(u, R, d.rho * R), 1e-10)
    assert pushed.stationarity <= 1e-10 and pushed.natural > 1e-8, pushed
