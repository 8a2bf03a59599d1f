"""QP backends (osqp, clarabel, cvxpy:*, qpsolvers:*) on small QPs with known answers.

Every backend the four modules register is run on every reference problem; backends not
installed here are skipped. Each reference problem's solution is derived by hand in its
docstring. Signs follow base.py: ``P x + q + Gᵀz + Aᵀy + z_box = 0``, ``z ≥ 0``,
``z_box < 0`` on an active lower bound, ``> 0`` on an active upper bound.
"""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.backends.base import LCP, QP, Status
from plateqp.errors import ProblemError, SolverError

# ---------------------------------------------------------------------------------------
# Tolerances, in one table: (atol on x, atol on multipliers) at accuracy "high".
# Backends not listed use DEFAULT_TOL. Looser rows, and why:
DEFAULT_TOL = (1e-6, 1e-6)
TOL: dict[str, tuple[float, float]] = {
    # ECOS and CVXOPT see the QP as a second-order cone program (cvxpy's quad_form →
    # SOC epigraph; qpsolvers' ECOS wrapper via a Cholesky factor of P). Measured at our
    # "high" presets: x off by up to 5e-6, multipliers by up to 3e-6 (tighter tolerances
    # make ECOS report optimal_inaccurate and CVXOPT fail).
    "cvxpy:ECOS": (1e-5, 5e-5),
    "cvxpy:CVXOPT": (1e-5, 5e-5),
    "qpsolvers:ecos": (1e-5, 5e-5),
    # SCS is first-order (ADMM on the conic form): looser on both.
    "cvxpy:SCS": (1e-5, 1e-4),
    "qpsolvers:scs": (1e-5, 1e-4),
}
# Loose check that every preset (including "low") lands near the answer.
PRESET_ATOL = 1e-3

# Known deviations, declared as data: status on the infeasible QP when it is not
# INFEASIBLE / ERROR. PIQP does not detect infeasibility on it and runs to max_iter.
KNOWN_INFEASIBLE_STATUS: dict[str, Status] = {
    "cvxpy:PIQP": Status.MAX_ITER,
    "qpsolvers:piqp": Status.MAX_ITER,
}

#: Known deviations at "high", as data: (backend, reference problem) whose solver's own tolerance
#: there is at the edge of what it reaches, so whether it converges depends on the BLAS's rounding.
#: It may end ERROR (xfail, said so), never a wrong OPTIMAL (an OPTIMAL answer is checked as any
#: other). Measured: CVXOPT through cvxpy's cone form at abstol 1e-9 ends "solver_error" on
#: lcp_symmetric_pd with OpenBLAS's SandyBridge kernels, OPTIMAL with Haswell's.
MAY_FAIL_HIGH = {("cvxpy:CVXOPT", "lcp_symmetric_pd")}

MODULES = ("osqp_", "clarabel_", "cvxpy_", "qpsolvers_")


def collect_backends() -> dict:
    """Every backend the four QP-backend modules register, installed or not."""
    out = {}
    for mod_name in MODULES:
        mod = importlib.import_module(f"plateqp.backends.{mod_name}")
        for b in mod.backends():
            out[b.name] = b
    return out


BACKENDS = collect_backends()


@pytest.fixture(params=sorted(BACKENDS))
def backend(request):
    b = BACKENDS[request.param]
    if not b.available():
        pytest.skip(f"{b.name} not installed")
    return b


def tol(name: str) -> tuple[float, float]:
    return TOL.get(name, DEFAULT_TOL)


# ---------------------------------------------------------------------------------------
# Reference problems: (problem, expected) with expected holding x, z, y, z_box (or x, w).


def projection_on_orthant():
    """min ½‖x − c‖² s.t. x ≥ 0 (lb = 0), c = (1, −2, 0.5, −0.25).

    P = I, q = −c. Stationarity x − c + z_box = 0 gives z_box = c − x. The minimiser
    is the projection x = max(c, 0) = (1, 0, 0.5, 0), so z_box = c − max(c, 0) =
    min(c, 0) = −max(−c, 0) = (0, −2, 0, −0.25): negative exactly where the lower
    bound is active, as the convention says.
    """
    c = np.array([1.0, -2.0, 0.5, -0.25])
    qp = QP(P=np.eye(4), q=-c, lb=np.zeros(4))
    return qp, {"x": np.maximum(c, 0), "z_box": np.minimum(c, 0)}


def one_active_inequality():
    """min x0² + ½x1² − 2x0 − x1 s.t. x0 + x1 ≤ 1 (active), −x0 ≤ 10 (inactive).

    P = diag(2, 1), q = (−2, −1); the free minimiser (1, 1) violates x0 + x1 ≤ 1.
    With the first row active: 2x0 − 2 + z1 = 0, x1 − 1 + z1 = 0, x0 + x1 = 1, so
    x0 = 1 − z1/2, x1 = 1 − z1, 2 − 3z1/2 = 1 → z1 = 2/3 > 0, x = (2/3, 1/3).
    The second row has slack (−2/3 < 10): z2 = 0.
    """
    qp = QP(
        P=np.diag([2.0, 1.0]),
        q=np.array([-2.0, -1.0]),
        G=np.array([[1.0, 1.0], [-1.0, 0.0]]),
        h=np.array([1.0, 10.0]),
    )
    return qp, {"x": np.array([2 / 3, 1 / 3]), "z": np.array([2 / 3, 0.0])}


def equality_min_norm():
    """min ½‖x‖² s.t. x0 + x1 + x2 = 3, x0 − x1 = 1.

    The minimum-norm solution of A x = b: x = Aᵀλ with A Aᵀ λ = b. A Aᵀ = diag(3, 2),
    so λ = (1, 0.5) and x = (1, 1, 1) + 0.5 (1, −1, 0) = (1.5, 0.5, 1). Stationarity
    x + Aᵀy = 0 gives y = −λ = (−1, −0.5).
    """
    qp = QP(
        P=np.eye(3),
        q=np.zeros(3),
        A=np.array([[1.0, 1.0, 1.0], [1.0, -1.0, 0.0]]),
        b=np.array([3.0, 1.0]),
    )
    return qp, {"x": np.array([1.5, 0.5, 1.0]), "y": np.array([-1.0, -0.5])}


def equality_and_upper_bound():
    """min ½‖x‖² − x0 − x1 s.t. x0 + x1 = 1, x1 ≤ 0.2 (ub = (+∞, 0.2)).

    Without the bound x = (0.5, 0.5), which breaks x1 ≤ 0.2; so x1 = 0.2, x0 = 0.8.
    Stationarity: x0 − 1 + y = 0 → y = 0.2; x1 − 1 + y + z_box1 = 0 → z_box1 = 0.6 > 0
    (upper bound active: positive). The infinite bound on x0 gives z_box0 = 0.
    """
    qp = QP(
        P=np.eye(2),
        q=np.array([-1.0, -1.0]),
        A=np.array([[1.0, 1.0]]),
        b=np.array([1.0]),
        ub=np.array([np.inf, 0.2]),
    )
    return qp, {"x": np.array([0.8, 0.2]), "y": np.array([0.2]), "z_box": np.array([0.0, 0.6])}


def inequality_and_both_bounds():
    """min ½‖x‖² − x0 − x1 s.t. x0 + x1 ≤ 1, 0.6 ≤ x1 ≤ 0.7, x0 free (lb0 = −∞, ub0 = +∞).

    The free minimiser (1, 1) breaks x0 + x1 ≤ 1. Try that row active with x1 = 0.6
    (lower bound): x0 = 0.4; x0 − 1 + z = 0 → z = 0.6 ≥ 0; x1 − 1 + z + z_box1 = 0 →
    z_box1 = 1 − 0.6 − 0.6 = −0.2 < 0 (lower bound active: negative). All KKT
    conditions hold, and the QP is strictly convex, so x = (0.4, 0.6).
    """
    qp = QP(
        P=np.eye(2),
        q=np.array([-1.0, -1.0]),
        G=np.array([[1.0, 1.0]]),
        h=np.array([1.0]),
        lb=np.array([-np.inf, 0.6]),
        ub=np.array([np.inf, 0.7]),
    )
    return qp, {"x": np.array([0.4, 0.6]), "z": np.array([0.6]), "z_box": np.array([0.0, -0.2])}


def lcp_symmetric_pd():
    """LCP(M, q), M = tridiag(1, 4, 1) (3×3, symmetric PD), q = (−1, 2, −3).

    Guess z2 = 0, z1, z3 > 0: w1 = 4z1 − 1 = 0 → z1 = 1/4; w3 = 4z3 − 3 = 0 → z3 = 3/4;
    then w2 = z1 + z3 + 2 = 3 ≥ 0. So z = (0.25, 0, 0.75), w = (0, 3, 0); complementary.
    As the QP ½zᵀMz + qᵀz, z ≥ 0: M z + q + z_box = 0, so z_box = −w = (0, −3, 0).
    """
    M = np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 4.0]])
    lcp = LCP(M=M, q=np.array([-1.0, 2.0, -3.0]))
    return lcp, {
        "x": np.array([0.25, 0.0, 0.75]),
        "w": np.array([0.0, 3.0, 0.0]),
        "z_box": np.array([0.0, -3.0, 0.0]),
    }


def infeasible():
    """x ≥ 0 and x0 + x1 ≤ −1 cannot both hold: no feasible point."""
    return QP(P=np.eye(2), q=np.zeros(2), G=np.array([[1.0, 1.0]]), h=np.array([-1.0]), lb=np.zeros(2))


REFERENCE = {
    f.__name__: f
    for f in (
        projection_on_orthant,
        one_active_inequality,
        equality_min_norm,
        equality_and_upper_bound,
        inequality_and_both_bounds,
        lcp_symmetric_pd,
    )
}


def as_sparse(problem):
    """The same problem with scipy.sparse CSC matrices."""
    if isinstance(problem, LCP):
        return problem
    s = {k: (sp.csc_matrix(getattr(problem, k)) if getattr(problem, k) is not None else None) for k in "PGA"}
    return QP(
        P=s["P"], q=problem.q, G=s["G"], h=problem.h, A=s["A"], b=problem.b, lb=problem.lb, ub=problem.ub
    )


# ---------------------------------------------------------------------------------------
# KKT helpers: one property each.


def as_qp(problem) -> QP:
    return problem.as_qp() if isinstance(problem, LCP) else problem


def dense(M):
    return M.toarray() if sp.issparse(M) else np.asarray(M)


def assert_dual_domain(qp: QP, sol, atol):
    """z ≥ 0; z_box ≤ 0 where only a lower bound can be active, ≥ 0 where only an upper."""
    if qp.G is not None:
        assert sol.z is not None and sol.z.shape == (qp.G.shape[0],)
        assert np.all(sol.z >= -atol), f"z has a negative entry: {sol.z}"
    if qp.A is not None:
        assert sol.y is not None and sol.y.shape == (qp.A.shape[0],)
    if qp.lb is not None or qp.ub is not None:
        assert sol.z_box is not None and sol.z_box.shape == (qp.n,)
        lb = qp.lb if qp.lb is not None else np.full(qp.n, -np.inf)
        ub = qp.ub if qp.ub is not None else np.full(qp.n, np.inf)
        assert np.all(sol.z_box[~np.isfinite(ub)] <= atol), "z_box > 0 where no upper bound"
        assert np.all(sol.z_box[~np.isfinite(lb)] >= -atol), "z_box < 0 where no lower bound"


def assert_stationary(qp: QP, sol, atol):
    """P x + q + Gᵀz + Aᵀy + z_box = 0."""
    r = dense(qp.P) @ sol.x + qp.q
    if qp.G is not None:
        r += dense(qp.G).T @ sol.z
    if qp.A is not None:
        r += dense(qp.A).T @ sol.y
    if sol.z_box is not None:
        r += sol.z_box
    np.testing.assert_allclose(r, 0.0, atol=10 * atol, err_msg="stationarity")


def assert_matches(sol, expected, atol_x, atol_mult):
    np.testing.assert_allclose(sol.x, expected["x"], atol=atol_x, err_msg="x")
    for key in ("z", "y", "z_box", "w"):
        if key in expected:
            got = getattr(sol, key)
            assert got is not None, f"{key} missing"
            np.testing.assert_allclose(got, expected[key], atol=atol_mult, err_msg=key)
    if "z" in expected:  # active G rows carry z > 0
        assert np.all(sol.z[expected["z"] > 0] > 0), f"z = {sol.z}"
    if "z_box" in expected:  # the sign of z_box says which bound is active
        zb = expected["z_box"]
        assert np.all(sol.z_box[zb < 0] < 0), f"lower bound active needs z_box < 0: {sol.z_box}"
        assert np.all(sol.z_box[zb > 0] > 0), f"upper bound active needs z_box > 0: {sol.z_box}"


# ---------------------------------------------------------------------------------------
# Tests


# every reference problem with dense matrices, and again with sparse ones (an LCP is dense)
CASES = [
    (ref, fmt)
    for ref in sorted(REFERENCE)
    for fmt in ("dense", "sparse")
    if (ref, fmt) != ("lcp_symmetric_pd", "sparse")
]


@pytest.mark.parametrize("ref, fmt", CASES)
def test_reference_problem_high(backend, ref, fmt):
    problem, expected = REFERENCE[ref]()
    if fmt == "sparse":
        problem = as_sparse(problem)
    sol = backend.solve(problem, accuracy="high")
    atol_x, atol_mult = tol(backend.name)
    if sol.status is Status.ERROR and (backend.name, ref) in MAY_FAIL_HIGH:
        pytest.xfail(f"{backend.name} ended {sol.solver_status} on {ref} at 'high' (MAY_FAIL_HIGH)")
    assert sol.status is Status.OPTIMAL, (sol.status, sol.solver_status)
    assert sol.solve_time >= 0
    qp = as_qp(problem)
    assert_matches(sol, expected, atol_x, atol_mult)
    assert_dual_domain(qp, sol, atol_mult)
    assert_stationary(qp, sol, atol_mult)
    if isinstance(problem, LCP):
        np.testing.assert_allclose(sol.w, problem.M @ sol.x + problem.q, atol=1e-12)


@pytest.mark.parametrize("accuracy", ["low", "default", "high"])
def test_every_preset_solves(backend, accuracy):
    problem, expected = one_active_inequality()
    sol = backend.solve(problem, accuracy=accuracy)
    assert sol.status.solved, (sol.status, sol.solver_status)
    np.testing.assert_allclose(sol.x, expected["x"], atol=PRESET_ATOL)
    np.testing.assert_allclose(sol.z, expected["z"], atol=PRESET_ATOL)


def test_infeasible_is_never_optimal(backend):
    sol = backend.solve(infeasible(), accuracy="high")
    allowed = {Status.INFEASIBLE, Status.ERROR}
    if backend.name in KNOWN_INFEASIBLE_STATUS:
        allowed.add(KNOWN_INFEASIBLE_STATUS[backend.name])
    assert sol.status in allowed, (sol.status, sol.solver_status)
    assert not sol.status.solved
    if sol.status is Status.INFEASIBLE:
        assert sol.x is None  # no iterate or certificate passed off as a solution


def test_unknown_accuracy_is_rejected(backend):
    with pytest.raises(ProblemError):
        backend.solve(one_active_inequality()[0], accuracy="ultra")


def test_nonsymmetric_lcp_is_rejected(backend):
    lcp = LCP(M=np.array([[2.0, 1.0], [0.0, 2.0]]), q=np.array([-1.0, -1.0]))
    with pytest.raises(SolverError):
        backend.solve(lcp)


def test_backend_protocol():
    assert BACKENDS, "no backend registered"
    for name, b in BACKENDS.items():
        assert b.name == name
        assert b.accepts == frozenset({"qp", "lcp"})
        assert isinstance(b.available(), bool)
        if b.available():
            assert isinstance(b.version(), str)


# Options pass through untouched and override the preset (direct backends).


@pytest.mark.parametrize(
    "name, options",
    [
        ("osqp", {"max_iter": 1, "polishing": False}),
        ("clarabel", {"max_iter": 1}),
    ],
)
def test_options_override_preset(name, options):
    b = BACKENDS[name]
    if not b.available():
        pytest.skip(f"{name} not installed")
    sol = b.solve(one_active_inequality()[0], accuracy="high", options=options)
    assert sol.status is Status.MAX_ITER, sol.solver_status


@pytest.mark.parametrize("name", ["osqp", "clarabel"])
def test_a_bad_option_value_is_a_problem_error(name):
    """A setting the solver knows, with a value it refuses (the unknown names of every backend:
    tests/backends/test_backends.py)."""
    b = BACKENDS[name]
    if not b.available():
        pytest.skip(f"{name} not installed")
    bad = {"osqp": {"eps_abs": -1.0}, "clarabel": {"max_iter": "many"}}[name]
    with pytest.raises(ProblemError, match="option|settings"):
        b.solve(one_active_inequality()[0], options=bad)


#: Installed cvxpy solvers that take P through a factorisation of it (a cone program):
#: an indefinite P is refused while cvxpy compiles (ValueError before the fix, a traceback).
FACTORISE_P = ("cvxpy:ECOS", "cvxpy:CVXOPT")


@pytest.mark.parametrize("name", FACTORISE_P)
def test_indefinite_p_is_a_one_line_solver_error(name):
    """cvxpy's "quad_form … indefinite" ValueError (cvxpy:ECOS and cvxpy:CVXOPT on the
    condensed form) becomes a SolverError of one line that keeps the cause."""
    b = BACKENDS.get(name)
    if b is None or not b.available():
        pytest.skip(f"{name} not installed")
    lcp = LCP(M=np.array([[1.0, 1.0 + 1e-6], [1.0 + 1e-6, 1.0]]), q=np.array([-1.0, -1.0]))  # eigenvalue −1e-6
    with pytest.raises(SolverError, match="cannot pass this problem") as info:
        b.solve(lcp, accuracy="high")
    assert "\n" not in str(info.value) and isinstance(info.value.__cause__, ValueError)


def test_cvxpy_records_defaults_for_unmapped_solver(monkeypatch):
    from plateqp.backends import cvxpy_

    if "cvxpy:OSQP" not in BACKENDS or not BACKENDS["cvxpy:OSQP"].available():
        pytest.skip("cvxpy with OSQP not installed")
    monkeypatch.delitem(cvxpy_.ACCURACY, "OSQP")
    sol = cvxpy_.solve(one_active_inequality()[0], solver="OSQP")
    assert sol.status.solved and sol.extras["preset"] == "defaults"


def test_qpsolvers_records_defaults_for_unmapped_solver():
    b = BACKENDS.get("qpsolvers:quadprog")
    if b is None or not b.available():
        pytest.skip("quadprog not installed")
    sol = b.solve(one_active_inequality()[0])
    assert sol.extras["preset"] == "defaults"


def test_modules_import_without_their_solvers():
    """With every solver package hidden, the modules import, register unavailable backends,
    and solving raises SolverError."""
    code = """
import sys
for m in ("osqp", "clarabel", "cvxpy", "qpsolvers"):
    sys.modules[m] = None  # makes `import m` raise ImportError
import importlib, numpy as np
from plateqp.backends.base import QP
from plateqp.errors import ProblemError, SolverError
names = []
for mod in ("osqp_", "clarabel_", "cvxpy_", "qpsolvers_"):
    for b in importlib.import_module("plateqp.backends." + mod).backends():
        assert not b.available() and b.version() is None, b.name
        try:
            b.solve(QP(P=np.eye(1), q=np.ones(1)))
        except SolverError:
            names.append(b.name)
        else:
            raise AssertionError(b.name + " solved without its solver")
print(len(names))
"""
    root = Path(__file__).resolve().parents[2]
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=root)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout.strip()) >= 4
