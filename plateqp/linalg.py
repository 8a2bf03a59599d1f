"""Sparse symmetric factorisation with equilibration and iterative refinement.

One class, :class:`Factor`, hides the library: CHOLMOD (scikit-sparse) where it is importable,
otherwise SciPy's SuperLU in symmetric mode (MMD on AᵀA+A ordering, no diagonal pivoting),
which measured close to CHOLMOD and 5× faster than SuperLU's defaults on plate matrices
(benchmarks/README.md). The matrix is first equilibrated, K̂ = S K S with S = diag(K)^(-1/2),
because deflection and slope dofs differ by (element size)² in scale; every solve is followed
by iterative refinement on the original matrix until the residual stops falling.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import MechanismError

try:  # optional, faster where it installs
    from sksparse.cholmod import cholesky as _cholmod_cholesky  # type: ignore

    HAVE_CHOLMOD = True
except Exception:  # pragma: no cover - depends on the machine
    HAVE_CHOLMOD = False

METHODS = ("auto", "cholmod", "superlu", "superlu-default")


class Factor:
    """Factorisation of a symmetric positive definite sparse matrix.

    Parameters
    ----------
    K : sparse matrix (n, n), symmetric positive definite
    method : "auto" (CHOLMOD if installed, else SuperLU symmetric mode), "cholmod",
        "superlu" (symmetric mode) or "superlu-default" (SciPy's defaults, for benchmarks)
    """

    def __init__(self, K, method: str = "auto") -> None:
        if method not in METHODS:
            raise ValueError(f"unknown factorisation {method!r}; choose one of {METHODS}")
        if method == "auto":
            method = "cholmod" if HAVE_CHOLMOD else "superlu"
        self.method = method
        self.K = sp.csc_matrix(K)
        d = self.K.diagonal()
        if np.any(d <= 0):
            raise MechanismError("the stiffness matrix has a zero or negative diagonal entry: "
                                 "a dof carries no stiffness (is part of the plate unconnected?)")
        self.s = 1.0 / np.sqrt(d)
        S = sp.diags(self.s)
        Ks = sp.csc_matrix(S @ self.K @ S)
        with warnings.catch_warnings():
            warnings.simplefilter("error", sp.linalg.MatrixRankWarning)
            try:
                if method == "cholmod":
                    if not HAVE_CHOLMOD:
                        raise ValueError("CHOLMOD (scikit-sparse) is not installed")
                    self._f = _cholmod_cholesky(Ks)
                    self._solve = self._f
                elif method == "superlu":
                    self._f = spla.splu(Ks, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                        options={"SymmetricMode": True})
                    self._solve = self._f.solve
                else:
                    self._f = spla.splu(Ks)
                    self._solve = self._f.solve
            except (RuntimeError, sp.linalg.MatrixRankWarning) as exn:
                raise MechanismError(f"the stiffness matrix is singular ({exn}): the plate is a "
                                     "mechanism or part of it is unconnected") from exn
            except Exception as exn:  # CHOLMOD raises CholmodNotPositiveDefiniteError
                if "positive definite" in str(exn).lower():
                    raise MechanismError(f"the stiffness matrix is not positive definite ({exn}): "
                                         "the plate is a mechanism") from exn
                raise

    @property
    def n(self) -> int:
        return self.K.shape[0]

    def nnz_factor(self) -> int:
        """Non-zeros in the factor(s), a measure of fill."""
        if self.method == "cholmod":
            return int(self._f.L().nnz)
        return int(self._f.L.nnz + self._f.U.nnz)

    def _raw(self, b: np.ndarray) -> np.ndarray:
        s = self.s if b.ndim == 1 else self.s[:, None]
        return s * self._solve(s * b)

    def solve(self, b, refine: int = 3) -> np.ndarray:
        """Solve K x = b (b may have several columns), with up to ``refine`` refinement steps."""
        b = np.asarray(b, dtype=float)
        x = self._raw(b)
        if refine:
            nb = np.linalg.norm(b, axis=0)
            nb = np.where(nb == 0, 1.0, nb)
            x = x if b.ndim > 1 else x.reshape(-1)
            r = b - self.K @ x
            res = np.linalg.norm(r, axis=0) / nb
            for _ in range(refine):
                if np.all(res < 1e-15):
                    break
                x_new = x + self._raw(r)
                r_new = b - self.K @ x_new
                res_new = np.linalg.norm(r_new, axis=0) / nb
                better = res_new < res
                x = np.where(better, x_new, x)
                r = np.where(better, r_new, r)
                stalled = not np.any(res_new < 0.5 * res)
                res = np.minimum(res, res_new)
                if stalled:
                    break
        return x

    def residual(self, x, b) -> float:
        """Relative residual ‖K x − b‖ / ‖b‖."""
        nb = np.linalg.norm(b)
        return float(np.linalg.norm(self.K @ x - b) / (nb if nb > 0 else 1.0))
