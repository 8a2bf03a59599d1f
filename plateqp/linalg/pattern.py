"""Scale and sum sparse matrices without dropping stored entries.

A fill-reducing order (AMD, and CHOLMOD's supernodes after it) is computed from the *stored*
pattern of a matrix, not from its values. plateqp's assembly stores every pair of neighbouring
nodes as a full block, every dof of one node against every dof of the other, and some of those
entries are exactly zero (on a uniform ACM mesh, some deflection–slope and slope–slope couplings,
within a node and between neighbours: 478 of 5,625 stored entries at 8²). With
them stored, the dofs of a node have one adjacency, AMD treats them as one supervariable and the
supernodes follow the nodes. SciPy's products and sums drop the zeros they compute
(``diag(s) @ K @ diag(s)``, ``K + Bᵀ B``): measured on ``families.grid_rigid`` with those zeros
dropped, CHOLMOD's factor had 7.7 M instead of 5.1 M non-zeros at 128² and its numeric
factorisation took 1.9× as long (38.9 M against 24.4 M non-zeros, 2.6× at 256²); ordered with
900 contact dofs last, 9.9 M against 6.7 M. So a matrix on its way to an ordering is scaled and
summed here, its stored pattern kept.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

try:  # SciPy's own CSR kernels (what ``A @ x`` runs), called on row blocks without building a matrix each
    from scipy.sparse._sparsetools import csr_matvec as _csr_matvec
    from scipy.sparse._sparsetools import csr_matvecs as _csr_matvecs
except ImportError:  # pragma: no cover - another SciPy layout: the blocks are built as matrices
    _csr_matvec = _csr_matvecs = None


#: entries :func:`scaled` scales at a time (a block's arrays stay in cache: 2 MB of values)
SCALE_BLOCK = 1 << 18


def scaled(K: sp.spmatrix, s: np.ndarray, factor: float = 1.0, spare: int = 0) -> sp.csr_matrix | sp.csc_matrix:
    """``factor · diag(s) K diag(s)`` with exactly ``K``'s stored pattern (CSR or CSC as ``K``;
    any other format becomes CSR). One copy of the values, no product. Where ``K``'s indices are
    sorted, its indices and pointers are shared, not copied (21 MB at 256²): the result is marked
    sorted, so SciPy never sorts it in place, and nothing in plateqp writes a matrix's indices
    (left writeable: compiled solvers such as PIQP take only writeable arrays).

    ``spare``: the values are the first ``nnz`` entries of an array with room for ``spare``
    more after them (unset), where a matrix that extends this one column by column can put its
    own (:func:`extended_values`: the primal QP's ``block_diag(K, I)`` without a copy of K's)."""
    K = K if sp.isspmatrix_csr(K) or sp.isspmatrix_csc(K) else sp.csr_matrix(K)
    s = np.asarray(s, dtype=float)
    # in place on one array: (s_i s_j)·factor·K_ij, the same rounding for (i, j) and (j, i), so a
    # symmetric K stays exactly symmetric; a block of entries at a time (SCALE_BLOCK), each
    # block's four passes in cache and no gather of the size of K
    nnz = int(K.indptr[-1])
    counts = np.diff(K.indptr)
    data = np.empty(nnz + int(spare))[:nnz]
    tmp = np.empty(min(SCALE_BLOCK, nnz))
    step = max(1, int(K.shape[0] * SCALE_BLOCK // max(nnz, 1)))  # columns (rows) a block
    for j0 in range(0, K.shape[0], step):
        j1 = min(K.shape[0], j0 + step)
        a, b = int(K.indptr[j0]), int(K.indptr[j1])
        part, t = data[a:b], tmp[:b - a] if b - a <= tmp.size else np.empty(b - a)
        part[:] = np.repeat(s[j0:j1], counts[j0:j1])
        np.take(s, K.indices[a:b], out=t, mode="clip")  # (mode "raise" buffers out: a copy)
        part *= t
        part *= factor
        part *= K.data[a:b]
    if not K.has_sorted_indices:  # SciPy may sort the result in place: its own indices
        return type(K)((data, K.indices.copy(), K.indptr.copy()), shape=K.shape)
    out = type(K)((data, K.indices, K.indptr), shape=K.shape, copy=False)
    if not np.shares_memory(out.indices, K.indices):  # SciPy chose another index width: no sharing
        return out
    out.has_sorted_indices = True
    return out


def _with_room(arr: np.ndarray, nnz: int, extra: int) -> np.ndarray | None:
    """``arr`` (its ``nnz`` entries) extended over the room after it in the array it is a view
    of, where that array holds at least ``extra`` more entries; else None."""
    base = arr.base
    if (base is None or base.ndim != 1 or base.dtype != arr.dtype or not base.flags.c_contiguous
            or not arr.flags.c_contiguous or arr.size != nnz or base.size < nnz + extra
            or base.__array_interface__["data"][0] != arr.__array_interface__["data"][0]):
        return None
    return base[:nnz + extra]


def extended_values(K: sp.spmatrix, extra: int) -> np.ndarray | None:
    """An array of ``K``'s stored values followed by room for ``extra`` more, sharing ``K``'s
    values where :func:`scaled` left that room after them (the room's entries unset), else None."""
    return _with_room(K.data, int(K.indptr[-1]), extra)


def extended_indices(K: sp.spmatrix, extra: int) -> np.ndarray | None:
    """``K``'s stored indices followed by ``n, n + 1, …, n + extra − 1`` (``n`` its order: the
    rows of an identity block appended after ``K``), sharing ``K``'s index array where it was
    made with room after it (the grid's assembly leaves one entry a row), else None. The room
    is written with those values, the same for every caller: nothing else reads it."""
    nnz, n = int(K.indptr[-1]), K.shape[0]
    out = _with_room(K.indices, nnz, extra)
    if out is None or not out.flags.writeable or n + extra > np.iinfo(out.dtype).max:
        return None
    out[nnz:] = np.arange(n, n + extra, dtype=out.dtype)
    return out


def csc_of_symmetric(K: sp.spmatrix, symmetric: bool) -> sp.csc_matrix:
    """``K`` as CSC. Where ``symmetric`` (the caller vouches that ``K`` is exactly symmetric,
    value for value) and ``K`` is CSR with sorted indices, its arrays are read as CSC: the CSR
    arrays of ``Kᵀ = K`` are ``K``'s CSC arrays, so nothing is converted (SciPy's conversion
    took 7 ms at 128², 0.3 s at 512² on a plate's K) and the arrays are shared, not copied."""
    if symmetric and sp.isspmatrix_csr(K) and K.shape[0] == K.shape[1] and K.has_sorted_indices:
        out = sp.csc_matrix((K.data, K.indices, K.indptr), shape=K.shape, copy=False)
        out.has_sorted_indices = True
        return out
    return sp.csc_matrix(K)


def add(*mats: sp.spmatrix) -> sp.csc_matrix:
    """The sum of sparse matrices of one shape, on the union of their stored patterns (an entry
    that sums to zero stays stored), sorted, CSC."""
    if not mats:
        raise ValueError("add needs at least one matrix")
    shape = mats[0].shape
    coo = [sp.coo_matrix(A) for A in mats]
    if any(A.shape != shape for A in coo):
        raise ValueError(f"add: matrices of different shapes {[A.shape for A in coo]}")
    out = sp.csc_matrix((np.concatenate([A.data for A in coo]),
                         (np.concatenate([A.row for A in coo]), np.concatenate([A.col for A in coo]))), shape=shape)
    out.sum_duplicates()  # keeps entries that sum to zero
    return out


def congruence(T: sp.spmatrix, K: sp.spmatrix, like: sp.spmatrix | None = None) -> sp.csr_matrix:
    """``Tᵀ K T``, with the stored pattern of ``like`` (a matrix of the result's shape, usually
    ``K`` permuted the way ``T`` nearly permutes it) kept where the product computed zeros."""
    out = (T.T @ K @ T).tocsr()
    if like is None:
        return out
    Z = sp.coo_matrix(like)
    return add(out, sp.coo_matrix((np.zeros(Z.nnz), (Z.row, Z.col)), shape=Z.shape)).tocsr()


def leading(P: sp.csc_matrix, k: int) -> sp.csc_matrix | None:
    """``P[:k, :k]`` as a view of the CSC matrix P's arrays (no copy; stored entries and their
    order kept), or None where P's first k columns hold a row past k (then it is no block)."""
    end = P.indptr[k]
    if end and P.indices[:end].max() >= k:
        return None
    K = sp.csc_matrix((P.data[:end], P.indices[:end], P.indptr[:k + 1]), shape=(k, k), copy=False)
    K.has_sorted_indices = P.has_sorted_indices
    return K


def abs_matvec(K: sp.csc_matrix, x: np.ndarray, chunk: int = 1 << 18) -> np.ndarray:
    """``|K| x`` for symmetric ``K`` (CSC or CSR) and ``x`` of shape (n,) or (n, k), a block of
    rows at a time: K's arrays read as CSR are K itself, so each block is ``chunk`` entries of
    |K| and gives its own rows (no copy of K's data: ``abs(K) @ x`` copied all of it, 43 MB at
    256²; a block takes 2 MB). Each block goes straight to SciPy's CSR kernel where it can (no
    matrix built per block: that took 4 of the 5 ms of one product at 128²)."""
    n = K.shape[0]
    x = np.asarray(x)
    direct = (_csr_matvec is not None and K.data.dtype == np.float64 and x.dtype == np.float64
              and K.indices.dtype == K.indptr.dtype)
    if direct:
        xc = np.ascontiguousarray(x)
        out = np.zeros((n,) + xc.shape[1:])
        flat = out.reshape(n, -1)
        k = flat.shape[1]
        j0 = 0
        while j0 < n:
            j1 = int(np.searchsorted(K.indptr, K.indptr[j0] + chunk, side="right")) - 1
            j1 = min(max(j1, j0 + 1), n)
            a, b = int(K.indptr[j0]), int(K.indptr[j1])
            ptr = K.indptr[j0:j1 + 1] - K.indptr[j0]
            part = flat[j0:j1]
            if xc.ndim == 1:
                _csr_matvec(j1 - j0, n, ptr, K.indices[a:b], np.abs(K.data[a:b]), xc, part.reshape(-1))
            else:
                _csr_matvecs(j1 - j0, n, k, ptr, K.indices[a:b], np.abs(K.data[a:b]), xc.reshape(-1),
                             part.reshape(-1))
            j0 = j1
        return out
    out = np.empty((n,) + np.shape(x)[1:])
    j0 = 0
    while j0 < n:
        j1 = int(np.searchsorted(K.indptr, K.indptr[j0] + chunk, side="right")) - 1
        j1 = min(max(j1, j0 + 1), n)
        a, b = K.indptr[j0], K.indptr[j1]
        rows = sp.csr_matrix((np.abs(K.data[a:b]), K.indices[a:b], K.indptr[j0:j1 + 1] - a), shape=(j1 - j0, n))
        out[j0:j1] = rows @ x
        j0 = j1
    return out
