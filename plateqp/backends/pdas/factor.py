"""The factor of the sparse method: ``K + σ diag(K) + B_Aᵀ W_A B_A`` kept current as the active set
changes (numeric refactorisation with one analysis, CHOLMOD's rank-k updates, or a Woodbury
correction on the factor in hand; see the package docstring, "The method")."""

from __future__ import annotations

import contextlib
import copy
import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ...errors import ProblemError, SingularMatrixError, SolverError
from ...linalg import Cholesky, Factor, bindings
from ...linalg.pattern import SCALE_BLOCK
from .options import DOWNDATE_LOSS, LOWRANK_COND, LOWRANK_COST, LOWRANK_MAX, SPAN_KEEP, SPAN_TOL

__all__ = ["SpringFactor", "TrailingFactor"]


class SpringFactor:
    """Factor of ``H(w) = K + σ diag(K) + Bᵀ diag(w) B``, kept current as ``w`` changes.

    CHOLMOD: one symbolic analysis of the pattern of ``K + BᵀB`` (equilibrated by
    ``diag(K)^(-1/2)``); changes by numeric refactorisation with that analysis or, with
    scikit-sparse, by rank-k update/downdate, whichever the measured costs say is cheaper.
    Otherwise :class:`plateqp.linalg.Factor` on every change.

    Without an in-place update (cvxopt's CHOLMOD, the default install; or Factor), a few
    changed rows are taken by the Sherman–Morrison–Woodbury formula on the factor in hand
    instead: for ``H(w) = H(w₀) + Uᵀ diag(Δw) U`` (``U`` the changed rows of ``B``),
    ``H(w)⁻¹b = x − Z C⁻¹ U x`` with ``x = H(w₀)⁻¹b``, ``Z = H(w₀)⁻¹Uᵀ`` (one solve with k
    right-hand sides; a column is kept for as long as the factor) and the k × k capacitance
    ``C = diag(1/Δw) + U Z``. It is used while those columns cost less than half a
    factorisation (measured), for at most ``LOWRANK_MAX`` rows (Z is n × k), and while the
    digits it loses, about ``ε Σ |Δw_i| (U Z)_ii`` (Woodbury is not backward stable for a stiff
    row: a rigid row entering or leaving loses ε κ), stay within what a downdate is allowed
    (``DOWNDATE_LOSS``); the exact steps' refinement takes what rounding is left.
    """

    def __init__(self, K: sp.csc_matrix, B: sp.csr_matrix, Kd: np.ndarray, c: np.ndarray,
                 sigma: float, method: str) -> None:
        libs = bindings()
        if method == "auto":
            method = ("cholmod" if "sksparse" in libs else "cvxopt" if "cvxopt" in libs else "linalg")
        if method not in ("cholmod", "cvxopt", "linalg", "superlu"):
            raise ProblemError("option factor must be 'auto', 'cholmod', 'cvxopt', 'linalg' or 'superlu', "
                               f"got {method!r}")
        lib = {"cholmod": "sksparse", "cvxopt": "cvxopt"}.get(method)
        if lib is not None and lib not in libs:
            raise SolverError(f"option factor={method!r}: that CHOLMOD binding is not in use here "
                              f"(plateqp.linalg found: {libs or 'none'})")
        self.method, self._lib = method, lib
        self.chol = Cholesky(lib) if lib else None
        m = B.shape[0]
        self.B, self.c = B, c
        self.s = 1.0 / np.sqrt(Kd)
        Ks = sp.csc_matrix(K)
        Ks.sort_indices()
        # all products B_ia B_ib of each row (their positions found below)
        L = np.diff(B.indptr)
        L2 = L * L
        pr = np.repeat(np.arange(m), L2)
        within = np.arange(L2.sum()) - np.repeat(np.cumsum(L2) - L2, L2)
        ia = B.indptr[pr] + within // L[pr]
        ib = B.indptr[pr] + within % L[pr]
        pair_r, pair_c = B.indices[ia], B.indices[ib]
        pair_val = B.data[ia] * B.data[ib]
        self._touched = None  # the triangle's entries the rows add to, and each product's (_in_place)
        self.pattern_nnz = Ks.nnz  # entries of K + BᵀB's pattern (K's own, stored zeros too, where B lies in it)
        if self.chol is None or not self._triangle(Ks, Kd, sigma, pr, pair_r, pair_c, pair_val):
            self._whole(Ks, Kd, sigma, pr, pair_r, pair_c, pair_val)
        self.order = None  # the triangle's order, where it is kept permuted (_permute)
        if self.chol is not None and self.chol.takes_permuted:
            self._permute()
        self._fresh()

    def _fresh(self) -> None:
        """No factor yet: nothing measured or counted."""
        self.w = None
        self.fac = None  # a plateqp.linalg.Factor (linalg, superlu)
        self.loss = 0.0
        self.t_factor = None  # seconds per numeric factorisation (last measured)
        self.t_row = None  # seconds per updated row (last measured)
        # seconds per solve with one right-hand side: the fastest measured (every solve with this
        # factor's pattern costs the same, and a slow one is the machine's noise: the last one
        # measured sent a five-row change at 64² to a refactorisation once in a test run)
        self.t_solve = None
        self.target = None  # the w solved for: self.w (the factor's) plus the low-rank rows
        self.lr = None  # the low-rank correction in use: (rows, Z columns, U, LU of C)
        # row -> its column of Z (kept while the factor is): with CHOLMOD the forward half
        # L⁻¹ P D B_rᵀ (see :meth:`_columns`), else H(self.w)⁻¹ B_rᵀ
        self._zcols: dict = {}
        self._span = None  # (:meth:`solve_in_span`) the w it holds for, Q, H(w)⁻¹Q
        self.stats = {"analyse_s": 0.0, "factorisations": 0, "factor_s": 0.0, "updates": 0, "updated_rows": 0,
                      "update_s": 0.0, "lowrank": 0, "lowrank_rows": 0, "lowrank_s": 0.0, "solves": 0,
                      "solve_s": 0.0, "span_solves": 0}

    def again(self, c: np.ndarray) -> None:
        """Start a new solve on this factor (kept from a solve before on the same K and B:
        :mod:`plateqp.linalg.keep`), whose rows' springs may differ (``c``, their stiffnesses in
        series: only the downdates' loss reads them): the factor, its ``w`` and its measured
        costs stay; the counts start again."""
        self.c = c
        self.stats = {k: 0 if isinstance(v, int) else 0.0 for k, v in self.stats.items()}

    def twin(self) -> SpringFactor:
        """A second factor of the same ``H(w)`` family (the sparse method's factor of ``K``
        alone beside its active-set one): the pattern, its equilibration and the rows'
        positions are shared, not built again (each refactorisation writes its rows into the
        shared triangle and restores it: :meth:`_in_place`); the factor is its own."""
        other = copy.copy(self)
        other.chol = Cholesky(self._lib) if self._lib else None
        other._fresh()
        return other

    def _triangle(self, Ks, Kd, sigma, pr, pair_r, pair_c, pair_val) -> bool:
        """CHOLMOD's triangle of ``K + σ diag(K)`` equilibrated, and where each product of a
        row's entries adds in it, built on that triangle alone; False where ``B``'s pattern
        does not lie in ``K``'s or the diagonal is not all stored (then :meth:`_whole`). ``K``'s
        columns sorted, each column's part of the triangle is a run of it (up to its diagonal,
        or from it): made a block of columns at a time (SCALE_BLOCK entries), so that no array of
        ``K``'s size is made but the triangle's own (at 512², with ``K``'s masks and a copy of
        its indices, 0.3 GB of fresh pages the kernel zeroed: a fifth of that size's CPU time
        is the kernel's), its indices in CHOLMOD's width as they are copied."""
        n = Ks.shape[0]
        indptr, idx = Ks.indptr, Ks.indices
        counts = np.diff(indptr)
        if np.any(counts == 0) or not Ks.has_sorted_indices:
            return False
        upper = self.chol.upper
        step = max(1, int(n * SCALE_BLOCK // max(int(indptr[-1]), 1)))
        blocks = [(j0, min(n, j0 + step)) for j0 in range(0, n, step)]
        # each column's diagonal: where it is stored, once
        on_diag = np.empty(n, dtype=np.int64)
        for j0, j1 in blocks:
            a, b = int(indptr[j0]), int(indptr[j1])
            hit = np.flatnonzero(idx[a:b] == np.repeat(np.arange(j0, j1, dtype=idx.dtype), counts[j0:j1]))
            if hit.size != j1 - j0:
                return False  # a column without its diagonal stored (or with it twice)
            on_diag[j0:j1] = hit + a
        if np.any(on_diag < indptr[:-1]) or np.any(on_diag >= indptr[1:]):
            return False
        lcount = on_diag - indptr[:-1] + 1 if upper else indptr[1:] - on_diag
        tptr = np.concatenate([[0], np.cumsum(lcount)])
        diag = tptr[1:] - 1 if upper else tptr[:-1]
        li = np.empty(int(tptr[-1]), dtype=np.int64)  # CHOLMOD's width: read, not widened again
        base = np.empty(int(tptr[-1]))
        for j0, j1 in blocks:
            a, b = int(indptr[j0]), int(indptr[j1])
            ta, tb = int(tptr[j0]), int(tptr[j1])
            cols = np.repeat(np.arange(j0, j1, dtype=idx.dtype), counts[j0:j1])
            part = idx[a:b] <= cols if upper else idx[a:b] >= cols
            li[ta:tb] = idx[a:b][part]
            vals = base[ta:tb]
            vals[:] = Ks.data[a:b][part]
            d = diag[j0:j1] - ta
            vals[d] += sigma * Kd[j0:j1]
            # s_i s_j first, as in _whole (to the bit)
            scale = self.s.take(li[ta:tb])
            scale *= np.repeat(self.s[j0:j1], lcount[j0:j1])
            vals *= scale
        inside = pair_r <= pair_c if upper else pair_r >= pair_c  # each off-diagonal pair once
        if np.array_equal(pair_r, pair_c):  # one unknown a row (a bed, posts at nodes): all on the diagonal
            pos = diag[pair_r]
        else:
            keys = np.repeat(np.arange(n, dtype=np.int64), lcount) * n + li
            pk = pair_c[inside].astype(np.int64) * n + pair_r[inside]
            pos = np.minimum(np.searchsorted(keys, pk), keys.size - 1)
            if keys.size == 0 or not np.all(keys[pos] == pk):
                return False
            del keys
        self.base, self.indices, self.indptr = base, li, tptr
        self.pair_row, self.pair_pos = pr[inside], pos
        self.pair_val = pair_val[inside] * (self.s[pair_r[inside]] * self.s[pair_c[inside]])
        self.nnz = base.size
        return True

    def _whole(self, Ks, Kd, sigma, pr, pair_r, pair_c, pair_val) -> None:
        """As :meth:`_triangle` on the whole pattern of ``K + BᵀB`` (for Factor: the whole
        matrix; for CHOLMOD: then its triangle)."""
        n = Ks.shape[0]
        idx = np.int32 if n < 2**31 - 1 else np.int64
        cols = np.repeat(np.arange(n, dtype=idx), np.diff(Ks.indptr))
        keys = cols.astype(np.int64) * n + Ks.indices
        pk = pair_c.astype(np.int64) * n + pair_r
        at = np.minimum(np.searchsorted(keys, pk), keys.size - 1)
        if keys.size and np.all(keys[at] == pk):  # B's pattern lies in K's (rows within one element)
            indptr, indices = Ks.indptr, Ks.indices
            base = Ks.data.astype(float, copy=True)
        else:  # K's stored pattern plus |B|ᵀ|B|: a sum of positives drops no entry, and the
            # ordering reads K's stored zeros (plateqp.linalg.pattern)
            Babs = abs(self.B)
            ones = sp.csc_matrix((np.ones(Ks.nnz), Ks.indices, Ks.indptr), shape=Ks.shape)
            pat = sp.csc_matrix(ones + Babs.T @ Babs)
            pat.sort_indices()
            indptr, indices = pat.indptr, pat.indices
            Kc = Ks.tocoo()
            cols = np.repeat(np.arange(n, dtype=idx), np.diff(indptr))
            keys = cols.astype(np.int64) * n + indices
            base = np.bincount(np.searchsorted(keys, Kc.col.astype(np.int64) * n + Kc.row), weights=Kc.data,
                               minlength=keys.size)
        nnz = keys.size
        base[np.searchsorted(keys, np.arange(n, dtype=np.int64) * (n + 1))] += sigma * Kd
        pair_pos = np.searchsorted(keys, pk)
        del keys
        self.pattern_nnz = nnz
        self.nnz, self.pair_row = nnz, pr
        if self.chol is None:  # plateqp.linalg.Factor: the whole matrix, as it is
            self.indptr, self.indices, self.base = indptr, indices, base
            self.pair_pos, self.pair_val = pair_pos, pair_val
        else:  # CHOLMOD reads one triangle only: that, equilibrated, is all that is kept
            low = np.flatnonzero(indices <= cols if self.chol.upper else indices >= cols)
            scale = self.s[indices[low]] * self.s[cols[low]]
            self.base = base[low] * scale
            self.indices = indices[low].astype(np.int64)  # CHOLMOD's width: read, not widened again
            self.indptr = np.concatenate([[0], np.cumsum(np.bincount(cols[low], minlength=n))])
            where = np.full(nnz, -1, dtype=np.int64)
            where[low] = np.arange(low.size)
            pl = where[pair_pos]
            inside = pl >= 0  # each off-diagonal pair twice in the pattern, once in the triangle
            self.pair_row, self.pair_pos = pr[inside], pl[inside]
            self.pair_val = pair_val[inside] * scale[pl[inside]]
            self.nnz = low.size

    def _permute(self) -> None:
        """The kept triangle made, once, the lower triangle of ``P H Pᵀ`` (``P``: AMD's order of
        its pattern, what CHOLMOD's own analysis starts from) by CHOLMOD's own permuted transpose
        (:meth:`plateqp.linalg.Cholesky.permuted_lower`). CHOLMOD then factorises it where it
        lies at every refactorisation; handed the triangle and an order, it made that permuted
        copy beside the factor each time (45 MB at 256²: :meth:`plateqp.linalg.Cholesky.analyse_permuted`).
        The values are moved, not recomputed: the same matrix, to the bit."""
        n = self.s.size
        T = self._on(self.base)
        order = self.chol.order(T)
        col = np.searchsorted(T.indptr, self.pair_pos, side="right") - 1
        on_diag = np.array_equal(self.pair_pos, T.indptr[1:][col] - 1)  # (an upper column ends at its diagonal)
        if on_diag:  # rows on one unknown each (a bed): the values moved, the rows' positions read off below
            M = self.chol.permuted_lower(T, order)
            self.base = M.data
        else:  # each entry's position as its value: where each new one came from
            M = self.chol.permuted_lower(T, order, np.arange(self.nnz, dtype=float))
            src = M.data.astype(np.int64)
            where = np.empty(self.nnz, dtype=np.int64)
            where[src] = np.arange(self.nnz)
            self.base = self.base.take(src)
        self.chol.forget_matrix()
        del T
        inv = np.empty(n, dtype=np.int64)
        inv[order] = np.arange(n)
        self.indices, self.indptr = M.indices, M.indptr
        # on the diagonal: the first entry of a sorted lower column
        self.pair_pos = M.indptr[inv[col]] if on_diag else where.take(self.pair_pos)
        self._touched = None
        self.order = order

    def _matrix(self, w: np.ndarray) -> sp.csc_matrix:
        """``H(w)``: with CHOLMOD, one triangle of it, equilibrated; else the whole matrix."""
        data = self.base + np.bincount(self.pair_pos, weights=w[self.pair_row] * self.pair_val,
                                       minlength=self.nnz)
        return self._on(data)

    def _on(self, data: np.ndarray) -> sp.csc_matrix:
        """The pattern with the values ``data``."""
        n = self.s.size
        H = sp.csc_matrix((n, n))  # the pattern's arrays set, not passed: SciPy would narrow them (a copy)
        H.data, H.indices, H.indptr = data, self.indices, self.indptr
        H.has_sorted_indices = True  # the pattern's columns were sorted when it was built: not checked again
        return H

    @contextlib.contextmanager
    def _in_place(self, w: np.ndarray):
        """``H(w)`` on :attr:`base`'s own array for the length of the block (CHOLMOD reads it
        there: no second array of the triangle's values), the entries the rows add to restored
        after it. The same values, to the bit, as :meth:`_matrix`: each entry's products are
        summed in the same order, then added once."""
        if self._touched is None:
            self._touched = np.unique(self.pair_pos, return_inverse=True)
        at, which = self._touched
        kept = self.base[at]
        self.base[at] += np.bincount(which, weights=w[self.pair_row] * self.pair_val, minlength=at.size)
        try:
            yield self._on(self.base)
        finally:
            self.base[at] = kept

    def refactor(self, w: np.ndarray) -> None:
        t0 = time.perf_counter()
        if self.chol is not None:
            with self._in_place(w) as H:
                if self.chol.sym is None:
                    if self.order is None:
                        self.chol.analyse(H)
                    else:
                        self.chol.analyse_permuted(H, self.order)
                    t1 = time.perf_counter()
                    self.stats["analyse_s"] += t1 - t0
                    t0 = t1
                try:
                    self.chol.factor(H)
                except SingularMatrixError as exn:
                    raise SolverError(f"pdas: the active-set matrix is not positive definite ({exn}); is P "
                                      "positive semidefinite?") from exn
        else:  # plateqp.linalg.Factor: its own choice of library, or SuperLU; analysis not re-used
            try:
                self.fac = Factor(self._matrix(w), method="auto" if self.method == "linalg" else "superlu")
            except Exception as exn:
                raise SolverError(f"pdas: the active-set matrix could not be factorised ({exn})") from exn
        dt = time.perf_counter() - t0
        self.t_factor = dt
        self.stats["factorisations"] += 1
        self.stats["factor_s"] += dt
        self.w = w.copy()
        self.target = self.w
        self.loss = 0.0
        self.lr = None
        self._zcols = {}

    def set(self, w: np.ndarray) -> None:
        """Make the factor that of ``H(w)``."""
        if self.w is None:
            self.refactor(w)
            return
        if self.target is not None and np.array_equal(w, self.target):
            return
        dw = w - self.w
        changed = np.flatnonzero(dw)
        if changed.size == 0:  # back to the factor's own w: the correction is dropped
            self.lr, self.target = None, self.w
            return
        down = changed[dw[changed] < 0]
        loss = self.loss + np.finfo(float).eps * np.sum(-dw[down] / self.c[down])
        if self.chol is None or not self.chol.can_update:
            if not self._low_rank(w, dw, changed, loss):
                self.refactor(w)
            return
        t_row = self.t_row if self.t_row is not None else self.t_factor / 400.0
        if changed.size * t_row > 0.7 * self.t_factor or loss > DOWNDATE_LOSS:
            self.refactor(w)
            return
        t0 = time.perf_counter()
        up = changed[dw[changed] > 0]
        for rows, subtract in ((up, False), (down, True)):  # updates first: stays definite
            if rows.size:
                C = (self.B[rows].T.tocsc() @ sp.diags(np.sqrt(np.abs(dw[rows])))).tocsc()
                C = sp.diags(self.s) @ C
                self.chol.update(sp.csc_matrix(C), subtract)
        dt = time.perf_counter() - t0
        self.t_row = dt / changed.size
        self.stats["updates"] += 1
        self.stats["updated_rows"] += int(changed.size)
        self.stats["update_s"] += dt
        self.w = w.copy()
        self.target = self.w
        self.loss = loss

    def _low_rank(self, w: np.ndarray, dw: np.ndarray, changed: np.ndarray, loss: float) -> bool:
        """Take ``w`` as the factor's ``w`` plus a Woodbury correction on the ``changed`` rows,
        if that is cheaper than a factorisation and keeps its digits (see the class); False:
        refactorise instead."""
        k = changed.size
        if k > LOWRANK_MAX or loss > DOWNDATE_LOSS:  # first: a first phase changes thousands of rows
            return False
        new = np.array([r for r in changed.tolist() if r not in self._zcols], dtype=np.int64)
        t_solve = self.t_solve if self.t_solve is not None else self.t_factor / 10.0
        # k right-hand sides in one block solve cost about 1 + (k − 1)/5 solves (measured on the
        # benchmark bed's factor through cvxopt's CHOLMOD, medians of 5: k = 2, 4, 8, 16 cost
        # 1.3-1.5, 1.5-1.7, 2.0-2.2, 3.0-3.6 solves at 64²-256²); "half a solve each" before
        # sent 8 rows at 128² to a refactorisation (0.095 s) instead of a block solve (0.024 s)
        if new.size and t_solve * (1.0 + (new.size - 1) / 5.0) > LOWRANK_COST * self.t_factor:
            return False
        t0 = time.perf_counter()
        if new.size:
            Znew = self._columns(self.B[new].T.toarray(order="F"))  # CHOLMOD's layout: not copied again
            for j, r in enumerate(new.tolist()):
                self._zcols[r] = Znew[:, j]  # a view: the block stays one array
            self.stats["solves"] += 1
        if new.size == k:  # every column is the new block's, in order: that block is Z
            Z = Znew
        else:  # the columns gathered into one array, which they then live in: no block kept beside it
            Z = np.column_stack([self._zcols[r] for r in changed.tolist()])
            for j, r in enumerate(changed.tolist()):
                self._zcols[r] = Z[:, j]
        U = self.B[changed]
        C = Z.T @ Z if self.chol is not None else U @ Z  # U H(w₀)⁻¹ Uᵀ either way
        # Woodbury is not backward stable for a stiff row: U x comes out with an absolute error
        # of about ε |Δw_i| (U H⁻¹ Uᵀ)_ii relative to x, which the row's weight then multiplies
        # into the residual (a rigid row added: ε κ, ~1e-7 of the load); and where H is nearly
        # singular along a rigid motion the row moves, (U H⁻¹ Uᵀ)_ii is huge. Both lose digits:
        loss = loss + np.finfo(float).eps * float(np.abs(dw[changed] * np.diag(C)).sum())
        C[np.diag_indices(k)] += 1.0 / dw[changed]
        ok = bool(np.all(np.isfinite(C))) and loss <= DOWNDATE_LOSS
        if ok:
            # a capacitance near singular (H(w) itself near singular, or cancellation): refactorise
            sv = np.linalg.svd(C, compute_uv=False)
            ok = sv[-1] > LOWRANK_COND * sv[0]
        if not ok:
            return False
        self.lr = (changed, Z, U, sla.lu_factor(C, check_finite=False))
        self.target = w.copy()
        dt = time.perf_counter() - t0
        self.stats["lowrank"] += 1
        self.stats["lowrank_rows"] += int(k)
        self.stats["lowrank_s"] += dt
        return True

    @property
    def clean(self) -> bool:
        """The factor is of ``H(w)`` itself: no downdate's loss, no low-rank correction."""
        return self.loss == 0.0 and self.lr is None

    def _solve(self, b: np.ndarray) -> np.ndarray:
        """``H(self.w)⁻¹ b`` with the factor (``b`` of shape (n,) or (n, k))."""
        if self.chol is not None:
            s = self.s if b.ndim == 1 else self.s[:, None]
            return s * self.chol.solve(s * b)
        return self.fac.solve(b, refine=0)

    def _columns(self, Ut: np.ndarray) -> np.ndarray:
        """The Woodbury columns of the rows ``Ut`` (n × k). With CHOLMOD (``H(w₀) = D⁻¹ Pᵀ L Lᵀ P
        D⁻¹``, ``D = diag(s)``), ``Y = L⁻¹ P D Uᵀ``: the forward half of a solve only (half the
        block solve's time), since ``U H(w₀)⁻¹ Uᵀ = YᵀY`` and ``H(w)⁻¹ b = D Pᵀ L⁻ᵀ (y − Y C⁻¹
        Yᵀ y)`` with ``y = L⁻¹ P D b`` (:meth:`solve`). Else ``Z = H(w₀)⁻¹ Uᵀ``."""
        if self.chol is not None:
            Ut *= self.s[:, None]  # in place: the caller's array is made for this
            return self.chol.forward(Ut, overwrite=True)
        return self._solve(Ut)

    def solve_in_span(self, b: np.ndarray) -> np.ndarray:
        """``H(target)⁻¹ b`` (one right-hand side), recycling the solves before it on the same
        ``H``: the right-hand sides solved are kept as an orthonormal basis ``Q`` (at most
        SPAN_KEEP columns) with ``H⁻¹Q``; ``b``'s part in their span costs no solve, the rest one
        solve, whose direction joins the basis. A sweep's values on a kept factor ask for
        ``f + t df`` or ``f + Bᵀ diag(w)(g + t dg)``: after two solves, none (the span is two
        vectors). On an orthonormal basis the combination cannot cancel (its coefficients are at
        most ‖b‖₂), so it is as accurate as a solve: each column's error is a solve's, summed
        with weights of at most ‖b‖₂. The basis is dropped when ``H`` changes (``target``)."""
        b = np.asarray(b, dtype=float)
        span = self._span
        if span is None or span[0] is not self.target or span[1].shape[1] >= SPAN_KEEP:
            span = self._span = (self.target, np.zeros((b.size, 0)), np.zeros((b.size, 0)))
        _, Q, X = span
        alpha = Q.T @ b
        r = b - Q @ alpha
        extra = Q.T @ r  # twice is enough (Gram–Schmidt's loss of orthogonality)
        r -= Q @ extra
        alpha += extra
        x = X @ alpha
        size = float(np.linalg.norm(r))
        if not np.isfinite(size):  # nothing to keep: solved as it is
            return self.solve(b)
        if size <= SPAN_TOL * np.linalg.norm(b):
            self.stats["span_solves"] += 1
            return x
        q = r / size
        xq = self.solve(q)
        self._span = (self.target, np.column_stack([Q, q]), np.column_stack([X, xq]))
        return x + size * xq

    def solve(self, b: np.ndarray) -> np.ndarray:
        t0 = time.perf_counter()
        if self.lr is not None and self.chol is not None:  # in the factor's own terms (see _columns)
            _, Y, _, lu = self.lr
            s = self.s if b.ndim == 1 else self.s[:, None]
            y = self.chol.forward(s * b)
            y -= Y @ sla.lu_solve(lu, Y.T @ y, check_finite=False)
            x = s * self.chol.backward(y)
        else:
            x = self._solve(b)
        if self.lr is not None and self.chol is None:
            _, Z, U, lu = self.lr
            x = x - Z @ sla.lu_solve(lu, U @ x, check_finite=False)
        self.stats["solves"] += 1
        dt = time.perf_counter() - t0
        self.stats["solve_s"] += dt
        if self.lr is None:
            self.t_solve = dt if self.t_solve is None else min(self.t_solve, dt)
        return x


class TrailingFactor:
    """Factor of ``H(w) = K + σ diag(K) + Bᵀ diag(w) B`` (:class:`SpringFactor`'s matrix) from the
    anchored plate's contacts-last factorisation, for the sparse method's exact steps on a
    floating plate.

    ``schur`` (:class:`plateqp.linalg.SchurFactor`, made with ``prox=σ``) factorises
    ``K̂ = K + σ diag(K)`` with the dofs ``c`` the rows act on ordered last and ``shift·I`` added
    on their (equilibrated) diagonal: with ``P K̂ Pᵀ = L Lᵀ``, ``L_oo L_ooᵀ = K̂_oo`` is the plate
    with those dofs held, and ``L_cc L_ccᵀ = S + shift·I`` (``S`` the Schur complement of ``K̂``
    on ``c``). ``H(w)`` differs from ``K̂`` on ``c`` only, so its factor is ``L`` with the
    trailing block replaced by the Cholesky factor of ``S_w = S + B_cᵀ diag(w) B_c`` (dense,
    ``|c|³/3`` flops a set; no sparse analysis or factorisation at all): a solve is ``L``'s
    forward half, ``z_c = L_cc y_c``, ``x_c = S_w⁻¹ z_c``, ``y_c = L_ccᵀ x_c``, ``L``'s backward
    half. Where the active rows leave a rigid motion ``v`` free, ``H(w) v = σ diag(K) v``
    exactly, as with :class:`SpringFactor` (the first correction, the hold check and the
    free motion's sharpening rest on that). The same interface as :class:`SpringFactor`
    (``set``, ``solve``, ``refactor``, ``clean``, ``stats``) for :func:`.exact.run_sparse`;
    exact, so ``clean``.
    """

    method = "trailing"

    def __init__(self, schur, B: sp.csr_matrix) -> None:
        if schur.chol is None or schur.chol.spent:
            raise ValueError("TrailingFactor needs the SchurFactor's own CHOLMOD factor, not spent")
        if not schur.prox > 0:
            raise ValueError("TrailingFactor needs a SchurFactor made with prox = σ > 0")
        self.schur = schur
        self.S = schur.schur(equilibrated=True)  # the Schur complement of K + σ diag(K)
        self.Bc = schur.rows_on_last(B)  # the rows on the trailing dofs, equilibrated
        self.w = self.target = None
        self.t_factor = None
        self._cho = None
        # no sparse factorisation of its own: its dense ones are counted apart
        self.stats = {"analyse_s": 0.0, "factorisations": 0, "factor_s": 0.0, "trailing_factorisations": 0,
                      "trailing_s": 0.0, "solves": 0, "solve_s": 0.0}

    clean = True  # the factor is always H(w)'s own

    def refactor(self, w: np.ndarray) -> None:
        t0 = time.perf_counter()
        rows = np.flatnonzero(w)
        Sw = self.S.copy()
        if rows.size:
            Br = self.Bc[rows]
            Sw += (Br.T @ sp.diags(w[rows]) @ Br).toarray()
        try:
            self._cho = sla.cho_factor(Sw, lower=True, overwrite_a=True, check_finite=False)
        except np.linalg.LinAlgError as exn:
            raise SolverError(f"pdas: the active-set matrix is not positive definite ({exn})") from exn
        dt = time.perf_counter() - t0
        self.t_factor = dt
        self.stats["trailing_factorisations"] += 1
        self.stats["trailing_s"] += dt
        self.w = self.target = w.copy()

    def set(self, w: np.ndarray) -> None:
        """Make the factor that of ``H(w)``."""
        if self.w is None or not np.array_equal(w, self.w):
            self.refactor(w)

    def solve(self, b: np.ndarray) -> np.ndarray:
        t0 = time.perf_counter()
        sf = self.schur
        s = sf.s if b.ndim == 1 else sf.s[:, None]
        y = sf.chol.forward(s * b)
        L, no = sf.Lll, sf.no
        z = L @ y[no:]  # = (P D b)_c − L_co y_o
        y[no:] = L.T @ sla.cho_solve(self._cho, z, check_finite=False)
        x = s * sf.chol.backward(y)
        self.stats["solves"] += 1
        self.stats["solve_s"] += time.perf_counter() - t0
        return x
