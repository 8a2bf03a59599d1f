r"""The contact problem in three standard forms: primal, condensed, dual.

All three start from the same nondimensional data (see :class:`Scaled`): the free-dof
stiffness K, load f, contact operator B, initial gaps g0 and flexibilities ρ = 1/c
(ρ = 0 for a rigid support). They must give the same reactions.

**Primal** (sparse, all dofs; works for a floating plate):

.. math::

    \min_{u,t}\ \tfrac12 u^T K u + \tfrac12 t^T t - f^T u
    \quad\text{s.t.}\quad B u - \sqrt{\rho}\, t \le g_0 .

The spring compression is s = √ρ t, so the spring energy ½ c s² = ½ t²: stiffness enters as
1/√c, never as c, and a very stiff support does not spoil the Hessian. The multipliers of
the constraints are the reactions R; stationarity in t gives t = √ρ R.

**Condensed** (the source paper's route): every dof other than the contact deflections
w_c = B u is eliminated by static condensation (one sparse factorisation with the contact
deflections ordered last, whose trailing block is S: :class:`plateqp.linalg.SchurFactor`; no
column solves). With the condensed stiffness S and load r,
the gaps z = g0 + ρR − w_c and the reactions satisfy the LCP

.. math::

    R = M z + q,\quad z \ge 0,\ R \ge 0,\ z^T R = 0,\qquad
    M = (I + S\rho)^{-1} S,\quad q = (I + S\rho)^{-1}(r - S g_0),

the KKT system of the bound-constrained QP  min ½ zᵀMz + qᵀz, z ≥ 0. For supports at nodes
S is the Schur complement K_cc − K_cn K_nn⁻¹ K_nc; off-node supports first change variables
so that one "master" dof per support is replaced by the support's deflection.

**Dual** (reactions only; needs two-sided supports that hold the plate, K nonsingular):
with the flexibility G = B K⁻¹ Bᵀ and F = G + diag(ρ),

.. math::

    \min_{R \ge 0}\ \tfrac12 R^T F R + d^T R,\qquad d = g_0 - B K^{-1} f,

whose KKT conditions are the LCP gap = F R + d ≥ 0, R ≥ 0, Rᵀgap = 0. G comes from the
trailing block of one factorisation of K with the contact dofs last, like S, without column
solves (:meth:`plateqp.linalg.SchurFactor.flexibility`). That G is accurate to about cond(K)·ε
only, so :func:`plateqp.solve` corrects the backend's answer: the exact gaps at its reactions
(u by a refined solve) shift d, and the backend solves again (:meth:`Dual.defect`; one
correction is typical at 1e-10). An export builds G by refined column solves instead, since
the data are then all another solver sees.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..backends.base import LCP, QP, RawSolution
from ..errors import MechanismError, ProblemError, SingularMatrixError
from ..linalg import SchurFactor, pattern
from .scaling import Scaled

FORMULATIONS = ("primal", "condensed", "dual")


@dataclass
class ContactSolution:
    """The common output of the formulations' ``recover``: scaled fields, in the plate's terms."""

    u: np.ndarray  # scaled free dofs
    R: np.ndarray  # scaled reactions
    s: np.ndarray  # scaled spring compressions


@dataclass
class Formulation:
    """Base: a problem in standard form plus the recovery of plate quantities from its solution."""

    name: str
    data: Scaled
    qp: QP | None = None
    lcp: LCP | None = None
    extras: dict = field(default_factory=dict)

    def problem(self, accepts: frozenset[str]) -> QP | LCP:
        """The form a backend takes: its QP if it takes QPs, else the LCP."""
        if "qp" in accepts and self.qp is not None:
            return self.qp
        if "lcp" in accepts and self.lcp is not None:
            return self.lcp
        raise ProblemError(f"the {self.name} formulation has no form this backend takes ({sorted(accepts)})")

    #: corrections :func:`plateqp.contact.pipeline.solve_contact` makes at most (see :meth:`Dual.defect`)
    max_corrections = 0

    def recover(self, raw: RawSolution) -> ContactSolution:
        raise NotImplementedError

    def defect(self, raw: RawSolution) -> np.ndarray:
        """The error of this problem's own data at ``raw``'s answer, in its q's units (a
        formulation with ``max_corrections > 0``; see :meth:`Dual.defect`)."""
        raise NotImplementedError

    def corrected(self, e: np.ndarray) -> Formulation:
        """The problem with q moved by ``e`` (a :meth:`defect`), for the backend to solve again."""
        raise NotImplementedError


def _with_identity(K: sp.csc_matrix, k: int) -> sp.csc_matrix:
    """``block_diag(K, I_k)`` in CSC, K's entries as stored (zeros and order kept); its values
    are K's own array, extended, where :func:`plateqp.linalg.pattern.scaled` left room for them,
    and its indices too where the assembly did (:func:`plateqp.linalg.pattern.extended_indices`)."""
    n = K.shape[0]
    nnz = K.indptr[-1]
    idx = np.int64 if n + k > np.iinfo(np.int32).max or nnz + k > np.iinfo(np.int32).max else np.int32
    indptr = np.concatenate([K.indptr.astype(idx, copy=False), nnz + np.arange(1, k + 1, dtype=idx)])
    indices = pattern.extended_indices(K, k) if K.indices.dtype == idx else None
    if indices is None:
        indices = np.concatenate([K.indices[:nnz].astype(idx, copy=False), np.arange(n, n + k, dtype=idx)])
    data = pattern.extended_values(K, k) if K.data.dtype == float else None
    if data is None:
        data = np.concatenate([K.data[:nnz].astype(float, copy=False), np.ones(k)])
    else:  # K's values where they were scaled, the identity's in the room left after them
        data[nnz:] = 1.0
    P = sp.csc_matrix((data, indices, indptr), shape=(n + k, n + k))
    P.has_sorted_indices = K.has_sorted_indices
    return P


class Primal(Formulation):
    def __init__(self, data: Scaled) -> None:
        m = data.m
        el = np.flatnonzero(data.rho > 0)
        ne = el.size
        # with no spring block, K itself (already CSC: no copy); else K's arrays and the identity's
        # joined column by column (block_diag went through COO and sorted every entry: 0.12 s at
        # 256²), K's stored zeros kept (the ordering reads them: plateqp.linalg.pattern)
        P = _primal_hessian(data, el)
        q = np.concatenate([-data.f, np.zeros(ne)])
        G = _rows_with_springs(data.B, el, -np.sqrt(data.rho[el]))
        null = np.vstack([data.modes, np.zeros((ne, data.modes.shape[1]))]) if data.floating else None
        super().__init__("primal", data, qp=QP(P=P, q=q, G=G, h=data.g0.copy(), singular=data.floating,
                                                null=null))
        self._el = el

    def recover(self, raw: RawSolution) -> ContactSolution:
        d = self.data
        u = raw.x[: d.n]
        R = raw.z if raw.z is not None else np.full(d.m, np.nan)
        s = np.zeros(d.m)
        s[self._el] = np.sqrt(d.rho[self._el]) * raw.x[d.n:]
        return ContactSolution(u, R, s)


def _rows_with_springs(B: sp.spmatrix, el: np.ndarray, t: np.ndarray) -> sp.csc_matrix:
    """``[B  T]`` in CSC, ``T`` (m × k) holding ``t[j]`` at row ``el[j]`` of its column j: B's
    columns as they are, then one entry a column (what ``sp.hstack([B, T], format="csc")``
    gives, without the stack's COO round trip: a bed's 3.4 → 1.2 ms at 256², 12 → 4 ms at 512²)."""
    Bc = sp.csc_matrix(B, dtype=float)
    m, n = Bc.shape
    k = el.size
    nnz = int(Bc.indptr[-1])
    idx = np.int64 if max(m, n + k, nnz + k) > np.iinfo(np.int32).max else np.int32
    indptr = np.concatenate([Bc.indptr.astype(idx, copy=False), nnz + np.arange(1, k + 1, dtype=idx)])
    indices = np.concatenate([Bc.indices[:nnz].astype(idx, copy=False), el.astype(idx, copy=False)])
    data = np.concatenate([Bc.data[:nnz], np.asarray(t, dtype=float)])
    G = sp.csc_matrix((data, indices, indptr), shape=(m, n + k))
    G.has_sorted_indices = Bc.has_sorted_indices
    return G


def _primal_hessian(data: Scaled, el: np.ndarray) -> sp.csc_matrix:
    """``block_diag(K, I)`` with one identity column per spring row ``el`` (K itself without
    springs), ``data.K`` then its leading block (:meth:`Scaled.share_K`); in a sweep
    (``data.memo``) the one a value before built for the same springs, whose leading block the
    memo's K already is."""
    ne = el.size
    memo = data.memo
    key = el.tobytes()
    if memo is not None and memo.get("primal-P", (None,))[0] == key:
        _, P, data.K = memo["primal-P"]
        return P
    P = _with_identity(data.K.tocsc(), ne) if ne else data.K.tocsc()
    if ne:
        data.share_K(P)
    if memo is not None:
        memo["primal-P"] = (key, P, data.K)
        memo["K"] = data.K  # one copy of K's values alive, P's
    return P


class Condensed(Formulation):
    def __init__(self, data: Scaled) -> None:
        super().__init__("condensed", data)
        T, fac, Koc, S = _cached(data, "condensed", lambda: _condense(data))
        m = data.m
        ft = T.T @ data.f
        fo = ft[m:]
        y0 = fac.solve_others(fo)
        r = ft[:m] - Koc.T @ y0
        rho = data.rho
        # M = (I + Sρ)⁻¹S has rows of very different sizes when soft and rigid supports mix
        # (a soft row is ~1/ρ, a rigid one ~S): solved plainly, each entry carries an error of
        # eps·‖M‖, which left the soft rows' reactions 1e-6 off and the deflections recovered
        # from them (w = g0 + ρR − z) 5e-8 off, with ρ a²/D = 1e8 next to rigid supports. With
        # the columns of A scaled by σ = 1/(1 + ρ diag S), every row is accurate to its own size.
        if not np.any(rho):  # rigid supports: σ = 1, A = I, M = S exactly (two m × m solves saved)
            M, q = S.copy(), r - S @ data.g0
        else:
            sigma = 1.0 / (1.0 + rho * np.maximum(np.diag(S), 0.0))
            A = np.eye(m) * sigma[None, :] + S * (rho * sigma)[None, :]
            M = sigma[:, None] * np.linalg.solve(A, S)
            q = sigma * np.linalg.solve(A, r - S @ data.g0)
            # symmetrise from the row that is accurate relative to the entry (the smaller σ)
            lo, hi = sigma[:, None] < sigma[None, :], sigma[:, None] > sigma[None, :]
            M = np.where(lo, M, np.where(hi, M.T, 0.5 * (M + M.T)))
        self.lcp = LCP(M, q, unknown="gaps")
        self.qp = self.lcp.as_qp()
        self._T, self._fac, self._Koc, self._fo, self._m = T, fac, Koc, fo, m

    def recover(self, raw: RawSolution) -> ContactSolution:
        d = self.data
        z = raw.x
        M, q = self.lcp.M, self.lcp.q
        R = M @ z + q
        # R = M z + q cancels where a support does not touch: what is left there is rounding
        # (a bound of it: m·eps·(|M||z| + |q|)), not a reaction. Left in, it failed the KKT check
        # of a plate that touches nothing (its force scale is then 1e-12 of the load) and
        # marked lifted supports as in contact; it is set to the zero it stands for.
        noise = 4 * d.m * np.finfo(float).eps * (np.abs(M) @ np.abs(z) + np.abs(q))
        R[np.abs(R) <= noise] = 0.0
        w_c = d.g0 + d.rho * R - z
        u_o = self._fac.solve_others(self._fo - self._Koc @ w_c)
        u = self._T @ np.concatenate([w_c, u_o])
        return ContactSolution(u, R, d.rho * R)


class Dual(Formulation):
    """The dual LCP in the reactions (module docstring).

    ``exact_flexibility=False`` (what :func:`plateqp.solve` uses): G from the trailing block of
    one contacts-last factorisation, accurate to about cond(K)·ε; an answer that fails the KKT
    check by that error is corrected by a re-solve (:meth:`defect`). ``True`` (what an export
    uses: its data are all another solver sees): G by m refined column solves, accurate to ε."""

    #: corrections :func:`plateqp.contact.pipeline.solve_contact` makes at most
    max_corrections = 3

    def __init__(self, data: Scaled, exact_flexibility: bool = False) -> None:
        super().__init__("dual", data)
        if data.floating:
            raise ProblemError("the dual formulation needs K⁻¹, but this plate floats: its two-sided "
                               "supports leave rigid motions free; use the primal or condensed formulation")
        refine = 3 if exact_flexibility else 0
        fac, G = _cached(data, "dual-exact" if refine else "dual", lambda: _flexibility(data, refine))
        B = data.B.tocsr()
        u0 = fac.solve(data.f, refine=3)
        F = G + np.diag(data.rho)
        dvec = data.g0 - B @ u0
        self.lcp = LCP(F, dvec, unknown="reactions")
        self.qp = self.lcp.as_qp()
        self._fac, self._d = fac, dvec
        self._shift = np.zeros(data.m)  # q = d + shift: the correction handed to the backend
        self._last: tuple | None = None  # (R, ContactSolution) of the last recover

    def recover(self, raw: RawSolution) -> ContactSolution:
        d = self.data
        R = raw.x
        if self._last is not None and np.array_equal(self._last[0], R):
            return self._last[1]
        # one refined solve with the whole right-hand side, not u0 − K⁻¹BᵀR: where the supports
        # carry the load, u0 and K⁻¹BᵀR are both ~w_load and cancel to a u far smaller, and the
        # rounding of each (ε|u0|) left a stationarity residual above its floor (measured: 3.5e-9
        # on a 64² plate on 30×30 posts at "high"; one solve: 7e-15)
        u = self._fac.solve(d.f - d.B.T @ R, refine=3)
        c = ContactSolution(u, R, d.rho * R)
        self._last = (R.copy(), c)
        return c

    def defect(self, raw: RawSolution) -> np.ndarray:
        r"""The error e of this problem's gaps at ``raw``'s reactions R: the exact gaps (u by a
        refined solve) minus the backend's F̃R + q.

        With G̃ the trailing block's flexibility, the backend solved LCP(F̃, q), q = d + s
        (s = 0 at first). :meth:`corrected` hands it LCP(F̃, q + e), whose solution R' meets
        F̃R' + d + (F − F̃)R = gap(R): a defect correction that contracts by about
        ‖F̃⁻¹(F − F̃)‖ ≈ cond(K)·ε per step, whose fixed point is the exact LCP's solution.
        Measured on grid_rigid(32, 15) / (64, 30) / (128, 30) with BPP at 1e-10: KKT 8e-10 /
        4e-8 / 5e-7 from G̃ alone, 4e-13 / 1e-12 / 1e-11 after one correction. It corrects
        G's error only, never the backend's: each corrected problem is solved by the same
        backend to the same tolerance, and the exact residuals of its answer are reported
        (:func:`plateqp.contact.kkt.defect_residual` decides whether a correction is worth it).
        """
        d = self.data
        c = self.recover(raw)
        gap = d.g0 + d.rho * c.R - d.B @ c.u
        return gap - (self.lcp.M @ c.R + self.lcp.q)

    def corrected(self, e: np.ndarray) -> Dual:
        """The same problem with q moved by ``e`` (a :meth:`defect`)."""
        nxt = copy.copy(self)
        nxt._shift = self._shift + e
        nxt.lcp = LCP(self.lcp.M, self._d + nxt._shift, unknown="reactions")
        nxt.qp = nxt.lcp.as_qp()
        nxt._last = None
        return nxt


# The condensed stiffness and the flexibility depend only on the model's K and B (not on the
# gaps, springs, loads or the deflection scale: K̃ and B̃ are independent of W), so a sweep over
# gaps, stiffnesses or loads that shares K and B (plateqp.studies.adapt_model) condenses once.
#: how many derived matrices a model keeps (Model.derived), most recent last
_CACHE_SIZE = 2
#: the kinds of derived matrices :func:`_cached` keeps
_MATRICES = ("condensed", "dual", "dual-exact")


def _cached(data: Scaled, kind: str, build):
    """``build()``, or what it gave before for this model's K and B (``data.derived``, the
    model's own list; none where the data came from no model)."""
    keep = data.derived
    if keep is not None and data.K_src is not None:
        for K, B, k, value in keep:
            if K is data.K_src and B is data.B_src and k == kind:
                return value
    value = build()
    if keep is not None and data.K_src is not None:
        keep.append((data.K_src, data.B_src, kind, value))
        # the oldest derived matrices past _CACHE_SIZE dropped; the list's other entries (kept
        # factorisations, the scaled data's memo: plateqp.contact.scaling.structure) stay
        mine = [e for e in keep if e[2] in _MATRICES]
        drop = {id(e) for e in mine[:-_CACHE_SIZE]}
        keep[:] = [e for e in keep if id(e) not in drop]
    return value


def _condense(data: Scaled):
    """Static condensation onto the contact deflections: (T, the factor of K̃ = Tᵀ K T with the
    contact deflections last (it solves with K̃_oo), K̃_oc, S)."""
    B = data.B.tocsr()
    m, n = B.shape
    master = _masters(B)
    others = np.setdiff1d(np.arange(n), master)
    order = np.concatenate([master, others])  # T permutes K so, but for the contact rows
    P = sp.csr_matrix((np.ones(n), (order, np.arange(n))), shape=(n, n))
    if np.all(np.diff(B.indptr) == 1) and np.all(B.data != 0):
        # every support on a node (one dof a row): Bm is diagonal, T a scaled permutation, and
        # K̃ = D Pᵀ K P D keeps K's pattern (no dense inverse, no sparse triple product: 0.7 s of
        # 1.7 s on grid_rigid(128, 30))
        d = np.concatenate([1.0 / B.data, np.ones(others.size)])
        T = (P @ sp.diags(d)).tocsr()
        Kt = pattern.scaled(_permuted(data.K, order), d)
        return _condensed_factor(data, T, Kt, m)
    Bm = B[:, master].tocsc()
    Bo = B[:, others].tocsc()
    # Bm is diagonal when every support sits on a node; near-diagonal otherwise
    try:
        Binv = np.linalg.inv(Bm.toarray())
    except np.linalg.LinAlgError as exn:
        raise ProblemError("the contact points are too close together to condense onto "
                           "(their interpolation rows are dependent); use the primal formulation") from exn
    # nearly dependent rows (two contact points much closer than a cell): the gaps are then
    # nearly dependent variables, S grows like cond², and the LCP is rounding (measured: two
    # elastic supports 1e-8 of a cell apart made I + Sρ exactly singular). The primal and the
    # dual keep such points apart through their springs; the condensed form refuses clearly.
    rowmax = np.maximum(np.abs(Bm).max(axis=1).toarray().ravel(), 1e-300)
    cond = (np.abs(Bm.toarray() / rowmax[:, None]).sum(axis=0).max()
            * np.abs(Binv * rowmax[None, :]).sum(axis=0).max())  # 1-norm, rows equilibrated
    if cond > CONDENSE_COND_MAX:
        raise ProblemError(f"the contact points are too close together to condense onto (their interpolation "
                           f"rows are dependent to 1/{cond:.0e}); use the primal or the dual formulation")
    Binv[np.abs(Binv) < 1e-14 * np.abs(Binv).max()] = 0.0
    Binv = sp.csr_matrix(Binv)
    X = (Binv @ Bo).tocsr()
    Tm = sp.hstack([Binv, -X])
    To = sp.hstack([sp.csr_matrix((others.size, m)), sp.identity(others.size)])
    T = (P @ sp.vstack([Tm, To])).tocsr()
    Kt = pattern.congruence(T, data.K, like=_permuted(data.K, order))  # stored zeros kept (ordering)
    return _condensed_factor(data, T, Kt, m)


def _permuted(K, order: np.ndarray) -> sp.csc_matrix:
    """``K[order][:, order]`` (CSC), without SciPy's slow path for the rows of a CSC matrix:
    through the transpose, a CSR view of the same arrays (exact for any K)."""
    K = sp.csc_matrix(K)
    return K.T.tocsr()[order][:, order].T.tocsc()


def _condensed_factor(data: Scaled, T, Kt, m: int):
    """(T, the factor of K̃ with its first m unknowns last, K̃_oc, S): see :func:`_condense`."""
    Koc = Kt[m:][:, :m].tocsc()
    # one factorisation of K̃ with the contact deflections last: its trailing block is S. A
    # floating plate's K̃ is singular, its K̃_oo (every contact point held) is not: the trailing
    # block is then factorised with a unit shift (K̃ equilibrated), which schur() takes off again
    try:
        fac = SchurFactor(Kt, np.arange(m), shift=1.0 if data.floating else 0.0)
    except SingularMatrixError as exn:
        raise MechanismError("with every contact point held, the plate can still move: the "
                             "supports do not prevent rigid motion (fewer than three non-collinear "
                             "contact points and no two-sided supports); use the primal formulation, "
                             "which reports this as no equilibrium") from exn
    return T, fac, Koc, fac.schur()


def _flexibility(data: Scaled, refine: int):
    """The factor of K (the contact dofs last) and the flexibility G = B K⁻¹ Bᵀ: from the
    trailing block alone (``refine = 0``), or by m column solves with ``refine`` steps each."""
    B = data.B.tocsr()
    try:
        fac = SchurFactor(data.K, np.unique(B.indices))
    except SingularMatrixError as exn:
        raise MechanismError(f"the plate's stiffness matrix is singular ({exn}): its two-sided supports "
                             "do not hold it; use the primal or condensed formulation") from exn
    # from the trailing block alone G is accurate to about cond(K)·ε (Dual.defect makes up
    # for it); m refined columns cost m solves (23.7 s against 0.8 s on grid_rigid(128, 30))
    return fac, fac.flexibility(B, refine=refine)

#: Condition number (1-norm, rows equilibrated) of the contact rows on their master dofs above
#: which the condensed form refuses: its matrix grows like cond², so 1e5 leaves ~1e-6 of the
#: digits (two supports about 1e-4 of a cell apart); the primal and the dual still solve them.
CONDENSE_COND_MAX = 1e5

def _masters(B: sp.csr_matrix) -> np.ndarray:
    """One distinct dof per contact row, the one with the largest weight (greedy)."""
    m = B.shape[0]
    taken: set[int] = set()
    out = np.empty(m, dtype=int)
    order = np.argsort(-abs(B).max(axis=1).toarray().ravel())  # strongest rows choose first
    for i in order:
        lo, hi = B.indptr[i], B.indptr[i + 1]
        cols, vals = B.indices[lo:hi], np.abs(B.data[lo:hi])
        for k in np.argsort(-vals):
            if cols[k] not in taken:
                out[i] = cols[k]
                taken.add(int(cols[k]))
                break
        else:
            raise ProblemError(f"contact point {i} shares all its dofs with other contact points; "
                               "use the primal formulation")
    return out


def formulate(data: Scaled, name: str, exact_data: bool = False) -> Formulation:
    """Build the named formulation from scaled data. ``exact_data``: the dual's flexibility by
    refined column solves (for an export; see :class:`Dual`); the others are unchanged."""
    table = {"primal": Primal, "condensed": Condensed, "dual": Dual}
    if name not in table:
        raise ProblemError(f"unknown formulation {name!r}; choose one of {FORMULATIONS}")
    if name == "dual":
        return Dual(data, exact_flexibility=exact_data)
    return table[name](data)
