"""The teaching backend ``toggle`` starts, as the engineers' recipe says, with every support in
contact, whichever unknowns the LCP has: on the condensed problem (z the gaps, w the
reactions) that is z = 0, the two-sided solution, which holds a floating plate wherever any set
of its supports does; on the dual (z the reactions) every z solved for. Where a round's
contact set does not hold the plate, the message names that set.

References: the default backend's answer on the source paper's floating scenes (a solution
of the LCP is unique in the reactions there); a 2 × 2 LCP whose only singular block is the
whole matrix.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.backends import get_backend
from plateqp.backends.base import LCP


def _solve(scene, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        return pq.solve(scene, accuracy="high", **kw)


@pytest.mark.parametrize("name", ["heave", "settlement"])
def test_toggle_solves_the_papers_floating_scenes_like_the_default_backend(name):
    scene = scenes.load(name)
    ref = _solve(scene)
    res = _solve(scene, backend="toggle")
    assert res.formulation == "condensed" and res.status == pq.Status.OPTIMAL and res.kkt.ok
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    np.testing.assert_array_equal(res.active, ref.active)


def test_a_round_whose_contact_set_does_not_hold_the_plate_names_that_set():
    """z the gaps: round 1 puts both rows in contact (z = 0, w = q); both reactions are
    negative, so both lift off, and M itself (the stiffness of a plate held by nothing) is
    singular: the set in contact that does not hold it is the empty one."""
    M = np.array([[1.0, -1.0], [-1.0, 1.0]])  # singular: a rigid motion free with no support
    sol = get_backend("toggle").solve(LCP(M, np.array([-1.0, -1.0]), unknown="gaps"))
    assert sol.status == pq.Status.ERROR and sol.x is None
    assert "round 2: the supports in contact (none) do not hold the plate" in sol.solver_status
    # on the dual form (z the reactions) the rows solved for are the supports in contact
    sol = get_backend("toggle").solve(LCP(M, np.array([-1.0, -1.0]), unknown="reactions"))
    assert sol.status == pq.Status.ERROR
    assert "round 1: the supports in contact (rows 1, 2) do not hold the plate" in sol.solver_status


def test_an_lcp_of_unknown_meaning_is_told_in_lcp_terms():
    M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    sol = get_backend("toggle").solve(LCP(M, np.array([-1.0, -1.0])))
    assert sol.status == pq.Status.ERROR
    assert "round 1: M_AA is singular for A = the rows solved for (rows 1, 2)" in sol.solver_status


def test_an_lcp_says_what_its_unknowns_are():
    with pytest.raises(pq.ProblemError, match="unknown"):
        LCP(np.eye(2), np.zeros(2), unknown="forces")


def seesaw():
    """A free square on four posts: two on the line y = 0.5, two settled far (0.5) above and
    below it. Two-sided, both settled posts pull; toggle lifts them off together and is left
    on the two posts of one line, about which the plate can turn (statics: no rigid motion of
    a free plate is held by two points)."""
    return pq.Scene(name="seesaw", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(10, 10),
                    loads=[pq.PointLoad(10.0, 0.5, 0.4)],
                    supports=[pq.Support(0.1, 0.5), pq.Support(0.9, 0.5), pq.Support(0.5, 0.9, gap=0.5),
                              pq.Support(0.5, 0.1, gap=0.5)])


def test_a_plate_round_on_two_posts_is_named_not_solved():
    scene = seesaw()
    R2 = pq.solve_bilateral(scene).reactions
    assert R2[2] < 0 and R2[3] < 0  # both settled posts in tension: the next round drops both
    with pytest.raises(pq.SolverError, match=r"round 2: the supports in contact \(rows 1, 2\) do not hold the plate"):
        _solve(scene, backend="toggle")
    assert _solve(scene).kkt.ok  # the problem itself has its answer (the plate rests on post 4)
