r"""The contact problem in the contact forces, with the soil as an operator: a plate on an elastic
half-space held matrix-free (:func:`plateqp.model.soil.attach_operator`).

With the soil's settlements v = H_F R eliminated, every contact row i reads

.. math::

    \text{gap} = g_0 + C R - B u \ge 0,\qquad R \ge 0,\qquad R^T \text{gap} = 0,\qquad
    K u = f - B^T R ,

C the rows' compliance: an elastic post's 1/c on its own row, the half-space's H_F on the bed's
rows (:attr:`plateqp.contact.scaling.Scaled.compliance`). Eliminating u as well (u = K_p⁻¹(f −
BᵀR) + V α, V the rigid motions the two-sided supports leave free, α their amounts, K_p the
stiffness with one deflection pinned per rigid motion: exact for every balanced load) leaves
the convex QP of the source paper's condensed route, here in the forces:

.. math::

    \min_R\ \tfrac12 R^T (B K_p^{-1} B^T + C) R + (g_0 - B K_p^{-1} f)^T R
    \quad\text{s.t.}\quad R \ge 0,\quad (B V)^T R = V^T f ,

whose gradient is the gap and whose equality multipliers are α. Its matrix is never formed:
one product costs a solve with the plate's one factorisation and the soil's FFT. It is solved
by an active-set PCG (:mod:`plateqp.backends.active_pcg`; :func:`solve_pressures` says how it is
started and preconditioned), with MPRGP inside SMALBE (:mod:`plateqp.backends.mprgp`) from its
answer where it does not settle, and the answer is checked as every other is (:func:`plateqp.contact.kkt.kkt_report`: the plate's stationarity with K itself, the soil's
law with the operator, the gaps and complementarity row by row).

The bonded comparison (:func:`solve_bilateral`) is the same problem without the bound.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..accuracy import Accuracy, Status
from ..errors import NoEquilibriumError, PlateQPWarning, ProblemError
from ..linalg.factor import Factor
from ..model import soil
from ..results import Result
from .answer import to_result
from .formulations import ContactSolution
from .kkt import kkt_report
from .scaling import Scaled
from .statics import NO_EQUILIBRIUM, supports_reach

#: the backends that take a matrix-free soil
BACKENDS = ("auto", "mprgp")
#: the solver's stopping tolerance against the KKT check's: a tenth, over √m (the solvers stop
#: on 2-norms over every row relative to the problem's; the check reads the worst row)
TOL_SHARE = 0.1
#: tighter re-solves (from the answer in hand) while the check fails but the solver converged
RETRIES = 2
#: at least this many contact rows: start from the solve of the mesh with half the cells a side
#: (its contact forces interpolated: the set moves little under refinement)
START_MIN = 2000
#: the accuracy the start's coarser solve is asked (it is only a start)
START_TOL = 1e-4
#: the products the start's coarser solve may take (a start that does not come cheaply is not
#: worth having: the solve goes on cold)
START_PRODUCTS = 1000
#: a rigid post's spring in the preconditioner's sparse soil: this many times its stiffest
RIGID = 100.0
#: the preconditioner's coarse plate resolves this many times the wavenumber where the plate's
#: compliance falls below the soil's (:func:`coarse_cells`)
COARSE_WAVES = 8.0
#: the preconditioner's coarse plate has at least this many cells a side
COARSE_MIN = 8


class PressureProblem:
    """The QP of the module's text for scaled contact data with a compliance operator: its
    product, linear term, equalities, and the plate's fields of an answer."""

    def __init__(self, data: Scaled) -> None:
        self.data = data
        n, V = data.n, data.modes
        self.pins = _pins(data)
        keep = np.ones(n, dtype=bool)
        keep[self.pins] = False
        self.keep = keep
        K = data.K.tocsc()
        self.fac = Factor(K[keep][:, keep].tocsc() if self.pins.size else K)
        self.BT = data.B.T.tocsr()
        self.G = np.asarray(data.B @ V) if V.shape[1] else None
        self.b = V.T @ data.f if V.shape[1] else None
        self.q = data.g0 - data.B @ self.solve_K(data.f, refine=3)
        self.matvecs = 0
        #: refinement steps of each product's solve: none at first (a plain solve is accurate to
        #: about cond(K)·ε, 1e-9 at 64²), refined for the last rounds (:func:`solve_pressures`)
        self.refine = 0

    def solve_K(self, F: np.ndarray, refine: int = 0) -> np.ndarray:
        """u with K u = F where F is balanced (u = 0 at the pins), the pinned plate's otherwise."""
        if not self.pins.size:
            return self.fac.solve(F, refine=refine)
        u = np.zeros(self.data.n)
        u[self.keep] = self.fac.solve(F[self.keep], refine=refine)
        return u

    def product(self, R: np.ndarray, refine: int) -> np.ndarray:
        """(B K_p⁻¹ Bᵀ + C) R, the solve refined ``refine`` times (counted in ``matvecs``)."""
        self.matvecs += 1
        return self.data.B @ self.solve_K(self.BT @ R, refine=refine) + self.data.compliance(R)

    def matvec(self, R: np.ndarray) -> np.ndarray:
        """:meth:`product` as the rounds ask (:attr:`refine`)."""
        return self.product(R, self.refine)

    def precise(self, R: np.ndarray) -> np.ndarray:
        """:meth:`product` with its solve refined once (about twice the work; the error of a plain
        solve, cond(K)·ε, squared)."""
        return self.product(R, 1)

    def recover(self, R: np.ndarray, alpha: np.ndarray | None, closed: np.ndarray | None = None) -> ContactSolution:
        """The plate's dofs and the rows' compressions of the forces R (refined solves); the rigid
        motions' amounts from the rows whose gap is closed (``closed``; default: those that carry
        load), else the solver's α."""
        d = self.data
        u = self.solve_K(d.f - self.BT @ R, refine=3)
        s = d.compliance(R)
        if self.G is not None:
            on = R > 1e-3 * max(R.max(initial=0.0), 1e-300) if closed is None else closed
            rhs = (d.g0 + s - d.B @ u)[on]
            if on.sum() >= self.G.shape[1] and np.linalg.matrix_rank(self.G[on]) == self.G.shape[1]:
                alpha = sla.lstsq(self.G[on], rhs)[0]
            u = u + d.modes @ (np.zeros(self.G.shape[1]) if alpha is None else alpha)
        return ContactSolution(u, R, s)


def soil_fit(model, data: Scaled) -> sp.csr_matrix:
    """S̃, the scaled stiffness of a sparse soil that resembles the half-space: Pasternak's
    k diag(A) + c2 L with the pressure symbol k + c2 ξ² equal to the half-space's (E/(1 − ν²)/2)·|ξ|
    at the bed's lowest and highest wavenumbers (π over its size, π over a cell), so that the two
    differ by at most ½√(ξ₂/ξ₁) between; the posts' springs (a rigid one: :data:`RIGID` × the
    stiffest). For :func:`preconditioner`."""
    fnd, p = model.scene.foundation, model.scene.plate
    rows, nodes = model.soil_rows, model.soil_nodes
    area = model.bed_areas()[nodes]
    a = fnd.E / (1.0 - fnd.nu**2) / 2.0
    xi1, xi2 = np.pi / np.sqrt(area.sum()), np.pi / np.sqrt(np.median(area))
    c2, k = a / (xi1 + xi2), a * xi1 * xi2 / (xi1 + xi2)
    Sb = (c2 * soil.shear_laplacian(model, nodes) + sp.diags(k * area)).tocoo()
    to_scaled = max(p.a, p.b) ** 2 / p.D  # a stiffness: the inverse of ρ's scaling
    diag = np.zeros(data.m)
    others = np.setdiff1d(np.arange(data.m), rows)
    if others.size:
        soft = data.rho[others] > 0
        stiff = max(to_scaled * Sb.diagonal().max(), (1.0 / data.rho[others][soft]).max(initial=0.0))
        diag[others] = np.where(soft, 1.0 / np.where(soft, data.rho[others], 1.0), RIGID * stiff)
    S = sp.csr_matrix((to_scaled * Sb.data, (rows[Sb.row], rows[Sb.col])), shape=(data.m, data.m))
    return (S + sp.diags(diag)).tocsr()


def preconditioner(model, data: Scaled):
    """v ↦ P⁻¹ v with P = B K⁻¹ Bᵀ + S̃⁻¹ (:func:`soil_fit`'s soil in place of the half-space):
    by Woodbury's identity P⁻¹ = S̃ − S̃ B (K + Bᵀ S̃ B)⁻¹ Bᵀ S̃, one sparse factorisation (the
    plate on the fitted soil, definite even for a floating plate), no dense matrix. The plate's
    part B K⁻¹ Bᵀ matters only at the wavenumbers where the plate is more compliant than the soil
    (:func:`coarse_cells`): where a coarser mesh resolves those, its plate takes the fine one's
    place (:func:`two_level`: the same form, a solve of the coarse plate per step); else, or where
    that mesh cannot be built, the fine plate itself."""
    S = soil_fit(model, data)
    cells = coarse_cells(model)
    if cells is not None:
        apply = two_level(model, data, cells, S)
        if apply is not None:
            return apply
    return _woodbury(S, data.B.tocsr(), data.K)


def _woodbury(S: sp.csr_matrix, B: sp.csr_matrix, K: sp.spmatrix):
    """v ↦ S v − S B (K + Bᵀ S B)⁻¹ Bᵀ S v (B: the rows' deflections from K's unknowns)."""
    fac = Factor((K + B.T @ S @ B).tocsc())
    BT = B.T.tocsr()

    def apply(v: np.ndarray) -> np.ndarray:
        y = S @ v
        return y - S @ (B @ fac.solve(BT @ y, refine=0))
    return apply


def coarse_cells(model) -> tuple[int, int] | None:
    """The coarsest mesh of :func:`two_level` (the scene's cells halved k ≥ 1 times, at least
    :data:`COARSE_MIN` a side) whose cells are at most π / (:data:`COARSE_WAVES` ξ*) wide, ξ* =
    (a / D)^(1/3) the wavenumber where the plate's compliance 1 / (D ξ⁴) equals the fitted soil's
    1 / (a ξ) (a = E / (1 − ν²) / 2, :func:`soil_fit`); None where not even one halving is."""
    from ..model.generators import mesh_cells

    nx, ny = mesh_cells(model.scene)
    fnd, p = model.scene.foundation, model.scene.plate
    width = np.pi / (COARSE_WAVES * (fnd.E / (1.0 - fnd.nu**2) / 2.0 / p.D) ** (1.0 / 3.0))
    best = None
    f = 2
    while min(nx, ny) // f >= COARSE_MIN and p.a / (nx // f) <= width and p.b / (ny // f) <= width:
        best, f = (nx // f, ny // f), 2 * f
    return best


def two_level(model, data: Scaled, cells: tuple[int, int], S: sp.csr_matrix):
    """:func:`_woodbury`'s form with the plate of the mesh of ``cells`` in place of the fine one:
    v ↦ S̃ v − S̃ Π (K̃_c + Πᵀ S̃ Π)⁻¹ Πᵀ S̃ v, Π the coarse plate's deflections at the fine rows'
    points (its element's interpolation, in the scaled dofs of :class:`Scaled`), K̃_c its scaled
    stiffness; symmetric positive definite as the fine form is (Πᵀ S̃ Π is the fine soil seen by
    the coarse plate). None where that plate cannot be built, or Π does not reach every row."""
    from ..errors import SingularMatrixError
    from ..estimate import COARSE_FAILURES, with_mesh
    from ..model.assembly import build_model

    p = model.scene.plate
    L = max(p.a, p.b)
    xy = model.contacts.xy
    try:
        scene = with_mesh(model.scene, *cells)
        scene.foundation = None  # only its plate: K and the interpolation
        coarse = build_model(scene)
        per = 1.0 / L ** coarse.dof_orders  # the scaled dofs per unit of the user's (W cancels)
        Pi = (coarse.interpolation(xy[:, 0], xy[:, 1])[:, coarse.free] @ sp.diags(per)).tocsr()
        K = sp.diags(per) @ sp.csr_matrix(coarse.K) @ sp.diags(per) * (L**2 / p.D)
        if np.any(np.diff(Pi.indptr) == 0):
            return None
        return _woodbury(S, Pi, K)
    except (*COARSE_FAILURES, SingularMatrixError):
        return None


def coarse_start(model, accuracy) -> np.ndarray | None:
    """The contact forces of the mesh with half the cells a side (solved matrix-free, itself
    started so while it is large enough, to :data:`START_TOL` and no further: no refinement of
    the settled set, no KKT check, no result), as pressures interpolated linearly to this
    model's rows × their areas; None where that mesh cannot be built or solved."""
    from scipy.interpolate import LinearNDInterpolator

    from ..estimate import COARSE_FAILURES, with_mesh
    from ..model.assembly import build_model
    from ..model.generators import mesh_cells

    nx, ny = mesh_cells(model.scene)
    try:
        coarse_model = build_model(with_mesh(model.scene, max(1, nx // 2), max(1, ny // 2)), soil_operator=True)
        if coarse_model.soil_flexibility is None:
            return None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)
            R = _start_forces(coarse_model, max(Accuracy.parse(accuracy).tol, START_TOL))
    except (*COARSE_FAILURES, NoEquilibriumError):
        return None
    if R is None:
        return None
    cc = coarse_model.contacts
    p = R / coarse_model.bed_areas()[cc.index]
    c = model.contacts
    at = LinearNDInterpolator(cc.xy, np.maximum(p, 0.0), fill_value=0.0)(c.xy)
    return np.nan_to_num(at) * model.bed_areas()[c.index] * (c.source == "bed")


def _start_forces(model, tol: float) -> np.ndarray | None:
    """The contact forces (user units) of :func:`solve_pressures`'s solver on ``model`` with the
    solver's tolerance ``tol`` and no accurate product: a start, not an answer (None where the
    solver does not converge or statics rule an equilibrium out)."""
    data = Scaled.from_model(model, operator=True)
    reach = supports_reach(data, band=tol)
    if not reach.possible and not reach.marginal:
        return None
    pr = PressureProblem(data)
    x0 = coarse_start(model, tol) if data.m >= START_MIN else None
    start = None if x0 is None else np.maximum(x0 / data.F0, 0.0)
    _, out = _Solver(model, data, pr, START_PRODUCTS).run("pdas-pcg", start, tol, [], precise=False)
    return data.F0 * out.x if out.status == "optimal" else None


def _pins(data: Scaled) -> np.ndarray:
    """One deflection dof per rigid motion, chosen so that no rigid motion leaves them all at rest
    (pivoted QR of the motions' deflections): K without them is positive definite."""
    V = data.modes
    if not V.shape[1]:
        return np.zeros(0, dtype=int)
    idx = np.flatnonzero(data.is_w)
    _, _, piv = sla.qr(V[idx].T, mode="economic", pivoting=True)
    return np.sort(idx[piv[:V.shape[1]]])


def check_backend(backend: str, formulation: str) -> None:
    if backend not in BACKENDS:
        raise ProblemError(f"backend {backend!r}: a half-space held matrix-free is solved in the contact forces by "
                           f"{' or '.join(repr(b) for b in BACKENDS)} only (the soil has no matrix for the others; "
                           f"a bed of at most {soil.HALFSPACE_OPERATOR_FROM} nodes gives every backend its unknowns)")
    if formulation not in ("auto", "condensed"):
        raise ProblemError(f"formulation {formulation!r}: a half-space held matrix-free is solved condensed onto "
                           "the contact forces only (formulation 'auto' or 'condensed')")


def solve_pressures(model, backend: str = "auto", formulation: str = "auto",
                    accuracy: str | float | Accuracy = "default", options: dict | None = None,
                    check_statics: bool = True) -> Result:
    """:func:`plateqp.contact.pipeline.solve_contact` for a model whose half-space is held
    matrix-free: the module's QP, solved and checked. ``backend``: "auto" (the active-set PCG of
    :mod:`plateqp.backends.active_pcg`, preconditioned by the plate on a fitted sparse soil
    (:func:`preconditioner`), MPRGP from its answer where it does not settle) or "mprgp" (MPRGP
    alone). ``options``: ``maxiter`` (products, default 20 000), ``x0`` (a start of the forces,
    user units; default from the mesh with half the cells a side where there are at least
    :data:`START_MIN` rows)."""
    check_backend(backend, formulation)
    acc = Accuracy.parse(accuracy)
    options = dict(options or {})
    options.pop("predict", None)
    maxiter = int(options.pop("maxiter", 20000))
    x0 = options.pop("x0", None)
    if options:
        raise ProblemError(f"options: {', '.join(sorted(options))} not taken by the matrix-free half-space route "
                           "(it takes maxiter and x0)")
    t0 = time.perf_counter()
    data = Scaled.from_model(model, operator=True)
    reach = supports_reach(data, band=acc.tol)
    if check_statics and not reach.possible and not reach.marginal:
        raise NoEquilibriumError(f"{NO_EQUILIBRIUM} ({reach.why}; found by statics, before any solve)")
    pr = PressureProblem(data)
    if x0 is None and data.m >= START_MIN:
        x0 = coarse_start(model, acc)
    start = None if x0 is None else np.maximum(np.asarray(x0, dtype=float) / data.F0, 0.0)
    t1 = time.perf_counter()
    method = "mprgp" if backend == "mprgp" else "pdas-pcg"
    solver = _Solver(model, data, pr, maxiter)
    tol, said = max(TOL_SHARE * acc.tol / np.sqrt(max(data.m, 1)), 1e-15), []
    for attempt in range(RETRIES + 1):
        method, out = solver.run(method, start, tol, said)
        c = pr.recover(out.x, out.alpha)
        rep = kkt_report(data, c, acc)
        if rep.ok or out.status != "optimal":
            break
        # again from the answer, tighter; MPRGP met its tolerance on products accurate to
        # cond(K)·ε, so its products' solves are refined (the active-set PCG's residuals are)
        start, tol, pr.refine = out.x, tol * 0.1, 2 if method == "mprgp" else 0
    t2 = time.perf_counter()
    status = (Status.OPTIMAL if rep.ok else Status.INACCURATE) if out.status == "optimal" else (
        Status.MAX_ITER if out.status == "max_iter" else Status.INACCURATE)
    res = to_result(model, data, c, status, method, "condensed", acc)
    res.kkt = rep
    res.iterations = solver.iterations
    res.extras = {"solver_status": out.status, "matvecs": pr.matvecs, "route": {"answered": f"{method}/condensed",
                  "tried": said}, "soil": "half-space held matrix-free", "started": "given" if x0 is not None else "cold"}
    res.times.update(formulate=t1 - t0, solve=t2 - t1, recover=time.perf_counter() - t2)
    if status != Status.OPTIMAL:
        why = f"{out.status}: {out.message}; worst KKT residual {rep.worst:.2e}, asked {rep.tol:.0e}"
        res.extras["why"] = f"{status.value}: {why}"
        warnings.warn(f"{method} on the condensed problem: {status.value} ({why})", PlateQPWarning, stacklevel=4)
    return res


class _Solver:
    """The solvers of :func:`solve_pressures` on one problem: the active-set PCG (its
    preconditioner built once), MPRGP from its answer where it does not settle."""

    def __init__(self, model, data: Scaled, pr: PressureProblem, maxiter: int) -> None:
        self.model, self.data, self.pr, self.maxiter = model, data, pr, maxiter
        self.precond = None
        self.iterations = 0

    def run(self, method: str, start, tol: float, said: list, precise: bool = True):
        from ..backends.active_pcg import active_set_pcg
        from ..backends.mprgp import solve_bound_qp

        pr, d = self.pr, self.data
        if method == "pdas-pcg":
            if self.precond is None:
                self.precond = preconditioner(self.model, d)
            c = 1.0 / np.mean(d.rho[self.model.soil_rows])  # the soil's point stiffness
            # a floating plate without a start: every row in contact (the bonded soil holds it)
            every = np.ones(d.m, dtype=bool) if start is None and pr.G is not None else None
            out = active_set_pcg(pr.matvec, pr.q, precond=self.precond, G=pr.G, b=pr.b, x0=start, active=every, c=c,
                                 tol=tol, maxiter=self.maxiter - pr.matvecs, precise=pr.precise if precise else None)
            self.iterations += out.iterations
            said.append({"method": method, "status": out.status, "why": out.message})
            if out.status == "optimal":
                return method, out
            method, start = "mprgp", out.x
        out = solve_bound_qp(pr.matvec, pr.q, lb=0.0, G=pr.G, b=pr.b, x0=start, tol=tol,
                             maxiter=max(self.maxiter - pr.matvecs, 1))
        self.iterations += out.iterations
        said.append({"method": "mprgp", "status": out.status, "why": out.message})
        return "mprgp", out


#: the bonded comparison's tolerance (the solver's, in gap units of the deflection scale)
BONDED_TOL = 1e-10


def solve_bonded(model) -> Result:
    """:func:`plateqp.contact.pipeline.solve_bilateral` for a half-space held matrix-free: the
    module's problem without the bound (R of either sign, every gap closed), a linear system
    solved by conjugate gradients on its operator. A solve that does not converge is a
    SolverError (the comparison has no accuracy to ask, so it never returns a rough answer)."""
    from ..backends.mprgp import solve_bound_qp
    from ..errors import SolverError
    t0 = time.perf_counter()
    data = Scaled.from_model(model, operator=True)
    pr = PressureProblem(data)
    out = solve_bound_qp(pr.matvec, pr.q, lb=-np.inf, G=pr.G, b=pr.b, tol=BONDED_TOL, maxiter=20000)
    if out.status != "optimal":
        raise SolverError(f"the two-sided comparison on the matrix-free half-space did not converge "
                          f"({out.status} after {out.iterations} iterations)")
    c = pr.recover(out.x, out.alpha, closed=np.ones(data.m, dtype=bool))
    res = to_result(model, data, c, Status.OPTIMAL, "mprgp", "bilateral", "high")
    res.active = np.ones(data.m, dtype=bool)
    res.times = {"solve": time.perf_counter() - t0}
    return res
