"""Sparse linear algebra: the one place in plateqp that binds CHOLMOD (and SuperLU).

=====================  ===========================================================
:class:`Cholesky`      one CHOLMOD factor (scikit-sparse, or cvxopt's wheels): AMD order,
                       symbolic analysis once (an order may be given), numeric
                       (re)factorisation, solves with many right-hand sides, the trailing
                       block of the factor, rank-k update/downdate (scikit-sparse)
:class:`Factor`        equilibrated, refined factor of an SPD matrix; CHOLMOD or SuperLU;
                       ``refactor`` re-uses the analysis
:class:`SchurFactor`   one factor with chosen unknowns last: the Schur complement on them
                       (static condensation) and ``B K⁻¹ Bᵀ`` from its trailing block
:func:`row_stiffness`  the stiffness of a matrix along each row of an operator (no solves)
:func:`solve_saddle`   the saddle-point system [K Bᵀ; B −diag(ρ)]
:mod:`residual`        ``b − K x`` to about 2⁻⁷⁰ of ``|K||x|`` in double arithmetic (an
                       error-free split of the product): what refinement reads
:mod:`pattern`         scale and sum without dropping stored entries (the orderings read
                       the stored pattern: a plate's structural zeros keep nodes together)
:mod:`seam`            CHOLMOD's C API inside cvxopt's wheel through ctypes (NumPy arrays
                       read in place; cvxopt's binding where it does not load)
:mod:`heap`            the C heap's freed memory returned to the system before a factor
                       is allocated (glibc's ``malloc_trim``)
:mod:`products`        ``K x`` remembered inside one solve (the final ``u``'s product read
                       by the backend, the KKT report and the Result is computed once)
=====================  ===========================================================

Errors are :class:`~plateqp.errors.SingularMatrixError`, in matrix words; a caller that
knows what the matrix stands for says so.

Which CHOLMOD binding is used is read at every call from :data:`HAVE_CHOLMOD`
(scikit-sparse) and :data:`HAVE_CVXOPT` (cvxopt's wheels): set one to False to switch that
binding off (tests and benchmarks do, to run each path); with both off, SuperLU.
"""

from __future__ import annotations

from ..errors import SingularMatrixError
from . import cholmod as _cholmod
from . import pattern
from .cholmod import Cholesky
from .factor import METHODS, Factor
from .rows import row_stiffness
from .saddle import solve_saddle
from .schur import SchurFactor

#: scikit-sparse's CHOLMOD imported (set False to switch it off)
HAVE_CHOLMOD = _cholmod.HAVE_SKSPARSE
#: cvxopt's CHOLMOD imported (set False to switch it off)
HAVE_CVXOPT = _cholmod.HAVE_CVXOPT


def bindings() -> list[str]:
    """The CHOLMOD bindings in use, best first: "sksparse" (analysis re-use, rank-k updates),
    "cvxopt" (analysis re-use). Empty: SuperLU only."""
    out = []
    if HAVE_CHOLMOD:
        out.append("sksparse")
    if HAVE_CVXOPT:
        out.append("cvxopt")
    return out


__all__ = ["HAVE_CHOLMOD", "HAVE_CVXOPT", "METHODS", "Cholesky", "Factor", "SchurFactor", "SingularMatrixError",
           "bindings", "pattern", "row_stiffness", "solve_saddle"]
