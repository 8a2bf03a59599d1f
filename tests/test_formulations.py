"""The standard forms of the contact problem (plateqp.contact.formulations) against dense
references built here from the same scaled data: the condensed stiffness on the contact
deflections is the inverse of the flexibility, ``S = (B K⁻¹ Bᵀ)⁻¹``, its load ``r = S B K⁻¹ f``;
the dual's matrix is ``B K⁻¹ Bᵀ + diag(ρ)`` and its vector ``g0 − B K⁻¹ f`` (K⁻¹ by SciPy's
SuperLU, an independent factorisation); the condensation cache gives a fresh build's answer.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import plateqp as pq
from plateqp.assembly import build_model
from plateqp.contact import Scaled
from plateqp.contact.formulations import formulate
from plateqp.families import family


def dense_reference(d: Scaled):
    """(G = B K⁻¹ Bᵀ, B K⁻¹ f) by SuperLU with dense right-hand sides."""
    lu = spla.splu(d.K.tocsc())
    return d.B @ lu.solve(d.B.T.toarray()), d.B @ lu.solve(d.f)


@pytest.fixture(scope="module")
def held():
    """A slab on four walls with a 5 × 5 grid of rigid posts (ρ = 0): K definite."""
    return Scaled.from_model(build_model(family("grid_rigid", 16, 5)))


def test_condensed_is_the_inverse_flexibility(held):
    d = held
    assert np.all(d.rho == 0)  # rigid: the condensed LCP is (S, r − S g0) itself
    G, wf = dense_reference(d)
    S = np.linalg.inv(G)
    lcp = formulate(d, "condensed").lcp
    np.testing.assert_allclose(lcp.M, S, rtol=0, atol=1e-9 * np.abs(S).max())
    q = S @ (wf - d.g0)
    np.testing.assert_allclose(lcp.q, q, rtol=0, atol=1e-9 * np.abs(q).max())


def test_dual_is_the_flexibility():
    d = Scaled.from_model(build_model(family("grid_elastic", 16, 5)))  # piles: ρ > 0
    assert np.all(d.rho > 0)
    G, wf = dense_reference(d)
    lcp = formulate(d, "dual").lcp
    np.testing.assert_allclose(lcp.M, G + np.diag(d.rho), rtol=0, atol=1e-12 * np.abs(G).max())
    np.testing.assert_allclose(lcp.q, d.g0 - wf, rtol=0, atol=1e-12 * np.abs(d.g0 - wf).max())


def test_condensation_is_reused_across_gap_changes():
    """Same K and B, other gaps: the cached condensation gives the answer of a fresh build."""
    from test_contact import symmetric_scene

    from plateqp.studies import adapt_model, set_param

    sc = symmetric_scene()
    base = build_model(sc)
    first = pq.solve(sc, backend="lemke", formulation="condensed", model=base)
    sc2 = set_param(sc, "supports.4.gap", -2e-3)
    reused = pq.solve(sc2, backend="lemke", formulation="condensed", model=adapt_model(base, sc2))
    fresh = pq.solve(sc2, backend="lemke", formulation="condensed")
    assert not np.allclose(first.reactions, fresh.reactions)
    np.testing.assert_allclose(reused.reactions, fresh.reactions, rtol=1e-10, atol=1e-12)
