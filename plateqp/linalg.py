"""Sparse symmetric factorisation with equilibration and iterative refinement.

One class, :class:`Factor`, hides the library. ``auto`` takes the first that imports:
CHOLMOD through scikit-sparse, CHOLMOD as shipped inside cvxopt's wheels (installed by
``plateqp[solvers]``; the fastest that installs from wheels alone: 0.5–0.7× scikit-sparse's
time here), then SciPy's SuperLU in symmetric mode (MMD on AᵀA+A ordering, no diagonal
pivoting: 2.3–2.5× faster than SuperLU's defaults at 256², but 1.3–4× CHOLMOD's time from
128² on; see benchmarks/README.md). The matrix is first equilibrated, K̂ = S K S with
S = diag(K)^(-1/2), because deflection and slope dofs differ by (element size)² in scale.

Every solve is followed by iterative refinement whose residual is summed in long double
(where the platform has it): the double-precision residual ‖K u − f‖/‖f‖ has a floor of
about eps·‖K‖‖u‖/‖f‖ (2e-8 at 256², even for the exact solution rounded to doubles), so it
cannot show convergence; the long-double residual brings the forward error to ~1e-13.
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

try:  # optional: CHOLMOD as shipped inside cvxopt's wheels (plateqp[solvers] installs it)
    from cvxopt import cholmod as _cvx_cholmod  # type: ignore
    from cvxopt import matrix as _cvx_matrix
    from cvxopt import spmatrix as _cvx_spmatrix

    HAVE_CVXOPT = True
except Exception:  # pragma: no cover - depends on the machine
    HAVE_CVXOPT = False

# residuals for iterative refinement are accumulated in long double where it is wider than
# double (x86-64 Linux/macOS: 64-bit mantissa); elsewhere (Windows, arm64 macOS) plain double
_EXTENDED = np.finfo(np.longdouble).eps < np.finfo(np.float64).eps

METHODS = ("auto", "cholmod", "cvxopt", "superlu", "superlu-default")


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
            method = "cholmod" if HAVE_CHOLMOD else "cvxopt" if HAVE_CVXOPT else "superlu"
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
                elif method == "cvxopt":
                    if not HAVE_CVXOPT:
                        raise ValueError("cvxopt is not installed")
                    L = sp.tril(Ks, format="coo")  # CHOLMOD reads the lower triangle
                    A = _cvx_spmatrix(_cvx_matrix(L.data), _cvx_matrix(L.row.astype(np.int64)),
                                      _cvx_matrix(L.col.astype(np.int64)), Ks.shape)
                    F = _cvx_cholmod.symbolic(A)
                    try:
                        _cvx_cholmod.numeric(A, F)
                    except ArithmeticError as exn:  # not positive definite
                        raise MechanismError("the stiffness matrix is not positive definite "
                                             f"(CHOLMOD stopped at column {exn}): the plate is a "
                                             "mechanism") from exn
                    self._f = F
                    self._cvx_A = A
                    self._solve = self._cvx_solve
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
        if self.method == "cvxopt":  # getfactor() converts the factor in place: copy first
            F = _cvx_cholmod.symbolic(self._cvx_A)
            _cvx_cholmod.numeric(self._cvx_A, F)
            return len(_cvx_cholmod.getfactor(F))
        return int(self._f.L.nnz + self._f.U.nnz)

    def _cvx_solve(self, b: np.ndarray) -> np.ndarray:
        B = _cvx_matrix(np.asarray(b, dtype=float).reshape(b.shape[0], -1))
        _cvx_cholmod.solve(self._f, B)
        return np.array(B).reshape(b.shape)

    def _raw(self, b: np.ndarray) -> np.ndarray:
        s = self.s if b.ndim == 1 else self.s[:, None]
        return s * self._solve(s * b)

    def _residual(self, b: np.ndarray, x: np.ndarray) -> np.ndarray:
        """b − K x, accumulated in long double where that is wider than double.

        In double, the residual of any float64 x is no smaller than about eps·‖|K||x|‖ (the
        rounding of x alone), which on fine plate meshes is 1e-8·‖b‖: refinement on a double
        residual cannot see errors below that. In long double it can (forward error ~1e-13).
        """
        if not _EXTENDED:
            return b - self.K @ x
        if getattr(self, "_KL", None) is None:
            self._KL = self.K.astype(np.longdouble)
        return (b.astype(np.longdouble) - self._KL @ x.astype(np.longdouble)).astype(np.float64)

    def solve(self, b, refine: int = 3) -> np.ndarray:
        """Solve K x = b (b may have several columns), with up to ``refine`` refinement steps.

        Refinement stops when the correction no longer halves or falls below ~eps·‖x‖
        (the residual itself is at its rounding floor long before x stops improving).
        """
        b = np.asarray(b, dtype=float)
        x = self._raw(b)
        if b.ndim == 1:
            x = x.reshape(-1)
        eps = np.finfo(np.float64).eps
        prev = np.inf
        for _ in range(refine):
            dx = self._raw(self._residual(b, x))
            ndx = np.linalg.norm(dx, axis=0)
            if np.all(ndx >= 0.5 * prev):  # no longer converging: keep x
                break
            x = x + dx
            prev = ndx
            if np.all(ndx <= 4 * eps * np.linalg.norm(x, axis=0)):
                break
        return x

    def residual(self, x, b) -> float:
        """Relative residual ‖K x − b‖ / ‖b‖."""
        nb = np.linalg.norm(b)
        return float(np.linalg.norm(self.K @ x - b) / (nb if nb > 0 else 1.0))


def solve_saddle(K, B, rho, f, g, refine: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """(u, R) of the saddle-point system [K Bᵀ; B −diag(ρ)] (u, R) = (f, g).

    The equilibrium of a plate held at the rows of B (deflection B u = g + ρ R, R of either
    sign): works where K alone is singular, as long as the rows hold it. Sparse LU with
    ``refine`` steps of iterative refinement. A singular system is a MechanismError.
    """
    K = sp.csc_matrix(K)
    B = sp.csr_matrix(B)
    n, m = K.shape[0], B.shape[0]
    A = sp.bmat([[K, B.T], [B, -sp.diags(np.asarray(rho, dtype=float))]], format="csc")
    rhs = np.concatenate([np.asarray(f, dtype=float), np.asarray(g, dtype=float)])
    try:
        lu = spla.splu(A)
        x = lu.solve(rhs)
        for _ in range(refine):
            x = x + lu.solve(rhs - A @ x)
    except RuntimeError as exn:
        raise MechanismError(f"the held rows do not hold the structure: the saddle-point system is singular ({exn})") from exn
    if not np.all(np.isfinite(x)):
        raise MechanismError("the held rows do not hold the structure: the saddle-point solve is not finite")
    return x[:n], x[n:]
