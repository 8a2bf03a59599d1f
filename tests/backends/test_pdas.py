"""Tests of the primal–dual active set backend (plateqp.backends.pdas).

References are external to the code under test, never its own earlier output:

* statics: a floating plate on three supports is statically determinate (reactions from
  force and moment balance, worked out in the comments); on a tensionless bed the reactions
  balance the total load and its moments;
* symmetry: a scene symmetric about both mid-lines and the diagonal has symmetric reactions;
* an independent algorithm: Lemke's method on the condensed LCP (plateqp.backends.lemke);
* small QPs solved by hand;
* no equilibrium: net uplift and a load outside the supports, where statics says no
  reactions R ≥ 0 can balance the load (plateqp.kkt.equilibrium_possible is the driver's
  check, turned off here so that the backend must find out by itself).

Each plate test runs both linear-algebra routes where they apply: ``method="condensed"``
(CHOLMOD, the rows' dofs ordered last) and ``method="sparse"`` (a factor of K + Bᵀ W_A B kept
current), with each CHOLMOD binding plateqp.linalg can use (scikit-sparse, cvxopt's wheels)
and with SuperLU.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp import linalg
from plateqp.backends import pdas as PD
from plateqp.backends.base import LCP, QP, Status
from plateqp.backends.pdas.reduced import ReducedQP
from plateqp.errors import NoEquilibriumError, ProblemError, SolverError
from plateqp.scenes.families import grid_rigid

PLATE = pq.Plate(a=1.0, b=1.0, h=0.02, E=1.0e7, nu=0.3)
ALL_SIMPLE = {k: "simple" for k in ("left", "right", "bottom", "top")}

#: (name, options, CHOLMOD binding used): the condensed method needs CHOLMOD and a definite K
#: (a floating plate goes to the sparse one); the sparse method refactorises with CHOLMOD's
#: analysis (scikit-sparse: also rank-k updates; cvxopt's wheels) or with plateqp.linalg.Factor.
ROUTES = [
    ("auto-sksparse", {}, "sksparse"),
    ("sparse-sksparse", {"method": "sparse"}, "sksparse"),
    ("auto-cvxopt", {}, "cvxopt"),
    ("sparse-cvxopt", {"method": "sparse"}, "cvxopt"),
    ("sparse-superlu", {"method": "sparse", "factor": "superlu"}, None),
]


@pytest.fixture(params=ROUTES, ids=lambda r: r[0])
def route(request, monkeypatch):
    _, options, binding = request.param
    have = {"sksparse": linalg.HAVE_CHOLMOD, "cvxopt": getattr(linalg, "HAVE_CVXOPT", False)}
    if binding is not None and not have[binding]:
        pytest.skip(f"CHOLMOD through {binding} is not installed")
    if binding == "cvxopt":  # scikit-sparse off: pdas takes the next binding plateqp.linalg found
        monkeypatch.setattr(linalg, "HAVE_CHOLMOD", False)
    return dict(options)


def solve(scene, options=None, **kw):
    return pq.solve(scene, backend="pdas", formulation="primal", accuracy="high", options=options, **kw)


def assert_kkt_ok(res):
    assert res.status is Status.OPTIMAL, (res.status, res.kkt.as_dict())
    assert res.kkt.ok and res.kkt.worst <= 1e-10, res.kkt.as_dict()


# ----------------------------------------------------------------------------- statics


def triangle(P, x, y, gaps=(0.0, 0.0, 0.0), n=8):
    """A free plate on one-sided supports at (0,0), (1,0), (0,1) and a point load P at (x, y)."""
    sups = [pq.Support(0.0, 0.0, gap=gaps[0]), pq.Support(1.0, 0.0, gap=gaps[1]),
            pq.Support(0.0, 1.0, gap=gaps[2])]
    return pq.Scene(name="triangle", plate=PLATE, mesh=pq.MeshSpec(n, n, "acm"), edges={},
                    loads=[pq.PointLoad(P, x, y)], supports=sups)


@pytest.mark.parametrize("x, y", [(0.4, 0.3), (0.1, 0.7), (0.25, 0.25)])
def test_floating_triangle_statics(route, x, y):
    # Vertical balance R1 + R2 + R3 = P; moments about the line x = 0 (through supports 1
    # and 3): R2·1 = P·x; about the line y = 0 (supports 1 and 2): R3·1 = P·y. Hence
    # R = P (1 − x − y, x, y), whatever the (small) settlements: the plate tilts rigidly.
    P = 100.0
    res = solve(triangle(P, x, y, gaps=(1e-4, 0.0, 2e-4)), route)
    np.testing.assert_allclose(res.reactions, P * np.array([1 - x - y, x, y]), rtol=1e-10, atol=1e-10 * P)
    assert res.active.all()
    assert_kkt_ok(res)


def test_floating_triangle_touching_supports(route):
    # g0 = 0 at all three: the same statics. (The KKT report's deflection scale is degenerate
    # here, since every support deflection is zero; the reactions are what is checked.)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = solve(triangle(60.0, 0.5, 0.2), route)
    np.testing.assert_allclose(res.reactions, 60.0 * np.array([0.3, 0.5, 0.2]), rtol=1e-10)
    assert res.kkt.natural <= 1e-12 and res.kkt.stationarity <= 1e-10


def bed_scene(n=16):
    """A free plate on a tensionless bed whose surface falls away towards (1, 1): about half
    of the plate lifts off under a uniform load and an off-centre point load."""
    return pq.Scene(name="bed", plate=PLATE, mesh=pq.MeshSpec(n, n, "acm"), edges={},
                    loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(2.0e4, gap={"profile": "linear", "g0": 0.0, "gx": 0.004, "gy": 0.002}))


def test_bed_carries_the_load(route):
    # A floating plate: the bed's reactions alone balance the load. Total: q·1·1 + P; moments
    # about x = 0 and y = 0: Σ R x_i = q·½ + P·0.6 and Σ R y_i = q·½ + P·0.55 (the bed's
    # springs sit at the nodes, so the moments are exact sums over nodes).
    res = solve(bed_scene(), route)
    assert_kkt_ok(res)
    R = res.reactions
    xy = res.model.contacts.xy
    total = 20.0 + 200.0
    assert R.sum() == pytest.approx(total, rel=1e-10)
    assert R @ xy[:, 0] == pytest.approx(20.0 * 0.5 + 200.0 * 0.6, rel=1e-10)
    assert R @ xy[:, 1] == pytest.approx(20.0 * 0.5 + 200.0 * 0.55, rel=1e-10)
    frac = res.active.mean()
    assert 0.2 < frac < 0.8  # partial contact: the test is not a two-sided bed in disguise
    assert np.all(R[~res.active] == 0.0) and np.all(R >= 0)


# ----------------------------------------------------------------------------- symmetry


def symmetric_scene(floating=False):
    """Supports on a 4 × 4 grid symmetric about x = ½, y = ½ and x = y; gaps depend on the
    distance from the centre only; uniform load and a central point load."""
    xs = [0.125, 0.375, 0.625, 0.875]
    sups = [pq.Support(x, y, gap=2e-4 * ((x - 0.5) ** 2 + (y - 0.5) ** 2) - 2e-5) for x in xs for y in xs]
    return pq.Scene(name="sym", plate=PLATE, mesh=pq.MeshSpec(16, 16, "acm"),
                    edges={} if floating else ALL_SIMPLE, supports=sups,
                    loads=[pq.UniformLoad(30.0), pq.PointLoad(150.0, 0.5, 0.5)])


@pytest.mark.parametrize("floating", [False, True], ids=["simple", "floating"])
def test_symmetric_reactions(route, floating):
    res = solve(symmetric_scene(floating), route)
    assert_kkt_ok(res)
    R = res.reactions.reshape(4, 4)  # R[i, j] at (xs[i], xs[j])
    scale = np.abs(R).max()
    assert scale > 0
    for image in (R[::-1, :], R[:, ::-1], R.T):
        np.testing.assert_allclose(R, image, rtol=0, atol=1e-10 * scale)
    assert 0 < res.active.sum() < 16


# ----------------------------------------------------------------------------- Lemke


def grid_scene(n_mesh=16, n_grid=5, elastic=True):
    """benchmarks/bench_contact.py's scene family (simply supported plate, grid of supports with
    heave in one corner and settlement in the other), every third support elastic."""
    a = 1.0
    xs = np.round(np.linspace(a / (n_grid + 1), a * n_grid / (n_grid + 1), n_grid) * n_mesh) / n_mesh
    sups = []
    for i, (x, y) in enumerate((x, y) for x in xs for y in xs):
        stiff = 3.0e4 * (1 + i % 4) if (elastic and i % 3 == 0) else "rigid"
        sups.append(pq.Support(float(x), float(y), gap=float(2e-4 * (x + y - a)), stiffness=stiff))
    return pq.Scene(name=f"grid{n_grid}", plate=PLATE, mesh=pq.MeshSpec(n_mesh, n_mesh, "acm"), edges=ALL_SIMPLE,
                    loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.7, 0.6)], supports=sups)


OFF_NODE = pq.Scene(name="off-node", plate=PLATE, mesh=pq.MeshSpec(12, 12, "acm"),
                    edges={"left": "simple", "right": "simple"},
                    loads=[pq.UniformLoad(10.0), pq.PointLoad(100.0, 0.55, 0.45)],
                    supports=[pq.Support(x, y, gap=-2e-4 * x, stiffness="rigid" if k % 2 else 5e4)
                              for k, (x, y) in enumerate((x, y) for x in np.linspace(0.13, 0.87, 5)
                                                         for y in np.linspace(0.11, 0.91, 5))])


@pytest.mark.parametrize("scene", [grid_scene(16, 5), grid_scene(24, 8), OFF_NODE], ids=["16-5", "24-8", "off-node"])
def test_agrees_with_lemke(route, scene):
    ref = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
    assert ref.status is Status.OPTIMAL
    res = solve(scene, route)
    assert_kkt_ok(res)
    scale = np.abs(ref.reactions).max()
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * scale)
    np.testing.assert_array_equal(res.active, ref.active)
    rigid = np.array([s.rigid for s in scene.supports])
    assert rigid.any() and (~rigid).any() and ref.active.any() and (~ref.active).any()  # a mixed scheme


def test_murty_safeguard_reaches_the_same_answer():
    # p = 0: no block exchange without progress, Murty's single exchanges take over at once
    scene = grid_scene(24, 8, elastic=False)
    ref = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
    res = solve(scene, {"p": 0, "trace": True})
    assert_kkt_ok(res)
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())
    assert any(s.get("exchange") == "single" for s in res.extras["trace"])


# ----------------------------------------------------------------------------- no equilibrium


NO_EQUILIBRIUM = {
    "net uplift": triangle(-100.0, 0.4, 0.3),
    "load outside the supports": triangle(100.0, 0.8, 0.8),
    "bed, net uplift": pq.Scene(name="bed-uplift", plate=PLATE, mesh=pq.MeshSpec(12, 12, "acm"), edges={},
                                loads=[pq.UniformLoad(-5.0), pq.PointLoad(2.0, 0.5, 0.5)],
                                foundation=pq.Foundation(2.0e4)),
}


@pytest.mark.parametrize("name", list(NO_EQUILIBRIUM))
def test_no_equilibrium_is_detected_by_the_backend(route, name):
    scene = NO_EQUILIBRIUM[name]
    # statics first (the driver's check): no reactions R ≥ 0 balance this load
    with pytest.raises(NoEquilibriumError, match="statics"):
        solve(scene, route)
    # the backend on its own: it must end UNBOUNDED (a certificate), never OPTIMAL
    with pytest.raises(NoEquilibriumError, match="unbounded"):
        solve(scene, route, check_statics=False)


def test_unbounded_certificate_on_the_qp():
    from plateqp.model.assembly import build_model
    from plateqp.contact import Primal, Scaled

    qp = Primal(Scaled.from_model(build_model(triangle(-100.0, 0.4, 0.3)))).qp
    raw = PD.solve(qp, "high")
    assert raw.status is Status.UNBOUNDED and raw.x is None
    d = raw.extras["ray"]  # P d = 0, G d ≤ 0, qᵀd < 0: the objective falls without bound along d
    scale = np.abs(d).max() * abs(qp.P).max()
    assert np.abs(qp.P @ d).max() <= 1e-8 * scale
    assert np.all(qp.G @ d <= 1e-12 * np.abs(qp.G @ d).max())
    assert qp.q @ d < 0


# ----------------------------------------------------------------------------- warm start, output


def test_warm_start_from_the_final_active_set():
    scene = grid_scene(24, 8)
    cold = solve(scene)
    act = cold.extras["active"]
    assert act.dtype == bool and act.shape == (len(scene.supports),)
    np.testing.assert_array_equal(act, cold.active)
    warm = solve(scene, {"active": act})
    assert_kkt_ok(warm)
    assert warm.iterations == 1 < cold.iterations
    np.testing.assert_allclose(warm.reactions, cold.reactions, rtol=0, atol=1e-12 * np.abs(cold.reactions).max())


def test_raw_solution_fields():
    from plateqp.model.assembly import build_model
    from plateqp.contact import Primal, Scaled

    qp = Primal(Scaled.from_model(build_model(grid_scene(12, 4)))).qp
    raw = PD.solve(qp, "high")
    assert raw.status is Status.OPTIMAL and raw.iterations >= 1 and raw.solve_time > 0
    assert raw.z.shape == (qp.G.shape[0],) and np.all(raw.z >= 0)
    # stationarity of the QP itself, t variables included: P x + q + Gᵀ z = 0
    r = qp.P @ raw.x + qp.q + qp.G.T @ raw.z
    assert np.abs(r).max() <= 1e-9 * np.abs(qp.q).max()
    assert np.all(qp.G @ raw.x - qp.h <= 1e-12 * np.abs(qp.h).max())
    assert raw.obj == pytest.approx(0.5 * raw.x @ (qp.P @ raw.x) + qp.q @ raw.x)


def test_iteration_limit_is_max_iter():
    from plateqp.model.assembly import build_model
    from plateqp.contact import Primal, Scaled

    qp = Primal(Scaled.from_model(build_model(grid_scene(24, 8)))).qp
    raw = PD.solve(qp, "high", options={"max_iter": 2})
    assert raw.status is Status.MAX_ITER and raw.iterations == 2
    assert raw.x is not None and raw.extras["active"].shape == (qp.G.shape[0],)  # the last iterate


# ----------------------------------------------------------------------------- small QPs by hand


def test_small_qp_by_hand():
    # min ½(x1² + x2²) − x1 − x2  s.t.  x1 + x2 ≤ 1: by symmetry x1 = x2 = ½, and
    # stationarity x − 1 + z = 0 gives z = ½.
    qp = QP(P=sp.identity(2, format="csc"), q=[-1.0, -1.0], G=sp.csr_matrix([[1.0, 1.0]]), h=[1.0])
    raw = PD.solve(qp, "high")
    np.testing.assert_allclose(raw.x, [0.5, 0.5], atol=1e-14)
    np.testing.assert_allclose(raw.z, [0.5], atol=1e-14)
    # h = 3: the constraint is slack, x = (1, 1), z = 0
    raw = PD.solve(QP(P=qp.P, q=qp.q, G=qp.G, h=[3.0]), "high")
    np.testing.assert_allclose(raw.x, [1.0, 1.0], atol=1e-14)
    assert raw.z[0] == 0.0


def test_separable_variable_is_a_spring():
    # min ½ u² − 2u + ½ t²  s.t.  u − t ≤ 0.5 (t: a spring of flexibility ρ = 1): active,
    # u − 2 + z = 0, t − z = 0, u − t = 0.5  ⇒  z = 0.75, u = 1.25, t = 0.75.
    qp = QP(P=sp.identity(2, format="csc"), q=[-2.0, 0.0], G=sp.csr_matrix([[1.0, -1.0]]), h=[0.5])
    raw = PD.solve(qp, "high")
    np.testing.assert_allclose(raw.x, [1.25, 0.75], atol=1e-14)
    np.testing.assert_allclose(raw.z, [0.75], atol=1e-14)


def test_separable_variable_with_stored_zeros_is_a_spring():
    # as above with u = (u0, u1) coupled, ½(2u0² − 2u0u1 + 2u1²) − 2u0 + ½t²  s.t.  u0 − t ≤ 0.5,
    # and P storing zeros between u0 and t (a formulation's pattern): t is still separable (a
    # spring). u1 = u0/2; active: 1.5 u0 − 2 + z = 0, t = z, u0 − t = 0.5 ⇒ z = 0.5, u0 = 1.
    P = sp.csc_matrix((np.array([2.0, -1.0, 0.0, -1.0, 2.0, 0.0, 1.0]),
                       np.array([0, 1, 2, 0, 1, 0, 2]), np.array([0, 3, 5, 7])), shape=(3, 3))
    assert P.nnz == 7  # the zeros stored
    qp = QP(P=P, q=[-2.0, 0.0, 0.0], G=sp.csr_matrix([[1.0, 0.0, -1.0]]), h=[0.5])
    assert ReducedQP(qp, 10).sep.tolist() == [2]
    raw = PD.solve(qp, "high")
    np.testing.assert_allclose(raw.x, [1.0, 0.5, 0.5], atol=1e-14)
    np.testing.assert_allclose(raw.z, [0.5], atol=1e-14)


# ----------------------------------------------------------------------------- refusals


def test_refuses_other_shapes():
    P = sp.identity(3, format="csc")
    G = sp.csr_matrix(np.ones((1, 3)))
    with pytest.raises(SolverError, match="QP"):
        PD.solve(LCP(np.eye(2), np.ones(2)))
    with pytest.raises(SolverError, match="primal"):
        PD.solve(QP(P=P, q=np.ones(3), lb=np.zeros(3)))
    with pytest.raises(SolverError, match="equality"):
        PD.solve(QP(P=P, q=np.ones(3), G=G, h=[1.0], A=G, b=[0.0]))
    with pytest.raises(SolverError, match="sparse"):
        PD.solve(QP(P=np.eye(3), q=np.ones(3), G=np.ones((1, 3)), h=[1.0]))
    with pytest.raises(SolverError, match="at most n constraint rows"):
        PD.solve(QP(P=P, q=np.ones(3), G=sp.csr_matrix(np.ones((4, 3))), h=np.ones(4)))
    with pytest.raises(SolverError, match=r"min\(n, 1\) \(option max_rows\)"):
        PD.solve(QP(P=P, q=np.ones(3), G=sp.csr_matrix(np.eye(3)[:2]), h=np.ones(2)), options={"max_rows": 1})
    with pytest.raises(ProblemError, match="max_rows"):
        PD.solve(QP(P=P, q=np.ones(3), G=G, h=[1.0]), options={"max_rows": 0})
    with pytest.raises(SolverError, match="no inequality|needs inequality"):
        PD.solve(QP(P=P, q=np.ones(3)))
    with pytest.raises(ProblemError, match="unknown option"):
        PD.solve(QP(P=P, q=np.ones(3), G=G, h=[1.0]), options={"rho": 1.0})
    with pytest.raises(ProblemError, match="active"):
        PD.solve(QP(P=P, q=np.ones(3), G=G, h=[1.0]), options={"active": [1, 0]})


def test_takes_the_primal_formulation_only():
    from plateqp.model.assembly import build_model
    from plateqp.contact import formulations_for
    from plateqp.contact import Condensed, Scaled

    assert formulations_for("pdas") == ["primal"]
    scene = grid_scene(8, 3)
    for form in ("condensed", "dual"):
        with pytest.raises(ProblemError, match="does not take"):
            pq.solve(scene, backend="pdas", formulation=form)
    # handed the condensed form's QP (bounds) directly, the backend says what it takes
    qp = Condensed(Scaled.from_model(build_model(scene))).qp
    with pytest.raises(SolverError, match="formulation='primal'"):
        PD.solve(qp)


@pytest.mark.skipif(not (linalg.HAVE_CHOLMOD or getattr(linalg, "HAVE_CVXOPT", False)),
                    reason="the condensed method needs CHOLMOD")
def test_condensed_method_refuses_a_floating_plate():
    with pytest.raises(SolverError, match="K is singular"):
        solve(triangle(100.0, 0.4, 0.3), {"method": "condensed"})
    assert solve(triangle(100.0, 0.4, 0.3, gaps=(1e-4, 0, 0))).extras["method"] == "sparse"  # auto falls back


def test_max_dense_auto_grows_with_the_mesh():
    """max_dense="auto" (the default): 2000 on small meshes, 16·√n between, 4000 at most; an
    integer is taken as given, anything else refused; the answer's extras say which applied."""
    from plateqp.backends.pdas.driver import auto_max_dense

    assert auto_max_dense(12_159) == 2000  # 64²
    assert auto_max_dense(48_895) == int(16 * np.sqrt(48_895)) == 3537  # 128²
    assert auto_max_dense(196_095) == 4000  # 256²
    sc = grid_rigid(12, 3)
    assert solve(sc).extras["max_dense"] == 2000
    assert solve(sc, {"max_dense": 5}).extras["max_dense"] == 5
    with pytest.raises(ProblemError, match="max_dense"):
        solve(sc, {"max_dense": "big"})


def test_max_dense_auto_on_soft_rows_is_8_root_n():
    """Every row soft (springs no stiffer than the plate under them): 8·√n, no floor, so a slab
    on a bed (961 rows at 32²) takes the sparse method's Newton phase, and 15 × 15 piles the
    condensed method; either way the answer is the other method's."""
    from plateqp.scenes import families as F
    from plateqp.backends.pdas.driver import auto_max_dense

    assert auto_max_dense(3007, soft=True) == int(8 * np.sqrt(3007)) == 438
    assert auto_max_dense(10**7, soft=True) == 4000
    bed = F.bed(32)
    bed.edges, bed.loads = dict(F.WALLS), F._loads()
    bed.validate()
    piles = F.grid_elastic(32, 15)
    for sc, method, other in ((bed, "sparse", "condensed"), (piles, "condensed", "sparse")):
        res = solve(sc)
        assert res.status == pq.Status.OPTIMAL and res.extras["method"] == method
        assert res.extras["max_dense"] == int(8 * np.sqrt(res.model.n_free))
        ref = solve(sc, {"method": other, "max_dense": 4000})
        assert np.abs(res.reactions - ref.reactions).max() <= 1e-9 * np.abs(ref.reactions).max()


def test_registered():
    b = pq.get_backend("pdas")
    assert b.accepts == frozenset({"qp"}) and b.available()
    assert "pdas" in pq.available_backends()


def test_the_primal_spring_block_and_its_leading_view_keep_k_as_stored():
    """P = block_diag(K, I) joined column by column keeps K's stored zeros (the ordering reads
    them), and pdas reads K back as a view of P's leading columns; any other kept set is
    sliced as before (against SciPy's block_diag and fancy indexing)."""
    from plateqp.backends.pdas.reduced import _leading_block
    from plateqp.contact.formulations import _with_identity

    rng = np.random.default_rng(5)
    A = sp.random(40, 40, density=0.15, format="csc", random_state=rng)
    K = sp.csc_matrix(A + A.T + 40 * sp.identity(40))
    K.data[::7] = 0.0  # stored zeros
    P = _with_identity(K, 6)
    assert P.nnz == K.nnz + 6  # no entry dropped
    assert abs(P - sp.block_diag([K, sp.identity(6)], format="csc")).max() == 0
    lead = _leading_block(P, np.arange(40))
    assert np.shares_memory(lead.data, P.data) and lead.nnz == K.nnz
    assert abs(lead - K).max() == 0
    keep = np.r_[0:10, 12:40, 41]  # not the leading columns: sliced
    ref = P.toarray()[np.ix_(keep, keep)]
    np.testing.assert_array_equal(_leading_block(P, keep).toarray(), ref)
    C = sp.csc_matrix(P + sp.csc_matrix(([1.0, 1.0], ([41, 3], [3, 41])), shape=P.shape))  # couples col 3 to 41
    np.testing.assert_array_equal(_leading_block(C, np.arange(40)).toarray(), C.toarray()[:40, :40])


def test_primal_with_springs_keeps_one_copy_of_k():
    """With elastic supports the primal P is block_diag(K, I): the formulation's K is then read
    back as a view of P's leading block (one copy of K alive, not two: 16 MB at 128² on the
    bed), equal entry for entry to the scaled K it was built from."""
    from plateqp.model.assembly import build_model
    from plateqp.contact.formulations import formulate
    from plateqp.contact.scaling import Scaled
    from plateqp.scenes.families import bed

    data = Scaled.from_model(build_model(bed(8)))
    K0 = data.K.copy()
    form = formulate(data, "primal")
    P = form.qp.P
    assert P.shape[0] > K0.shape[0]  # the spring block is there
    assert np.shares_memory(data.K.data, P.data) and np.shares_memory(data.K.indices, P.indices)
    assert data.K.nnz == K0.nnz and abs(data.K - K0).max() == 0
    np.testing.assert_array_equal(data.K.indices, K0.indices)  # stored pattern and order kept


def test_refinement_stops_at_rounding_and_not_before():
    """The stop test of the exact steps (Oettli–Prager's backward error): a step solved by
    SciPy's sparse LU (and refined) passes it; the same step moved by 1e-11 relative does not. And |K||u| by
    blocks of rows is SciPy's abs(K) @ |u|, from K's CSC arrays or its CSR ones."""
    import scipy.sparse.linalg as spla

    from plateqp.model.assembly import build_model
    from plateqp.backends.pdas.reduced import ReducedQP, at_rounding
    from plateqp.contact.formulations import formulate
    from plateqp.contact.scaling import Scaled
    from plateqp.scenes.families import grid_rigid
    from plateqp.linalg.pattern import abs_matvec

    data = Scaled.from_model(build_model(grid_rigid(12, 3)))
    pb = ReducedQP(formulate(data, "primal").problem(frozenset({"qp"})), max_rows=10**6)
    x = np.abs(np.random.default_rng(2).standard_normal(pb.K.shape[0]))
    ref = abs(pb.K) @ x
    X = np.abs(np.random.default_rng(3).standard_normal((pb.K.shape[0], 3)))  # several columns at once
    for chunk in (7, 1000, 1 << 20):
        np.testing.assert_allclose(abs_matvec(pb.K, x, chunk), ref, rtol=1e-14)
        np.testing.assert_allclose(abs_matvec(pb.K.tocsr(), x, chunk), ref, rtol=1e-14)
        np.testing.assert_allclose(abs_matvec(pb.K, X, chunk), abs(pb.K) @ X, rtol=1e-14)
    idx = np.arange(pb.m)  # every post held at its gap: the saddle-point system, solved by LU
    BA = pb.B[idx]
    n = pb.K.shape[0]
    S = sp.bmat([[pb.K, BA.T], [BA, None]], format="csc")
    rhs = np.concatenate([pb.f, pb.g[idx]])
    lu = spla.splu(S)
    sol = lu.solve(rhs)
    for _ in range(3):  # LU's own refinement, to its backward error's floor
        sol += lu.solve(rhs - S @ sol)
    u, lam = sol[:n], sol[n:]

    def residuals(u, lam):
        return pb.f - pb.K @ u - BA.T @ lam, BA @ u - pb.g[idx] - pb.rho[idx] * lam

    assert at_rounding(pb, u, idx, BA, lam, *residuals(u, lam))
    u2 = u * (1 + 1e-11)
    assert not at_rounding(pb, u2, idx, BA, lam, *residuals(u2, lam))


@pytest.mark.skipif(not (linalg.HAVE_CHOLMOD or getattr(linalg, "HAVE_CVXOPT", False)),
                    reason="the condensed method needs CHOLMOD")
def test_a_plate_free_to_turn_about_its_one_held_edge_goes_to_the_sparse_method():
    """A 14² plate simply supported on one edge only (free to turn about it: K singular) on
    stiff tensionless springs. Its trailing block's smallest pivot is 1.3e-13, above the old
    pivot test (1e-13): the dense method took it, and with M from a singular K a row whose
    gap and reaction both end near zero was called infeasible both with and without it
    (Murty's exchange toggled it for 470 steps, MAX_ITER; found by a random search of beds
    against Lemke). The trailing block's smallest eigenvalue (about 1e-16) now sends it to the
    sparse method; the answer is Lemke's on the condensed LCP."""
    sc = pq.Scene(name="degenerate bed", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(14, 14, "acm"),
                  edges={"left": pq.Edge("simple")},
                  loads=[pq.UniformLoad(10.562219778473672), pq.PointLoad(238.64432399423725, 0.38191689757498704,
                                                                          0.47209873368839095)],
                  foundation=pq.Foundation(585552.1007047191, gap={"profile": "linear", "g0": -0.0007319166055056706,
                                                                   "gx": -0.0009688701355287073,
                                                                   "gy": -0.002965447593238504}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        with pytest.raises(SolverError, match="K is singular"):
            # (max_dense: its 210 soft rows are past "auto"'s 8·√n, which would refuse them first)
            pq.solve(sc, backend="pdas", accuracy=1e-10, options={"method": "condensed", "max_dense": 4000})
        res = pq.solve(sc, backend="pdas", accuracy=1e-10)
        ref = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
    assert res.extras["method"] == "sparse"
    assert res.status == Status.OPTIMAL and res.kkt.ok
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


def test_dense_method_classifies_a_repeated_set_on_the_exact_equations():
    """The dense method's safeguard, on a one-row LCP whose dense data disagree with the exact
    equations (as M from the trailing block can, to cond(K)·ε): the dense classification calls
    the row's gap negative without it and its reaction negative with it, so block and Murty
    exchanges alike would toggle it for ever (MAX_ITER; seen with the rule removed). Met a second
    time, the set is solved on the exact equations, where the row is inactive with a positive
    gap: OPTIMAL after three sets."""
    from types import SimpleNamespace

    from plateqp.backends.pdas.dense import run_dense

    pb = SimpleNamespace(rho=np.zeros(1), k=np.ones(1), c=np.ones(1), g=np.ones(1), f=np.ones(1),
                         B=sp.csr_matrix(np.ones((1, 1))))

    class Cond:
        first: dict = {}

        def basic(self, A):  # the dense data: infeasible either way
            return (np.array([-1e-6]), np.zeros(1)) if A[0] else (np.zeros(1), np.array([-1e-6]))

        def exact(self, A, lam):  # the exact equations: u = 0.5, gap = g − u = 0.5 > 0
            return np.array([0.5]), np.where(A, -1e-6, 0.0)

    steps: list = []
    out = run_dense(pb, Cond(), np.zeros(1, dtype=bool), 1e-11, 50, 6, steps)
    assert out.status == Status.OPTIMAL and not out.A[0]
    assert [t["solve"] for t in steps] == ["dense", "dense", "exact"]


def floating_bed(n, k):
    return pq.Scene(name="floating bed", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                    edges={}, loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(k, gap={"profile": "linear", "g0": 0.0, "gx": 1e-4, "gy": 0.5e-4}))


@pytest.mark.skipif(not (linalg.HAVE_CHOLMOD or getattr(linalg, "HAVE_CVXOPT", False)),
                    reason="the condensed method needs CHOLMOD")
@pytest.mark.parametrize("k", [2e4, 1e9])
def test_a_floating_bed_goes_to_the_sparse_method(k):
    """A floating 24² plate on a tensionless bed: K is singular (rigid motions), but the
    trailing block's smallest pivot (1e-13) passed the old pivot test, so the dense method
    took it, with M from a singular K. On soft springs the answer still passed; on springs of
    1e9 the block steps ran to MAX_ITER (1300 sets, 10 s). The smallest-eigenvalue estimate
    (3e-16) now sends it to the sparse method; the reactions are Lemke's."""
    sc = floating_bed(24, k)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        res = pq.solve(sc, backend="pdas", accuracy=1e-10)
        ref = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
    assert res.extras["method"] == "sparse"
    assert res.status == Status.OPTIMAL and res.kkt.ok, (res.status, res.kkt.as_dict())
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * np.abs(ref.reactions).max())


def random_lcp(seed, m):
    """An LCP ``gap = d + Mλ`` (M symmetric positive definite) with a known strictly
    complementary solution ``λ*``: ``d = gap* − Mλ*``."""
    rng = np.random.default_rng(seed)
    Z = rng.standard_normal((m, m)) / np.sqrt(m) + np.eye(m)
    M = Z.T @ Z + np.diag(rng.uniform(0, 1, m) * (rng.random(m) < 0.5))
    support = rng.random(m) < 0.2
    lam = np.where(support, rng.uniform(0.5, 2.0, m), 0.0)
    gap = np.where(support, 0.0, rng.uniform(0.1, 1.0, m))
    return M, gap - M @ lam, lam, support


@pytest.mark.parametrize("seed", range(6))
def test_lawson_hanson_first_set_is_the_solution_of_a_random_lcp(seed):
    """first_set finds the support of the known solution, and SciPy's NNLS (M = RᵀR: the LCP
    is the KKT system of min ‖Rλ + R⁻ᵀd‖, λ ≥ 0) finds the same reactions."""
    from scipy.optimize import nnls

    from plateqp.backends.pdas.dense import first_set

    m = 30 + 20 * seed
    M, d, lam, support = random_lcp(seed, m)
    c = np.random.default_rng(seed).uniform(0.5, 2.0, m)  # row weights choose the order, not the answer
    A, steps = first_set(M, d, c, 1e-12, 0.0, np.inf)
    assert A is not None and steps >= support.sum()
    np.testing.assert_array_equal(A, support)
    R = np.linalg.cholesky(M).T
    ref = nnls(R, -np.linalg.solve(R.T, d))[0]
    np.testing.assert_allclose(ref, lam, atol=1e-9)


def test_lawson_hanson_first_set_gives_up_over_budget_and_survives_dependent_rows():
    from plateqp.backends.pdas.dense import first_set

    M, d, _, support = random_lcp(7, 60)
    A, steps = first_set(M, d, np.ones(60), 1e-12, 0.0, 1e5)  # two rows' work at most
    assert A is None and steps <= 2
    # two supports at one point: a repeated row and column (M singular), both pressed
    Md = np.block([[M, M[:, :1]], [M[:1, :], M[:1, :1]]])
    dd = np.append(d, d[0])
    A, steps = first_set(Md, dd, np.ones(61), 1e-12, 0.0, np.inf)
    if A is not None:  # either twin may carry; the rest is the solution's support
        assert A[1:60].tolist() == support[1:].tolist() and A[0] + A[60] == support[0]


@pytest.mark.skipif(not (linalg.HAVE_CHOLMOD or getattr(linalg, "HAVE_CVXOPT", False)),
                    reason="the condensed method needs CHOLMOD")
def test_post_grid_starts_from_the_lawson_hanson_set():
    """25 × 25 rigid posts on a 36² plate: the block steps from ``d < 0`` (620 rows) take
    several sets; Lawson–Hanson's set is the final one (one exact step confirms it), and the
    reactions are Lemke's. Seen failing with first_set returning its set one row short."""
    sc = grid_rigid(36, 25)
    res = pq.solve(sc, backend="pdas", formulation="primal", accuracy="high", options={"trace": True})
    ref = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
    assert res.extras["first_set"] == "lawson-hanson" and res.extras["first_set_steps"] >= res.extras["active"].sum()
    assert [t["solve"] for t in res.extras["trace"]] == ["exact"]
    assert res.iterations == res.extras["first_set_steps"] + 1
    assert_kkt_ok(res)
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-9 * np.abs(ref.reactions).max())


@pytest.mark.parametrize("seed", range(6))
def test_random_stiff_beds_are_solved_exactly(seed):
    """Random plates on tensionless beds as stiff as 1e5–1e7 (10²–15², held on one edge or
    floating; mixed heave and settlement): pdas never gives up and agrees with Lemke on the
    condensed LCP. Before the dense method classified repeated sets on the exact equations,
    3 of 40 such beds ended MAX_ITER."""
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(10, 16))
    sc = pq.Scene(name="bed", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(n, n, "acm"),
                  edges={} if seed % 2 else {"left": pq.Edge("simple")},
                  loads=[pq.UniformLoad(rng.uniform(1, 30)),
                         pq.PointLoad(rng.uniform(10, 300), rng.uniform(0.2, 0.8), rng.uniform(0.2, 0.8))],
                  foundation=pq.Foundation(10 ** rng.uniform(5, 7), gap={
                      "profile": "linear", "g0": rng.uniform(-1e-3, 1e-3), "gx": rng.uniform(-5e-3, 5e-3),
                      "gy": rng.uniform(-5e-3, 5e-3)}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pq.PlateQPWarning)
        try:
            ref = pq.solve(sc, backend="lemke", formulation="condensed", accuracy="high")
        except NoEquilibriumError:  # a floating plate lifted off: pdas must say so too
            with pytest.raises(NoEquilibriumError):
                pq.solve(sc, backend="pdas", accuracy=1e-10)
            return
        res = pq.solve(sc, backend="pdas", accuracy=1e-10)
    assert ref.status == Status.OPTIMAL
    assert res.status == Status.OPTIMAL and res.kkt.ok
    np.testing.assert_allclose(res.reactions, ref.reactions, rtol=0, atol=1e-8 * np.abs(ref.reactions).max())


def test_more_rows_than_the_old_cap_of_100000():
    """pdas took at most 100 000 rows, and ``backend="auto"`` (pdas on the primal) then refused
    every bed finer than 316 × 316 cells. A chain (1-D Laplacian, a small diagonal) under a
    random downward load, with an obstacle under every other node at a random gap: 100 001 rows
    on 200 003 unknowns. Checked by the KKT conditions written out here: stationarity
    P x + q + Gᵀz = 0, G x ≤ h, z ≥ 0, z·(h − G x) = 0."""
    n, m = 200_003, 100_001
    off = np.full(n - 1, -1.0)
    P = sp.diags([off, np.full(n, 2.0 + 1e-3), off], [-1, 0, 1], format="csc")
    rng = np.random.default_rng(0)
    q = -rng.uniform(0.0, 1.0, n)
    G = sp.csr_matrix((np.ones(m), (np.arange(m), np.arange(0, 2 * m, 2))), shape=(m, n))
    h = rng.uniform(0.0, 50.0, m)
    sol = PD.solve(QP(P=P, q=q, G=G, h=h), accuracy="high")
    assert sol.status == Status.OPTIMAL
    x, z = sol.x, sol.z
    assert np.abs(P @ x + q + G.T @ z).max() <= 1e-12 * np.abs(q).max()
    gap = h - G @ x
    assert gap.min() >= -1e-12 * np.abs(h).max() and z.min() >= 0.0
    assert np.abs(z * gap).max() <= 1e-12 * np.abs(h).max() * np.abs(z).max()
    assert 0 < np.count_nonzero(z) < m  # a real contact problem: some obstacles touched, not all
