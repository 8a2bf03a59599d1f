"""The settings of the pdas backend: accuracy presets, method options and tuning constants."""

from __future__ import annotations

#: Tolerances of each accuracy preset (a direct method: exact up to rounding at every preset).
#:
#: ``feas_tol``
#:     a reaction ``λ_i`` (a gap, as the force ``c_i gap_i``) counts as negative only below
#:     ``−feas_tol`` times the force scale ``max(‖λ‖∞, 10⁻¹² ‖f‖₁)``; smaller negatives are
#:     rounding (and such reactions are clipped to zero in the answer).
#: ``accept_tol``
#:     relative natural and stationarity residuals of the answer above which the status is
#:     ``INACCURATE`` instead of ``OPTIMAL``.
ACCURACY: dict[str, dict[str, float]] = {
    "low": {"feas_tol": 1e-8, "accept_tol": 1e-6},
    "default": {"feas_tol": 1e-11, "accept_tol": 1e-8},
    "high": {"feas_tol": 1e-13, "accept_tol": 1e-10},
}

#: Method settings (not accuracy: the answer is exact at every value); options override them.
#:
#: :method: "auto" (condensed where it applies, else sparse), "condensed", "sparse".
#: :max_dense: the condensed method only if the rows touch at most this many dofs; "auto":
#:                :data:`MAX_DENSE_AUTO`.
#: :penalty: κ (sparse): a rigid row's spring in ``H_A`` is κ times its local stiffness (on a
#:                row that reads several unknowns, at most twice its softest unknown's:
#:                :func:`.reduced.penalty_stiffness`).
#: :prox: σ (sparse): ``H_A`` includes σ diag(K) (definite for a floating plate).
#: :factor: (sparse) "cholmod" (scikit-sparse: analysis re-used, rank-k updates),
#:                "cvxopt" (CHOLMOD in cvxopt's wheels: analysis re-used, a numeric
#:                refactorisation at every change), "linalg" (:class:`plateqp.linalg.Factor`'s
#:                own choice, a new factorisation at every change), "superlu" (Factor's SuperLU,
#:                likewise); "auto": the first of these that is installed.
#: :p: block exchanges allowed without progress before Murty's single exchange
#:                (cycles always go to Murty's). 6, not Júdice–Pires' 3: on 30 × 30 post grids
#:                the block steps stall near the end (infeasible rows 7 → 24 → 12 → 41), and
#:                with 3 tries Murty's one-row steps then took 25–35 more sets; with 6, the
#:                block steps find a better set: 61 → 35, 46 → 34, 62 → 30 and 58 → 31 sets at
#:                32², 64², 128², 256² (a quarter of the dense method's time at 64²). Nothing
#:                else measured changed (other post grids, beds, 45² and 63² posts at 128²).
#: :max_rows: refuse a ``G`` with more rows than ``min(n, max_rows)``; None (the default):
#:                than ``n``. (It was 100 000, and ``backend="auto"``, which takes pdas for the
#:                primal problem, then refused every bed finer than 316 × 316 cells: the sparse
#:                method's memory grows as m, the dense method's is bounded by ``max_dense``,
#:                Lawson–Hanson's by LH_MEMORY; a 400² bed, 160 801 springs, solved in 9.5 s,
#:                2.6× one raw CHOLMOD factorise-and-solve.)
#: :max_iter: active sets solved before ``Status.MAX_ITER``; default 50 + 2 m.
#: :lh_start: (sparse, stiff rows, held plate, cold start) find the active set first by
#:                Lawson–Hanson's method with the flexibility's rows computed as it frees them
#:                (:func:`.sparse.lawson_hanson`, within LH_TIME factorisations' time).
#: :dual_start: (sparse, stiff rows, cold start) where that is off or gave up, find it by
#:                projected Newton on the dual energy (:func:`.sparse.dual_newton`); with both
#:                False: plain PDAS from the two-sided problem (every row active).
#: :anchor_start: (stiff rows, K singular: a floating plate, cold start) find the active set
#:                first on the plate with its rows anchored by soft springs (ANCHOR): method
#:                "auto", up to ``max_dense`` rows, by the condensed method's dense steps
#:                (:func:`.dense.anchored_set`); else by Lawson–Hanson on the anchored plate's
#:                flexibility (:func:`.sparse.anchored_plate`, with ``lh_start``); then the
#:                sparse method's exact steps from that set.
SETTINGS: dict = {"method": "auto", "max_dense": "auto", "penalty": 1e8, "prox": 1e-12, "factor": "auto",
                  "p": 6, "max_rows": None, "max_iter": None, "dual_start": True, "lh_start": True,
                  "anchor_start": True}

#: ``max_dense="auto"``: ``max(lo, min(hi, per_root · √n))`` for ``n`` coupled dofs. The condensed
#: method costs one contacts-last factorisation and about m³ dense flops (the trailing block and
#: M), the sparse one about 20–30 factorisations of K (≈ 100 n^1.5 flops each on plate meshes),
#: so the crossover grows with the mesh. Measured (CPU s, condensed / sparse, one run each):
#: 64², m = 1600: 0.61–0.83 / 1.09, m = 2025: 1.07 / 0.94–1.00; 128², m = 2025: 1.59 / 3.98,
#: m = 3025: 3.84 / 7.20, m = 3969: 7.33 / 4.63; 256², m = 2025: 3.74 / 27.5, m = 3969: 10.3 /
#: 29.9. ``lo`` keeps the earlier fixed limit (2000) on small meshes; ``hi`` bounds the dense
#: blocks' memory (m² doubles each: 128 MB at 4000).
MAX_DENSE_AUTO = (2000, 4000, 16.0)
#: ... where every row is soft (``ρ_i k_i ≥ 1``): ``MAX_DENSE_SOFT · √n``, no floor. The sparse
#: method there is a Newton phase on one factor (2–8 factorisations in all, not 20–30), so the
#: crossover is lower: measured (CPU s, condensed / sparse, medians of 3, on scenes built
#: from families.py): a walled slab on a bed, 32² (n = 3007), m = 961: 0.091 / 0.014; grid_elastic
#: 40 × 40 at 48² (m = 1600): 0.385 / 0.112, at 64²: 0.429 / 0.183, at 96² (n = 27 455): 0.486 /
#: 0.519; 30 × 30 piles over a bed at 32² (m = 1861): 0.402 / 0.144; grid_elastic 30 × 30 at
#: 64² (n = 16 895, m = 900): 0.140 / 0.145, at 128²: 0.311 / 0.728; 15 × 15 at 64²: 0.043 /
#: 0.081. The even split lies near m = 8 √n.
MAX_DENSE_SOFT = 8.0

#: Keys accepted in the ``options`` dict of :func:`solve`.
OPTIONS = ("active", "trace") + tuple(SETTINGS) + tuple(ACCURACY["default"])

#: (sparse) A first correction with Rayleigh quotient δuᵀ(H − σD)δu / (σ δuᵀDδu) below this is
#: a rigid motion the active rows do not hold.
SINGULAR_QUOTIENT = 1.0
#: (sparse) A rigid motion d the active rows leave free is one the load does no work along when
#: |fᵀd| ≤ FREE_WORK Σ|f_j d_j| + FREE_FLOOR Σ|f_j| max|d_j| (rounding: the sum's own, and d's,
#: which for a load on d's axis is all of Σ|f_j d_j|: measured 7e-13 of the second term for a
#: point load on the line of two posts at 8², 3.5e-12 at 64², 2.7e-11 at 128², and 1.0e-10 for
#: one 1e-10 of the plate's size off it, so a load within about FREE_FLOOR of the plate's size
#: of the axis is on it; at 128² d's rounding is above that: a load on the line is called
#: unbounded there); the steps then leave d out (any solution along it is
#: one; contact.statics.settle picks the canonical deflection). At most FREE_MOTIONS of them (a
#: plate has three rigid motions); each sharpened by FREE_SHARPEN inverse iterations.
FREE_WORK, FREE_FLOOR, FREE_MOTIONS, FREE_SHARPEN = 1e-9, 1e-11, 3, 2
#: Where the QP names the plate's rigid motions (:attr:`plateqp.backends.base.QP.null`), a free
#: motion found by the inverse iterations is replaced by the exact rigid motion nearest it (its
#: D-projection onto those that move no active row: the null space of ``B_A N``, singular values
#: above RIGID_RANK of the largest), where it is within FREE_RIGID of it (D-norm, relative).
FREE_RIGID, RIGID_RANK = 1e-6, 1e-9
#: ... and the final set's hold check is the rank of ``B_A N`` there (:func:`.motions.rows_hold`,
#: no solve) where the least held rigid motion is also this many times stiffer than the inverse
#: iterations' threshold SINGULAR_QUOTIENT·σ; else the inverse iterations decide (two solves:
#: 0.024 s of 0.35 s on the benchmark bed at 128²). The quotient falls as h⁴ (D grows as
#: h⁻⁴): on the benchmark bed 1.4e-5 at 32², 5.7e-8 at 128² (σ = 1e-12).
HOLD_MARGIN = 100.0
#: Refinement: at most this many solves per active set while it changes, and for the final set.
INNER_LOOSE, INNER_EXACT = 2, 12
#: (sparse) While the active set changes, refinement stops at this relative residual.
LOOSE_TOL = 1e-7
#: (sparse) Rebuild the factor rather than downdate when the digits lost to downdates
#: (Σ ε·ΔW_i/c_i) would pass this: a soft spring's downdate loses ~ε, a rigid row's penalty
#: ~ε·κ = 2e-8, which would hide the σ-sized modes of a plate the active rows do not hold.
DOWNDATE_LOSS = 1e-10
#: (sparse, without an in-place update) A change of at most LOWRANK_MAX rows is taken by a
#: Woodbury correction on the factor in hand (its n × k columns: 26 MB at 256² for 16 rows)
#: while its new columns (one block solve) cost at most
#: LOWRANK_COST factorisations and its capacitance's singular values stay above LOWRANK_COND
#: relative (else the factor is rebuilt).
LOWRANK_MAX, LOWRANK_COST, LOWRANK_COND = 16, 0.5, 1e-10
#: (sparse) A sweep's first solve of a value on the kept factor: a right-hand side within
#: SPAN_TOL (relative, 2-norm) of the span of those solved before on the same matrix (at most
#: SPAN_KEEP) is their combination, no solve (:meth:`.factor.SpringFactor.solve_in_span`; a
#: gap's or a load's values span two; 2 · SPAN_KEEP vectors of the plate's size kept beside it).
SPAN_KEEP, SPAN_TOL = 3, 1e-14
#: (sparse, soft rows) Phase 1: at most this many Newton steps, PCG to this relative tolerance
#: (at most PCG_MAX iterations each); it ends when a step changes at most
#: max(NEWTON_SETTLED, NEWTON_SETTLED_FRACTION · m) rows, or when its solves have cost
#: NEWTON_BUDGET factorisations.
NEWTON_STEPS, PCG_TOL, PCG_MAX = 8, 5e-2, 30
NEWTON_SETTLED, NEWTON_SETTLED_FRACTION, NEWTON_BUDGET = 10, 2e-3, 3.0
#: The line search looks for the minimum up to this step length.
ALPHA_MAX = 1e3
#: (sparse, stiff rows) Phase 1, projected Newton on the dual energy: at most DUAL_STEPS steps.
#: Full (projected) steps until DUAL_RISES of them have raised the energy; then monotone steps
#: from the lowest point met, the arc halved (down to ALPHA_MIN) until Armijo's sufficient
#: decrease ARMIJO. It applies where two inverse iterations give K a Rayleigh quotient above
#: DUAL_DEFINITE·σ (a held plate). A rise is one above DUAL_ROUNDING relative (rounding of ψ).
#: It ends when the step of the free rows leaves at most max(NEWTON_SETTLED,
#: NEWTON_SETTLED_FRACTION · m) rows infeasible at LOOSE_TOL: the exact steps start from that
#: set (after DUAL_STEPS, from the set whose step left the fewest).
DUAL_STEPS, DUAL_RISES, ARMIJO, ALPHA_MIN, DUAL_DEFINITE, DUAL_ROUNDING = 60, 8, 1e-4, 1e-4, 1e2, 1e-9
#: ... or when three steps in a row changed ψ by at most DUAL_FLAT relative.
DUAL_FLAT = 1e-7
#: (condensed, cold start, stiff rows: median ρ_i k_i < 1) The first active set by
#: Lawson–Hanson's method on the dual QP (rows freed one at a time, most negative gap first;
#: :func:`.dense.first_set`). Its k-th row costs 3k² + 2mk + LH_OVERHEAD flops (BLAS 2, and
#: Python's overhead); it gives up when that work would pass LH_BUDGET times the block steps'
#: first Cholesky, that of the set ``d < 0`` (|A₀|³/3 flops), or when, after LH_PROBE rows,
#: the rows freed plus the rows still pressed (the final size, foretold) would. The block steps
#: then start from ``d < 0`` as before. Measured (single solves, CPU): 30 × 30 post grids, 900
#: rows, 124–131 in contact at the end: from ``d < 0`` (892 rows) the block steps took 30–34
#: sets and 0.07–0.10 s, these 145 rows 0.02–0.03 s, and their set was the final one; 44 × 44
#: posts at 128² (1936 rows, 177 at the end): 48 block sets. Where most rows end in contact
#: (stiff beds on a held plate: 193 of 529, 1091 of 1521), it gives up at the probe.
LH_BUDGET, LH_OVERHEAD, LH_PROBE = 0.5, 5e4, 24
#: (sparse, stiff rows, held plate, cold start) Lawson–Hanson's first set with the rows of M
#: computed as they are freed (:func:`.sparse.lawson_hanson`): LH_BLOCK rows a block solve,
#: while the method has taken at most LH_TIME factorisations' time (then the projected Newton
#: phase, from the reactions reached). Measured at 128² (CPU): a post on every node, 16 129
#: rows, 209 in contact at the end: 261 sets, 348 rows computed, 2.5–3 s in all (12–16
#: factorisations; the projected Newton phase took 54 factorisations, 12.7 s in all); one block
#: solve of 1, 4, 8, 16 right-hand sides cost 12, 5.8, 5.1, 3.8 ms a column, and 16 computed
#: more rows never freed than 8 saved. Where most rows end in contact (stiff beds on a held
#: plate: 864 of 1521 at 40², 5272 of 9025 at 96²) it would take one step a row (387 s at 96²):
#: it gives up when, LH_PROBE rows freed, more than LH_PRESSED of all rows are still pressed
#: (post grids and a post on every node: 10–15 %; those beds: 82 %, 87 %), and the projected
#: Newton phase starts from its reactions.
#: The rows of M it keeps (m doubles each, in a buffer that doubles) may take at most LH_MEMORY
#: bytes per dof of the plate, a quarter of what plateqp plans for a whole solve
#: (:data:`plateqp.model.memory.BYTES_PER_DOF`): a post on every node needs 33 MB at 128², 416 MB at
#: 256² (389 rows in contact, 590 MB allowed); at 512² it would give up.
LH_BLOCK, LH_TIME, LH_PRESSED, LH_MEMORY = 8, 30.0, 0.5, 3000
#: (sparse, stiff rows, floating plate, cold start) Lawson–Hanson on the anchored plate's
#: flexibility (:func:`.sparse.anchored_plate`) may take LH_ANCHORED factorisations' time: where
#: it gives up, the exact steps start from every row (plain PDAS: 18–155 factorisations on the
#: floating and one-edge slabs measured), not from the projected Newton phase. Measured (CPU,
#: one run each), a post on every node, slab simply supported on one edge only: 48², 402 sets
#: took 0.44 s in all, past 30 factorisations' time (it gave up at 381 sets, 1.33 s in all;
#: plain 1.25 s); 128² with 63 × 63 posts, 624 sets, 6.7 s in all (plain 31 s).
LH_ANCHORED = 100.0
#: ... and it gives up where, (rows freed, fraction) = LH_ANCHORED_PROBE, more than that
#: fraction of the rows are still pressed: the anchored plate starts sunk (every row pressed),
#: so LH_PROBE's test would stop it on every plate; by 96 rows freed the pressed fraction is
#: near the fraction that ends in contact (measured: held on one edge 0.15–0.16, final
#: 0.15–0.22; floating 0.38–0.45, final 0.38–0.41; held plates 0.04–0.06).
LH_ANCHORED_PROBE = (96, 0.3)
#: (condensed) A trailing pivot L_ii², or the estimate of the trailing block's smallest
#: eigenvalue (two inverse iterations), below this (K equilibrated to a unit diagonal) means K is
#: singular to working precision (a floating plate): the sparse method takes over. Measured: a
#: floating plate's estimate 3e-16–5e-16 (its smallest pivot 1e-13–5e-13: a pivot test at 1e-13
#: let a bed at 24² and 40² through, and with springs of 1e9 the dense method then ran to
#: MAX_ITER); held plates 7e-8 (256², 1936 posts) to 4e-6.
PIVOT_TOL = 1e-11
#: (method "auto", stiff rows, K singular, cold start) The anchored plate's springs, ANCHOR·K_jj
#: on each dof the rows act on (K equilibrated: ANCHOR is the trailing block's shift). Small,
#: so its contact set is the plate's but for rows whose gap and force are both within about
#: ANCHOR of their scale; not so small that its rigid motions, at ANCHOR, fall below the held
#: plates' softest modes (7e-8–4e-6, see PIVOT_TOL) by more than a few decades.
ANCHOR = 1e-8
#: (sparse, floating plate, anchored first set) The exact steps run on the anchored plate's
#: contacts-last factorisation with its trailing block replaced (:class:`.factor.TrailingFactor`:
#: no sparse factorisation, but a dense Cholesky of the rows' ``n_c`` dofs a set and solves
#: through the contacts-last factor's fill) while ``n_c³/3`` is at most TRAILING_SHARE of that
#: factorisation's flops (TRAILING_MAX dofs where its flops are not known); else on a sparse
#: factorisation of their own (:class:`.factor.SpringFactor`). Measured (CPU, interleaved,
#: slabs floating or held on one edge): 0.016–0.08 of it (128² with 9 posts, 128² and 96²
#: with 900) 12–45 % faster; 0.23 (64², 900 posts) 15–25 % slower; 0.30 (128², 2 025 posts) 0–20 % slower.
TRAILING_SHARE, TRAILING_MAX = 0.15, 500

RAY_MESSAGE = ("the active rows leave a null direction d of K that no inactive row is pressed along: "
               "K d = 0, G d ≤ 0, qᵀd < 0 (the QP is unbounded below)")
