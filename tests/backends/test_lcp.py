"""The in-house LCP solvers' shared seam (plateqp.backends.lcp) and the contract every one of
them keeps: Lemke's method, block principal pivoting (bpp) and projected Gauss–Seidel (pgs),
run through the registry on the same problems.

References (never the code's own earlier output): LCPs solved by hand; brute-force enumeration
of all 2ⁿ complementary splits; the bound-constrained QP solved by scipy's BVLS through a
Cholesky factor (tests/lcp_reference.py); problems built from a known solution; Farkas'
certificate and the natural residual checked from their definitions; on plates, statics.
Method-specific tests: tests/backends/test_lemke.py, test_bpp.py, test_pgs.py.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from lcp_reference import (INFEASIBLE_PSD, M2, assert_certificate, brute_force, bvls_reference, check_lcp,
                           from_solution, random_spd, rounding_zero_lcp)
import scipy.sparse as sp

import plateqp as pq
from plateqp.backends import get_backend, registry
from plateqp.backends import lcp as seam
from plateqp.backends.base import LCP, QP, Backend, Status
from plateqp.contact import formulations_for
from plateqp.errors import NoEquilibriumError, ProblemError, SolverError

IN_HOUSE = ("lemke", "bpp", "pgs")
EXACT = ("lemke", "bpp")

# ----------------------------------------------------------------------------- the table

# (backend, accuracy, options, relative tolerance on z against an exact reference)
SOLVERS = [
    pytest.param("lemke", "high", {}, 1e-12, id="lemke-high"),
    pytest.param("lemke", "low", {}, 1e-12, id="lemke-low"),  # a direct method: exact at every preset
    pytest.param("bpp", "high", {}, 1e-12, id="bpp-high"),
    pytest.param("bpp", "default", {}, 1e-12, id="bpp-default"),
    pytest.param("pgs", "high", {}, 1e-9, id="pgs-high"),
    pytest.param("pgs", "high", {"omega": 1.3}, 1e-9, id="psor-high"),
]


def solve(backend, M, q, accuracy="high", **options):
    return get_backend(backend).solve(LCP(M, q), accuracy=accuracy, options=options)


# ----------------------------------------------------------------------------- hand-solved


@pytest.mark.parametrize("backend, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize(
    "q, z_exact, w_exact",
    [
        ([-5.0, -6.0], [4 / 3, 7 / 3], [0.0, 0.0]),  # both free: 2z1+z2 = 5, z1+2z2 = 6
        ([-1.0, 2.0], [0.5, 0.0], [0.0, 2.5]),  # 2z1 = 1; w2 = 1/2 + 2
        ([1.0, -4.0], [0.0, 2.0], [3.0, 0.0]),  # 2z2 = 4; w1 = 2 + 1
        ([1.0, 0.0], [0.0, 0.0], [1.0, 0.0]),  # q ≥ 0: z = 0 (w2 = 0 too: degenerate)
    ],
)
def test_hand_solved_2x2(backend, accuracy, options, rtol, q, z_exact, w_exact):
    sol = solve(backend, M2, np.array(q), accuracy, **options)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_exact, rtol=0, atol=10 * rtol)
    np.testing.assert_allclose(sol.w, w_exact, rtol=0, atol=10 * rtol)


# ----------------------------------------------------------------------------- random SPD


@pytest.mark.parametrize("backend, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize("n, seed", [(5, 0), (12, 1), (40, 2), (90, 3), (300, 4)])
def test_random_spd_against_bvls(backend, accuracy, options, rtol, n, seed):
    rng = np.random.default_rng(seed)
    M = random_spd(n, rng)
    q = rng.standard_normal(n)
    sol = solve(backend, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w, rtol=1e-8)
    z_ref = bvls_reference(M, q)
    np.testing.assert_allclose(sol.x, z_ref, rtol=0, atol=rtol * max(1.0, np.abs(z_ref).max()))
    assert sol.obj == pytest.approx(0.5 * z_ref @ M @ z_ref + q @ z_ref, rel=1e-9)


@pytest.mark.parametrize("backend, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize("seed", range(6))
def test_random_spd_against_brute_force(backend, accuracy, options, rtol, seed):
    rng = np.random.default_rng(100 + seed)
    n = 5 + seed  # 5 … 10
    M = random_spd(n, rng)
    q = rng.standard_normal(n) - 0.3
    (z_ref,) = brute_force(M, q)  # P-matrix: exactly one solution
    sol = solve(backend, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_ref, rtol=0, atol=rtol * max(1.0, np.abs(z_ref).max()))


# ----------------------------------------------------------------------------- degenerate


@pytest.mark.parametrize("backend, accuracy, options, rtol", SOLVERS)
@pytest.mark.parametrize("seed", range(3))
def test_degenerate_integer_data_with_ties(backend, accuracy, options, rtol, seed):
    """SPD M with integer entries, q ∈ {0, −1}: zeros in q and ties everywhere."""
    rng = np.random.default_rng(300 + seed)
    n = 30
    B = rng.integers(-1, 2, (n, n)).astype(float)
    M = B @ B.T + np.eye(n)
    q = -rng.integers(0, 2, n).astype(float)
    sol = solve(backend, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    check_lcp(M, q, sol.x, sol.w, rtol=1e-8)
    np.testing.assert_allclose(sol.x, bvls_reference(M, q), atol=max(rtol, 1e-12) * 10)


@pytest.mark.parametrize("backend, accuracy, options, rtol", SOLVERS)
def test_degenerate_known_solution(backend, accuracy, options, rtol):
    """z*_i = w*_i = 0 on a fifth of the indices: both splits of those are solutions."""
    rng = np.random.default_rng(12)
    M = random_spd(60, rng)
    q, z_star, w_star = from_solution(M, rng, degenerate=0.2)
    sol = solve(backend, M, q, accuracy, **options)
    assert sol.status is Status.OPTIMAL
    np.testing.assert_allclose(sol.x, z_star, rtol=0, atol=rtol * 10)
    np.testing.assert_allclose(sol.w, w_star, rtol=0, atol=rtol * 10 * np.abs(M).max())


@pytest.mark.parametrize("backend", IN_HOUSE)
def test_zero_matrix_and_a_rounding_negative_q_is_solved(backend):
    """M zero up to rounding, q ≥ 0 up to rounding (lcp_reference.rounding_zero_lcp): z = 0.
    Before the fix Lemke's method claimed that no solution exists and BPP said M is not PSD."""
    M, q = rounding_zero_lcp()
    sol = solve(backend, M, q, "high")
    assert sol.status is Status.OPTIMAL
    np.testing.assert_array_equal(sol.x, np.zeros(3))


# ----------------------------------------------------------------------------- no solution


@pytest.mark.parametrize("backend", EXACT)
@pytest.mark.parametrize("M, q", INFEASIBLE_PSD)
def test_no_solution_is_infeasible_with_a_certificate(backend, M, q):
    sol = solve(backend, M, q, "default")
    assert sol.status is Status.INFEASIBLE and sol.x is None and sol.w is None
    assert "no solution" in sol.solver_status and "plate" not in sol.solver_status
    assert_certificate(M, q, sol.extras["certificate"])


@pytest.mark.parametrize("M, q", INFEASIBLE_PSD)
def test_no_solution_pgs_never_optimal(M, q):
    for acc in ("low", "default", "high"):
        sol = solve("pgs", M, q, acc, max_iter=3000)
        assert sol.status is Status.MAX_ITER and not sol.status.solved


# ----------------------------------------------------------------------------- interface


@pytest.mark.parametrize("backend", IN_HOUSE)
def test_backend_shape_and_capabilities(backend):
    b = get_backend(backend)
    assert isinstance(b, seam.LCPBackend) and isinstance(b, Backend) and registry()[backend] is b
    assert b.accepts == frozenset({"lcp"}) and b.available() is True and b.formulations is None
    assert "plateqp" in b.version()
    assert formulations_for(b) == ["condensed", "dual"]
    assert b.exact == (backend in EXACT) and b.warm_start == (backend == "bpp")
    module = __import__(f"plateqp.backends.{backend}", fromlist=["ACCURACY"])
    assert set(module.ACCURACY) == {"low", "default", "high"} and module.backends() == [b]
    sol = b.solve(LCP(sp.csr_matrix(M2), np.array([-1.0, 2.0])), accuracy="high")
    np.testing.assert_allclose(sol.x, [0.5, 0.0], atol=1e-10)
    assert sol.solve_time > 0 and (sol.iterations >= 1 or backend == "lemke")


@pytest.mark.parametrize("backend, bad", [
    ("lemke", {"tolerance": 1e-3}), ("lemke", {"max_iter": 0}), ("lemke", {"trace": 1}),
    ("lemke", {"pivot_tol": 1.0}), ("lemke", {"refactor_every": -1}), ("lemke", {"covering": [1.0]}),
    ("bpp", {"tolerance": 1e-3}), ("bpp", {"max_iter": 0}), ("bpp", {"p": -1}), ("bpp", {"active": [1, 0]}),
    ("bpp", {"active": np.array([True])}), ("bpp", {"feas_tol": -1.0}), ("bpp", {"trace": "yes"}),
    ("bpp", {"sing_tol": True}),
    ("pgs", {"tolerance": 1e-3}), ("pgs", {"omega": 2.0}), ("pgs", {"omega": 0.0}), ("pgs", {"max_iter": 0}),
    ("pgs", {"time_limit": 0}), ("pgs", {"z0": [1.0]}), ("pgs", {"tol": 2.0}),
])
def test_bad_options(backend, bad):
    with pytest.raises(ProblemError):
        get_backend(backend).solve(LCP(M2, np.array([-1.0, -1.0])), options=bad)


@pytest.mark.parametrize("backend", IN_HOUSE)
def test_unknown_option_names_the_known_ones(backend):
    b = get_backend(backend)
    with pytest.raises(ProblemError, match=r"unknown option\(s\) \['tolerance'\].*known: .*max_iter"):
        b.solve(LCP(M2, np.array([-1.0, -1.0])), options={"tolerance": 1e-3})


@pytest.mark.parametrize("backend", IN_HOUSE)
def test_rejects_qp_and_unknown_accuracy(backend):
    b = get_backend(backend)
    with pytest.raises(ProblemError, match="LCPs only"):
        b.solve(QP(P=M2, q=np.array([-1.0, -1.0]), lb=np.zeros(2)))
    with pytest.raises(ProblemError, match="accuracy"):
        b.solve(LCP(M2, np.array([-1.0, -1.0])), accuracy="extreme", options={"tolerance": 1})


# ----------------------------------------------------------------------------- the seam itself


def test_settings_scale_only_the_named_tolerances():
    table = {"low": {"a_tol": 1e-4, "b_tol": 1e-4, "n": 3}, "default": {"a_tol": 1e-6, "b_tol": 1e-6, "n": 5},
             "high": {"a_tol": 1e-9, "b_tol": 1e-9, "n": 7}}
    assert seam.settings(table, "high", ("a_tol",)) == {"a_tol": 1e-9, "b_tol": 1e-9, "n": 7}
    got = seam.settings(table, 1e-7, ("a_tol",))  # nearest preset "default", ratio 0.1
    assert got == {"a_tol": pytest.approx(1e-7), "b_tol": 1e-6, "n": 5}
    assert seam.settings(table, "low", ("a_tol",), b_tol=0.5, n=None) == {"a_tol": 1e-4, "b_tol": 0.5, "n": 3}
    for bad in (1.0, -1e-3, float("nan"), True, "x"):
        with pytest.raises(ProblemError, match="b_tol must be a number in"):
            seam.settings(table, "low", ("a_tol",), b_tol=bad)
    with pytest.raises(ProblemError):
        seam.settings(table, "ultra", ("a_tol",))


def test_option_value_checks():
    assert seam.check_int("k", 3, 1) == 3 and seam.check_flag("t", np.True_) is True
    for bad in (0, 2.0, True, "3"):
        with pytest.raises(ProblemError, match="k must be an integer ≥ 1"):
            seam.check_int("k", bad, 1)
    with pytest.raises(ProblemError, match="t must be True or False"):
        seam.check_flag("t", 1)


def test_natural_residual_from_its_definition():
    M = np.array([[4.0, 1.0], [1.0, 2.0]])
    q = np.array([-1.0, 3.0])
    z = np.array([0.5, 0.1])  # w = (1.1, 3.7): both complementarity pairs violated
    w = M @ z + q
    expected = max(abs(min(4 * 0.5, 1.1)), abs(min(2 * 0.1, 3.7))) / max(3.7, 3.0)
    assert seam.natural_residual(M, q, z, w) == pytest.approx(expected, rel=1e-15)
    z = np.array([0.25, 0.0])  # the solution: w = (0, 3.25)
    assert seam.natural_residual(M, q, z, M @ z + q) == 0.0


def test_is_certificate_checks_every_condition():
    M, q = INFEASIBLE_PSD[0]
    tol = seam.certificate_tol(2)
    assert seam.is_certificate(M, q, np.array([1.0, 1.0]), tol)  # Mᵀy = 0, qᵀy = −2
    assert not seam.is_certificate(M, q, np.array([1.0, 0.0]), tol)  # Mᵀy = (1, −1) has a positive entry
    assert not seam.is_certificate(M, -q, np.array([1.0, 1.0]), tol)  # qᵀy = 2 > 0
    assert not seam.is_certificate(M, q, np.array([1.5, -0.5]), tol)  # y has a negative entry
    assert not seam.is_certificate(M, q, np.zeros(2), tol) and not seam.is_certificate(M, q, None, tol)


# ----------------------------------------------------------------------------- plates


def floating_scene(**kw):
    sups = [pq.Support(x, y) for x in (0, 0.5, 1) for y in (0, 0.5, 1)]
    return pq.Scene(plate=pq.Plate(1, 1, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8),
                    loads=[pq.PointLoad(10, 0.3, 0.6)], supports=sups, **kw)


@pytest.fixture(scope="module")
def lemke_floating():
    return pq.solve(floating_scene(), backend="lemke", formulation="condensed", accuracy="high")


@pytest.mark.parametrize("backend, accuracy, atol", [("bpp", "high", 1e-10), ("pgs", "default", 1e-6)])
def test_floating_plate_statics_and_lemke(backend, accuracy, atol, lemke_floating):
    sc = floating_scene()
    res = pq.solve(sc, backend=backend, formulation="condensed", accuracy=accuracy)
    assert res.status is Status.OPTIMAL and res.kkt.ok
    R = res.reactions
    x = np.array([s.x for s in sc.supports])
    y = np.array([s.y for s in sc.supports])
    P, xp, yp = 10.0, 0.3, 0.6
    assert R.min() >= -atol * P
    assert R.sum() == pytest.approx(P, rel=atol)  # vertical equilibrium
    assert (R * x).sum() == pytest.approx(P * xp, rel=atol)  # moments about the axes
    assert (R * y).sum() == pytest.approx(P * yp, rel=atol)
    np.testing.assert_allclose(R, lemke_floating.reactions, rtol=0, atol=atol * P)
    # the contact set, from the reactions (Result.active counts R > 1e-9 max R as contact,
    # finer than PGS's "default" tolerance)
    np.testing.assert_array_equal(R > atol * P, lemke_floating.reactions > atol * P)
    if backend == "bpp":
        np.testing.assert_array_equal(res.active, lemke_floating.active)


@pytest.mark.parametrize("backend", IN_HOUSE)
def test_plate_no_equilibrium_is_never_optimal(backend):
    """Every support far from a load at the plate's corner: the plate tips off. An exact solver
    proves it (NoEquilibriumError through the pipeline, its certificate in the message)."""
    sups = [pq.Support(x, y) for x in (0.6, 0.8) for y in (0.6, 0.8)]
    sc = pq.Scene(plate=pq.Plate(1, 1, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(6, 6),
                  loads=[pq.PointLoad(10, 0.1, 0.1)], supports=sups)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            res = pq.solve(sc, backend=backend, formulation="condensed", check_statics=False,
                           options={"time_limit": 0.3} if backend == "pgs" else None)
        except NoEquilibriumError as exn:
            assert backend in EXACT and "ended infeasible" in str(exn) and "certificate" in str(exn)
            return
        except (SolverError, pq.MechanismError):
            return
    assert backend not in EXACT, "an exact solver must prove that there is no equilibrium"
    assert not res.status.solved
