"""The teaching backends: "toggle the springs" and the penalty method.

References: the 2 × 2 LCP with the closed-form solution z = (4/3, 7/3); Lemke's exact answer on
the same LCP or scene; the penalty method's first-order error (the answer of LCP(M + εI, q)
differs from the exact one by O(ε), so the error falls 100× when ε does).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.backends.lemke import lemke
from plateqp.backends.toggle import penalty, toggle
from plateqp.errors import ProblemError

#: A symmetric positive definite LCP on which toggling every sign change at once cycles through
#: three contact sets (found by a search over random 4 × 4 SPD matrices; eigenvalues 0.023 … 7.3).
M_CYCLE = np.array([[2.844343, 2.297693, -0.171521, -1.7712],
                    [2.297693, 2.275866, 0.730716, -0.366356],
                    [-0.171521, 0.730716, 3.568384, 2.850456],
                    [-1.7712, -0.366356, 2.850456, 4.226177]])
Q_CYCLE = np.array([-1.17332, -0.316549, -1.245159, 1.426829])


def held_scene():
    """A simply supported square on a 3 × 3 grid of one-sided posts with small gaps (held: every
    contact set gives a definite M_AA)."""
    pts = [(x, y) for x in (0.25, 0.5, 0.75) for y in (0.25, 0.5, 0.75)]
    gaps = [0, 1e-5, -1e-5, 2e-5, 0, -2e-5, 1e-5, 0, 0]
    return pq.Scene(name="held", plate=pq.Plate(1, 1, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(16, 16),
                    edges={k: "simple" for k in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.7, 0.6)],
                    supports=[pq.Support(x, y, gap=g) for (x, y), g in zip(pts, gaps)])


def test_toggle_closed_form():
    sol = toggle(np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0]), accuracy="high")
    assert sol.status == pq.Status.OPTIMAL
    np.testing.assert_allclose(sol.x, [4 / 3, 7 / 3], rtol=1e-14)


def test_toggle_cycles_where_an_exact_method_finishes():
    sol = toggle(M_CYCLE, Q_CYCLE)
    assert sol.status == pq.Status.MAX_ITER and "cycled" in sol.solver_status and sol.extras["cycle"] == 3
    ref = lemke(M_CYCLE, Q_CYCLE, accuracy="high")  # the LCP has a solution
    assert ref.status == pq.Status.OPTIMAL
    assert tuple(np.flatnonzero(ref.x > 0)) not in sol.extras["sets"][-3:]  # the cycle misses it
    assert toggle(M_CYCLE, Q_CYCLE, max_iter=2).solver_status.startswith("max_iter")


@pytest.mark.parametrize("formulation", ["condensed", "dual"])
def test_toggle_on_a_held_plate_agrees_with_lemke(formulation):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = pq.solve(held_scene(), backend="lemke", accuracy="high")
        res = pq.solve(held_scene(), backend="toggle", formulation=formulation, accuracy="high")
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_toggle_says_when_the_contact_set_does_not_hold_the_plate():
    """A singular round leaves no answer: a SolverError that says why and names the set in
    contact, not a Result of zeros (the LCP of a plate held by nothing: tests/test_toggle_start.py)."""
    from plateqp.backends import get_backend
    from plateqp.backends.base import LCP

    M = np.array([[1.0, -1.0], [-1.0, 1.0]])
    sol = get_backend("toggle").solve(LCP(M, np.array([-1.0, -1.0]), unknown="gaps"))
    assert sol.status == pq.Status.ERROR and sol.x is None
    assert sol.solver_status.startswith("round 2: the supports in contact (none) do not hold the plate")


def cluster_scene():
    """Eight posts in a tight cluster under a simply supported slab, mixed heave and settlement:
    toggling cycles through three contact sets (notebooks/09_toggle_how_it_fails)."""
    posts = [(0.48, 0.52), (0.48, 0.55), (0.50, 0.55), (0.51, 0.62),
             (0.54, 0.52), (0.56, 0.58), (0.57, 0.52), (0.57, 0.61)]
    gap0 = 1e-4 * np.array([1, 2, 1, -1, 1, 1, -2, 0])
    return pq.Scene(name="cluster", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(10, 10),
                    edges={e: "simple" for e in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.7, 0.7), pq.PointLoad(100.0, 0.2, 0.1)],
                    supports=[pq.Support(x, y, gap=float(g)) for (x, y), g in zip(posts, gap0)])


def test_a_toggle_that_cycles_says_so_in_the_result_and_its_json():
    with pytest.warns(pq.PlateQPWarning, match="cycled"):
        res = pq.solve(cluster_scene(), backend="toggle", formulation="dual")
    assert res.status == pq.Status.MAX_ITER
    assert "cycled" in res.extras["why"] and "cycled" in res.to_dict()["why"]
    assert "why" not in pq.solve(held_scene(), backend="lemke").to_dict()  # an OPTIMAL answer has no why


def test_toggle_failures_say_why_on_the_command_line(tmp_path, capsys):
    import json

    from plateqp.cli import main

    f = tmp_path / "cluster.toml"
    cluster_scene().to_toml(f)
    assert main(["solve", str(f), "--backend", "toggle", "--formulation", "dual", "--json"]) == 5
    assert "cycled" in json.loads(capsys.readouterr().out)["why"]
    # the floating heave slab: toggle starts with every support in contact and finishes
    assert main(["solve", "heave", "--backend", "toggle", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)["reactions"]
    assert main(["solve", "heave", "--json"]) == 0
    ref = json.loads(capsys.readouterr().out)["reactions"]
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-8 * np.abs(ref).max())


def test_penalty_error_is_first_order_in_the_compliance():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = pq.solve(held_scene(), backend="lemke", accuracy="high")
        errs = []
        for ratio in (1e-4, 1e-6):
            res = pq.solve(held_scene(), backend="penalty", formulation="condensed", accuracy="high",
                           options={"ratio": ratio})
            assert res.status == pq.Status.INACCURATE and not res.kkt.ok  # it penetrates: flagged
            errs.append(np.abs(res.reactions - ref.reactions).max() / np.abs(ref.reactions).max())
    assert errs[0] / errs[1] == pytest.approx(100.0, rel=0.02)


def test_penalty_penetration_is_epsilon_times_the_force():
    M, q = np.array([[2.0, 1.0], [1.0, 2.0]]), np.array([-5.0, -6.0])
    sol = penalty(M, q, ratio=1e-3)
    eps = sol.extras["epsilon"]
    assert eps == pytest.approx(2e-3)
    np.testing.assert_allclose(sol.w, -eps * sol.x, rtol=1e-9)  # w = M z + q = −ε z in contact
    assert sol.status == pq.Status.INACCURATE
    with pytest.raises(ProblemError, match="ratio"):
        penalty(M, q, ratio=0.0)
