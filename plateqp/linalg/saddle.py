"""The saddle-point solve [K Bᵀ; B −diag(ρ)] (u, R) = (f, g): one place for it."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import structural_rank

from ..errors import SingularMatrixError


def solve_saddle(K, B, rho, f, g, refine: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """(u, R) of the saddle-point system [K Bᵀ; B −diag(ρ)] (u, R) = (f, g).

    Rows ``B u = g + ρ R`` held with multipliers ``R`` of either sign: the system is
    nonsingular where ``K`` alone is singular, as long as the rows remove its null space.
    Sparse LU with ``refine`` steps of iterative refinement. A singular system is a
    SingularMatrixError.
    """
    K = sp.csc_matrix(K)
    B = sp.csr_matrix(B)
    n = K.shape[0]
    A = sp.bmat([[K, B.T], [B, -sp.diags(np.asarray(rho, dtype=float))]], format="csc")
    rhs = np.concatenate([np.asarray(f, dtype=float), np.asarray(g, dtype=float)])
    if structural_rank(A) < A.shape[0]:
        # more held rows than the dofs they act on (many rigid supports in one element): SuperLU
        # would factorise it and its solve call BLAS with negative sizes ("On entry to DTRSV
        # parameter number 6 had an illegal value", printed by BLAS itself)
        raise SingularMatrixError("the saddle-point system is singular: more rows than the dofs they act on")
    try:
        lu = spla.splu(A)
        x = lu.solve(rhs)
        for _ in range(refine):
            x = x + lu.solve(rhs - A @ x)
    except RuntimeError as exn:
        raise SingularMatrixError(f"the saddle-point system is singular: the rows do not remove the null "
                                  f"space of the matrix ({exn})") from exn
    if not np.all(np.isfinite(x)):
        raise SingularMatrixError("the saddle-point system is singular: its solve is not finite")
    return x[:n], x[n:]
