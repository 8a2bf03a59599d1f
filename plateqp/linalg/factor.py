"""Sparse symmetric positive definite factorisation, equilibrated, with iterative refinement.

:class:`Factor` hides the library. ``auto`` takes the first CHOLMOD binding in use
(:func:`plateqp.linalg.bindings`: scikit-sparse, then the copy inside cvxopt's wheels, 0.5–0.7×
scikit-sparse's time here), else SciPy's SuperLU in symmetric mode (MMD on AᵀA+A ordering, no
diagonal pivoting: 2.3–2.5× faster than SuperLU's defaults at 256², but 1.3–4× CHOLMOD's time
from 128² on; see benchmarks/README.md). The matrix is first equilibrated, K̂ = S K S with
S = diag(K)^(-1/2), since unknowns of one matrix may differ by orders of magnitude in scale.

Every solve is followed by iterative refinement on a residual computed to about 2⁻⁷⁰ of
``|K||u|`` (:class:`~plateqp.linalg.residual.Residual`: an error-free split of the product, in
double arithmetic, on every platform): the double-precision residual ‖K u − f‖/‖f‖ has a floor
of about eps·‖K‖‖u‖/‖f‖ (2e-8 on a 256² plate, even for the exact solution rounded to doubles),
so it cannot show convergence; the exact residual brings the forward error to ~1e-16
(measured on ACM and BFS plates at 32²–256², benchmarks/README.md).
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import SingularMatrixError
from . import pattern
from .cholmod import Cholesky, lower
from .residual import Residual

METHODS = ("auto", "cholmod", "cvxopt", "superlu", "superlu-default")


def equilibration(K: sp.spmatrix, diagonal: np.ndarray | None = None) -> np.ndarray:
    """``s = diag(K)^(-1/2)`` (``diagonal``: ``diag(K)``, where the caller has it);
    SingularMatrixError if a diagonal entry is not positive."""
    d = K.diagonal() if diagonal is None else np.asarray(diagonal, dtype=float)
    bad = np.flatnonzero(~(d > 0))
    if bad.size:
        raise SingularMatrixError(f"the matrix has a zero or negative diagonal entry (row {bad[0]}): "
                                  "it is not positive definite", int(bad[0]))
    return 1.0 / np.sqrt(d)


class Refined:
    """Solves of ``K x = b`` by a raw solver, with iterative refinement on ``K`` itself."""

    K: sp.csc_matrix

    def _raw(self, b: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _residual(self, b: np.ndarray, x: np.ndarray) -> np.ndarray:
        """b − K x to about 2⁻⁷⁰ of |K||x| (:class:`~plateqp.linalg.residual.Residual`).

        In double, the residual of any float64 x is no smaller than about eps·‖|K||x|‖ (the
        rounding of x alone), which for a fine plate mesh is 1e-8·‖b‖: refinement on a double
        residual cannot see errors below that. With the error-free split it can (forward error
        ~1e-16), in double arithmetic on every platform.
        """
        if getattr(self, "_res", None) is None:
            # K symmetric: the contract of both subclasses (only its lower triangle is factorised)
            self._res = Residual(self.K, getattr(self, "s", None), symmetric=True)
        return self._res(b, x)

    def solve(self, b, refine: int = 3) -> np.ndarray:
        """Solve K x = b (b may have several columns), with up to ``refine`` refinement steps.

        A step is taken only while it still changes the answer: refinement converges linearly,
        each correction about ρ times the one before (``ρ``: the last two corrections' ratio;
        for the first, the correction against the solution itself, the solve's own error), so
        it stops when the next correction is predicted below eps·‖x‖, when a correction falls
        below ~eps·‖x‖, or when a correction no longer halves (the residual itself is at its
        rounding floor long before x stops improving). On a 128² plate (cond ~1e8) one step
        takes the forward error from 3e-9 to rounding; a second would change x by 1e-16 and is
        not taken (at 256² the first correction, 4e-8, predicts 2e-15: a second is taken).
        """
        b = np.asarray(b, dtype=float)
        x = self._raw(b)
        if b.ndim == 1:
            x = x.reshape(-1)
        eps = np.finfo(np.float64).eps
        prev = np.linalg.norm(x, axis=0)  # the first "correction": x itself, from zero
        for k in range(refine):
            dx = self._raw(self._residual(b, x))
            ndx = np.linalg.norm(dx, axis=0)
            if k and np.all(ndx >= 0.5 * prev):  # no longer converging: keep x
                break
            x = x + dx
            nx = np.linalg.norm(x, axis=0)
            with np.errstate(divide="ignore", invalid="ignore"):
                nxt = np.where(prev > 0, ndx * ndx / prev, 0.0)  # the next correction, predicted
            prev = ndx
            if np.all((ndx <= 4 * eps * nx) | (nxt <= eps * nx)):
                break
        return x

    def residual(self, x, b) -> float:
        """Relative residual ‖K x − b‖ / ‖b‖."""
        nb = np.linalg.norm(b)
        return float(np.linalg.norm(self.K @ x - b) / (nb if nb > 0 else 1.0))

    @property
    def n(self) -> int:
        return self.K.shape[0]


class Factor(Refined):
    """Factorisation of a symmetric positive definite sparse matrix.

    Parameters
    ----------
    K : sparse matrix (n, n), symmetric positive definite
    method : "auto" (the first CHOLMOD binding in use, else SuperLU symmetric mode),
        "cholmod" (scikit-sparse), "cvxopt" (CHOLMOD in cvxopt's wheels), "superlu"
        (symmetric mode) or "superlu-default" (SciPy's defaults, for benchmarks)
    order : permutation (n,), optional
        A fill-reducing order to use instead of the library's own.

    Raises
    ------
    SingularMatrixError
        ``K`` is not positive definite (to working precision).
    """

    def __init__(self, K, method: str = "auto", order: np.ndarray | None = None) -> None:
        if method not in METHODS:
            raise ValueError(f"unknown factorisation {method!r}; choose one of {METHODS}")
        if method == "auto":
            from . import bindings  # read at every call: a test may switch one off

            libs = bindings()
            method = "cholmod" if "sksparse" in libs else "cvxopt" if "cvxopt" in libs else "superlu"
        self.method = method
        self.order = None if order is None else np.asarray(order, dtype=np.int64)
        self.chol = None
        if method in ("cholmod", "cvxopt"):
            try:
                self.chol = Cholesky("sksparse" if method == "cholmod" else "cvxopt")
            except ValueError as exn:
                raise ValueError(f"factorisation {method!r}: {exn}") from None
        self.refactor(K)

    def refactor(self, K) -> None:
        """Factorise new values; with CHOLMOD the analysis of the first matrix is re-used, so
        ``K`` must have that pattern (or a part of it)."""
        self.K = sp.csc_matrix(K)
        self._res = None
        self.s = equilibration(self.K)
        if self.chol is not None:
            # with an order, the triangle comes permuted and is analysed in its own (natural) order:
            # the lower one is then factorised where it lies, the upper one through a copy
            A = lower(self.K, self.s, self.order, upper=self.chol.upper and self.order is None)
            if self.chol.sym is None:
                self.chol.analyse(A, natural=self.order is not None)
            self.chol.factor(A)
            return
        Ks = pattern.scaled(self.K, self.s)  # its stored pattern kept (the ordering reads it)
        if self.order is not None:
            Ks = Ks[self.order][:, self.order]
        with warnings.catch_warnings():
            warnings.simplefilter("error", sp.linalg.MatrixRankWarning)
            try:
                if self.method == "superlu":
                    self._lu = spla.splu(Ks, permc_spec="NATURAL" if self.order is not None else "MMD_AT_PLUS_A",
                                         diag_pivot_thresh=0.0, options={"SymmetricMode": True})
                else:
                    self._lu = spla.splu(Ks, permc_spec="NATURAL" if self.order is not None else "COLAMD")
            except (RuntimeError, sp.linalg.MatrixRankWarning) as exn:
                raise SingularMatrixError(f"the matrix is singular ({exn})") from exn

    def nnz_factor(self) -> int:
        """Non-zeros in the factor(s), a measure of fill."""
        if self.chol is not None:
            return self.chol.nnz(lower(self.K, self.s, self.order))
        return int(self._lu.L.nnz + self._lu.U.nnz)

    def _solve_scaled(self, b: np.ndarray) -> np.ndarray:
        if self.chol is not None:
            return self.chol.solve(b)
        return self._lu.solve(b)

    def _raw(self, b: np.ndarray) -> np.ndarray:
        s = self.s if b.ndim == 1 else self.s[:, None]
        if self.order is None:
            return s * self._solve_scaled(s * b)
        p = self.order
        x = np.empty_like(b, dtype=float)
        x[p] = self._solve_scaled((s * b)[p])
        return s * x
