"""Assembly of element matrices on an unstructured mesh through a scatter pattern, into a canonical CSR.

:func:`block_pattern` works out once, from the mesh's cells and the dofs kept, where every
entry of every cell's matrix goes: the nd × nd blocks that couple two nodes (one per node and one
per pair of nodes that share a cell), each summed over its cells in the order of the cells (a
sparse matrix with one 1 per cell's block, applied in compiled code), laid out as SciPy's BSR→CSR
conversion lays them, and the entries of the kept rows and columns picked in CSR order.
:meth:`BlockPattern.assemble` is then one product and one gather: the block (p, q) and the block
(q, p) add the same values in the same order, so a mesh of symmetric element matrices gives a
matrix symmetric value for value. Sorted indices, no duplicates: the CSR is canonical. A pattern
serves every set of matrices of the same cells and kept dofs (a mesh reused with another plate).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class BlockPattern:
    """Where the entries of the cells' matrices go: ``sums`` (nb, nc·k²) the sparse matrix that
    sums each block over its cells (columns: the cells' blocks, cell by cell, row node by column
    node), ``pick`` the entries of the blocks' data (nb·nd², block by block) in the kept CSR's
    order, and that CSR's ``indices``, ``indptr`` and order ``n``."""

    sums: sp.csr_matrix
    pick: np.ndarray
    indices: np.ndarray
    indptr: np.ndarray
    n: int
    nd: int

    def assemble(self, Ke: np.ndarray) -> sp.csr_matrix:
        """Σ over the cells of their matrices ``Ke`` (nc, k·nd, k·nd), in canonical CSR."""
        nc, nd = Ke.shape[0], self.nd
        k = Ke.shape[1] // nd
        blocks = Ke.reshape(nc, k, nd, k, nd).transpose(0, 1, 3, 2, 4).reshape(nc * k * k, nd * nd)
        data = (self.sums @ blocks).reshape(-1)[self.pick]
        out = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))
        out.has_sorted_indices = True
        out.has_canonical_format = True
        return out


def block_pattern(cells: np.ndarray, n_nodes: int, nd: int, pos: np.ndarray, ncol: int) -> BlockPattern:
    """The :class:`BlockPattern` of cells ``cells`` (nc, k) on ``n_nodes`` nodes of ``nd`` dofs,
    keeping the dofs with ``pos`` ≥ 0 (``pos``: each dof's new index, increasing over the kept
    dofs, ``ncol`` of them)."""
    cells = np.asarray(cells, dtype=np.int64)
    nc, k = cells.shape
    # block (p, q) of each cell, then the cell: sorted, each block's cells come in their own order
    key = ((cells[:, :, None] * n_nodes + cells[:, None, :]) * nc + np.arange(nc)[:, None, None]).reshape(-1)
    order = np.argsort(key)
    key = key[order] // nc
    new = np.empty(len(key), dtype=bool)
    new[0] = True
    np.not_equal(key[1:], key[:-1], out=new[1:])
    start = np.flatnonzero(new)
    nb = len(start)
    sums = sp.csr_matrix((np.ones(len(key)), order, np.append(start, len(key))), shape=(nb, len(key)))
    bp, bq = key[start] // n_nodes, key[start] % n_nodes
    indptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(bp, minlength=n_nodes), out=indptr[1:])
    # SciPy's BSR→CSR of the blocks numbered entry by entry: each CSR entry's place in the blocks' data
    ids = np.arange(nb * nd * nd, dtype=float).reshape(nb, nd, nd)
    full = sp.bsr_matrix((ids, bq, indptr), shape=(n_nodes * nd, n_nodes * nd)).tocsr()
    row_kept = pos >= 0
    cols = pos[full.indices]
    m = np.repeat(row_kept, np.diff(full.indptr)) & (cols >= 0)
    per_row = np.add.reduceat(m.astype(np.int64), full.indptr[:-1])[row_kept]  # every row has its diagonal block
    out_ptr = np.zeros(ncol + 1, dtype=np.int64)
    np.cumsum(per_row, out=out_ptr[1:])
    small = np.int32 if nb * nd * nd < 2**31 else np.int64  # kept with the mesh: the smaller type that holds them
    return BlockPattern(sums, full.data[m].astype(small), cols[m].astype(small), out_ptr, ncol, nd)


def assemble_blocks(Ke: np.ndarray, cells: np.ndarray, n_nodes: int, pos: np.ndarray, ncol: int) -> sp.csr_matrix:
    """Σ over the cells of their element matrices, on the dofs with ``pos`` ≥ 0.

    ``Ke`` (nc, k·nd, k·nd): each cell's matrix on its k nodes' dofs (node-major); ``cells`` (nc, k)
    its nodes; ``pos`` (n_nodes·nd,) each dof's new index, increasing over the kept dofs (−1:
    dropped), ``ncol`` of them. Returns the (ncol, ncol) matrix in canonical CSR
    (:func:`block_pattern`, then :meth:`BlockPattern.assemble`)."""
    nc, k = cells.shape
    return block_pattern(cells, n_nodes, Ke.shape[1] // k, pos, ncol).assemble(Ke)
