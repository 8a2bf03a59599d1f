"""CHOLMOD through the bindings that install: scikit-sparse, or the copy inside cvxopt's wheels.

The one module of plateqp that imports them. :class:`Cholesky` is one sparse Cholesky factor
``A = L Lᵀ`` with the calls the rest of :mod:`plateqp.linalg` needs: a fill-reducing (AMD)
order, the symbolic analysis (once, with CHOLMOD's ordering or a given one; every numeric
factorisation of the same pattern re-uses it), the numeric factorisation, solves with many
right-hand sides, whole or in halves (``forward``: ``L⁻¹ P b``; ``backward``: ``Pᵀ L⁻ᵀ y``),
the trailing block ``L[k:, k:]`` of the factor, and (scikit-sparse only) rank-k update and
downdate. Matrices are
SciPy CSC holding the lower triangle, all CHOLMOD reads (or the upper one where
:attr:`Cholesky.upper`: the seam, which takes either).

CHOLMOD inside cvxopt's wheels is called through its C API (ctypes, :mod:`plateqp.linalg.seam`) where its
library and the layout of ``cholmod_common`` are the ones checked (CHOLMOD 3, as cvxopt 1.3
ships it): CHOLMOD then reads the NumPy arrays of one triangle in place, with no cvxopt
matrix built (0.15 s of a 1.3 s factorisation at 256²), and each factor has its own workspace.
There a triangle can also be handed already permuted (:meth:`Cholesky.permuted_lower`, then
:meth:`Cholesky.analyse_permuted`): CHOLMOD factorises it where it lies, where handed a triangle
and an order it makes a permuted copy of it beside the factor. Elsewhere, or with :data:`plateqp.linalg.seam.SEAM` set False, cvxopt's own binding is used, as
below.

Reading the factor: cvxopt's only call for it, ``cholmod.getfactor``, hands the numeric factor
over to the matrix it returns and leaves a symbolic one that no longer solves. So the trailing
block is copied straight out of CHOLMOD's factor structure instead (:func:`_cvx_trailing`,
through ``ctypes``; the fields of ``cholmod_factor`` have kept their order since CHOLMOD 1.0)
and checked against a solve with the factor; if that check fails (another build, another
layout), ``getfactor`` is the fallback and the factor is spent (:attr:`Cholesky.spent`).
"""

from __future__ import annotations

import contextlib
import ctypes
import threading
import warnings

import numpy as np
import scipy.sparse as sp

from ..errors import SingularMatrixError
from . import heap
from .seam import _Direct, _seam, _stype
from .seam import view as _view

try:  # optional, faster where it installs
    import sksparse.cholmod as _sk  # type: ignore

    HAVE_SKSPARSE = True
except Exception:  # pragma: no cover - depends on the machine
    HAVE_SKSPARSE = False

#: cvxopt's CHOLMOD keeps one global workspace (its ``Common``) and one global options dict, so
#: two threads in it at once (a Dask cluster of threads, a thread pool) corrupt each other:
#: measured, a threaded LocalCluster left later symbolic analyses failing in the same process.
#: Every call into it holds this lock (re-entrant: an options block holds it around its calls).
_CVX_LOCK = threading.RLock()


class _Locked:
    """A module whose callables run under :data:`_CVX_LOCK`."""

    def __init__(self, module) -> None:
        self._module = module

    def __getattr__(self, name):
        attr = getattr(self._module, name)
        if not callable(attr):
            return attr

        def call(*args, **kwargs):
            with _CVX_LOCK:
                return attr(*args, **kwargs)

        return call


try:  # optional: CHOLMOD as shipped inside cvxopt's wheels (plateqp[solvers] installs it)
    from cvxopt import amd as _cvx_amd_module  # type: ignore
    from cvxopt import cholmod as _cvx_cholmod_module

    _cvx_amd, _cvx_cholmod = _Locked(_cvx_amd_module), _Locked(_cvx_cholmod_module)
    from cvxopt import matrix as _cvx_matrix
    from cvxopt import spmatrix as _cvx_spmatrix

    HAVE_CVXOPT = True
except Exception:  # pragma: no cover - depends on the machine
    HAVE_CVXOPT = False

LIBS = ("sksparse", "cvxopt")


@contextlib.contextmanager
def _cvx_options(**kw):
    """cvxopt's CHOLMOD options are one global dict: set them for one call, then restore (under
    :data:`_CVX_LOCK`, so no other thread's call sees them)."""
    with _CVX_LOCK:
        old = dict(_cvx_cholmod.options)
        _cvx_cholmod.options.update(kw)
        try:
            yield
        finally:
            _cvx_cholmod.options.clear()
            _cvx_cholmod.options.update(old)


@contextlib.contextmanager
def _sk_quiet():
    """scikit-sparse warns when it converts a matrix's index or value type: expected here."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", _sk.CholmodTypeConversionWarning)
        yield


def lower(K: sp.spmatrix, s: np.ndarray | None = None, perm: np.ndarray | None = None,
          upper: bool = False) -> sp.csc_matrix:
    """Lower triangle of ``(S K S)[perm][:, perm]``, ``S = diag(s)``, in O(nnz) (CSC); ``K``
    symmetric. Without ``perm`` the entries are kept in ``K``'s own column order (no sort).
    ``upper``: the upper triangle instead (what CHOLMOD reads without transposing it first:
    its numeric factorisation took 0.90 s instead of 0.97 s at 256², the same factor)."""
    K = sp.csc_matrix(K)
    n = K.shape[0]
    col = np.repeat(np.arange(n, dtype=K.indices.dtype), np.diff(K.indptr))  # K's own index width
    row = K.indices
    if perm is None:
        # the kept positions once (take, not three boolean masks); each column's count from
        # where its bounds fall among them (n binary searches, not a bincount over nnz);
        # the column's scale by repeat, not a gather: 5 ms against 9 ms at 128²
        keep = np.flatnonzero(row <= col if upper else row >= col)
        indptr = np.searchsorted(keep, K.indptr).astype(np.int64)
        rows = row.take(keep)
        data = K.data.take(keep)
        if s is not None:
            w = s.take(rows)
            w *= np.repeat(s, np.diff(indptr))
            data *= w  # s_i s_j first, as before: the same rounding for (i, j) and (j, i)
        out = sp.csc_matrix((data, rows, indptr), shape=(n, n))
        out.has_sorted_indices = K.has_sorted_indices
        return out
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    r, c = inv[row], inv[col]
    keep = r <= c if upper else r >= c
    data = K.data[keep]
    if s is not None:
        data = data * s[row[keep]] * s[col[keep]]
    return sp.csc_matrix((data, (r[keep], c[keep])), shape=(n, n))


def permute_lower(A: sp.csc_matrix, perm: np.ndarray) -> sp.csc_matrix:
    """The lower triangle of ``P (A + Aᵀ − diag A) Pᵀ`` from the lower triangle ``A``."""
    A = A.tocoo()
    n = A.shape[0]
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    r, c = inv[A.row], inv[A.col]
    return sp.csc_matrix((A.data, (np.maximum(r, c), np.minimum(r, c))), shape=(n, n))


class Cholesky:
    """One sparse Cholesky factor through a CHOLMOD binding.

    Parameters
    ----------
    lib : "sksparse" or "cvxopt"

    ``analyse`` once, then ``factor`` any matrix of that pattern (or a sub-pattern) as often as
    needed; ``solve``, ``trailing``, ``update`` act on the last numeric factor.
    """

    def __init__(self, lib: str) -> None:
        if lib not in LIBS:
            raise ValueError(f"unknown CHOLMOD binding {lib!r}; choose one of {LIBS}")
        if not {"sksparse": HAVE_SKSPARSE, "cvxopt": HAVE_CVXOPT}[lib]:
            raise ValueError(f"the CHOLMOD binding {lib!r} is not installed")
        self.lib = lib
        self.sym = None  # scikit-sparse: the analysis; cvxopt: the factor object itself
        self.F = None
        self.spent = False  # cvxopt: the numeric factor was handed to getfactor (no more solves)
        self.given = None  # scikit-sparse: an order given to analyse (applied to A and b here)
        self.vorder = None  # the matrix came permuted (analyse_permuted): the order applied to b here
        self._last = (None, None)  # cvxopt: the last matrix converted, and its conversion
        seam = _seam() if lib == "cvxopt" else None
        self.direct = _Direct(seam) if seam is not None else None  # CHOLMOD's C API, no conversion

    @property
    def upper(self) -> bool:
        """Hand this factor the upper triangle (``lower(..., upper=True)``) rather than the lower
        one: CHOLMOD through the seam reads that without transposing it (it takes either)."""
        return self.direct is not None

    @property
    def can_update(self) -> bool:
        """Rank-k update/downdate in place (scikit-sparse only)."""
        return self.lib == "sksparse" and self.F is not None

    def _cvx(self, A: sp.csc_matrix):
        if self._last[0] is A:
            return self._last[1]
        key = A
        if _stype(A) == 1:  # an upper triangle (made for the seam): cvxopt reads the lower one
            A = sp.csc_matrix(A.T)
        cols = np.repeat(np.arange(A.shape[0], dtype=np.int64), np.diff(A.indptr))
        out = _cvx_spmatrix(_cvx_matrix(A.data.astype(float)), _cvx_matrix(A.indices.astype(np.int64)),
                            _cvx_matrix(cols), A.shape)
        self._last = (key, out)
        return out

    def _sk_matrix(self, A: sp.csc_matrix) -> sp.csc_matrix:
        return A if self.given is None else permute_lower(A, self.given)

    def order(self, A: sp.csc_matrix) -> np.ndarray:
        """A fill-reducing (AMD) order of the pattern of ``A`` (lower triangle)."""
        if self.direct is not None:
            return self.direct.order(A)
        if self.lib == "sksparse":
            with _sk_quiet():
                return _sk.analyze(A, mode="supernodal", ordering_method="amd").P()
        return np.array(_cvx_amd.order(self._cvx(A), uplo="L"), dtype=np.int64).ravel()

    def analyse(self, A: sp.csc_matrix, natural: bool = False, order: np.ndarray | None = None) -> None:
        """Symbolic analysis of the pattern of ``A``: CHOLMOD's own ordering; with ``natural``
        the order ``A`` comes in (for an order given by permuting ``A``); with ``order`` that
        order, exactly (no postordering): the factor is of ``A[order][:, order]`` while the
        solves take and give vectors in ``A``'s own order."""
        n = A.shape[0]
        self.F, self.spent, self.given, self.vorder = None, False, None, None
        if order is not None:
            order = np.asarray(order, dtype=np.int64)
        if self.direct is not None:
            try:
                self.direct.analyse(A, np.arange(n, dtype=np.int64) if natural and order is None else order)
            except OSError:  # CHOLMOD did not keep the order: not the layout checked; the binding instead
                self.direct = None
            else:
                self.sym = self.direct.L
                return
        if self.lib == "sksparse":
            self.given = order
            with _sk_quiet():
                self.sym = _sk.analyze(self._sk_matrix(A), mode="supernodal",
                                       ordering_method="natural" if (natural or order is not None) else "default")
            return
        if natural or order is not None:  # CHOLMOD would postorder even a given order
            p = np.arange(n, dtype=np.int64) if order is None else order
            with _cvx_options(nmethods=1, postorder=False):
                self.sym = _cvx_cholmod.symbolic(self._cvx(A), p=_cvx_matrix(p))
        else:
            self.sym = _cvx_cholmod.symbolic(self._cvx(A))

    @property
    def takes_permuted(self) -> bool:
        """:meth:`analyse_permuted` is what this factor prefers: the seam, which then factorises
        the matrix in place (no copy of it inside CHOLMOD)."""
        return self.direct is not None

    def analyse_permuted(self, A: sp.csc_matrix, order: np.ndarray) -> None:
        """Symbolic analysis of ``A``, the lower triangle of a matrix ``M`` already permuted:
        ``A = tril(M[order][:, order])`` (:func:`lower` with ``perm=order``), in that order
        exactly. The solves still take and give vectors in ``M``'s order (permuted here);
        :meth:`forward`, :meth:`backward` and :meth:`trailing` work in ``order``, as with
        ``analyse(M, order=order)``. Through the seam CHOLMOD then factorises the triangle where
        it lies: handed ``M``'s triangle and an order, it makes a permuted copy of it for the
        numeric factorisation (45 MB at 256², beside a 254 MB factor)."""
        if self.direct is None or _stype(A) != -1:
            raise ValueError("analyse_permuted needs the seam and a lower triangle")
        self.analyse(A, natural=True)  # (where the seam gives up, the binding analyses A as it comes)
        self.vorder = np.asarray(order, dtype=np.int64)

    def permuted_lower(self, A: sp.csc_matrix, order: np.ndarray, values: np.ndarray | None = None) -> sp.csc_matrix:
        """``tril(M[order][:, order])`` from ``A``, the upper triangle of a symmetric ``M``
        (``values``: in place of ``A``'s, one per stored entry), for :meth:`analyse_permuted`;
        by CHOLMOD's own permuted transpose, through the seam only."""
        if self.direct is None:
            raise ValueError("permuted_lower needs the seam")
        return self.direct.permuted_lower(A, order, A.data if values is None else values)

    def forget_matrix(self) -> None:
        """Let go of the last matrix handed to :meth:`order` (the seam keeps its widened
        pattern for the analysis of the same matrix)."""
        if self.direct is not None:
            self.direct.forget()
        self._last = (None, None)

    def _to_factor(self, b: np.ndarray) -> np.ndarray:
        return b if self.vorder is None else np.asarray(b, dtype=float)[self.vorder]

    def _from_factor(self, x: np.ndarray) -> np.ndarray:
        if self.vorder is None:
            return x
        out = np.empty_like(x)
        out[self.vorder] = x
        return out

    def factor(self, A: sp.csc_matrix) -> None:
        """Numeric factorisation with the analysis; SingularMatrixError if ``A`` is not
        positive definite (``column``: where it stopped, in the factor's order)."""
        if self.sym is None:
            self.analyse(A)
        if self.F is None and A.nnz >= heap.RELEASE_FROM:  # the factor is allocated now: the heap's
            heap.release()  # freed memory goes back to the system first (plateqp.linalg.heap)
        if self.direct is not None:
            self.direct.factor(A)
            self.F = self.sym
            return
        if self.lib == "sksparse":
            try:
                with _sk_quiet():
                    self.F = self.sym.cholesky(self._sk_matrix(A))
            except _sk.CholmodNotPositiveDefiniteError as exn:
                col = getattr(exn, "column", None)
                raise SingularMatrixError(f"the matrix is not positive definite ({exn})", col) from exn
            return
        try:
            _cvx_cholmod.numeric(self._cvx(A), self.sym)
        except ArithmeticError as exn:
            col = int(str(exn)) if str(exn).strip().isdigit() else None
            raise SingularMatrixError(f"the matrix is not positive definite (CHOLMOD stopped at column {exn} "
                                      "of its elimination order)", col) from exn
        self.F, self.spent = self.sym, False
        self._last = (None, None)  # the conversion is not needed any more

    def _check(self) -> None:
        if self.spent:
            raise RuntimeError("this cvxopt factor was read by getfactor and no longer solves")

    def _cvx_solve(self, b: np.ndarray, systems) -> np.ndarray:
        if self.direct is not None:
            return self.direct.solve(b, systems)
        b = np.asarray(b, dtype=float)
        B = _cvx_matrix(b.reshape(b.shape[0], -1).copy())
        for sys_ in systems:
            _cvx_cholmod.solve(self.F, B, sys=sys_)
        return np.array(B).reshape(b.shape)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A⁻¹ b`` for ``b`` of shape (n,) or (n, k) (the factor's permutation applied inside)."""
        self._check()
        if self.lib == "sksparse":
            if self.given is not None:
                x = np.empty_like(b, dtype=float)
                with _sk_quiet():
                    x[self.given] = self.F.solve_A(np.asarray(b, dtype=float)[self.given])
                return x
            with _sk_quiet():
                return self.F.solve_A(b)
        return self._from_factor(self._cvx_solve(self._to_factor(b), (0,)))

    def forward(self, b: np.ndarray, overwrite: bool = False) -> np.ndarray:
        """``y = L⁻¹ P b`` (``A = Pᵀ L Lᵀ P``): half a solve, ``y`` in the factor's order.
        ``overwrite``: ``b`` (float, (n, k) in Fortran order) may be permuted in place, a column
        at a time, rather than copied (for a caller whose block is made for this solve)."""
        self._check()
        if self.lib == "sksparse":
            b = np.asarray(b, dtype=float)
            with _sk_quiet():
                pb = self.F.apply_P(b if self.given is None else b[self.given])
                return self.F.solve_L(pb, use_LDLt_decomposition=False)
        if self.vorder is not None:  # CHOLMOD's own order is the natural one
            if overwrite and b.ndim == 2 and b.dtype == np.float64 and b.flags.f_contiguous:
                for j in range(b.shape[1]):
                    b[:, j] = b[self.vorder, j]
                return self._cvx_solve(b, (4,))
            return self._cvx_solve(self._to_factor(b), (4,))
        return self._cvx_solve(b, (7, 4))  # cvxopt's sys: 7 P, 4 L

    def backward(self, y: np.ndarray) -> np.ndarray:
        """``x = Pᵀ L⁻ᵀ y``: the other half; ``backward(forward(b)) = A⁻¹ b``."""
        self._check()
        if self.lib == "sksparse":
            with _sk_quiet():
                x = self.F.apply_Pt(self.F.solve_Lt(np.asarray(y, dtype=float), use_LDLt_decomposition=False))
            if self.given is None:
                return x
            out = np.empty_like(x)
            out[self.given] = x
            return out
        if self.vorder is not None:
            return self._from_factor(self._cvx_solve(y, (5,)))
        return self._cvx_solve(y, (5, 8))  # 5 Lᵀ, 8 Pᵀ

    def trailing(self, no: int) -> np.ndarray:
        """The trailing block ``L[no:, no:]`` of the factor ``A = L Lᵀ`` (in the factor's order:
        after a natural-order analysis or with a given order), dense. With cvxopt it is copied
        out of the factor, which then still solves; only if that copy fails its check is the
        factor read by ``getfactor`` and spent."""
        if self.lib == "sksparse":
            return self.F.L()[no:, no:].toarray()
        if self.direct is not None:
            out = _trailing_at(self.direct.L.value, no)
            if out is None or not self._trailing_checks(out, no):
                raise SingularMatrixError("the factor's trailing block failed its check against a solve "
                                          "(the matrix is near singular, or the factor is not laid out as read)")
            return out
        try:
            out = _cvx_trailing(self.F, no)
        except (ValueError, OSError, AttributeError):
            out = None
        if out is not None and self._trailing_checks(out, no):
            return out
        G = _cvx_cholmod.getfactor(self.F)
        self.spent = True
        colptr, rowind, vals = (np.asarray(memoryview(v)).ravel() for v in G.CCS)  # no copies
        n = G.size[0]
        start = int(colptr[no])
        cols = np.repeat(np.arange(n - no), np.diff(colptr[no:]))
        out = np.zeros((n - no, n - no))
        out[rowind[start:] - no, cols] = vals[start:]
        return out

    def _trailing_checks(self, T: np.ndarray, no: int) -> bool:
        """The factor's own forward solve agrees with the block read: in the factor's order,
        ``L⁻¹ (0, v) = (0, T⁻¹ v)`` (the trailing block is the Schur complement's factor)."""
        k = T.shape[0]
        if k == 0:
            return True
        if not np.all(np.isfinite(T)) or np.any(np.diagonal(T) <= 0):
            return False
        v = np.random.default_rng(0).standard_normal(k)
        y = self._cvx_solve(np.concatenate([np.zeros(no), v]), (4,))  # cvxopt's sys 4: L alone
        yl = y[no:]
        r = T @ yl - v
        # a bound on max_i Σ_j |T_ij y_j| + |v_i| with no |T| formed: |T_i|·|y| ≤ ‖T‖_F ‖y‖₂
        scale = np.linalg.norm(T) * np.linalg.norm(yl) + np.abs(v).max()
        return bool(np.all(np.abs(y[:no]) == 0) and np.all(np.abs(r) <= 1e-10 * scale))

    def flops(self) -> float | None:
        """The numeric factorisation's multiply-adds, counted from the factor's supernodes:
        Σ over supernodes of Σ over their columns of (rows from that column down)², the count
        ``n³/3 + …`` of a dense Cholesky (exactly n(n+1)(2n+1)/6 for one dense supernode).
        None unless the factor is a supernodal one read through the direct seam."""
        if self.direct is None or not self.direct.L:
            return None
        head = _header(self.direct.L.value)
        if head is None or not head[2]:
            return None
        h = head[0]
        ns = int(h[_NSUPER])
        sup = _view(int(h[_SUPER]), ns + 1, np.int64).astype(float)
        pi = _view(int(h[_PI]), ns + 1, np.int64).astype(float)
        nc, nr = np.diff(sup), np.diff(pi)
        # Σ_{k<nc} (nr − k)² in closed form, per supernode
        k = nc - 1
        return float(np.sum(nc * nr**2 - 2 * nr * k * (k + 1) / 2 + k * (k + 1) * (2 * k + 1) / 6))

    def update(self, C: sp.csc_matrix, subtract: bool) -> None:
        """``A ± C Cᵀ`` in place (scikit-sparse)."""
        if not self.can_update:
            raise RuntimeError(f"rank-k update needs scikit-sparse (this factor: {self.lib})")
        with _sk_quiet():
            self.F.update_inplace(C, subtract=subtract)

    def nnz(self, A: sp.csc_matrix) -> int:
        """Non-zeros of the factor of ``A`` (cvxopt: of a copy, since reading spends it)."""
        if self.lib == "sksparse":
            return int(self.F.L().nnz)
        F = _cvx_cholmod.symbolic(self._cvx(A))
        _cvx_cholmod.numeric(self._cvx(A), F)
        return len(_cvx_cholmod.getfactor(F))


# --------------------------------------------------------------------------- cvxopt's factor, read in place

_api = ctypes.pythonapi
_api.PyCapsule_GetName.restype = ctypes.c_char_p
_api.PyCapsule_GetName.argtypes = [ctypes.py_object]
_api.PyCapsule_GetPointer.restype = ctypes.c_void_p
_api.PyCapsule_GetPointer.argtypes = [ctypes.py_object, ctypes.c_char_p]

# cholmod_factor: 22 size_t/pointer fields (n, minor, Perm, ColCount, IPerm, nzmax, p, i, x, z,
# nz, next, prev, nsuper, ssize, xsize, maxcsize, maxesize, super, pi, px, s), then the ints
# ordering, is_ll, is_super, is_monotonic, itype, xtype, dtype
_N, _MINOR, _NZMAX, _P, _I, _X, _NZ = 0, 1, 5, 6, 7, 8, 10
_NSUPER, _SSIZE, _XSIZE, _SUPER, _PI, _PX, _S = 13, 14, 15, 18, 19, 20, 21
_LONG, _REAL, _DOUBLE = 2, 1, 0


def _cvx_trailing(F, no: int) -> np.ndarray | None:
    """``L[no:, no:]`` (of ``L Lᵀ``) copied from cvxopt's numeric factor without touching it;
    None where the factor is not of the expected kind (64-bit indices, real, double)."""
    ptr = _api.PyCapsule_GetPointer(F, _api.PyCapsule_GetName(F))
    return _trailing_at(ptr, no) if ptr else None


def _header(ptr: int) -> tuple[np.ndarray, int, int] | None:
    """The ``cholmod_factor`` at ``ptr``: its 22 size/pointer fields, ``is_ll`` and
    ``is_super``; None unless it is a complete numeric factor of the kind read here (64-bit
    indices, real, double)."""
    h = _view(ptr, 22, np.uint64)
    _ordering, is_ll, is_super, _monotonic, itype, xtype, dtype = _view(ptr + 22 * 8, 7, np.int32)
    if int(h[_MINOR]) != int(h[_N]) or itype != _LONG or xtype != _REAL or dtype != _DOUBLE:
        return None
    return h, int(is_ll), int(is_super)


def _trailing_at(ptr: int, no: int) -> np.ndarray | None:
    """``L[no:, no:]`` of the ``cholmod_factor`` at ``ptr`` (see :func:`_cvx_trailing`)."""
    head = _header(ptr)
    if head is None:
        return None
    h, is_ll, is_super = head
    n = int(h[_N])
    if not 0 <= no <= n:
        return None
    k = n - no
    out = np.zeros((k, k), order="F")  # column-major, as CHOLMOD holds it and LAPACK reads it: no copy
    if is_super:
        if not is_ll:
            return None
        ns = int(h[_NSUPER])
        sup = _view(int(h[_SUPER]), ns + 1, np.int64)
        pi = _view(int(h[_PI]), ns + 1, np.int64)
        px = _view(int(h[_PX]), ns + 1, np.int64)
        s = _view(int(h[_S]), int(h[_SSIZE]), np.int64)
        x = _view(int(h[_X]), int(h[_XSIZE]), np.float64)
        if sup[ns] != n:
            return None
        for j in range(max(int(np.searchsorted(sup, no, side="right")) - 1, 0), ns):
            c0, c1 = int(sup[j]), int(sup[j + 1])
            if c1 <= no:
                continue
            rows = s[pi[j]:pi[j + 1]]
            nr, nc = rows.size, c1 - c0
            blk = x[px[j]:px[j] + nr * nc].reshape(nc, nr).T  # column-major, leading dimension nr
            j0 = max(no - c0, 0)  # the supernode's first column in the trailing block
            r0, a, b = int(rows[j0]) - no, c0 + j0 - no, c1 - no
            if r0 == a and int(rows[-1]) - no == k - 1 and nr - j0 == k - a:
                # its rows are the trailing ones from its own first column on (the last supernode,
                # a dense block): copied by columns, the part above its diagonal zeroed
                out[a:, a:b] = blk[j0:, j0:]
                for i in range(a + 1, b):
                    out[a:i, i] = 0.0
            else:
                out[np.ix_(rows[j0:] - no, np.arange(c0 + j0, c1) - no)] = np.tril(blk[j0:, j0:])
        return out
    p = _view(int(h[_P]), n + 1, np.int64)
    i = _view(int(h[_I]), int(h[_NZMAX]), np.int64)
    x = _view(int(h[_X]), int(h[_NZMAX]), np.float64)
    nz = _view(int(h[_NZ]), n, np.int64)
    for j in range(no, n):
        lo = int(p[j])
        out[i[lo:lo + nz[j]] - no, j - no] = x[lo:lo + nz[j]]
    if not is_ll:  # simplicial LDLᵀ: unit L with D stored on its diagonal
        d = np.diagonal(out).copy()
        if np.any(d <= 0):
            return None
        np.fill_diagonal(out, 1.0)
        out *= np.sqrt(d)[None, :]
    return out
