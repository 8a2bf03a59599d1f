"""``b − K x`` to about 2⁻⁷⁰ of ``|K||x|``, in double precision only: what iterative refinement needs.

Summed in double, the residual of any float64 ``x`` carries an error of about eps·``|K||x|``
(1e-8 of ``‖b‖`` on a fine plate), so refinement on it cannot bring the forward error below
cond·eps. Long double (x86: a 64-bit mantissa) did better but cost 11× a double product here
(8.5 ms against 0.76 ms for a 128² plate's K) and is plain double on Windows and arm64 macOS.

:class:`Residual` splits the product so that its leading part is computed *exactly* in double
(an error-free splitting in the manner of Ozaki et al., "Error-free transformations of matrix
multiplication by using fast routines of matrix multiplication", Numer. Algorithms 59, 2012):

1. ``K̃ = D K D`` and ``ỹ = D⁻¹ x`` with ``D`` the powers of two nearest ``diag(K)^(-1/2)``
   (exact: only exponents change; the rows become comparable, so one grid serves them all);
2. ``K̃ = K₁ + K₂``: ``K₁`` rounded to multiples of ``2^(E−a)`` (``2^E > max|K̃|``), and
   ``ỹ = y₁ + y₂``: ``y₁`` on multiples of ``2^(f−β)`` (``2^f > max|ỹ|``, per column). Both
   differences are exact, ``|K₂| ≤ 2^(E−a−1)``, ``|y₂| ≤ 2^(f−β−1)``;
3. every product in ``K₁ y₁`` is an integer of at most ``a + β`` bits times ``2^(E+f−a−β)`` and a
   row holds at most ``N`` of them: with ``a + β ≤ 52 − log₂ N`` every partial sum is exact,
   in any order;
4. ``r̃ = (D b − K₁ y₁) − (K₁ y₂ + K₂ ỹ)``: one rounding on a difference already ~2⁻²³ of
   ``|K̃||ỹ|``, the rest summed in double at 2⁻²³ of that scale; ``r = D⁻¹ r̃`` (exact).

The error is about ``N·2⁻⁷⁶ max|K̃| max|ỹ|`` plus eps·``|r|``: below long double's
``N·2⁻⁶⁴ |K||x|`` for the balanced ``K̃``, ``ỹ`` of an equilibrated SPD matrix. Three double
products a residual (3 ms at 128², against 9 ms in long double) and one split of ``K``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

_MANTISSA = 53  # bits of a float64 significand


class Residual:
    """``b − K x`` for one sparse ``K`` (any square CSC/CSR matrix; SPD is where it is balanced).

    ``scale``: the equilibration to balance ``K`` with (default ``diag(K)^(-1/2)``); the
    powers of two nearest it are used, so it changes the accuracy, never the exactness.
    ``symmetric``: the caller vouches that ``K``'s stored pattern is symmetric (an SPD matrix's
    is, as assembled), so the longest column is the longest row. The split of ``K`` is made
    once; :meth:`__call__` takes ``b`` and ``x`` of shape (n,) or (n, k). Non-finite entries
    in ``K`` (nothing to split) fall back to the double product.
    """

    def __init__(self, K: sp.spmatrix, scale: np.ndarray | None = None, symmetric: bool = False) -> None:
        K = K if sp.isspmatrix_csc(K) or sp.isspmatrix_csr(K) else sp.csc_matrix(K)
        self.K = K
        n = K.shape[0]
        if scale is None:  # diag(K)^(-1/2) where positive, else 1
            d = K.diagonal()
            with np.errstate(divide="ignore", invalid="ignore"):
                scale = np.where(d > 0, 1.0 / np.sqrt(d), 1.0)
        scale = np.asarray(scale, dtype=float)
        ok = (scale > 0) & np.isfinite(scale)  # elsewhere no scaling (2⁰)
        k = np.zeros_like(scale)
        k[ok] = np.rint(np.log2(scale[ok]))
        self.d = np.exp2(k)  # powers of two: scaling by them is exact
        self.dinv = np.exp2(-k)
        # two arrays of nnz, no more (fresh pages cost as much as the arithmetic here)
        data = np.repeat(self.d, np.diff(K.indptr))
        K1 = self.d[K.indices]
        data *= K1
        data *= K.data
        top = max(float(data.max()), -float(data.min())) if data.size else np.nan  # nan or inf: not finite
        self.exact = bool(np.isfinite(top))
        if not self.exact:
            return
        E = int(np.frexp(top)[1])  # max|K̃| < 2^E
        # the most stored entries (duplicates included) a row of the product sums: for CSR a row's
        # count; for CSC, counted over the row indices, unless the pattern is symmetric (then a
        # column's count is a row's: that count took 11 ms at 256², as long as two double products)
        counts = np.diff(K.indptr)
        if sp.isspmatrix_csc(K) and not symmetric:
            counts = np.bincount(K.indices, minlength=n)
        N = int(max(counts.max(initial=0), 1))
        bits = _MANTISSA - 1 - int(np.ceil(np.log2(N + 1)))
        self.a = bits // 2
        self.beta = bits - self.a
        grid = np.ldexp(1.0, E - self.a)
        np.divide(data, grid, out=K1)
        np.rint(K1, out=K1)
        K1 *= grid
        data -= K1  # exact: K₂
        fmt = type(K)
        self.K1 = fmt((K1, K.indices, K.indptr), shape=K.shape)
        self.K2 = fmt((data, K.indices, K.indptr), shape=K.shape)

    def __call__(self, b: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``b − K x``: the error about 2⁻⁷⁰ of ``|K||x|`` row by row (see the module)."""
        b = np.asarray(b, dtype=float)
        x = np.asarray(x, dtype=float)
        if not self.exact:
            return b - self.K @ x
        col = b.ndim == 2
        d = self.d[:, None] if col else self.d
        dinv = self.dinv[:, None] if col else self.dinv
        y = x * dinv
        m = np.abs(y).max(axis=0) if y.size else np.zeros(y.shape[1:])
        if not np.all(np.isfinite(m)):
            return b - self.K @ x  # nothing exact about inf or nan
        grid = np.ldexp(1.0, np.frexp(m)[1] - self.beta)  # per column
        y1 = np.rint(y / grid)
        y1 *= grid
        y2 = y - y1  # exact
        r = b * d
        r -= self.K1 @ y1  # K₁ y₁ is exact; one rounding here
        r -= self.K1 @ y2 + self.K2 @ y
        r *= dinv
        return r
