"""backend="auto" never gives up where an exact route succeeds.

Four scenes where the first route (pdas on the sparse primal) stopped short of an answer that
an exact route on the condensed LCP gives, each checked against a reference that does not
come from the route under test: lemke on the condensed LCP, statics (ΣR = the load on a
floating plate), and the rigid motion a plate with no load makes onto heaved posts (R = 0).
The fallback itself is tested with the first route made to fail, and it must never turn a
failing answer into an OPTIMAL one.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.backends import get_backend
from plateqp.backends.base import RawSolution, Status
from plateqp.errors import SolverError

#: x, y, gap, stiffness of the ten elastic posts under the floating DKT plate (stiffness ratio 1e9)
POSTS = [
    (1.4972154164452047, 0.10000055908943817, -0.0037700091854410596, 1e9),
    (0.6566022888150616, 0.9096938971962758, -0.005761899735723358, 1e6),
    (0.5310323790522946, 0.47946370849526765, -0.011970454053953243, 1e11),
    (0.6119815295363715, 0.6138221519885013, -0.013985778577631103, 1e8),
    (1.4848470169436314, 0.02833291254349357, -0.008588282926942841, 1e7),
    (0.6550841823632576, 0.40326134319899243, -0.0009009541315171815, 1e3),
    (0.7177479628571244, 0.11160530396980806, -0.0018270169047059862, 1e5),
    (0.7697028101609193, 0.2489548436261646, -0.012729698629977578, 1e2),
    (0.594191626351861, 0.15396747786979614, -0.0013658809534465507, 1e10),
    (1.1078054515760742, 0.9334837024036152, -0.01443700579933558, 1e4),
]


def stiff_ratio_scene() -> pq.Scene:
    """A floating 2 × 1 DKT plate on ten posts of stiffness 1e2 … 1e11, heaves to −0.014."""
    return pq.Scene(name="stiffness-ratio", plate=pq.Plate(2.0, 1.0, 0.2, 3e10, 0.3),
                    mesh=pq.MeshSpec(8, 4, "dkt", size=0.25),
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 1.322644695203601, 0.5255178326330209)],
                    supports=[pq.Support(x, y, gap=g, stiffness=c) for x, y, g, c in POSTS])


def post_at_hinge_scene() -> pq.Scene:
    """An ACM plate hinged on its left edge, a rigid post 0.001 from that edge."""
    return pq.Scene(name="post-at-hinge", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8, "acm"),
                    edges={"left": pq.Edge("simple")}, loads=[pq.UniformLoad(10.0)],
                    supports=[pq.Support(0.001, 0.5), pq.Support(1.0, 0.5), pq.Support(0.5, 0.2)])


HEAVE = 6.7e-5


def floating_no_load_scene() -> pq.Scene:
    """A floating BFS plate with an opening on four corner posts, no load, one post heaved."""
    return pq.Scene(name="floating-no-load", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8, "bfs"),
                    openings=[pq.Opening(0.375, 0.625, 0.375, 0.625)],
                    supports=[pq.Support(x, y, gap=-HEAVE if (x, y) == (0.0, 0.0) else 0.0)
                              for x in (0.0, 1.0) for y in (0.0, 1.0)])


def hinged_no_load_scene() -> pq.Scene:
    """A plate hinged on its left edge, no load, two posts on the right edge heaved 1e-4."""
    return pq.Scene(name="hinged-no-load", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8, "acm"),
                    edges={"left": pq.Edge("simple")},
                    supports=[pq.Support(1.0, 0.25, gap=-1e-4), pq.Support(1.0, 0.75, gap=-1e-4)])


def quiet_solve(scene, **kw) -> pq.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pq.solve(scene, **kw)


@pytest.mark.parametrize("make", [stiff_ratio_scene, post_at_hinge_scene])
def test_auto_answers_where_lemke_on_the_condensed_lcp_does(make):
    scene = make()
    ref = quiet_solve(scene, backend="lemke", formulation="condensed")
    assert ref.status == pq.Status.OPTIMAL  # the independent exact route succeeds ...
    res = quiet_solve(scene)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok  # ... and so does the default
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-6 * np.abs(ref.reactions).max())
    route = res.extras["route"]
    assert route["answered"] == f"{res.backend}/{res.formulation}"
    if len(route["tried"]) > 1:  # the first route stopped short: it says why
        assert route["tried"][0]["route"] == "pdas/primal" and route["tried"][0]["why"]


def test_floating_plate_reactions_balance_the_load():
    res = quiet_solve(stiff_ratio_scene())
    assert res.status == pq.Status.OPTIMAL
    assert res.reactions.min() >= 0.0
    assert res.reactions.sum() == pytest.approx(10.0 * 2.0 * 1.0 + 100.0, rel=1e-6)


def rigid_gaps(scene, w_of):
    return np.array([s.gap - w_of(s.x, s.y) for s in scene.supports])


@pytest.mark.parametrize("backend,formulation", [("auto", "auto"), ("pdas", "primal"), ("lemke", "condensed"),
                                                 ("bpp", "condensed")])
def test_no_load_on_a_floating_plate_is_a_rigid_lift(backend, formulation):
    """No load: the plate rises onto the heaved post as a body, every reaction zero, no gap
    negative, the heaved post touching."""
    scene = floating_no_load_scene()
    res = quiet_solve(scene, backend=backend, formulation=formulation)
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    F = scene.plate.D * HEAVE  # the force that bends this plate by the heave (L = 1)
    assert np.abs(res.reactions).max() <= 1e-9 * F
    assert res.gaps.min() >= -1e-9 * HEAVE and abs(res.gaps[0]) <= 1e-9 * HEAVE
    xs = np.linspace(0.05, 0.95, 5)
    w = np.array([[res.deflection(x, y) for x in xs] for y in (0.1, 0.9)])
    plane = np.linalg.lstsq(np.c_[np.ones(10), np.tile(xs, 2), np.repeat([0.1, 0.9], 5)], w.ravel(), rcond=None)
    assert np.abs(plane[1]).max(initial=0.0) <= (1e-9 * HEAVE) ** 2 * 10  # a plane: no bending


@pytest.mark.parametrize("backend,formulation", [("auto", "auto"), ("pdas", "primal"), ("osqp", "primal")])
def test_no_load_on_a_hinged_plate_turns_it_about_the_hinge(backend, formulation):
    """No load, both posts heaved 1e-4: the plate turns about its hinge, w = −1e-4 x, R = 0."""
    if backend not in pq.available_backends() and backend != "auto":
        pytest.skip(f"{backend} is not installed")
    scene = hinged_no_load_scene()
    res = quiet_solve(scene, backend=backend, formulation=formulation, accuracy="low" if backend == "osqp" else "default")
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    F = scene.plate.D * 1e-4
    tol = 1e-3 if backend == "osqp" else 1e-9
    assert np.abs(res.reactions).max() <= tol * F
    for x, y in ((0.25, 0.3), (0.5, 0.5), (0.9, 0.8)):
        assert res.deflection(x, y) == pytest.approx(-1e-4 * x, abs=tol * 1e-4)


# -- the fallback itself -------------------------------------------------------------------------

class Failing:
    """Wraps a backend: its answers end with the given status, and wrong (x scaled by 1.5: the KKT
    check fails them whatever status they claim)."""

    def __init__(self, backend, status=Status.MAX_ITER, message="iteration limit reached", exc=None):
        self.b, self.status, self.message, self.exc = backend, status, message, exc

    def __getattr__(self, name):
        return getattr(self.b, name)

    def solve(self, problem, accuracy="default", options=None):
        if self.exc is not None:
            raise self.exc
        raw = self.b.solve(problem, accuracy=accuracy, options=options)
        return RawSolution(status=self.status, x=1.5 * raw.x, z=None if raw.z is None else 1.5 * raw.z, iterations=raw.iterations,
                           solver_status=self.message, extras=dict(raw.extras))


def held_scene() -> pq.Scene:
    return pq.Scene(name="held", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                    edges={e: pq.Edge("simple") for e in ("left", "right", "bottom", "top")},
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.7, 0.6)],
                    supports=[pq.Support(x, y, gap=0.0) for x in (0.25, 0.5, 0.75) for y in (0.25, 0.75)])


def use(monkeypatch, **wrapped):
    from plateqp.backends import registry

    reg = registry()
    for name, w in wrapped.items():
        monkeypatch.setitem(reg, name, w)


@pytest.mark.parametrize("failure", [dict(status=Status.MAX_ITER, message="iteration limit 70 reached"),
                                     dict(status=Status.INACCURATE, message="no infeasible row"),
                                     dict(exc=SolverError("the active-set matrix is not positive definite"))])
def test_a_first_route_that_stops_short_hands_over_to_the_next_exact_route(monkeypatch, failure):
    ref = quiet_solve(held_scene(), backend="lemke", formulation="condensed")
    use(monkeypatch, pdas=Failing(get_backend("pdas"), **failure))
    res = quiet_solve(held_scene())
    assert res.status == pq.Status.OPTIMAL and res.formulation == "condensed"
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    first, last = res.extras["route"]["tried"][0], res.extras["route"]["tried"][-1]
    assert first["route"] == "pdas/primal"
    why = failure.get("message") or str(failure["exc"])
    assert why in first["why"]
    assert last["route"] == res.extras["route"]["answered"] == f"{res.backend}/condensed"


def test_the_first_route_that_answers_is_the_only_one_run(monkeypatch):
    calls = []
    pdas = get_backend("pdas")

    class Counting(Failing):
        def solve(self, problem, accuracy="default", options=None):
            calls.append(1)
            return self.b.solve(problem, accuracy=accuracy, options=options)

    use(monkeypatch, pdas=Counting(pdas))
    res = quiet_solve(held_scene())
    assert res.status == pq.Status.OPTIMAL and res.backend == "pdas" and len(calls) == 1
    assert res.extras["route"] == {"answered": "pdas/primal", "tried": [{"route": "pdas/primal", "status": "optimal"}]}


def test_the_fallback_never_makes_a_failing_answer_optimal(monkeypatch):
    """Every exact route fails: the answer keeps a failing status and says why each stopped."""
    use(monkeypatch, **{name: Failing(get_backend(name), Status.INACCURATE, f"{name} stopped")
                        for name in ("pdas", "bpp", "lemke")})
    res = quiet_solve(held_scene())
    assert res.status != pq.Status.OPTIMAL
    tried = res.extras["route"]["tried"]
    assert [t["route"] for t in tried][:3] == ["pdas/primal", "bpp/condensed", "lemke/condensed"]
    assert all(t["why"] for t in tried)


def test_a_named_backend_is_never_swapped(monkeypatch):
    use(monkeypatch, pdas=Failing(get_backend("pdas")))
    res = quiet_solve(held_scene(), backend="pdas")
    assert res.status == pq.Status.MAX_ITER and res.backend == "pdas"


def heave_dominated_scene() -> pq.Scene:
    """A floating concrete slab on four posts, heaved 10⁵ times the deflection its load causes."""
    return pq.Scene(name="heave-dominated", plate=pq.Plate(1.0, 1.0, 0.2, 3e10, 0.3), mesh=pq.MeshSpec(6, 6),
                    loads=[pq.UniformLoad(1.0), pq.PointLoad(100.0, 0.43, 0.6)],
                    supports=[pq.Support(x, y, gap=g) for (x, y), g in
                              zip(((0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)),
                                  (-0.017, 0.0, -0.01, -0.005, -0.012))])


@pytest.mark.parametrize("accuracy", ["low", "default"])
def test_a_small_load_beside_large_heaves_keeps_its_own_force_scale(monkeypatch, accuracy):
    """The heaves' force is the scale only where the load does no work: reactions 1 % off a load
    10⁻⁵ of that force are caught at every accuracy."""
    scene = heave_dominated_scene()
    ref = quiet_solve(scene, backend="lemke", formulation="condensed", accuracy=accuracy)
    assert ref.status == pq.Status.OPTIMAL
    np.testing.assert_allclose(ref.reactions.sum(), 101.0, rtol=1e-6)

    class Off(Failing):
        def solve(self, problem, accuracy="default", options=None):
            raw = self.b.solve(problem, accuracy=accuracy, options=options)
            raw.x = raw.x + 0.01 * np.abs(raw.x).max()  # every gap opened by 1 % of the largest
            return raw

    use(monkeypatch, lemke=Off(get_backend("lemke")))
    res = quiet_solve(scene, backend="lemke", formulation="condensed", accuracy=accuracy)
    assert res.status != pq.Status.OPTIMAL and not res.kkt.ok


def lifted_on_one_post_scene() -> pq.Scene:
    """A floating 4² BFS slab, no load, rigid and elastic posts, two heaved by 8e-6 and 1.4e-6."""
    posts = [(0.3577, 0.3117, 0.0, "rigid"), (0.999, 0.8126, 0.0, "rigid"), (0.6573, 0.6192, 0.0, 5380.17),
             (0.5419, 0.8728, -8.0286e-06, "rigid"), (0.9486, 0.9336, -1.4495e-06, 1644.88)]
    return pq.Scene(name="lifted", plate=pq.Plate(1.0, 1.0, 0.2, 3e10, 0.3), mesh=pq.MeshSpec(4, 4, "bfs"),
                    supports=[pq.Support(x, y, gap=g, stiffness=c) for x, y, g, c in posts])


def test_pdas_lifts_a_plate_its_anchored_set_leaves_free():
    """The anchored plate's first set is the one heaved rigid post: its penalty factor with the
    plate free to turn about that post was not definite ("the active-set matrix is not positive
    definite"); pdas now starts again from every row, and the plate rises as a body, R = 0."""
    scene = lifted_on_one_post_scene()
    res = quiet_solve(scene, backend="pdas")
    assert res.status == pq.Status.OPTIMAL and res.kkt.ok
    assert np.abs(res.reactions).max() <= 1e-9 * scene.plate.D * 8.0286e-06
    assert res.gaps.min() >= -1e-9 * 8.0286e-06


def hinge_heave_scene() -> pq.Scene:
    """A concrete slab hinged on its left edge, one rigid post 0.001 from the hinge, one heaved
    13 mm: the plate turns about the hinge onto the heaved post, whose lever carries the load."""
    return pq.Scene(name="hinge-heave", plate=pq.Plate(2.0, 1.0, 0.2, 3e10, 0.3), mesh=pq.MeshSpec(32, 16, "acm"),
                    edges={"left": pq.Edge("simple")}, loads=[pq.UniformLoad(10.0)],
                    supports=[pq.Support(0.001, 0.6711), pq.Support(1.1268, 0.6115), pq.Support(1.1198, 0.1272, gap=-0.013)])


@pytest.mark.parametrize("backend,formulation", [("auto", "auto"), ("pdas", "primal"), ("lemke", "condensed")])
def test_an_optimal_answer_on_a_hinged_plate_balances_the_moment_about_the_hinge(backend, formulation):
    """Statics about the hinge, Σ R_i x_i = q b a²/2 = 20 (exact for the element: its
    interpolation holds the rigid turn), to the accuracy asked, or the answer is not OPTIMAL.
    The plate turns about the hinge as a body, and K u's rounding along that turn (ε Vᵀ|K||u|,
    2.4e-5 of the forces) passed into the reactions: every route's moment was 3–4e-5 off, and
    pdas's answer was OPTIMAL at 1e-6 (its stationarity norm 5e-7). The KKT check's statics
    along the free turn sees that (lemke's answer is INACCURATE); pdas's exact steps leave K u's
    part along the turn out of their residual, and its moment is exact to rounding."""
    scene = hinge_heave_scene()
    res = quiet_solve(scene, backend=backend, formulation=formulation)
    x = np.array([s.x for s in scene.supports])
    moment_error = abs(res.reactions @ x - 20.0) / 20.0
    assert res.status != pq.Status.OPTIMAL or moment_error <= 10 * res.kkt.tol
    if backend != "lemke":  # pdas, also what auto answers with
        assert res.status == pq.Status.OPTIMAL and moment_error <= 1e-10


def test_the_options_given_go_to_the_first_route_only(monkeypatch):
    """pdas's own options are not handed to bpp or lemke (which would refuse them)."""
    use(monkeypatch, pdas=Failing(get_backend("pdas")))
    res = quiet_solve(held_scene(), options={"method": "sparse"})
    assert res.status == pq.Status.OPTIMAL and res.extras["route"]["answered"] == "bpp/condensed"
