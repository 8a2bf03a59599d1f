r"""The Schur complement on chosen unknowns, from the trailing block of one factorisation.

With the unknowns ``l`` (``last``) ordered after all the others ``o`` (AMD order among those),
one sparse Cholesky factor of the equilibrated matrix

.. math::

    P K P^T = L L^T,\qquad
    L = \begin{pmatrix} L_{oo} & 0 \\ L_{lo} & L_{ll} \end{pmatrix},\qquad
    L_{ll} L_{ll}^T = K_{ll} - K_{lo} K_{oo}^{-1} K_{ol} = S,

holds in its trailing dense block the Schur complement ``S`` (the static condensation of every
other unknown onto ``l``), and ``(K⁻¹)_ll = S⁻¹``. So for rows ``B`` acting on ``l`` only,
``B K⁻¹ Bᵀ = Z^T Z`` with ``Z = L_ll⁻¹ B_lᵀ`` (one dense triangular solve): no column solves
at all. Measured on a 128² plate with 900 such unknowns: the contacts-last factor costs about
1.5 plain factorisations, where the 900 columns ``K⁻¹ B_iᵀ`` (each about 1/50 of a
factorisation, even solved in blocks) would cost 18.

The same factor solves with ``K`` (:meth:`SchurFactor.solve`), in halves for a caller that
needs only the trailing part of one (:meth:`SchurFactor.forward`, :meth:`SchurFactor.backward`,
and the dense ``trailing_forward``/``trailing_backward`` for vectors on ``l``), and with ``K_oo``
(:meth:`SchurFactor.solve_others`, two solves with ``K``). The fill-reducing order (AMD on the
rest) is handed to CHOLMOD with the matrix itself: one pass over ``K``, one conversion. A matrix that is only semidefinite
but whose block ``K_oo`` is definite is factorised with ``shift`` added to the trailing
diagonal (``S + shift·I`` is definite); :meth:`SchurFactor.schur` takes it off again.

Without a CHOLMOD binding, ``S`` comes from a factor of ``K_oo`` (:class:`Factor`, SuperLU)
and solves with blocks of columns of ``K_ol``: the fallback, never the route where CHOLMOD is.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..errors import SingularMatrixError
from .cholmod import Cholesky, lower
from .factor import Factor, Refined, equilibration

BLOCK = 256  # right-hand sides solved together (fallback)
SCHUR_METHODS = ("auto", "sksparse", "cvxopt", "blocks")


def symmetric_from_lower(A: np.ndarray, block: int = 128) -> np.ndarray:
    """``A`` (square) made symmetric from its lower triangle, in place, and returned: the part
    above the diagonal is overwritten, by blocks of columns (no mask or second array of A's size,
    as ``np.tril(A) + np.tril(A, -1).T`` makes)."""
    n = A.shape[0]
    for j0 in range(0, n, block):
        j1 = min(n, j0 + block)
        A[j0:j1, j1:] = A[j1:, j0:j1].T
        D = A[j0:j1, j0:j1]
        D[...] = np.tril(D) + np.tril(D, -1).T
    return A


def _plus_diagonal(A: sp.csc_matrix, d: np.ndarray) -> sp.csc_matrix:
    """``A + diag(d)``, in place where each column of the triangle ``A`` holds its diagonal."""
    n = A.shape[0]
    for ends in (A.indptr[:-1], A.indptr[1:] - 1):  # a lower triangle starts, an upper one ends, at it
        if A.has_sorted_indices and np.all(np.diff(A.indptr) > 0) and np.array_equal(A.indices[ends], np.arange(n)):
            A.data[ends] += d
            return A
    out = A + sp.diags(d, format="csc")
    out.sort_indices()
    return out


class _Solver(Refined):
    """``K`` (or ``K_oo``) with a raw solve function, refined on ``K`` itself."""

    def __init__(self, K: sp.csc_matrix, raw) -> None:
        self.K = K
        self._raw_fn = raw

    def _raw(self, b: np.ndarray) -> np.ndarray:
        return self._raw_fn(b)


class SchurFactor:
    """One factorisation of ``K`` with the unknowns ``last`` ordered last.

    Parameters
    ----------
    K : sparse (n, n), symmetric positive definite (semidefinite with a definite ``K_oo``
        if ``shift > 0``)
    last : int array
        The distinct unknowns ordered last, in the order of :meth:`schur`'s rows.
    shift : float
        The trailing block is factorised as ``S + shift·I`` (in the equilibrated units, where
        ``K`` has a unit diagonal); :meth:`solve` then refuses.
    pivot_tol : float
        SingularMatrixError if a trailing pivot ``L_ii²`` or the estimate of the smallest
        eigenvalue of ``S`` (:meth:`smallest_eigenvalue`, both equilibrated) is below this:
        ``K`` is singular to that precision. A pivot alone can stay well above the smallest
        eigenvalue: a floating plate's trailing block (a bed at 24² and 40²) had its smallest
        pivot at 1e-13 and 5e-13, its smallest eigenvalue at 3e-16 and 5e-16.
    method : "auto" (the first CHOLMOD binding in use, else "blocks"), "sksparse",
        "cvxopt", or "blocks" (``S`` by solves with a :class:`Factor` of ``K_oo``).
    diagonal : ``diag(K)``, where the caller has it (it equilibrates ``K``).
    prox : float
        ``prox·diag(K)`` added on every unknown (``prox·I`` equilibrated) before the shift: the
        factor, :meth:`schur` and :meth:`flexibility` are then those of ``K + prox·diag(K)``
        (a proximal term a caller wants in every solve; CHOLMOD methods only).

    Raises
    ------
    SingularMatrixError
        ``K`` (``K_oo`` if shifted) is not positive definite. ``column`` is where the
        factorisation stopped in the factor's order: below ``n − len(last)`` it is ``K_oo``.
    """

    def __init__(self, K, last, shift: float = 0.0, pivot_tol: float = 0.0, method: str = "auto",
                 diagonal: np.ndarray | None = None, prox: float = 0.0) -> None:
        if method not in SCHUR_METHODS:
            raise ValueError(f"unknown method {method!r}; choose one of {SCHUR_METHODS}")
        self.K = sp.csc_matrix(K)
        n = self.K.shape[0]
        self.last = np.asarray(last, dtype=np.int64)
        mask = np.zeros(n, dtype=bool)
        mask[self.last] = True
        if mask.sum() != self.last.size:
            raise ValueError("the unknowns ordered last must be distinct")
        self.n, self.nl, self.no = n, self.last.size, n - self.last.size
        self.shift, self.prox = float(shift), float(prox)
        if method == "auto":
            from . import bindings  # read at every call: a test may switch one off

            libs = bindings()
            method = libs[0] if libs else "blocks"
        self.method = method
        if self.prox and method == "blocks":
            raise ValueError("prox needs a CHOLMOD method")
        self.s = equilibration(self.K, diagonal)
        self.stats = {"analyse_s": 0.0, "factor_s": 0.0, "extract_s": 0.0, "factorisations": 1, "solves": 0,
                      "solve_s": 0.0, "last": int(self.nl), "method": method}
        self._mask = mask
        self._solver = self._others = None
        self.chol = None
        if method == "blocks":
            self._by_blocks()
        else:
            self._by_trailing_block(method)
        if self.nl and pivot_tol > 0:
            pivot = np.diagonal(self.Lll).min() ** 2
            if pivot < pivot_tol:
                raise SingularMatrixError("the matrix is singular to working precision (a pivot of the trailing "
                                          f"block is {pivot:.1e} of its diagonal)")
            low = self.smallest_eigenvalue()
            if low < pivot_tol:
                raise SingularMatrixError("the matrix is singular to working precision (the trailing block's "
                                          f"smallest eigenvalue is about {low:.1e} of its diagonal)")

    # ------------------------------------------------------------------ building

    def _by_trailing_block(self, lib: str) -> None:
        t0 = time.perf_counter()
        chol = Cholesky(lib)
        A = lower(self.K, self.s, upper=chol.upper)  # one pass over K, for the order
        order = chol.order(A)
        self.perm = np.concatenate([order[~self._mask[order]], self.last])
        extra = np.where(self._mask, self.shift, 0.0) + self.prox if (self.shift or self.prox) else None
        if chol.takes_permuted:  # the triangle made in the factor's order: CHOLMOD factorises it in place
            A = chol.permuted_lower(A, self.perm)
            chol.forget_matrix()
            if extra is not None:
                A = _plus_diagonal(A, extra[self.perm])
            chol.analyse_permuted(A, self.perm)
        else:
            if extra is not None:
                A = _plus_diagonal(A, extra)
            chol.analyse(A, order=self.perm)
        t1 = time.perf_counter()
        chol.factor(A)
        t2 = time.perf_counter()
        self.Lll = chol.trailing(self.no)
        t3 = time.perf_counter()
        self.chol = chol
        self.stats.update(analyse_s=t1 - t0, factor_s=t2 - t1, extract_s=t3 - t2, spent=chol.spent)

    def _by_blocks(self) -> None:
        t0 = time.perf_counter()
        o = np.flatnonzero(~self._mask)
        K = self.K
        Koo = K[o][:, o]
        Kol = K[o][:, self.last].tocsc()
        fac = Factor(Koo)
        t1 = time.perf_counter()
        S = K[self.last][:, self.last].toarray()
        for j0 in range(0, self.nl, BLOCK):
            cols = slice(j0, min(self.nl, j0 + BLOCK))
            S[:, cols] -= Kol.T @ fac.solve(Kol[:, cols].toarray())
        S = 0.5 * (S + S.T)
        sl = self.s[self.last]
        Ss = S * np.outer(sl, sl) + self.shift * np.eye(self.nl)
        try:
            self.Lll = np.linalg.cholesky(Ss) if self.nl else np.zeros((0, 0))
        except np.linalg.LinAlgError as exn:
            raise SingularMatrixError("the matrix is singular: its Schur complement is not positive definite") \
                from exn
        self._others = fac
        self._o = o
        self.stats.update(factor_s=t1 - t0, extract_s=time.perf_counter() - t1)

    # ------------------------------------------------------------------ the trailing block

    def smallest_eigenvalue(self, iterations: int = 2) -> float:
        """An estimate of the smallest eigenvalue of the equilibrated ``S`` (of ``K``'s, where
        ``K`` is singular: a floating plate's rigid motions show in ``S``): the Rayleigh quotient
        after ``iterations`` inverse iterations with the trailing block (dense triangular solves,
        O(m²) each), from a fixed random start. An upper bound on the smallest eigenvalue;
        measured: 3e-16–5e-16 on floating plates, 7e-8–4e-6 on held ones (64² to 512²)."""
        L = self.Lll
        if L.size == 0:
            return np.inf
        v = np.random.default_rng(0).standard_normal(L.shape[0])
        for _ in range(iterations):
            v = sla.solve_triangular(L, v, lower=True, check_finite=False)
            v = sla.solve_triangular(L, v, lower=True, trans="T", check_finite=False)
            norm = np.linalg.norm(v)
            if not np.isfinite(norm) or norm == 0:
                return 0.0
            v /= norm
        return float(np.linalg.norm(L.T @ v) ** 2)

    def schur(self, equilibrated: bool = False) -> np.ndarray:
        """``S = K_ll − K_lo K_oo⁻¹ K_ol`` (dense, rows and columns in the order of ``last``);
        ``equilibrated``: in the factor's units (``D S D``, ``D = diag(s)`` on ``last``)."""
        L = self.Lll
        S = symmetric_from_lower(sla.blas.dsyrk(1.0, L, lower=1)) if L.size else np.zeros((0, 0))
        if self.shift:
            S[np.diag_indices_from(S)] -= self.shift
        if equilibrated:
            return S
        sl = 1.0 / self.s[self.last]
        return S * np.outer(sl, sl)

    def rows_on_last(self, B) -> sp.csr_matrix:
        """Rows ``B`` (m × n, acting on ``last`` only) as rows on ``last``, equilibrated:
        ``B_l D_l`` (m × len(last), columns in the order of ``last``)."""
        B = sp.csr_matrix(B)
        if np.any(B.data[~self._mask[B.indices]] != 0):
            raise ValueError("the rows act on unknowns that are not ordered last")
        return sp.csr_matrix(B[:, self.last] @ sp.diags(self.s[self.last]))

    def flexibility(self, B, refine: int = 0, shifted: bool = False) -> np.ndarray:
        """``B K⁻¹ Bᵀ`` (dense m × m) for rows ``B`` (m × n, sparse) acting on ``last`` only.

        ``refine = 0``: from the trailing block alone, ``Z = L_ll⁻¹ B_lᵀ``, ``ZᵀZ`` (where each
        row is one unknown and each unknown one row, ``S⁻¹`` by LAPACK's POTRI, rows and
        columns picked and scaled). Backward stable, but as an inverse of ``S`` its relative
        error is about cond(S)·ε. ``refine > 0``: the columns ``K⁻¹ Bᵀ`` by solves with this
        factor in blocks, each refined (exact residuals, plateqp.linalg.residual) to about ε: m solves, for a
        caller that uses ``B K⁻¹ Bᵀ`` as its final data (an exported dual; plateqp.solve's dual
        takes the trailing block's and corrects its answer instead). Measured on a 6 × 6 plate with 34
        supports (cond K 1.8e5): relative error 6e-14 from the trailing block, 1e-16 refined,
        and the dual formulation's KKT natural residual 1.1e-10 against 2e-11.

        ``shifted``: a shifted factor's ``B K̂⁻¹ Bᵀ`` (``K̂ = K + shift·diag(K)`` on ``last``;
        from the trailing block only), which a shifted factor otherwise refuses.
        """
        if self.shift and not (shifted and refine == 0):
            raise ValueError("flexibility needs an unshifted factor (K definite)")
        B = sp.csr_matrix(B)
        Bl = self.rows_on_last(B)
        if refine > 0:
            m = B.shape[0]
            BT = B.T.tocsc()
            G = np.empty((m, m))
            for j0 in range(0, m, BLOCK):
                cols = slice(j0, min(m, j0 + BLOCK))
                G[:, cols] = B @ self.solve(BT[:, cols].toarray(), refine=refine)
            return 0.5 * (G + G.T)
        m = Bl.shape[0]
        if m == 0:
            return np.zeros((0, 0))
        if m == self.nl and np.all(np.diff(Bl.indptr) == 1) and np.unique(Bl.indices).size == m:
            dof, b = Bl.indices, Bl.data
            Sinv = symmetric_from_lower(sla.lapack.dpotri(self.Lll, lower=1)[0])  # (L Lᵀ)⁻¹, from its lower triangle
            if not np.array_equal(dof, np.arange(m)):  # rows in another order than their unknowns
                Sinv = Sinv[np.ix_(dof, dof)]
            Sinv *= np.outer(b, b)
            return Sinv
        Z = sla.solve_triangular(self.Lll, Bl.T.toarray(), lower=True, check_finite=False)
        return symmetric_from_lower(sla.blas.dsyrk(1.0, Z, trans=1, lower=1))

    # ------------------------------------------------------------------ solves

    def _count(self, t0: float) -> None:
        self.stats["solves"] += 1
        self.stats["solve_s"] += time.perf_counter() - t0

    def _raw_full(self, b: np.ndarray) -> np.ndarray:
        """``K̂⁻¹ b`` with the factor itself (``K̂ = K`` + the shift on the trailing diagonal)."""
        t0 = time.perf_counter()
        s = self.s if b.ndim == 1 else self.s[:, None]
        x = s * self.chol.solve(s * b)
        self._count(t0)
        return x

    def solve_shifted(self, b: np.ndarray) -> np.ndarray:
        """``K̂⁻¹ b`` (``K̂ = K + shift·diag(K)`` on ``last``; ``K`` itself if unshifted), one
        solve with the factor itself, unrefined."""
        if self.chol is None or self.chol.spent:
            raise ValueError("solve_shifted needs this factor's own CHOLMOD factor, not spent")
        return self._raw_full(b)

    # the two halves of a solve with ``K = D⁻¹ Pᵀ L Lᵀ P D⁻¹`` (``D = diag(s)``), for a caller
    # that needs only the trailing part of one half: ``y = L⁻¹ P D b`` is in the factor's order,
    # its last ``nl`` entries belong to ``last``; ``(K⁻¹ b)_last = D_l L_ll⁻ᵀ y_l``

    def forward(self, b: np.ndarray) -> np.ndarray:
        """``y = L⁻¹ P D b`` (half a solve with ``K``; ``b`` of shape (n,))."""
        self._usable()
        t0 = time.perf_counter()
        y = self.chol.forward(self.s * b)
        self.stats["solve_s"] += time.perf_counter() - t0
        self.stats["solves"] += 0.5
        return y

    def backward(self, y: np.ndarray) -> np.ndarray:
        """``K⁻¹ b = D Pᵀ L⁻ᵀ y`` for ``y = forward(b)``."""
        self._usable()
        t0 = time.perf_counter()
        x = self.s * self.chol.backward(y)
        self.stats["solve_s"] += time.perf_counter() - t0
        self.stats["solves"] += 0.5
        return x

    def trailing_forward(self, b_last: np.ndarray) -> np.ndarray:
        """``forward(b)[no:]`` for a ``b`` that is zero off ``last`` (``b_last``: its values on
        ``last``): ``L_ll⁻¹ D_l b_l``, a dense triangular solve; the rest of ``forward(b)`` is 0."""
        return sla.solve_triangular(self.Lll, self.s[self.last] * b_last, lower=True, check_finite=False)

    def trailing_backward(self, y_last: np.ndarray) -> np.ndarray:
        """``(K⁻¹ b)[last]`` from ``forward(b)[no:]``: ``D_l L_ll⁻ᵀ y_l``, a dense triangular solve."""
        return self.s[self.last] * sla.solve_triangular(self.Lll, y_last, lower=True, trans=1, check_finite=False)

    @property
    def can_split(self) -> bool:
        """The factor solves in halves (:meth:`forward`, :meth:`backward`): CHOLMOD, unshifted,
        not spent."""
        return self.chol is not None and not self.chol.spent and not self.shift and not self.prox

    def _usable(self) -> None:
        if not self.can_split:
            raise ValueError("forward/backward need this factor's own CHOLMOD factor, unshifted")

    def solve(self, b, refine: int = 0) -> np.ndarray:
        """``K⁻¹ b`` (``b`` of shape (n,) or (n, k)), with ``refine`` refinement steps. With the
        factor itself while it solves; else (a cvxopt factor spent by reading it, or the
        blocks method) from a second factorisation of ``K``, made once."""
        if self.shift or self.prox:
            raise ValueError("solve needs an unshifted factor of K itself (K definite)")
        if self._solver is None:
            if self.chol is not None and not self.chol.spent:
                self._solver = _Solver(self.K, self._raw_full)
            else:
                t0 = time.perf_counter()
                fac = Factor(self.K)
                self.stats["factorisations"] += 1
                self.stats["factor_s"] += time.perf_counter() - t0

                def raw(b, fac=fac):
                    t0 = time.perf_counter()
                    x = fac._raw(b)
                    self._count(t0)
                    return x

                self._solver = _Solver(self.K, raw)
        return self._solver.solve(b, refine=refine)

    def solve_others(self, b, refine: int = 3) -> np.ndarray:
        """``K_oo⁻¹ b`` (``b`` over the unknowns not ordered last, in their own order), with
        ``refine`` refinement steps. With the factor: ``z = K̂⁻¹ (b, 0)``, then
        ``K_oo⁻¹ b = [K̂⁻¹ (b, −Ŝ z_l)]_o`` (``Ŝ = S + shift·I``): two solves."""
        if self._others is None:
            o = np.flatnonzero(~self._mask)
            self._o = o
            if self.chol is not None and not self.chol.spent:
                Koo = self.K[o][:, o].tocsc()
                L = self.Lll
                sl = self.s[self.last]

                def raw(b):
                    two = b.ndim > 1
                    full = np.zeros((self.n,) + b.shape[1:])
                    full[o] = b
                    z = self._raw_full(full)[self.last]
                    zs = z / (sl[:, None] if two else sl)  # equilibrated
                    Sz = L @ (L.T @ zs) / (sl[:, None] if two else sl)  # (S + shift·D⁻²) z, in K's units
                    full[self.last] = -Sz
                    return self._raw_full(full)[o]

                self._others = _Solver(Koo, raw)
            else:
                t0 = time.perf_counter()
                self._others = Factor(self.K[o][:, o])
                self.stats["factorisations"] += 1
                self.stats["factor_s"] += time.perf_counter() - t0
        return self._others.solve(b, refine=refine)

    @property
    def others(self) -> np.ndarray:
        """The unknowns not ordered last, in the order :meth:`solve_others` takes them."""
        return np.flatnonzero(~self._mask)
