"""Statics of one-sided supports (plateqp.contact.statics), against statics by hand.

* The edge of the supports' reach: a floating plate on four posts at the corners of
  [0.25, 0.75]², a point load P at (0.75 + d, 0.5). For d > 0 the load lies outside the posts'
  hull and there is no equilibrium; for d ≤ 0 the lever rule and the scene's symmetry give
  the reactions: each post at x = 0.25 carries P·(−d), each at x = 0.75 carries P/2 + P·d.
  At every distance 1e-12 … 1e-6 on either side, no solver that was right may be blamed
  (SolverError, exit 4), the statics pre-check must say "no equilibrium" wherever that is
  certain, and every answer given must satisfy the lever rule.
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.accuracy import Status
from plateqp.backends.base import RawSolution

P = 10.0
POSTS = [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)]
DISTANCES = [1e-6, 1e-8, 1e-10, 1e-12, 0.0, -1e-12, -1e-10, -1e-8, -1e-6]
EXACT = ["bpp", "lemke", "pdas"]


def posts(d: float) -> pq.Scene:
    return pq.Scene(name="posts", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                    loads=[pq.PointLoad(P, 0.75 + d, 0.5)], supports=[pq.Support(x, y) for x, y in POSTS])


def lever_rule(d: float) -> np.ndarray:
    """Reactions of the four posts (scene order) for a load at (0.75 + d, 0.5), d ≤ 0."""
    left, right = -P * d, P / 2 + P * d
    return np.array([left, right, right, left])


@pytest.mark.parametrize("backend", EXACT + ["osqp"])
@pytest.mark.parametrize("d", DISTANCES)
def test_no_solver_is_blamed_at_the_edge_of_the_supports_reach(backend, d):
    if backend not in pq.available_backends():
        pytest.skip(f"{backend} is not installed")
    try:
        res = pq.solve(posts(d), backend=backend)
    except pq.NoEquilibriumError as exn:
        assert d > 0, f"{backend}: no equilibrium claimed for a load inside the posts' hull ({exn})"
        return
    except pq.SolverError as exn:  # before: bpp, lemke, pdas at d = 1e-10 ("the solver failed")
        pytest.fail(f"{backend} blamed at d = {d:g}: {exn}")
    # an answer: only where statics cannot tell (on the edge, within 1e-10 outside) or inside
    assert d <= 1e-10, f"{backend} answered for a load {d:g} outside the hull: the pre-check must refuse it"
    assert res.status == Status.OPTIMAL
    np.testing.assert_allclose(res.reactions, lever_rule(min(d, 0.0)), rtol=0, atol=1e-5 * P)
    assert res.reactions.sum() == pytest.approx(P, rel=1e-5)  # 10 × the asked accuracy


@pytest.mark.parametrize("d", [1e-8, 1e-6, 1e-3])
def test_outside_by_more_than_rounding_statics_says_no_before_any_solve(d):
    with pytest.raises(pq.NoEquilibriumError, match="found by statics"):
        pq.solve(posts(d), backend="bpp")


class _ClaimsNoEquilibrium:
    """bpp, except that it always answers "infeasible" (a solver whose certificate is approximate)."""

    def __init__(self, real):
        self._real = real

    def __getattr__(self, name):
        return getattr(self._real, name)

    def solve(self, problem, accuracy=None, options=None):
        return RawSolution(Status.INFEASIBLE, solver_status="primal infeasible (claimed)")


def test_within_the_asked_accuracy_of_the_edge_the_solvers_verdict_stands(monkeypatch):
    """Inside the hull by less than the asked accuracy, "no equilibrium" is within a solver's
    tolerance: NoEquilibriumError (exit 3); well inside, a solver that finds none has failed
    (SolverError)."""
    import plateqp.contact.pipeline as pipeline

    real = pipeline.get_backend
    monkeypatch.setattr(pipeline, "get_backend", lambda name: _ClaimsNoEquilibrium(real(name)))
    with pytest.raises(pq.NoEquilibriumError):
        pq.solve(posts(-1e-8), backend="bpp")  # 1e-8 inside, default accuracy 1e-6
    with pytest.raises(pq.SolverError, match="failed"):
        pq.solve(posts(-1e-8), backend="bpp", accuracy="high")  # 1e-9: now 1e-8 inside is a margin
    with pytest.raises(pq.SolverError, match="failed"):
        pq.solve(posts(-0.25), backend="bpp")  # the load at the centre


def test_cli_exit_code_at_the_edge(tmp_path, capsys):
    """The user sees "no equilibrium" (exit 3), never "the solver failed" (exit 4), for a load
    1e-10 outside the posts' hull."""
    from plateqp.cli import main

    f = tmp_path / "edge.toml"
    posts(1e-10).to_toml(f)
    for backend in EXACT:
        code = main(["solve", str(f), "--backend", backend])
        err = capsys.readouterr().err
        assert code == 3 and "failed" not in err and err.count("\n") == 1, (backend, code, err)


# ---------------------------------------------------------------------------------------------
# Reactions unique, deflection not unique
# ---------------------------------------------------------------------------------------------

CORNERS = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]


def on_corners(x: float, y: float, posts=CORNERS) -> pq.Scene:
    return pq.Scene(name="free-tilt", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                    loads=[pq.PointLoad(P, x, y)], supports=[pq.Support(px, py) for px, py in posts])


#: name → (scene, reactions by statics alone). The load on corner post 0 is carried by it
#: alone; the load at the middle of the edge y = 0 by the two posts of that edge (moment about
#: that edge: R2 + R3 = 0 with R ≥ 0); the load on the line between two posts by them. Each
#: leaves a tilt of the plate free (one way, or both for the two posts alone).
TILTS = {
    "on a corner post": (on_corners(0.0, 0.0), [P, 0.0, 0.0, 0.0]),
    "between two posts": (on_corners(0.5, 0.0), [P / 2, P / 2, 0.0, 0.0]),
    "on the line of two posts": (on_corners(0.5, 0.5, [(0.0, 0.5), (1.0, 0.5)]), [P / 2, P / 2]),
}
PAIRS = [(b, f) for b in pq.available_backends() for f in ("primal", "condensed")
         if f in __import__("plateqp.contact", fromlist=["formulations_for"]).formulations_for(b)]


@pytest.mark.parametrize("name", list(TILTS))
@pytest.mark.filterwarnings("ignore::plateqp.errors.PlateQPWarning")
def test_every_backend_gives_the_same_deflection_when_it_is_not_unique(name):
    """Before: OPTIMAL from every backend, with w_max from 0 to −0.08 (tilted either way).
    Now: each OPTIMAL answer is flagged, its reactions are those of statics, and its deflection
    is the canonical one: for the first two scenes that of the same plate with all four posts
    two-sided (their reactions at the unloaded posts are zero by the same statics, so that
    answer is one of the one-sided answers, and it is unique); for the last, symmetric about
    the line of the posts (the scene is, so the least-norm answer is)."""
    scene, R_ref = TILTS[name]
    W = 0.01 * P / scene.plate.D  # the load's deflection scale
    ref = pq.solve_bilateral(scene).w_nodes() if len(R_ref) == 4 else None
    checked = 0
    for backend, form in PAIRS:
        try:
            res = pq.solve(scene, backend=backend, formulation=form)
        except pq.PlateQPError:  # refused (floating plate on the condensed form, indefinite P) or failed
            continue
        if res.status != Status.OPTIMAL:
            continue
        checked += 1
        assert not res.deflection_unique, (backend, form)
        np.testing.assert_allclose(res.reactions, R_ref, rtol=0, atol=1e-5 * P, err_msg=f"{backend}/{form}")
        w = res.w_nodes()
        if ref is not None:
            np.testing.assert_allclose(w, ref, rtol=0, atol=1e-5 * W, err_msg=f"{backend}/{form}")
        else:
            Wg = res.model.grid.to_grid(w)  # the grid view: symmetric about the line of the posts
            np.testing.assert_allclose(Wg, Wg[::-1, :], rtol=0, atol=1e-5 * W, err_msg=f"{backend}/{form}")
    assert checked >= 3


def test_a_unique_deflection_is_left_alone():
    res = pq.solve(on_corners(0.4, 0.3), backend="bpp")
    assert res.deflection_unique and res.to_dict()["deflection_unique"] is True
    assert pq.solve(posts(-0.25), backend="pdas").deflection_unique


def test_cli_says_the_deflection_is_not_unique(tmp_path, capsys):
    import json

    from plateqp.cli import main

    f = tmp_path / "corner.toml"
    on_corners(0.0, 0.0).to_toml(f)
    assert main(["solve", str(f), "--backend", "clarabel", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["deflection_unique"] is False and abs(d["w_max"]) < 1e-5 * 0.01 * P / on_corners(0, 0).plate.D
    assert main(["solve", str(f), "--backend", "bpp"]) == 0
    assert "reactions unique, deflection not unique" in capsys.readouterr().out


# ---------------------------------------------------------------------------------------------
# The contact flag is judged per support
# ---------------------------------------------------------------------------------------------

def test_an_open_support_is_not_in_contact_because_another_settles_far():
    """Four posts at the corners of [0.25, 0.75]² carry a centre load P/4 each (symmetry); a
    fifth support under the centre sits 1e-5 below the deflected plate (its gap set from the
    four-post answer), so it stays open with R = 0. Before: with a sixth support settled by
    1000 at a corner, every gap within tol · 1000 of zero counted as touching, and the fifth
    support was reported in contact with R = 0 and its gap 1e-5 open."""
    def scene(extra):
        return pq.Scene(name="flag", plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=pq.MeshSpec(8, 8),
                        loads=[pq.PointLoad(P, 0.5, 0.5)], supports=[pq.Support(x, y) for x, y in POSTS] + extra)

    res0 = pq.solve(scene([]), backend="bpp")
    wc = res0.model.grid.to_grid(res0.w_nodes())[4, 4]  # the centre node (0.5, 0.5)
    for far in ([], [pq.Support(0.0, 0.0, gap=1000.0)]):
        sc = scene([pq.Support(0.5, 0.5, gap=wc + 1e-5)] + far)
        for backend in ("bpp", "lemke", "pdas", "osqp"):
            res = pq.solve(sc, backend=backend)
            assert res.status == Status.OPTIMAL, backend
            np.testing.assert_allclose(res.reactions[:4], P / 4, rtol=1e-6)
            assert abs(res.reactions[4]) <= 1e-9 * P and res.gaps[4] > 0.9e-5, (backend, res.gaps)
            assert list(res.active) == [True] * 4 + [False] * (1 + len(far)), (backend, far, res.active)


@pytest.mark.parametrize("rows", [0, 1, 2, 3, 5000])
def test_null_space_of_tall_and_short_constraint_sets(rows):
    """settle's null space of the loaded supports' rigid-motion rows: A N = 0, N orthonormal, of
    dimension 3 − rank, whether A has fewer rows than 3 or thousands (a bed's nodes)."""
    from plateqp.contact.statics import _null_space

    rng = np.random.default_rng(rows)
    xy = rng.uniform(0.0, 1.0, (rows, 2))
    A = np.column_stack([np.ones(rows), xy])  # w = a + b x + c y at each row's point
    if rows == 2:
        A[1] = 2.0 * A[0]  # dependent: rank 1
    N = _null_space(A, 3)
    rank = np.linalg.matrix_rank(A) if rows else 0
    assert N.shape == (3, 3 - rank)
    np.testing.assert_allclose(A @ N, 0.0, atol=1e-12 * max(1.0, rows))
    np.testing.assert_allclose(N.T @ N, np.eye(3 - rank), atol=1e-12)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_the_cone_kept_for_statics_is_the_whole_cone(k):
    """The columns kept for the cone test (those on the rim of the projected hull) generate the
    same cone: SciPy's NNLS on all columns gives the same distance for loads inside, outside
    and just off its edge; columns on both sides of every plane are all kept."""
    from scipy.optimize import nnls

    from plateqp.contact.statics import _generators

    rng = np.random.default_rng(k)
    xy = rng.uniform(-1, 1, (2, 2000))
    A = np.vstack([np.ones(2000), xy])[:k] + 0.05 * rng.standard_normal((k, 2000))  # one-sided
    A = rng.standard_normal((k, k)) @ A  # in some other basis, as Qᵀ Bᵀ is
    G = _generators(A)
    assert G.shape[1] < A.shape[1] // 10
    # every column lies in the cone of those kept: the two cones are one
    for a in A.T:
        assert nnls(G, a, maxiter=10**5)[1] <= 1e-12 * np.linalg.norm(a)
    for _ in range(30):
        b = A @ rng.uniform(0, 1, 2000) * rng.uniform(0.5, 2) + rng.standard_normal(k) * rng.choice([0, 1e-9, 1, 100])
        full, kept = nnls(A, b, maxiter=10**5)[1], nnls(G, b, maxiter=10**5)[1]
        assert abs(full - kept) <= 1e-12 * np.linalg.norm(b) + 1e-9 * full
    B = np.hstack([A, -A[:, :1]])  # a column on the other side: no projection, every column
    assert _generators(B).shape == B.shape
