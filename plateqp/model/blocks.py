"""Assembly of element matrices on an unstructured mesh by node blocks, into a canonical CSR.

:func:`assemble_blocks` sums the nd × nd blocks that couple two nodes over the cells that hold
both, in the order of the cells (the same order for the block (p, q) and the block (q, p), so a
mesh of symmetric element matrices gives a matrix symmetric value for value), lays the blocks
out as a block-sparse matrix (SciPy's BSR, its conversion to CSR in compiled code) and keeps the
rows and columns of the dofs asked for. Sorted indices, no duplicates: the CSR is canonical.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def assemble_blocks(Ke: np.ndarray, cells: np.ndarray, n_nodes: int, pos: np.ndarray, ncol: int) -> sp.csr_matrix:
    """Σ over the cells of their element matrices, on the dofs with ``pos`` ≥ 0.

    ``Ke`` (nc, k·nd, k·nd): each cell's matrix on its k nodes' dofs (node-major); ``cells`` (nc, k)
    its nodes; ``pos`` (n_nodes·nd,) each dof's new index, increasing over the kept dofs (−1:
    dropped), ``ncol`` of them. Returns the (ncol, ncol) matrix in canonical CSR."""
    nc, k = cells.shape
    nd = Ke.shape[1] // k
    p = np.repeat(cells, k, axis=1).ravel().astype(np.int64)  # block (a, b) of each cell: node p = cells[a]
    q = np.tile(cells, (1, k)).ravel().astype(np.int64)
    key = p * n_nodes + q
    order = np.argsort(key, kind="stable")  # the cells in their own order within each block
    key = key[order]
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    blocks = Ke.reshape(nc, k, nd, k, nd).transpose(0, 1, 3, 2, 4).reshape(nc * k * k, nd, nd)
    data = np.add.reduceat(blocks[order], start, axis=0)
    bp, bq = key[start] // n_nodes, key[start] % n_nodes
    indptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(bp, minlength=n_nodes), out=indptr[1:])
    full = sp.bsr_matrix((data, bq, indptr), shape=(n_nodes * nd, n_nodes * nd)).tocsr()
    return _keep(full, pos, ncol)


def _keep(A: sp.csr_matrix, pos: np.ndarray, ncol: int) -> sp.csr_matrix:
    """The rows and columns of ``A`` (canonical CSR) whose ``pos`` ≥ 0, renumbered by ``pos``."""
    if ncol == A.shape[0] and np.array_equal(pos, np.arange(ncol)):
        A.has_sorted_indices = True
        A.has_canonical_format = True
        return A
    row_of = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    m = (pos[row_of] >= 0) & (pos[A.indices] >= 0)
    counts = np.bincount(pos[row_of[m]], minlength=ncol)
    indptr = np.zeros(ncol + 1, dtype=np.int64)
    np.cumsum(counts, out=indptr[1:])
    out = sp.csr_matrix((A.data[m], pos[A.indices[m]], indptr), shape=(ncol, ncol))
    out.has_sorted_indices = True  # pos increases: the kept columns keep their order
    out.has_canonical_format = True
    return out
