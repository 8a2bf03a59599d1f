r"""Primal–dual active set (semismooth Newton) for the sparse primal contact QP.

The problem: ``min ½ xᵀPx + qᵀx`` s.t. ``G x ≤ h`` with ``P`` sparse, few rows ``m ≪ n`` in
``G``, no equalities, no bounds (the primal formulation, :class:`plateqp.contact.formulations.Primal`);
any other shape is a :class:`~plateqp.errors.SolverError`. Separable variables (a spring's
``t``) are eliminated exactly, leaving the contact problem in the plate's own terms
(:class:`~.reduced.ReducedQP`): ``K u − f + Bᵀλ = 0``, ``λ ≥ 0``, ``gap = g + ρλ − B u ≥ 0``,
``λ·gap = 0``.

The method: semismooth Newton on ``min(λ, c ⊙ gap) = 0``; each step solves the equality
problem of its active set, all infeasible rows exchanged at once (block principal pivoting on
the dual LCP) and, where the count of infeasible rows stops falling or a set comes back, one
row at a time (Murty's rule, finite where ``B K⁻¹ Bᵀ + diag(ρ)`` is a P-matrix). Two ways to
solve a step:

- ``method="condensed"`` (:mod:`.dense`): one contacts-last sparse Cholesky of ``K`` whose
  trailing block gives the dual LCP's matrix ``M = B K⁻¹ Bᵀ + diag(ρ)``, dense steps on it and
  the final set refined on the exact sparse equations; needs ``K`` definite and at most
  ``max_dense`` dofs under the rows.
- ``method="sparse"`` (:mod:`.sparse`): a factor of ``K + σ diag(K) + B_Aᵀ W_A B_A`` (a spring on
  each active row), iterative refinement to the exact step, refactorisations, rank-k updates
  or Woodbury corrections as the set changes; for beds, floating plates and many rows. Where
  every row is soft (ρ k ≥ 1) and the plate is held (by its two-sided supports, or by the
  start's rows and the final set's), σ = 0 and ``W = 1/ρ``: the factor is the step's own
  matrix, and a set's step one solve (``extras["shift"] = 0.0``); else, or where that run
  does not end on a held set, the shifted factor above.

First phases find the contact set before the exact steps where plain exchanges would be slow
(Newton–PCG on soft rows, Lawson–Hanson and projected Newton on the dual for stiff ones, the
anchored plate's set for a floating one); a floating plate's free rigid motions are found and
judged by the load's work along them (status ``UNBOUNDED`` with the ray in ``extras["ray"]``
where the plate cannot be held; a unique reaction with a non-unique deflection otherwise).

Contract:

- **Options** (:data:`OPTIONS`, defaults in :data:`SETTINGS` and :data:`ACCURACY`): ``method``
  ("auto", "condensed", "sparse"), ``active`` (a warm start: bool over the rows of ``G``),
  ``max_iter``, ``max_dense``, ``max_rows``, ``p`` (steps before Murty's rule), the sparse
  method's ``penalty``, ``prox`` and ``factor``, the first phases' switches (``lh_start``,
  ``dual_start``, ``anchor_start``), ``feas_tol``, ``accept_tol``, ``trace``.
- **Output.** ``x`` (``u`` with the eliminated variables restored), ``z = λ ≥ 0`` (one per row
  of ``G``, qpsolvers' sign), ``iterations`` (sets solved, the first phases' steps included),
  ``extras["active"]`` (the final set: a sweep's next warm start), ``extras["first_phase"]``,
  the counts and times of the linear algebra.
- **Accuracy.** A direct method: at every preset the final set is solved to rounding; the
  presets set only ``feas_tol`` (a negative reaction or gap counted as zero) and
  ``accept_tol``, the residual (relative natural and stationarity) above which the answer is
  ``INACCURATE``. Where the QP names the plate's rigid motions (``QP.null``), the sparse
  method's residual leaves out K u's part along them (its rounding, where the plate moves far
  as a body): the reactions balance the load along them to rounding of the load.

Layout: :mod:`.reduced` (the contact problem, the exchange rule), :mod:`.dense`,
:mod:`.sparse`, :mod:`.motions` (free rigid motions), :mod:`.factor` (the sparse method's
factors), :mod:`.driver` (:func:`pdas`), :mod:`.options`; this file the backend :class:`PDAS`.
The design, step by step, with the measurements behind each choice: docs/design/pdas.md.
"""

from __future__ import annotations

from ...errors import SolverError
from ..base import QP, Backend, RawSolution, check_options, plateqp_version
from .driver import pdas
from .options import ACCURACY, OPTIONS, SETTINGS

__all__ = ["ACCURACY", "OPTIONS", "PDAS", "SETTINGS", "backends", "pdas", "solve"]


class PDAS(Backend):
    """The pdas backend (the shape of :class:`~plateqp.backends.base.Backend`): the primal
    formulation's QP only; a direct method (``exact``) that takes a first active set
    (``warm_start``: option ``active``, and ``extras["active"]`` in the answer)."""

    name = "pdas"
    accepts = frozenset({"qp"})
    #: The QP of the primal formulation only (see :func:`plateqp.contact.formulations_for`).
    formulations = ("primal",)
    exact = True
    warm_start = True

    def available(self) -> bool:
        """PDAS needs NumPy and SciPy only (CHOLMOD makes it faster): always available."""
        return True

    def version(self) -> str | None:
        return plateqp_version()  # the backend is part of plateqp

    def solve(self, problem, accuracy="default", options: dict | None = None) -> RawSolution:
        """Solve the primal formulation's :class:`~plateqp.backends.base.QP`.

        Parameters
        ----------
        problem : QP
            Sparse ``P``, ``G`` with ``m ≤ n`` rows (``m ≤ min(n, max_rows)`` with that option),
            ``h``; nothing else.
        accuracy : {"low", "default", "high"}, a float (a KKT tolerance; see base.preset) or an Accuracy
            Preset of :data:`ACCURACY`.
        options : dict, optional
            Keys among :data:`OPTIONS` (see :func:`pdas`).

        Raises
        ------
        SolverError
            Not a QP of the primal formulation's shape (an LCP, equalities, bounds, dense or too
            many rows).
        ProblemError
            Unknown accuracy or option.
        """
        if not isinstance(problem, QP):
            raise SolverError(f"the pdas backend solves the primal formulation's QP only, got "
                              f"{type(problem).__name__}; use formulation='primal'")
        return pdas(problem, accuracy=accuracy, **check_options(self.name, options, OPTIONS))


_BACKEND = PDAS()


def backends() -> list[Backend]:
    """The backends this module provides: ``[PDAS()]``."""
    return [_BACKEND]


def solve(problem, accuracy="default", options: dict | None = None) -> RawSolution:
    """``PDAS().solve``: the module-level call kept for scripts that import the module."""
    return _BACKEND.solve(problem, accuracy, options)
