"""CHOLMOD's C API inside cvxopt's wheels, through ctypes (used by :class:`plateqp.linalg.Cholesky`).

CHOLMOD ships inside cvxopt's wheels as a shared library (cvxopt.libs/ on Linux, .dylibs/ on
macOS). cvxopt's own binding takes a cvxopt matrix: converting a 256² plate's K into one costs
0.15 s (its constructor sorts 2.7 M triplets), and extracting the lower triangle for it 0.2 s,
a quarter of the whole factorisation. Through ctypes CHOLMOD reads NumPy's arrays in place
(a ``cholmod_sparse`` pointing at the arrays of :func:`plateqp.linalg.cholmod.lower`, best
with ``upper=True``: CHOLMOD reads an upper triangle without transposing it; handed
the whole symmetric matrix instead, CHOLMOD took 0.2 s longer at 256² than with the lower
triangle). Each factor has its own ``cholmod_common`` (no shared workspace: no lock). The
fields set in it are found at the offsets of CHOLMOD 3's ``cholmod_common``, checked against
the defaults ``cholmod_l_start`` writes there before anything is set; any other layout or
library and the binding is used.
"""

from __future__ import annotations

import ctypes

import numpy as np
import scipy.sparse as sp

from ..errors import SingularMatrixError

# cholmod_factor: its first fields (size_t or pointer each), as read in plateqp.linalg.cholmod
_MINOR, _PERM = 1, 2


def view(addr: int, count: int, dtype) -> np.ndarray:
    """``count`` items at ``addr`` (no copy; valid while the factor lives)."""
    if count == 0:
        return np.zeros(0, dtype=dtype)
    if not addr:
        raise ValueError("null pointer in the factor")
    buf = (ctypes.c_char * (count * np.dtype(dtype).itemsize)).from_address(addr)
    return np.frombuffer(buf, dtype=dtype, count=count)


_ITYPE_LONG, _XTYPE_REAL, _DTYPE_DOUBLE = 2, 1, 0
_COMMON_BYTES = 1 << 16  # CHOLMOD 3's cholmod_common is about 2.3 kB
# offsets in cholmod_common (CHOLMOD 3.0): supernodal, print, nmethods, method[0] (168 bytes
# each; its ordering at +132), postorder
_OFF_SUPERNODAL, _OFF_PRINT, _OFF_NMETHODS, _OFF_POSTORDER = 48, 144, 168, 1864
_OFF_METHOD0, _METHOD_BYTES, _OFF_ORDERING = 184, 168, 132
_SUPERNODAL = 2  # CHOLMOD_AUTO (1) by default
_NATURAL, _GIVEN, _AMD = 0, 1, 2  # CHOLMOD's ordering codes
# the defaults cholmod_l_start writes (offset, type, value): dbound, grow0..2, maxrank,
# supernodal_switch, supernodal, final_ll, zrelax[0], nrelax[0], nrelax[2], print, nmethods,
# method[0].lnz, method[0].ordering, method[1].ordering, postorder
_LAYOUT = ((0, "d", 0.0), (8, "d", 1.2), (16, "d", 1.2), (24, "q", 5), (32, "q", 8), (40, "d", 40.0),
           (_OFF_SUPERNODAL, "i", 1), (60, "i", 0), (80, "d", 0.8), (104, "q", 4), (120, "q", 48),
           (_OFF_PRINT, "i", 3), (_OFF_NMETHODS, "i", 0), (_OFF_METHOD0, "d", -1.0),
           (_OFF_METHOD0 + _OFF_ORDERING, "i", _GIVEN), (_OFF_METHOD0 + _METHOD_BYTES + _OFF_ORDERING, "i", _AMD),
           (_OFF_POSTORDER, "i", 1))


class _Sparse(ctypes.Structure):
    _fields_ = [("nrow", ctypes.c_size_t), ("ncol", ctypes.c_size_t), ("nzmax", ctypes.c_size_t),
                ("p", ctypes.c_void_p), ("i", ctypes.c_void_p), ("nz", ctypes.c_void_p), ("x", ctypes.c_void_p),
                ("z", ctypes.c_void_p), ("stype", ctypes.c_int), ("itype", ctypes.c_int), ("xtype", ctypes.c_int),
                ("dtype", ctypes.c_int), ("sorted", ctypes.c_int), ("packed", ctypes.c_int)]


class _Dense(ctypes.Structure):
    _fields_ = [("nrow", ctypes.c_size_t), ("ncol", ctypes.c_size_t), ("nzmax", ctypes.c_size_t),
                ("d", ctypes.c_size_t), ("x", ctypes.c_void_p), ("z", ctypes.c_void_p), ("xtype", ctypes.c_int),
                ("dtype", ctypes.c_int)]


class _Seam:
    """The CHOLMOD and AMD libraries inside cvxopt's wheels, through ctypes."""

    def __init__(self) -> None:
        import glob
        import os

        import cvxopt

        base = os.path.dirname(cvxopt.__file__)
        found = {}
        for name in ("cholmod", "amd"):
            for pattern in (os.path.join(base, os.pardir, "cvxopt.libs", f"lib{name}-*"),
                            os.path.join(base, ".dylibs", f"lib{name}*")):
                hits = sorted(glob.glob(pattern))
                if hits:
                    found[name] = ctypes.CDLL(hits[0])  # its dependencies are loaded with cvxopt's modules
                    break
            else:
                raise OSError(f"no lib{name} inside cvxopt's wheel")
        c, a = found["cholmod"], found["amd"]
        vp, i64p = ctypes.c_void_p, ctypes.POINTER(ctypes.c_int64)
        for fn, args, res in (("cholmod_l_start", [vp], ctypes.c_int), ("cholmod_l_finish", [vp], ctypes.c_int),
                              ("cholmod_l_analyze", [vp, vp], vp),
                              ("cholmod_l_analyze_p", [vp, vp, vp, ctypes.c_size_t, vp], vp),
                              ("cholmod_l_factorize", [vp, vp, vp], ctypes.c_int),
                              ("cholmod_l_solve", [ctypes.c_int, vp, vp, vp], vp),
                              ("cholmod_l_free_dense", [ctypes.POINTER(vp), vp], ctypes.c_int),
                              ("cholmod_l_transpose_sym", [vp, ctypes.c_int, vp, vp, vp], ctypes.c_int),
                              ("cholmod_l_free_factor", [ctypes.POINTER(vp), vp], ctypes.c_int)):
            f = getattr(c, fn)
            f.argtypes, f.restype = args, res
        a.amd_l_order.argtypes = [ctypes.c_int64, i64p, i64p, i64p, vp, vp]
        a.amd_l_order.restype = ctypes.c_int
        self.c, self.amd = c, a
        common = self.common()  # the layout check
        try:
            raw = bytes(common)
            for off, kind, want in _LAYOUT:
                got = np.frombuffer(raw, dtype={"d": np.float64, "q": np.int64, "i": np.int32}[kind],
                                    count=1, offset=off)[0]
                if got != want:
                    raise OSError(f"cholmod_common is not CHOLMOD 3's (offset {off}: {got}, expected {want})")
        finally:
            c.cholmod_l_finish(common)

    def common(self):
        buf = (ctypes.c_char * _COMMON_BYTES)()
        if not self.c.cholmod_l_start(buf):
            raise OSError("cholmod_l_start failed")
        return buf


_SEAM: _Seam | None | bool = False  # False: not tried yet
#: use the direct seam where it loads (set False to use cvxopt's binding: tests run both)
SEAM = True


def _seam() -> _Seam | None:
    global _SEAM
    if _SEAM is False:
        try:
            _SEAM = _Seam()
        except (ImportError, OSError, AttributeError, ValueError):  # another build, another platform
            _SEAM = None
    return _SEAM if SEAM else None


def _stype(A: sp.csc_matrix) -> int:
    """CHOLMOD's ``stype`` for the triangle ``A`` holds: −1 lower, 1 upper (or both: a whole
    symmetric matrix, read by its upper triangle). With sorted indices, O(n): where each column
    starts or ends at its diagonal."""
    n = A.shape[0]
    d = np.arange(n)
    counts = np.diff(A.indptr)
    if A.has_sorted_indices and np.all(counts > 0):
        if np.array_equal(A.indices[A.indptr[:-1]], d):
            return -1
        if np.array_equal(A.indices[A.indptr[1:] - 1], d):
            return 1
    col = np.repeat(d, counts)
    return -1 if np.all(A.indices >= col) else 1


def _set_int(buf, off: int, value: int) -> None:
    ctypes.c_int.from_buffer(buf, off).value = value


class _Direct:
    """One CHOLMOD factor through the seam: the analysis, the numeric factor, solves."""

    def __init__(self, seam: _Seam) -> None:
        self.s = seam
        self.cm = seam.common()
        _set_int(self.cm, _OFF_PRINT, 0)  # CHOLMOD prints nothing (stdout may carry JSON)
        # supernodal L Lᵀ always, as cvxopt's binding sets it (the same factor, to the bit); a
        # simplicial L D Lᵀ would also pass an indefinite matrix without a word
        _set_int(self.cm, _OFF_SUPERNODAL, _SUPERNODAL)
        self.L = ctypes.c_void_p()
        self._hold = None  # the arrays the last cholmod_sparse points at
        self._wide = None  # (A, indptr, indices as int64): order, analyse and factor of one A widen once

    def __del__(self) -> None:
        try:
            if self.L:
                self.s.c.cholmod_l_free_factor(ctypes.byref(self.L), self.cm)
            self.s.c.cholmod_l_finish(self.cm)
        except Exception:  # pragma: no cover - interpreter shutdown
            pass

    def _indices(self, A: sp.csc_matrix) -> tuple[np.ndarray, np.ndarray]:
        """``A``'s indptr and indices as CHOLMOD's 64-bit integers, widened once per matrix (the
        same triangle goes through order, analyse and factor). ``A`` then holds the wide arrays
        itself: one copy of its pattern alive, not two (10 MB at 256²)."""
        if self._wide is None or self._wide[0] is not A:
            self._wide = (A, np.ascontiguousarray(A.indptr, dtype=np.int64),
                          np.ascontiguousarray(A.indices, dtype=np.int64))
            A.indptr, A.indices = self._wide[1], self._wide[2]
        return self._wide[1], self._wide[2]

    def forget(self) -> None:
        """Drop the widened pattern of the last matrix (and with it that matrix)."""
        self._wide = None

    def _sparse(self, A: sp.csc_matrix) -> _Sparse:
        n = A.shape[0]
        p, i = self._indices(A)
        x = np.ascontiguousarray(A.data, dtype=np.float64)
        self._hold = (p, i, x)
        return _Sparse(n, n, int(p[-1]), p.ctypes.data, i.ctypes.data, None, x.ctypes.data, None, _stype(A),
                       _ITYPE_LONG, _XTYPE_REAL, _DTYPE_DOUBLE, int(bool(A.has_sorted_indices)), 1)

    def permuted_lower(self, A: sp.csc_matrix, perm: np.ndarray, values: np.ndarray) -> sp.csc_matrix:
        """``tril(M[perm][:, perm])`` for the symmetric ``M`` whose upper triangle ``A`` is, with
        ``values`` (one per stored entry of ``A``) in place of ``A``'s own: CHOLMOD's
        ``cholmod_l_transpose_sym``, the very copy its numeric factorisation makes of a triangle
        handed with an order, made once here into NumPy's arrays; each column's rows then
        sorted (a transpose with an order leaves some out of order)."""
        n = A.shape[0]
        counts = np.diff(A.indptr)
        full = counts > 0
        if A.has_sorted_indices:  # each column's last row at most its own
            upper = np.all(A.indices[A.indptr[1:][full] - 1] <= np.flatnonzero(full))
        else:
            upper = np.all(A.indices <= np.repeat(np.arange(n), counts))
        if not upper:
            raise ValueError("permuted_lower takes an upper triangle")
        p, i = self._indices(A)
        nnz = int(p[-1])
        x = np.ascontiguousarray(values, dtype=np.float64)
        if x.size != nnz:
            raise ValueError("one value a stored entry")
        perm = np.ascontiguousarray(perm, dtype=np.int64)
        S = _Sparse(n, n, nnz, p.ctypes.data, i.ctypes.data, None, x.ctypes.data, None, 1,
                    _ITYPE_LONG, _XTYPE_REAL, _DTYPE_DOUBLE, int(bool(A.has_sorted_indices)), 1)
        fp, fi, fx = np.empty(n + 1, dtype=np.int64), np.empty(nnz, dtype=np.int64), np.empty(nnz)
        F = _Sparse(n, n, nnz, fp.ctypes.data, fi.ctypes.data, None, fx.ctypes.data, None, -1,
                    _ITYPE_LONG, _XTYPE_REAL, _DTYPE_DOUBLE, 0, 1)
        if not self.s.c.cholmod_l_transpose_sym(ctypes.byref(S), 1, perm.ctypes.data, ctypes.byref(F), self.cm) \
                or fp[n] != nnz:
            raise SingularMatrixError("CHOLMOD's permuted transpose failed (an order that is no permutation?)")
        M = sp.csc_matrix((n, n))  # the arrays set, not passed: SciPy would narrow the indices (a copy)
        M.data, M.indices, M.indptr = fx, fi, fp
        M.has_sorted_indices = False
        M.sort_indices()
        return M

    def order(self, A: sp.csc_matrix) -> np.ndarray:
        n = A.shape[0]
        p, i = self._indices(A)
        P = np.empty(n, dtype=np.int64)
        i64p = ctypes.POINTER(ctypes.c_int64)
        st = self.s.amd.amd_l_order(n, p.ctypes.data_as(i64p), i.ctypes.data_as(i64p), P.ctypes.data_as(i64p),
                                    None, None)
        if st < 0:
            raise SingularMatrixError(f"AMD failed (status {st})")
        return P

    def analyse(self, A: sp.csc_matrix, perm: np.ndarray | None) -> None:
        """The symbolic analysis of ``A``: CHOLMOD's own ordering (``perm`` None), or exactly
        ``perm``, not postordered. The identity is asked as CHOLMOD's natural ordering: a lower
        triangle is then factorised where it lies, while a given order, even the identity, has
        CHOLMOD factorise a permuted copy (two for a lower triangle)."""
        if self.L:
            self.s.c.cholmod_l_free_factor(ctypes.byref(self.L), self.cm)
        S = self._sparse(A)
        n = A.shape[0]
        if perm is None:
            L = self.s.c.cholmod_l_analyze(ctypes.byref(S), self.cm)
        else:  # exactly this order: one method, the given one (or the natural one), not postordered
            perm = np.ascontiguousarray(perm, dtype=np.int64)
            natural = bool(np.array_equal(perm, np.arange(n)))
            off = _OFF_METHOD0 + _OFF_ORDERING
            _set_int(self.cm, _OFF_NMETHODS, 1)
            _set_int(self.cm, off, _NATURAL if natural else _GIVEN)
            _set_int(self.cm, _OFF_POSTORDER, 0)
            try:
                if natural:
                    L = self.s.c.cholmod_l_analyze(ctypes.byref(S), self.cm)
                else:
                    L = self.s.c.cholmod_l_analyze_p(ctypes.byref(S), perm.ctypes.data, None, 0, self.cm)
            finally:
                _set_int(self.cm, _OFF_NMETHODS, 0)
                _set_int(self.cm, off, _GIVEN)
                _set_int(self.cm, _OFF_POSTORDER, 1)
        self._hold = None  # CHOLMOD keeps no pointer into A
        if not L:
            raise SingularMatrixError("CHOLMOD's symbolic analysis failed (out of memory?)")
        self.L = ctypes.c_void_p(L)
        if perm is not None and not np.array_equal(view(int(view(L, 3, np.uint64)[_PERM]), n, np.int64), perm):
            raise OSError("CHOLMOD did not keep the given order")  # the layout is not what it was checked to be

    def factor(self, A: sp.csc_matrix) -> None:
        S = self._sparse(A)
        ok = self.s.c.cholmod_l_factorize(ctypes.byref(S), self.L, self.cm)
        self._hold = self._wide = None  # released: a refactorisation brings its own matrix
        n = A.shape[0]
        minor = int(view(self.L.value, 2, np.uint64)[_MINOR])
        if minor < n:
            raise SingularMatrixError(f"the matrix is not positive definite (CHOLMOD stopped at column {minor} "
                                      "of its elimination order)", minor)
        if not ok:
            raise SingularMatrixError("CHOLMOD's numeric factorisation failed (out of memory?)")

    def solve(self, b: np.ndarray, systems) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        n = b.shape[0]
        B = np.asfortranarray(b.reshape(n, -1))
        k = B.shape[1]
        X = _Dense(n, k, n * k, n, B.ctypes.data, None, _XTYPE_REAL, _DTYPE_DOUBLE)
        cur = ctypes.byref(X)
        owned = []
        try:
            for sys_ in systems:
                out = self.s.c.cholmod_l_solve(sys_, self.L, cur, self.cm)
                if not out:
                    raise SingularMatrixError("CHOLMOD's solve failed (out of memory?)")
                owned.append(ctypes.c_void_p(out))
                cur = out
                if len(owned) > 1:  # the system before is read: freed now, not held beside this one
                    self.s.c.cholmod_l_free_dense(ctypes.byref(owned.pop(0)), self.cm)
            D = _Dense.from_address(owned[-1].value)
            x = np.frombuffer((ctypes.c_double * (n * k)).from_address(D.x), dtype=np.float64).copy()
        finally:
            for o in owned:
                self.s.c.cholmod_l_free_dense(ctypes.byref(o), self.cm)
        return x.reshape(k, n).T.reshape(b.shape) if b.ndim > 1 else x
