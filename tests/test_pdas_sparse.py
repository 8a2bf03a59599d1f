"""pdas's sparse method on many contacts (issue 11, "no cliff"): a post on every node, and a bed.

References, none of them pdas's own earlier output:

* an independent algorithm on another formulation: Lemke's method on the condensed LCP;
* statics by hand: the total load (q·a² + P) against the posts' reactions plus the walls'
  (``K_full u − f_full`` at the prescribed w-dofs), and the moments about both axes;
* contact physics from the deflection interpolated at each support: R ≥ 0, gap ≥ 0, R·gap = 0.

And the path: with stiff rows on a held plate and no warm start, the sparse method finds the
contact set by projected Newton on the dual energy (``extras["first_phase"] == "dual"``), and
the exact steps after it only confirm that set and exchange a few rows.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp import families as F
from plateqp.backends.pdas import sparse as pdas_sparse
from plateqp.errors import ProblemError

TOTAL = F.Q * F.A * F.A + F.P  # kN: 10 kN/m² on 8 m × 8 m plus the 300 kN column
MOMENT_X = F.Q * F.A**3 / 2 + F.P * F.PX  # Σ load · x
MOMENT_Y = F.Q * F.A**3 / 2 + F.P * F.PY
SPARSE = {"method": "sparse"}


def solve(scene, backend="pdas", formulation="primal", accuracy=1e-10, options=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, backend=backend, formulation=formulation, accuracy=accuracy, options=options)


def support_xy(res):
    return res.model.contacts.xy


def wall_reactions(res):
    """Upward forces of the walls at their w-dofs, and where (from the full stiffness)."""
    m = res.model
    nd = m.element.ndof_node
    e = m.K_full @ res.u - m.f_full  # −(wall reaction) at prescribed dofs
    fixed_w = m.fixed[m.fixed % nd == 0]
    return -e[fixed_w], m.grid.node_xy()[fixed_w // nd]


def assert_contact_physics(res, gap0):
    xy = support_xy(res)
    w = res.deflection(xy[:, 0], xy[:, 1])
    gap = gap0 - w
    R = res.reactions
    scale_R, scale_g = np.abs(R).max(), np.abs(gap0).max() + np.abs(w).max()
    assert R.min() >= -1e-10 * scale_R
    assert gap.min() >= -1e-9 * scale_g
    assert np.abs(R * gap).max() <= 1e-9 * scale_R * scale_g


@pytest.fixture(scope="module")
def every_node_16():
    """A post on every interior node of a 16² slab: pdas's sparse method and Lemke."""
    sc = F.grid_rigid(16, "all")
    return sc, solve(sc, options=SPARSE), solve(sc, "lemke", "condensed", "high")


def test_every_node_a_post_agrees_with_lemke_on_the_condensed_lcp(every_node_16):
    sc, res, ref = every_node_16
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert ref.status == pq.Status.OPTIMAL
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * scale)
    assert (res.active == ref.active).all()
    assert 0.05 < res.active.mean() < 0.9  # mixed gaps: many posts but not all carry load


def test_every_node_a_post_takes_the_dual_first_phase(every_node_16):
    _, res, _ = every_node_16
    ex = res.extras
    assert ex["method"] == "sparse" and ex["first_phase"] == "dual"
    assert ex["first_phase_steps"] >= 2
    assert res.iterations - ex["first_phase_steps"] <= 4  # the exact steps confirm a near set


def test_every_node_a_post_statics_24():
    """24²: 529 posts, walls on four sides; force and moment balance by hand, contact physics."""
    sc = F.grid_rigid(24, "all")
    res = solve(sc, options=SPARSE)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.extras["first_phase"] == "dual"
    Rw, xyw = wall_reactions(res)
    xy = support_xy(res)
    R = res.reactions
    np.testing.assert_allclose(R.sum() + Rw.sum(), TOTAL, rtol=1e-9)
    np.testing.assert_allclose(R @ xy[:, 0] + Rw @ xyw[:, 0], MOMENT_X, rtol=1e-9)
    np.testing.assert_allclose(R @ xy[:, 1] + Rw @ xyw[:, 1], MOMENT_Y, rtol=1e-9)
    assert R.sum() > 0.3 * TOTAL  # the posts carry a real share, not only the walls
    assert_contact_physics(res, np.array([s.gap for s in sc.supports]))


def test_monotone_steps_alone_reach_the_same_answer(every_node_16, monkeypatch):
    """No full steps allowed (every step searched back until ψ falls): the globalised
    branch alone finds the set; the answer is Lemke's."""
    sc, _, ref = every_node_16
    monkeypatch.setattr(pdas_sparse, "DUAL_RISES", -1)
    res = solve(sc, options={**SPARSE, "trace": True})
    assert res.status == pq.Status.OPTIMAL and res.extras["first_phase"] == "dual"
    alphas = [s["alpha"] for s in res.extras["trace"] if str(s["step"]).startswith("dual") and "alpha" in s]
    assert alphas and min(alphas) < 1.0  # the arc was searched back
    energies = [s["energy"] for s in res.extras["trace"] if "energy" in s]
    assert all(b <= a + 1e-10 * abs(a) for a, b in zip(energies, energies[1:]))  # ψ never rises
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * scale)


def test_plain_pdas_without_the_dual_start_agrees(every_node_16):
    sc, _, ref = every_node_16
    res = solve(sc, options={**SPARSE, "dual_start": False})
    assert res.extras["first_phase"] == "none"
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    with pytest.raises(ProblemError, match="dual_start"):
        solve(sc, options={**SPARSE, "dual_start": "yes"})


def test_floating_plate_skips_the_dual_phase():
    """K singular (no walls): the dual energy needs K⁻¹, so the phase declines; the answer
    still carries the whole load by statics."""
    res = solve(F.floating(16, 9), options=SPARSE)
    assert res.status == pq.Status.OPTIMAL and res.extras["first_phase"] == "none"
    np.testing.assert_allclose(res.reactions.sum(), TOTAL, rtol=1e-9)


def test_bed_24_statics_and_contact_physics():
    """Free slab on a tensionless bed (625 one-sided springs): the springs carry the column."""
    sc = F.bed(24)
    res = solve(sc, options=SPARSE)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok and res.extras["first_phase"] == "newton"
    np.testing.assert_allclose(res.reactions.sum(), F.P, rtol=1e-9)
    xy = support_xy(res)
    np.testing.assert_allclose(res.reactions @ xy[:, 0], F.P * F.PX, rtol=1e-9)
    np.testing.assert_allclose(res.reactions @ xy[:, 1], F.P * F.PY, rtol=1e-9)
    assert 0.05 < res.active.mean() < 0.95
    assert res.reactions.min() >= -1e-10 * res.reactions.max()
