r"""Primal–dual active set (semismooth Newton) for the sparse primal contact QP.

The problem
-----------
The primal formulation's QP (:class:`plateqp.contact.formulations.Primal`)

.. math::

    \min_x\ \tfrac12 x^T P x + q^T x \quad\text{s.t.}\quad G x \le h,

with ``P`` sparse, few rows ``m ≪ n`` in ``G``, no equalities and no bounds. The backend
refuses any other shape with a :class:`~plateqp.errors.SolverError`, so that it is offered
only where it makes sense.

Variables ``x_j`` that are *separable* (the column of ``P`` holds only ``P_jj > 0``, the column
of ``G`` one entry ``γ`` in row ``i``) are eliminated exactly: stationarity gives
``x_j = −(q_j + γ λ_i) / P_jj``. On the primal formulation those are the spring variables
``t`` (``P_tt = 1``, ``G_it = −√ρ_i``), so what remains is the contact problem in the plate's
own terms, with ``K = P_uu``, ``f = −q_u``, ``B = G_u`` and, per row, a flexibility
``ρ_i = Σ γ²/P_jj`` (0: rigid) and gap ``g_i = h_i + Σ γ q_j / P_jj``:

.. math::

    K u - f + B^T\lambda = 0,\qquad
    \lambda \ge 0,\quad \mathrm{gap} = g + \rho\lambda - B u \ge 0,\quad
    \lambda_i\,\mathrm{gap}_i = 0 .

The method
----------
Semismooth Newton on ``min(λ, c ⊙ gap) = 0`` (``c_i = k_i / (1 + ρ_i k_i)``, the local
stiffness ``k_i = Σ_j B_ij² K_jj`` of row ``i`` in series with its spring), i.e. the
primal–dual active set method: with the active set ``A = {i : λ_i − c_i gap_i > 0}`` each
step solves the equality-constrained problem

.. math::

    K u + B_A^T \lambda_A = f,\qquad B_A u - \rho_A \lambda_A = g_A,\qquad \lambda_I = 0 .

With exact steps (``gap_A = 0``, ``λ_I = 0``) the rule reads: a row leaves ``A`` when its
reaction is negative and enters when its gap is, all at once; this is block principal
pivoting (Júdice & Pires 1994) on the dual LCP, and the choice of ``c`` only scales the
tolerances. **Globalisation**: block exchanges can cycle (the plate's condensed stiffness is
not an M-matrix, so the monotone convergence of PDAS is not guaranteed), so the number of
infeasible rows is watched; when it has not fallen below its best value for ``p`` steps, or
an active set comes back, one row only is exchanged, the infeasible row of largest index
(Murty's rule), until the count falls again. Murty's rule terminates for a P-matrix, which
the dual LCP's matrix ``B K⁻¹ Bᵀ + diag(ρ)`` is whenever ``K`` is definite and ``B`` has full
row rank; ``max_iter`` bounds the work for the rest (``Status.MAX_ITER``).

Two ways to solve a step
------------------------
``method="condensed"`` (:mod:`.dense`; the default where CHOLMOD is at hand, through
scikit-sparse or the copy in cvxopt's wheels, ``K`` is definite and the rows touch at most
``max_dense`` dofs ("auto": 2000 to 4000 as the mesh grows, :data:`.options.MAX_DENSE_AUTO`;
where every row is soft, 8 √n for n dofs, :data:`.options.MAX_DENSE_SOFT`, as the sparse
method's Newton phase is cheaper there):
discrete supports on a held plate). The dofs the rows act on go *last* in
the elimination order (AMD order on the rest); one sparse Cholesky ``K = L Lᵀ``
(:class:`plateqp.linalg.SchurFactor`) then holds, in its trailing dense block ``L_cc``, the
static condensation of every other dof: ``L_cc L_ccᵀ`` is the condensed stiffness. With ``Z = L_cc⁻¹ B_cᵀ`` (a dense triangular solve) the dual LCP

.. math::

    \mathrm{gap} = d + M\lambda,\qquad M = Z^T Z + \mathrm{diag}(\rho) = B K^{-1} B^T + \mathrm{diag}(\rho),
    \qquad d = g - B K^{-1} f,

costs no column solves at all (where each row is one dof, ``M`` is the inverse of
``L_cc L_ccᵀ``, LAPACK's POTRI, rows and columns scaled). Measured on a 128 × 128 plate with a
30 × 30 grid of supports: the contacts-last factor costs about 1.5–2 plain factorisations,
plus a third of one to read ``L_cc``, where the columns ``K⁻¹ B_iᵀ`` (each about 1/50 of a
factorisation, even solved in blocks) would cost 18 for the 900 rows. Each active set is
then a dense Cholesky of ``M_AA`` (|A|³/3 flops). The final set is solved on the exact sparse
equations by iterative refinement with ``K⁻¹`` and ``M_AA`` (two sparse solves per step, while
the residuals are above rounding: usually none), so rounding in ``d`` (``g − B K⁻¹ f``
cancels) does not reach the answer. ``M`` itself is accurate to about ``cond(K)·ε``; at a row
whose gap and reaction both end near zero that can call it infeasible both in and out of the
set, and Murty's rule then toggles it for ever (in exact arithmetic it terminates). So a set
met a second time is classified on the exact equations instead, as the final one is. ``K``
must be definite: a floating plate's (or one free to turn about a single held edge) is found
by the trailing block's smallest pivot and an estimate of its smallest eigenvalue (two inverse
iterations, :meth:`plateqp.linalg.SchurFactor.smallest_eigenvalue`) below ``PIVOT_TOL``, or
CHOLMOD stops on it (the QP's hint ``QP.singular``, which the primal formulation sets for a
floating plate, skips that factorisation), and goes to the sparse method. With stiff rows and
no given set, such a plate's first set is the contact set of the *anchored* plate: each dof
the rows act on held by a spring of ``ANCHOR·K_jj`` (``10⁻⁸``: the contacts-last factor with
that shift on its trailing diagonal, definite where the rows, held, hold the plate), found
by the dense steps on its LCP without exact steps (:func:`.dense.anchored_set`); the sparse
method's exact steps then solve the plate itself from that set (``extras["first_phase"] ==
"anchored"``, option ``anchor_start``; where that set leaves the plate free to move, as one
heaved post under a plate with no load does, and its factor with the rows' penalty is not
definite to working precision, they start again from every row: ``extras["anchored_dropped"]``), on the anchored factorisation itself where the rows'
dofs are few enough (its trailing block replaced by the dense Cholesky of ``S + B_cᵀ W_A B_c``,
:class:`.factor.TrailingFactor`; ``extras["factor"] == "trailing"``, its dense factorisations in
``trailing_factorisations``; no second sparse factorisation: a floating 128² slab on 9 posts
0.69 s → 0.43 s, on 900 posts 0.84 s → 0.70 s, held on one edge on 900 posts 1.14 s → 0.79 s,
CPU, one run each), else on a sparse factorisation of their own. Measured on a 128² slab with 30 × 30 posts (CPU, one
run): held on one edge only, 7.5 s (29 sets, one factorisation each) → 0.9 s (2
factorisations); floating on the posts alone, 2.9 s → 0.9 s. With stiff rows (median ``ρ_i k_i < 1``: rigid posts) and no
given set, the first set is found by Lawson–Hanson's method on the dual QP
(:func:`.dense.first_set`: rows freed one at a time, a Cholesky factor grown by a row, k²
flops a step) while that costs less than about one of the block steps' Cholesky factors of
``d < 0``: where few of many rows end in contact the block steps from ``d < 0`` take tens
of large dense factorisations (30 × 30 posts: 30–34 sets from 892 rows to 124–131), these
about one step per contact, and their set is the final one. The same factor
solves throughout: with cvxopt, ``L_cc`` is copied out of CHOLMOD's factor without spending it
(:mod:`plateqp.linalg.cholmod`; before, a second, plain factorisation of ``K`` did the solves).

``method="sparse"`` (:mod:`.sparse`; beds: every node a contact point; floating plates; no
CHOLMOD). One
sparse Cholesky of

.. math::

    H_A = K + \sigma\,\mathrm{diag}(K) + B_A^T W_A B_A,\qquad
    W_i = \frac{1}{\rho_i + 1/\beta_i},\quad \beta_i = \kappa\, k_i,

a spring on each active row (the row's own spring for an elastic support; a stiff penalty
spring, ``κ = 10⁸``, for a rigid one; in series for a stiff elastic one); ``σ = 10⁻¹²`` keeps
``H_A`` definite for a floating plate whose active rows do not hold it. The exact step is
reached by iterative refinement on the exact equations (proximal augmented Lagrangian):
with ``r_u = f − K u − B_Aᵀλ_A`` and ``r_A = B_A u − g_A − ρ_A λ_A``,

.. math::

    H_A\,\delta u = r_u - B_A^T W_A r_A,\qquad
    \lambda_A \leftarrow \lambda_A + W_A (r_A + B_A \delta u),\qquad u \leftarrow u + \delta u,

exact in one step for springs, contracting a rigid row's error by about
``1/(1 + κ k λ_min(flexibility))`` per step. While the active set still changes one or two
solves classify the rows; the final set is solved to rounding. The factor follows the active
set: the symbolic analysis (of the pattern of ``K + BᵀB``, which contains every ``H_A``) is
done once and every change is a numeric refactorisation with it; with scikit-sparse, rows
that enter or leave are instead added or removed by CHOLMOD's rank-k update/downdate when
that is cheaper (the costs are measured as the solve goes: about 0.4 ms a row against 0.15 s
a factorisation on a 128 × 128 plate). A downdate of a stiff penalty loses about ``ε κ``
relative; that only slows the refinement, and the factor is rebuilt when the accumulated
loss says so. Without CHOLMOD every change refactorises with :class:`plateqp.linalg.Factor`
(SuperLU: its analysis cannot be re-used). Without an in-place update (cvxopt's CHOLMOD, the
default install, or Factor), a change of a few soft rows is taken by the Sherman–Morrison–
Woodbury formula on the factor in hand (one solve with k right-hand sides, a k × k
capacitance) while that costs under half a factorisation; not for a rigid row, entering or
leaving, whose weight would multiply Woodbury's rounding into the residual (``ε κ``), nor
where the factor is nearly singular along a rigid motion the rows move
(``extras["lowrank"]``, ``extras["lowrank_rows"]``). On the 128 × 128 bed below, the last
exchange (two rows) is such a correction: two factorisations instead of three.

A bed's first steps change thousands of rows each (plain PDAS from the two-sided start:
16 641 → 11 501 → 9 352 → 8 727 → 8 658 rows in contact on a 128 × 128 bed, a
refactorisation each). So when every row is a soft spring (``ρ_i k_i ≥ 1``: no stiffer than
the plate under it), a first phase finds the contact without refactorising: semismooth
Newton on the energy ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²`` (the tensionless bed's
own energy), each Newton system solved roughly (PCG to ``PCG_TOL``) with one factor as
preconditioner, then an exact line search (the energy is piecewise quadratic along a line).
Removing soft springs changes ``H`` only in its few smooth, spring-dominated modes, so PCG
needs a handful of iterations. When a Newton step changes few rows (``NEWTON_SETTLED``), the
factor is rebuilt once for that active set and exact steps finish as above. On a cold start
the factor is that of the two-sided matrix: on the 128 × 128 bed three Newton steps, 13 PCG
iterations, then one exact step and two rows exchanged (a Woodbury correction): two
factorisations. With a warm start the factor is that of its set, so a good one (a sweep's
previous answer; :mod:`plateqp.contact.predict`'s coarse mesh, 8 of 16 641 rows wrong on that
bed) costs one factorisation (no Newton step where the set's own minimiser keeps it or moves
at most LOWRANK_MAX rows; those a Woodbury correction), and a bad one costs PCG
iterations, not refactorisations (every row of the bed's set flipped at random in 10 %: three
Newton steps, two factorisations).

Stiff rows (rigid posts) on a held plate, cold start: plain PDAS from the two-sided start cycles
and falls back to Murty's one row per step (a 64 × 64 slab with 45 × 45 posts: 407 steps, each a
refactorisation). So a first phase finds the contact. First Lawson–Hanson's method as in the
condensed method (:func:`.dense.first_set`), but with the rows of ``M`` it frees computed as it
frees them, by solves with a factor of ``K`` alone (:func:`.sparse.lawson_hanson`; eight rows in
one block solve, the freed row and the rows pressed hardest after it): where few of many rows
end in contact that is about as many solves as contacts, never all of ``M`` (a post on every
node of a 128 × 128 slab: 261 sets, 348 of 16 129 rows computed, 209 in contact; the exact steps
then confirm the set in one step). Its time is held to ``LH_TIME`` factorisations (measured as
it goes), and where most rows stay pressed after ``LH_PROBE`` rows freed (a broad contact, as on
a stiff bed: one row a step would take hundreds of steps) it stops there; either way it hands
the reactions it reached, feasible, to projected Newton on the dual energy
``ψ(λ) = ½λᵀMλ + dᵀλ`` over ``λ ≥ 0`` (Bertsekas 1982; :func:`.sparse.dual_newton`), ``M`` never
formed: from ``λ = 0`` (or those reactions) each step solves the active set
``F = {λ > 0} ∪ {gap ≤ 0}`` (the Newton step of ``ψ`` on that face) and clips its negative
reactions to zero; ``ψ`` and the gaps at a clipped point take one solve with a second factor, of
``K`` alone. Full steps are taken until ``DUAL_RISES`` of them have raised ``ψ``; then monotone
steps (the arc searched back to Armijo's decrease) from the lowest point met. It hands its set
to the exact steps when a step leaves few rows infeasible or ``ψ`` stops moving (same slab: 21
steps in all; from Lawson–Hanson's reactions on a stiff bed at 40², 4 steps instead of 15). Both
need ``K`` definite (two inverse iterations tell, :func:`.sparse.held_plate`). On a floating
plate (where method "auto" has not found the anchored plate's set already, above: with
``method="sparse"``, or above ``max_dense`` rows) Lawson–Hanson runs on the anchored plate's
flexibility instead (:func:`.sparse.anchored_plate`: each row held by a spring of
``ANCHOR·k_i``), without the probe for a broad contact (the anchored plate starts sunk, every
row pressed) and within ``LH_ANCHORED`` factorisations' time; where it gives up, the exact
steps start from the rows it holds and those still pressed (the projected Newton phase needs
the plate's own ``K⁻¹``). Options ``lh_start=False`` and ``dual_start=False`` turn the first
phases off, ``anchor_start=False`` the anchored ones (plain PDAS from every row).
``extras["first_phase"]`` says which first phase ran ("newton", "lawson-hanson", "dual",
"anchored", "anchored lawson-hanson", "anchored lawson-hanson (gave up)" or "none"),
``extras["first_phase_steps"]`` its steps (``extras["anchored_s"]``: the anchored plate's time,
its factorisation included; ``extras["anchored_first_set"]``: how its dense steps started, as
the condensed method's ``extras["first_set"]``), and ``extras["lh_sets"]``,
``extras["lh_columns"]``, ``extras["lh_s"]`` the sets Lawson–Hanson solved, the rows of ``M`` it
computed and their solves' time (``extras["lh_gave_up"]``: "time", "pressed" or "memory", where
it gave up: the rows it keeps may take ``LH_MEMORY`` bytes per dof).

Singular steps and no equilibrium (sparse method)
-------------------------------------------------
If the active rows do not hold a floating plate, the refinement's first correction is
dominated by a rigid motion ``d`` (``K d ≈ 0``, ``B_A d ≈ 0``), recognised by its Rayleigh
quotient ``δuᵀ(H_A − σD)δu / (σ δuᵀDδu) < 1`` (a held plate gives ``λ_min/σ ≳ 10⁴``). Rows that
``d`` would press into (``B_i d > 0``) enter the active set; if there are none and the load
does work along ``d`` (``fᵀd > 0``), then ``K d = 0``, ``G d ≤ 0``, ``qᵀd < 0``: a certificate
that the QP is unbounded below, the plate cannot be held (``Status.UNBOUNDED``,
``extras["ray"]``; the contact driver turns it into :class:`~plateqp.errors.NoEquilibriumError`
after its own statics check). Before it is judged, ``d`` is sharpened by inverse iteration with
``H_A`` and, where the QP names the plate's rigid motions ``N`` (``QP.null``, which the primal
formulation sets for a floating plate; checked to be ``P``'s null space to rounding before it
is used), replaced by the exact one nearest it: its ``diag(K)``-projection onto the rigid motions
that move no active row (``N`` times the null space of ``B_A N``; FREE_RIGID, RIGID_RANK), so
that its work is the load's statics along an exact motion, free of ``d``'s own rounding (the
plate's softest elastic modes, which grow with the mesh). If the load does no work along it
(``|fᵀd| ≤ FREE_WORK Σ|f_j d_j| + FREE_FLOOR Σ|f_j| max|d_j|``: a load balanced about a line of
supports, or on a corner support), every ``u + t d`` solves the step equally well: the
corrections leave ``d`` out (projected off in the ``diag(K)`` metric, at most three such
motions; and the residual's work along it taken off before each solve, which would return it
multiplied by 1/σ) and the method goes on; the reactions are unique, the deflection is not, and
:func:`plateqp.contact.statics.settle` picks the canonical one (``deflection_unique = False``).
The answer's residuals are checked as always: the work left along ``d`` stays in the
stationarity residual that decides ``OPTIMAL`` against ``INACCURATE``. Where the load pushes
along ``−d`` and the rows it presses would make a set already left on its exact step, the push
is taken as rounding and ``d`` kept out the same way (else a load 1e-10 inside the line of
two posts cycled between the sets with and without the far posts), and a set met again is
solved exactly before it is judged. Before a floating plate's final set is called optimal,
its hold on the plate is checked: where the QP names the rigid motions, by the rank of
``B_A N`` and the stiffness of the least held one (:func:`.motions.rows_hold`, no solve;
``extras["hold_check"] = "rigid motions"``), else by two inverse iterations with ``H_A``
(:func:`.motions.free_mode`, two solves; ``"inverse iteration"``), whose free motion is judged
as above. The condensed method needs a definite ``K`` and leaves floating plates to the
sparse one.

Warm start and output
---------------------
Option ``active`` (bool array over the rows of ``G``) gives the first active set (default:
for the condensed method, Lawson–Hanson's set (stiff rows, within its budget) or else the
rows the unsupported plate would press into, ``d < 0``, as ``extras["first_set"]`` says; for
the sparse one, the set its first phase finds, or every row, the two-sided problem, where no
first phase applies; on soft rows a warm start is the first phase's factor, above);
``extras["active"]`` holds the final set,
so a sweep can warm start each solve from the previous one. ``x`` (``u`` with the eliminated
variables restored), ``z = λ ≥ 0`` (one per row of ``G``, the qpsolvers sign convention),
``iterations`` (active sets solved, the steps of the first phase and Lawson–Hanson's
included: ``extras["first_set_steps"]``, ``extras["lh_sets"]``, even where it gave up),
``solve_time``; ``extras`` has the method and the counts and times of the linear algebra
(``extras["trace"]`` each step, with option ``trace``).

Accuracy
--------
A direct method: at every preset the final active set is solved to rounding. The presets of
:data:`ACCURACY` set only the tolerance under which a negative reaction or gap counts as zero
(``feas_tol``) and the residual above which the answer is flagged ``INACCURATE``
(``accept_tol``), checked on the answer itself: the relative natural residual
``max |min(λ_i, c_i gap_i)| / max(‖λ‖∞, 10⁻¹² ‖f‖₁)`` (as :mod:`plateqp.contact.kkt`) and the relative
stationarity residual ``‖K u − f + Bᵀλ‖ / max(‖f‖, ‖Bᵀλ‖)``.

Layout
------
:mod:`.reduced` (the QP read back as a contact problem, :class:`~.reduced.ReducedQP`; the
exchange rule), :mod:`.dense` (``method="condensed"``), :mod:`.sparse` (``method="sparse"``),
:mod:`.motions` (its free rigid motions), :mod:`.factor` (its factors), :mod:`.driver` (the
:func:`pdas` function), :mod:`.options` (presets and settings); this file holds the backend,
:class:`PDAS`.
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
