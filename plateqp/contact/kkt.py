r"""Residuals of the contact KKT conditions, on the plate's own terms.

Evaluated on the nondimensional problem (:class:`plateqp.contact.scaling.Scaled`: deflections by
W, forces by F0), with u the free dofs, R the reactions, s the spring compressions and
gap = g0 + s − B u:

=================  ==============================================================
stationarity       ‖K u − f + Bᵀ R‖ / max(‖f‖, ‖Bᵀ R‖)
spring             max |s − ρ R| / δ           (elastic supports: R = c s)
primal             max(0, −gap) / δ
dual               max(0, −R) / ρ_R
complementarity    max |R_i gap_i| / (ρ_R δ)
natural            max |min(R_i, k_i gap_i)| / ρ_R
=================  ==============================================================

The last is the natural residual of the complementarity conditions in force units: a gap
error counts as the force it would take to close it, with k_i the local stiffness at support
i (:func:`local_stiffness`: the Rayleigh bound b K bᵀ / (b bᵀ)² of
:func:`plateqp.linalg.row_stiffness`, an upper bound of the condensed stiffness, capped by the
distance to the nearest held point, in series with the support's own spring). Gap-unit
residuals alone cannot see reaction errors where supports are close together: measured on a
64² plate on a 30×30 support grid, Clarabel ended with gap-unit residuals of 3e-12 and
reactions 1e-7 off; the natural residual sees that.

with the deflection scale δ = max(‖B u‖∞, ‖g0‖∞, max |w| of the plate, min(floor / tol, 1) w_load)
(the last: a gap error below what the stationarity's rounding floor moves the plate by, floor ×
the load's deflection scale ``Scaled.w_load``, cannot be resolved; it counts where the plate
does not bend, as under a load exactly on a support) and the force scale
ρ_R = max(‖R‖∞, 10⁻¹² ‖f‖₁), or ‖f‖₁ where every reaction is at most tol · ‖f‖₁ (the supports
carry nothing to the accuracy asked: :func:`reaction_scale`).

Stationarity also holds the statics along each rigid motion V_j the two-sided supports leave
free (:func:`statics_residual`; on a bed, the total reaction's error relative to the load),
which the norm over every dof misses where the plate moves far as a body: a free slab sinking
into a bed, its reactions 2.1e-8 short of the load at 256² with the norm at 1.1e-10.

Two refinements for the extremes (benchmarks/README.md, "Extremes"):

- Stationarity is a force residual; the deflection error it can cause is up to about that
  fraction of the load's own deflection scale (``Scaled.w_load``). Where the supports carry the
  load straight down the plate deflects much less than that, so the part of the residual above
  its rounding floor (ε‖|K||u| + |f| + |Bᵀ||R|‖) is scaled by w_load / δ when that exceeds 1.
- Two close contact points that both act (rows of B with cosine above 1 − ``CLOSE_ROWS``, springs
  too stiff to tell them apart) share their load in a way no residual above sees; there the
  natural residual also holds max |R − R*| / ρ_R, R* the reactions of an exact solve holding
  the same contact set (:func:`close_pairs_error`).

A result is ``ok`` when the worst residual is at most the tolerance of its accuracy (a preset's,
``KKT_TOL``, or the number given). The report also holds the stationarity residual's rounding
floor, ``floor`` = ε‖|K||u| + |f| + |Bᵀ||R|‖ / max(‖f‖, ‖Bᵀ R‖) (Oettli–Prager): an answer exact
to double precision can show a residual up to about that, and it grows with the mesh (the 2-norm
over every dof: 4e-10 on a 256² bed, whose exact answer then fails 1e-10). A report that fails
only there is ``at_floor``, and the solve's warning says so and which accuracy to ask. Unlike
qpsolvers' own check, this tests the sign of every reaction and complementarity support by
support.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..accuracy import NO_WORK, PRESET_TOL, Accuracy
from ..errors import MechanismError
from ..linalg import row_stiffness, solve_saddle
from ..linalg.pattern import abs_matvec
from ..linalg.products import remembered, times
from ..results import KKTReport
from .formulations import ContactSolution
from .scaling import Scaled

#: The tolerance of each accuracy preset; a numeric accuracy is its own tolerance.
KKT_TOL = PRESET_TOL


def kkt_report(data: Scaled, c: ContactSolution, accuracy: str | float | Accuracy) -> KKTReport:
    """The KKT residuals of a scaled contact solution."""
    u, R, s = c.u, c.R, c.s
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(R))):
        inf = float("inf")
        return KKTReport(inf, inf, inf, inf, inf, inf, Accuracy.parse(accuracy).tol, 1.0)
    tol = Accuracy.parse(accuracy).tol
    BtR = data.B.T @ R
    r = times(data.K, u) - data.f + BtR
    kb = plate_stiffness(data)
    k = kb / (1.0 + data.rho * kb)  # local_stiffness
    force = max(np.linalg.norm(data.f), np.linalg.norm(BtR))
    # no load and no reaction beyond rounding of the heaves' forces (a plate lifted as a body onto
    # heaved posts): the force scale is what the data can do, the force that closes the largest heave
    heave = heave_force(data, kb)
    force = max(heave if force <= NO_WORK * heave else force, 1e-300)
    st = np.linalg.norm(r) / force
    w = data.B @ u
    delta = deflection_scale(data, u, w)
    # A force residual st (of the load) deflects the plate by up to about st · w_load, the load's
    # own deflection scale; where the supports carry the load straight down the plate deflects
    # far less than that, and the same residual is a larger error relative to what it does.
    # Measured: HiGHS on the primal, stationarity 4e-11, deflections 1.4e-7 off (actual deflection
    # 3e-4 of the load's scale). The part of st above its rounding floor is scaled so.
    BR = abs(data.B).T @ np.abs(R)
    floor = np.finfo(float).eps * np.linalg.norm(abs_K_times(data, np.abs(u)) + np.abs(data.f) + BR) / force
    # a gap error below what that floor moves the plate by (floor · w_load) is not resolvable:
    # where the plate does not bend (a load on a post: δ 1e-18 m and less) the gap residuals of
    # an exact answer were a large part of δ. δ is at least that motion ÷ tol (at most w_load)
    delta = max(delta, min(floor / tol, 1.0) * data.w_load)
    st = max(st, (st - 10.0 * floor) * data.w_load / delta)
    gap = data.g0 + s - w
    rscale = reaction_scale(R, data.f, tol, heave)
    natural = np.abs(np.minimum(R, k * gap)).max(initial=0.0) / rscale
    # the same natural residual in deflection units: a support in contact whose gap is left open
    # by ε (its reaction off by about k ε) changes the deflections by ε, which the force scale of
    # the largest reaction cannot see when that reaction is a heaved support's, 1e3 × the others'
    natural = max(natural, np.abs(np.minimum(R / np.maximum(k, 1e-300), gap)).max(initial=0.0) / delta)
    natural = max(natural, close_pairs_error(data, R, gap, rscale, delta, tol))
    # statics along the rigid motions the two-sided supports leave free
    balance = statics_residual(data, BtR, BR, force)
    return KKTReport(
        floor=float(floor),
        stationarity=float(max(st, balance)),
        spring=float(np.abs(s - compressions(data, R)).max(initial=0.0) / delta),
        primal=float(max(0.0, -gap.min(initial=0.0)) / delta),
        dual=float(max(0.0, -R.min(initial=0.0)) / rscale),
        # divided in turn: rscale · delta underflows to 0 (0/0) when there is no load and no gap
        complementarity=float(np.abs(R * gap).max(initial=0.0) / rscale / delta),
        natural=float(natural),
        tol=tol,
        scale=delta * data.W,
    )


def statics_residual(data: Scaled, BtR: np.ndarray, BR: np.ndarray, force: float) -> float:
    """Statics along each rigid motion ``V_j`` the two-sided supports leave free (``data.modes``:
    a floating plate's three, a plate hinged on one edge's turn about it): the largest
    ``|V_jᵀ(f − BᵀR)| / s_j``, ``s_j`` the larger of ``|V_j|ᵀ|f|`` and ``|V_j|ᵀ|Bᵀ||R|`` (at least
    ``force · max|V_j|``, the stationarity's force scale): on a bed, the total reaction's error
    relative to the total load. 0 on a held plate.

    The reactions balance the load along ``V_j`` exactly (``K V_j = 0``). The norm of K u − f +
    BᵀR over every dof does not see an error there where the plate moves far as a body: K's
    rounding along that motion, up to ε |V_j|ᵀ|K||u|, then passes into the reactions of an
    answer that trusts ``K u``. Measured: a free slab sinking into a bed, its reactions 1.3e-9
    (128²) and 2.1e-8 (256²) short of the load with the norm at 1.3e-11 and 1.1e-10; a slab
    hinged on one edge and turned 13 mm onto a heaved post, its moment about the hinge 3.4e-5
    off with the norm at 5e-7 (OPTIMAL at 1e-6). No rounding floor of K's: an answer whose
    residual leaves K u's part along V out (pdas's exact steps,
    :func:`plateqp.backends.pdas.sparse.solve_active`) balances to about ε (3e-12 and 1e-14
    there). ``BR``: ``|Bᵀ||R|``."""
    V = data.modes
    if V is None or V.shape[1] == 0:
        return 0.0
    aV = np.abs(V)
    scale = np.maximum(np.maximum(aV.T @ np.abs(data.f), aV.T @ BR), force * aV.max(axis=0))
    scale = np.maximum(scale, 1e-300)
    return float((np.abs(V.T @ (data.f - BtR)) / scale).max())


def compressions(data: Scaled, R: np.ndarray) -> np.ndarray:
    """The supports' compressions the reactions R cause: ρ R, or with a half-space held
    matrix-free its operator's settlements under the bed's rows (:attr:`Scaled.compliance`)."""
    return data.rho * R if data.compliance is None else data.compliance(R)


def abs_K_times(data: Scaled, x: np.ndarray) -> np.ndarray:
    """``|K| x``: by blocks of K (no copy of it), or in a sweep (``data.memo``) with ``|K|`` kept
    for the solves of the same K (its values only; K's index arrays shared)."""
    return remembered(data.K, x, "abs", lambda: _abs_K_product(data, x))


def _abs_K_product(data: Scaled, x: np.ndarray) -> np.ndarray:
    """The product :func:`abs_K_times` remembers."""
    memo = data.memo
    if memo is None:
        return abs_matvec(data.K, x)
    kept = memo.get("abs_K")
    if kept is None or kept[0] is not data.K:
        K = data.K
        end = K.indptr[-1]
        kept = memo["abs_K"] = (K, sp.csc_matrix((np.abs(K.data[:end]), K.indices[:end], K.indptr), shape=K.shape,
                                                 copy=False))
    return kept[1] @ x


def deflection_scale(data: Scaled, u: np.ndarray, w: np.ndarray | None = None) -> float:
    """The deflection scale δ of the gap residuals: the largest of the contact deflections B u,
    the gaps and the plate's own deflection (with every support touching at zero gap, the first
    two vanish)."""
    w = data.B @ u if w is None else w
    return max(np.abs(w).max(initial=0.0), np.abs(data.g0).max(initial=0.0),
               np.abs(u[data.is_w]).max(initial=0.0), 1e-300)


def defect_residual(data: Scaled, c: ContactSolution, e: np.ndarray, M: np.ndarray, tol: float) -> float:
    """What correcting an error ``e`` in the gaps of an LCP gap = M R + q (a formulation's own
    data, :meth:`plateqp.contact.formulations.Dual.defect`) would change in the solution ``c``,
    in the units of :func:`kkt_report`'s natural residual: the gaps by e (max(k|e|/ρ_R, |e|/δ):
    a gap left open by e where a support acts shows as about k·e), and, to first order on the
    contact set A of ``c``, the reactions by ΔR = M_AA⁻¹ e_A (/ρ_R; large where two close
    supports share a load, whose split is what an error of M spoils first)."""
    if e.size == 0:
        return 0.0
    R = c.R
    rscale = reaction_scale(R, data.f, tol)
    a = np.abs(e)
    size = max((local_stiffness(data) * a).max() / rscale, a.max() / deflection_scale(data, c.u))
    A = np.flatnonzero(R > tol * rscale)
    if A.size:
        try:
            size = max(size, np.abs(np.linalg.solve(M[np.ix_(A, A)], e[A])).max() / rscale)
        except np.linalg.LinAlgError:  # a singular contact set: the gaps' measure alone
            pass
    return float(size)


def heave_force(data: Scaled, kb: np.ndarray | None = None) -> float:
    """The force that bends the plate by its largest heave where that post stands:
    max k_i · max(−g0_i, 0), k the plate's own stiffness there (:func:`plate_stiffness`, an
    upper bound; a soft post's spring left out, as a plate turned as a body about its hinge moves
    every dof by about the heave, whatever the springs). With no load it is the scale of every
    force there can be: the reactions of a plate lifted as a body onto heaved posts, and its
    internal forces K u, are zero to rounding of it. ``kb``: :func:`plate_stiffness`, where
    the caller has it."""
    heave = np.maximum(-data.g0, 0.0)
    if not heave.any():
        return 0.0
    kb = plate_stiffness(data) if kb is None else kb
    return float((kb * heave).max(initial=0.0))


def heave_bound(data: Scaled) -> float:
    """An upper bound of :func:`heave_force` without the Rayleigh quotients (CIRCLE / s² for the
    plate's stiffness; infinite where the spacings are not known)."""
    heave = np.maximum(-data.g0, 0.0)
    if not heave.any():
        return 0.0
    if data.spacing is None:
        return float("inf")
    return float((CIRCLE / np.maximum(data.spacing, 1e-300) ** 2 * heave).max())


def reaction_scale(R: np.ndarray, f: np.ndarray, tol: float, heave: float = 0.0) -> float:
    """The force scale ρ_R of the force residuals: the largest reaction; but where every reaction
    is at most ``tol`` of the load (‖f‖₁; where the load and the reactions are below
    ``NO_WORK`` × ``heave``, :func:`heave_force`, that force), the supports carry nothing to the
    accuracy asked and their reactions are measured against that. (Against
    the largest of them, an interior-point solver's 1e-13 of the load at open supports read as a
    100 % error: every scene where nothing touches came back INACCURATE; with no load, a rigid
    lift's reactions of 1e-16 read as 100 % errors of themselves. The deflections those forces
    cause are still measured, in deflection units, by the natural residual.)"""
    rmax = np.abs(R).max(initial=0.0)
    load = np.abs(f).sum()
    if max(load, rmax) <= NO_WORK * heave:  # no load that does work beside the heaves
        load = heave
    if rmax <= tol * load:
        return max(load, 1e-300)
    return max(rmax, 1e-12 * load, 1e-300)


#: Two contact points are close when their rows of B have a cosine above 1 − CLOSE_ROWS (about
#: half a cell apart or less) and their springs do not tell them apart (ρ·k small): an error δ in
#: how they share the load then shows in the stationarity residual only as δ·‖B_i − B_j‖ and in
#: their gaps as δ·‖B_i − B_j‖², hidden from every residual above. Measured: HiGHS on the
#: primal passed at 1e-9 with the shares of two supports 1e-3 of a cell apart 1.5e-6 off.
CLOSE_ROWS = 0.1


def close_pairs_error(data: Scaled, R, gap, rscale: float, delta: float, tol: float) -> float:
    """Where two close contact points both act: max |R − R*| / ρ_R, with R* the reactions of an
    exact solve (sparse LU of the saddle-point system, refined) holding the same contact set.
    0 where there is no such pair, or where that contact set does not hold the plate."""
    if data.m < 2 or data.compliance is not None:
        # (a matrix-free soil's rows are distinct nodes; its compliance is no diagonal ρ to hold
        # a contact set with: there the natural residual is the check)
        return 0.0
    memo = data.memo if data.memo is not None else {}
    if "rows_gram" not in memo:  # K and B alone: once per sweep
        B = data.B.tocsr()
        if np.diff(B.indptr).max(initial=0) <= 1 and np.unique(B.indices).size == B.indices.size:
            # each row reads an unknown of its own (a bed, posts at distinct nodes): every two rows
            # are orthogonal (cosine 0), no pair is close; B Bᵀ is not formed (12 ms at 256²)
            memo["rows_gram"] = None
        else:
            G = (B @ B.T).tocoo()
            memo["rows_gram"] = (B, G, np.sqrt(np.maximum(G.diagonal(), 1e-300)),
                                 np.maximum(row_stiffness(data.K, B, "diagonal"), 1e-300))
    if memo["rows_gram"] is None:
        return 0.0
    B, G, nrm, kb = memo["rows_gram"]
    on = (R > tol * rscale) | (np.abs(gap) <= tol * delta)
    i, j = G.row, G.col
    cos = G.data / (nrm[i] * nrm[j])
    apart = (1.0 - cos) + (data.rho[i] + data.rho[j]) * np.maximum(kb[i], kb[j])  # springs tell apart too
    close = (i < j) & on[i] & on[j] & (apart < CLOSE_ROWS)
    if not close.any():
        return 0.0
    A = np.flatnonzero(on)
    try:
        _, R_exact = solve_saddle(data.K, B[A], data.rho[A], data.f, data.g0[A])
    except MechanismError:  # singular: the contact set does not hold the plate
        return 0.0
    return float(np.abs(R[A] - R_exact).max() / rscale)


#: k ≤ CIRCLE · D / s²: the stiffness at the centre of a plate clamped on a circle of radius r
#: is 16π D / r²; with r = s/2 (s the distance to the nearest held point) it bounds the plate's
#: stiffness at a contact point with every other held point held, with margin for an edge that
#: is held between its nodes, nearer than the nearest held node.
CIRCLE = 64.0 * np.pi


def local_stiffness(data: Scaled) -> np.ndarray:
    """Force per unit gap at each support, an upper bound of the plate's stiffness there in
    series with the support's spring (1/ρ): the smaller of b K bᵀ / (b bᵀ)² (b the support's
    row of B: a Rayleigh quotient of K, so it bounds the condensed stiffness) and CIRCLE·D/s²
    (nondimensional D = 1; s the distance to the nearest held point or held edge).

    The first alone grows like 1/h² as the mesh is refined, and made the natural residual
    conservative by a factor that grew with the mesh: measured on a floating slab on 5×5 posts
    at 64², Clarabel's reactions were 7e-7 off and the residual said 5e-4; with the bound by
    the distance to the nearest held point it says 5e-6 (benchmarks/README.md, Limitations)."""
    # Rayleigh: for u = b/(b·b), b·u = 1 and uᵀKu = bKbᵀ/(b·b)² bounds the condensed stiffness
    # 1/(b K⁻¹ bᵀ) from above, whatever K is. Σ b_j² K_jj is no bound where most of a support's
    # interpolation weight sits on prescribed dofs (a support beside a clamped edge: it said 11.9
    # where the plate's stiffness is about 8e4, and wrong reactions passed).
    kb = plate_stiffness(data)
    return kb / (1.0 + data.rho * kb)


def plate_stiffness(data: Scaled) -> np.ndarray:
    """The plate's own part of :func:`local_stiffness` (without the supports' springs); K, B and
    the spacings alone, so in a sweep (``data.memo``) computed once."""
    if data.memo is not None and "plate_stiffness" in data.memo:
        return data.memo["plate_stiffness"]
    kb = row_stiffness(data.K, data.B, "rayleigh")
    if data.spacing is not None:
        kb = np.minimum(kb, CIRCLE / np.maximum(data.spacing, 1e-300) ** 2)
    if data.memo is not None:
        data.memo["plate_stiffness"] = kb
    return kb
