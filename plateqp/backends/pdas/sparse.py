r"""The sparse method: a factor of ``K + σ diag(K) + B_Aᵀ W_A B_A`` kept current as the active
set changes (:mod:`.factor`), exact steps by refinement, and a first phase: Newton–PCG for soft
rows, projected Newton on the dual energy for stiff rows on a held plate (see the package
docstring: "Two ways to solve a step", "Singular steps and no equilibrium"). The exact steps
that follow the first phase: :mod:`.exact`."""

from __future__ import annotations

import time

from typing import NamedTuple

import numpy as np

from ...linalg.keep import kept
from ...linalg.products import times
from .dense import first_set
from .factor import SpringFactor
from .motions import deflate, project, softest
from .options import (
    ALPHA_MAX,
    ALPHA_MIN,
    ANCHOR,
    ARMIJO,
    DUAL_DEFINITE,
    DUAL_FLAT,
    DUAL_RISES,
    DUAL_ROUNDING,
    DUAL_STEPS,
    INNER_EXACT,
    INNER_LOOSE,
    LH_ANCHORED,
    LH_ANCHORED_PROBE,
    LH_BLOCK,
    LH_MEMORY,
    LH_PRESSED,
    LH_PROBE,
    LH_TIME,
    LOOSE_TOL,
    LOWRANK_MAX,
    NEWTON_BUDGET,
    NEWTON_SETTLED,
    NEWTON_SETTLED_FRACTION,
    NEWTON_STEPS,
    PCG_MAX,
    PCG_TOL,
    SINGULAR_QUOTIENT,
)
from .reduced import ROUNDING_STOP, ReducedQP, at_rounding, infeasible

__all__ = ["SpringFactor", "solve_active"]


class Step:
    """Outcome of one active set (sparse method): ``u``, ``λ`` (zero off the set), residual, ray."""

    def __init__(self, u, lam, residual, solves, ray=None):
        self.u, self.lam, self.residual, self.solves, self.ray = u, lam, residual, solves, ray


def solve_active(pb: ReducedQP, fac: SpringFactor, W: np.ndarray, A: np.ndarray, u: np.ndarray,
                  lam: np.ndarray, sigma: float, exact: bool, null: list = ()) -> Step:
    """Refine ``(u, λ_A)`` towards the exact step of active set ``A`` (see the module docstring).

    ``null``: free rigid motions of ``A`` that the load does no work along (``D``-orthonormal);
    the corrections leave them out, so the step is one of the (equally good) solutions."""
    idx = np.flatnonzero(A)
    BA = pb.B[idx]
    absBA = abs(BA)
    WA, gA, rhoA = W[idx], pb.g[idx], pb.rho[idx]
    lamA = lam[idx].copy()
    u = u.copy()
    fnorm = max(np.abs(pb.f).max(initial=0.0), np.finfo(float).tiny)
    gnorm = np.abs(pb.g).max(initial=0.0)
    best = np.inf
    tol = 0.0 if exact else LOOSE_TOL
    n_max = INNER_EXACT if exact else INNER_LOOSE
    solves = 0
    res = np.inf
    # the plate's rigid motions V (a floating plate's, a hinged one's turn): K's rounding, ε|K||u|
    # and more where the plate moves far as a body, would pass into the reactions' balance along
    # them (Vᵀ(f − BᵀΛ) = VᵀKu = 0 exactly in the model); the residual's V-part is taken without
    # it, (I − V(VᵀV)⁻¹Vᵀ)K u, so the refinement ends on reactions that balance the load along V
    V, lift = pb.rigid(), pb.lift()
    # a sweep's next value on the kept factor: its first solve leaves the reactions short of the
    # load along V (the plate moved as a body); that part is corrected before the first check,
    # which then reads K once, not once before and once after it (where the columns H⁻¹V are at
    # hand: a load's value that moves many springs, the factor made anew, may not need them).
    # The lifted residual's V-part needs no product with K: Vᵀ(I − V(VᵀV)⁻¹Vᵀ)K u = 0, so
    # Vᵀ r_u = Vᵀ(f − BᵀΛ)
    Z = _lift_at_hand(pb, fac, lift, sigma, exact, null, solve=False)
    if Z is not None and not balanced(pb, V, BA.T @ lamA, absBA, lamA):
        r_A = BA @ u - gA - rhoA * lamA
        du = Z @ (V.T @ (pb.f - BA.T @ (lamA + WA * r_A)))
        lamA += WA * (r_A + BA @ du)
        u += du
    for k in range(n_max + 1):
        BtL = BA.T @ lamA
        Ku = times(pb.K, u)
        if lift is not None:
            Ku = Ku - lift @ (V.T @ Ku)
        r_u = pb.f - Ku - BtL
        r_A = BA @ u - gA - rhoA * lamA
        # the rows' scale from the terms that make B u (|B_A||u|), not from B u itself: on a bed
        # whose soil has unknowns, B u = w − v is rounding where the bed touches at zero gap
        delta = max(np.abs(pb.B @ u).max(initial=0.0), (absBA @ np.abs(u)).max(initial=0.0), gnorm,
                    np.finfo(float).tiny)
        res = max(np.abs(r_u).max() / max(fnorm, np.abs(BtL).max(initial=0.0)),
                  np.abs(r_A).max(initial=0.0) / delta)
        if res <= tol or k == n_max or (k >= 2 and res > 0.5 * best):
            break
        # another correction would not change the answer; not before the first correction where
        # the factor carries a shift (σ > 0): that correction is also the singular step's test
        if exact and (k >= 1 or sigma == 0.0) and at_rounding(pb, u, idx, BA, lamA, r_u, r_A):
            if lift is None or balanced(pb, V, BtL, absBA, lamA):
                break
            Z = _lift_at_hand(pb, fac, lift, sigma, exact, null)
            if Z is not None:  # the rest at rounding: only the part along V is left to correct
                du = Z @ (V.T @ (r_u - BA.T @ (WA * r_A)))
                lamA += WA * (r_A + BA @ du)
                u += du
                continue
        best = min(best, res)
        du = project(null, pb.Kd, fac.solve(deflate(null, pb.Kd, r_u - BA.T @ (WA * r_A))))
        solves += 1
        if k == 0:
            Bdu = BA @ du
            Ddu = float(du @ (pb.Kd * du))
            energy = float(du @ (pb.K @ du)) + float(Bdu @ (WA * Bdu))
            if Ddu > 0 and energy < SINGULAR_QUOTIENT * sigma * Ddu:
                return Step(u, lam, np.inf, solves, ray=du / np.abs(du).max())
        lamA += WA * (r_A + BA @ du)
        u += du
    out = np.zeros_like(lam)
    out[idx] = lamA
    return Step(u, out, res, solves)


def _lift_at_hand(pb: ReducedQP, fac, lift, sigma: float, exact: bool, null, solve: bool = True) -> np.ndarray | None:
    """:func:`lift_columns` where the correction along V may be taken on them: an exact step
    with rigid motions, no free ones among them (``null``), on an unshifted factor (σD is all that
    holds a shifted one along V: H⁻¹V is 1/σ there) kept for the solves to come (a sweep's: in a
    single solve one correction costs less than the k columns); else None. ``solve`` False: only
    where they are kept on this factor already."""
    if lift is None or not exact or len(null) or sigma != 0.0 or kept() is None:
        return None
    return lift_columns(fac, lift, solve)


def lift_columns(fac, lift: np.ndarray, solve: bool = True) -> np.ndarray | None:
    """``H⁻¹ V(VᵀV)⁻¹`` on the factor in hand (k solves), kept on it while its springs stay (a
    sweep's values on the kept factor: the correction along V then costs no solve); None where
    the factor does not say what it holds (``target``), or, ``solve`` False, where they are not
    kept on it."""
    target = getattr(fac, "target", None)
    if target is None:
        return None
    memo = getattr(fac, "_lift", None)
    if memo is not None and memo[1] is lift and np.array_equal(memo[0], target):
        return memo[2]
    if not solve:
        return None
    Z = fac.solve(lift)
    fac._lift = (np.array(target, copy=True), lift, Z)
    return Z


def balanced(pb: ReducedQP, V: np.ndarray, BtL: np.ndarray, absBA, lamA: np.ndarray) -> bool:
    """The reactions balance the load along the rigid motions ``V`` to rounding of the sums:
    ``|Vᵀ(f − BᵀΛ)| ≤ ROUNDING_STOP · 16 ε |V|ᵀ(|f| + |B_A|ᵀ|Λ_A|)``. The residual's other parts
    are at rounding long before that where the plate moves far as a body (a sweep's next value
    from the kept factor: its first solve left the bed's reactions 1e-10 short of the load)."""
    aV = np.abs(V)
    size = aV.T @ (np.abs(pb.f) + absBA.T @ np.abs(lamA))
    return bool(np.all(np.abs(V.T @ (pb.f - BtL)) <= ROUNDING_STOP * 16 * np.finfo(float).eps * size))


def line_search(pb: ReducedQP, W: np.ndarray, u: np.ndarray, du: np.ndarray) -> float:
    """Exact minimiser ``α ∈ (0, ALPHA_MAX]`` of the (convex, piecewise quadratic) energy
    ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²`` along ``u + α du`` (∞ where the energy still
    falls past ALPHA_MAX). Its slope is piecewise linear in α: between two of the rows'
    breakpoints ``α_i = −r_i/s_i`` (``r = B u − g``, ``s = B du``) it is ``c₁ α + c₀``, with
    ``c₁ = duᵀK du + Σ W_i s_i²`` and ``c₀ = duᵀ(K u − f) + Σ W_i s_i r_i`` over the rows acting
    there. A first ``hi`` (1, doubled) where the slope is ≥ 0 bounds the root; the breakpoints
    below it sorted, the coefficients are running sums, and the root is read on the first piece
    whose end has a slope ≥ 0 (a sort of the few breakpoints before a Newton step's end, not a
    bisection of 60 passes over every row)."""
    r = pb.B @ u - pb.g
    s = pb.B @ du
    ws = W * s
    a2 = float(du @ (pb.K @ du))
    b = float(du @ (pb.K @ u - pb.f))

    def slope(al):
        return al * a2 + b + float(ws @ np.maximum(0.0, r + al * s))

    hi = 1.0
    while slope(hi) < 0:
        hi *= 2
        if hi > ALPHA_MAX:
            return np.inf  # the energy falls without bound along du: left to the exact steps
    # just after α = 0: the rows pressed (r > 0), or at their threshold and pressing further
    on = (r > 0) | ((r == 0) & (s > 0))
    c1 = a2 + float(ws[on] @ s[on])
    c0 = b + float(ws[on] @ r[on])
    # the breakpoints in (0, hi): a row starts to act there (s_i > 0) or lets go (s_i < 0)
    j = np.flatnonzero(((s > 0) & (r < 0)) | ((s < 0) & (r > 0)))
    at = -r[j] / s[j]
    ahead = at < hi
    j, at = j[ahead], at[ahead]
    order = np.argsort(at, kind="stable")
    j, at = j[order], at[order]
    sign = np.where(s[j] > 0, 1.0, -1.0)
    C1 = np.concatenate([[c1], c1 + np.cumsum(sign * (ws[j] * s[j]))])  # piece k: (at[k − 1], at[k])
    C0 = np.concatenate([[c0], c0 + np.cumsum(sign * (ws[j] * r[j]))])
    reached = C1[:-1] * at + C0[:-1] >= 0
    k = int(np.argmax(reached)) if reached.any() else at.size  # else on the last piece, up to hi
    lo, top = (at[k - 1] if k > 0 else 0.0), (at[k] if k < at.size else hi)
    if not C1[k] > 0:  # a flat piece (rounding): its end
        return float(top)
    return float(min(max(-C0[k] / C1[k], lo), top))  # on its piece (rounding of the running sums)


def newton_pcg(pb: ReducedQP, fac: SpringFactor, W: np.ndarray, sigma: float, steps,
               start: np.ndarray | None = None) -> tuple:
    """Phase 1 of the sparse method, for soft rows (springs no stiffer than the plate under them).

    Semismooth Newton on the energy ``½uᵀKu − fᵀu + Σ ½ W_i max(0, B_i u − g_i)²`` (the exact
    energy of a tensionless bed), each Newton system ``(K + σD + B_Aᵀ W_A B_A) δu = −∇`` solved
    only roughly (PCG to ``PCG_TOL``) with one factor as preconditioner, then an exact line
    search: no refactorisation until the active set settles. The factor is that of the set
    ``start`` (a warm start: a good one is the answer's set, and the first step finds nothing
    to change; a bad one costs PCG iterations, each wrong row one more at most, never a
    factorisation), or of the two-sided matrix (every row active) on a cold start. Returns
    ``(u, A, steps)``; 0 steps where the warm start's own minimiser keeps its set or moves at
    most LOWRANK_MAX rows of it (the exact steps take those on the warm start's factor).
    """
    B, K, f, g = pb.B, pb.K, pb.f, pb.g
    first = W.copy() if start is None else np.where(start, W, 0.0)
    u, A, start = _first_minimiser(pb, fac, W, sigma, first, start)
    if start is not None:
        changes = int((A ^ start).sum())
        if changes <= LOWRANK_MAX:
            # u is that set's step and it keeps, or moves few enough rows for the exact steps to
            # take them on this factor (a low-rank correction), as they would after a Newton
            # step that settled; that step's gradient and PCG solves are saved (2 of 7 on the
            # benchmark bed at 128² from its coarse mesh's set, 8 rows moved). More rows go to
            # the Newton steps, not to exact exchanges: at 512² the coarse set (3 rows wrong)
            # moved 156, and exact block exchanges from there took 3 factorisations
            if steps is not None:
                steps.append({"step": "newton 0", "active": int(A.sum()), "infeasible": changes,
                              "solve": "warm start"})
            return u, A, 0
    k = -1
    for k in range(NEWTON_STEPS):
        WA = np.where(A, W, 0.0)
        grad = K @ u - f + B.T @ (WA * (B @ u - g))
        du, its = _pcg(pb, fac, WA, sigma, -grad)
        alpha = line_search(pb, W, u, du)
        if not np.isfinite(alpha):
            break
        u = u + alpha * du
        A_new = B @ u - g > 0
        changes = int((A_new ^ A).sum())
        if steps is not None:
            steps.append({"step": f"newton {k + 1}", "active": int(A.sum()), "infeasible": changes,
                          "solve": f"pcg {its}", "alpha": round(alpha, 3)})
        A = A_new
        if changes <= max(NEWTON_SETTLED, NEWTON_SETTLED_FRACTION * pb.m):
            break
        if fac.t_factor is not None and fac.stats["solve_s"] > NEWTON_BUDGET * fac.t_factor:
            break
    return u, A, k + 1


def _first_minimiser(pb: ReducedQP, fac: SpringFactor, W: np.ndarray, sigma: float, first: np.ndarray,
                     start: np.ndarray | None) -> tuple:
    """:func:`newton_pcg`'s first ``(u, A, start)``: the minimiser with the rows of ``first``
    held, its set, and the warm start (None where the Newton steps are to run whatever it moves)."""
    B, f, g = pb.B, pb.f, pb.g
    u = None
    if _springs_changed(fac, first, start):
        # the warm start's springs all changed (a sweep of their stiffness): the factor kept, of
        # the springs before, preconditions the Newton steps as well as a new one (their ratio
        # bounds its spectrum), and the exact steps factorise once, for the set they settle on.
        # Where the set's minimiser (solved to WARM_PCG_TOL: PCG_TOL misjudged rows near their
        # threshold, 30 for 16 on the 64² grid of elastic posts) moves few rows, the factor of the
        # warm start's set serves the exact steps as after a plain start (a low-rank correction)
        u = _pcg(pb, fac, first, sigma, f + B.T @ (first * g), tol=WARM_PCG_TOL)[0]
        A = B @ u - g > 0
        if int((A ^ start).sum()) > LOWRANK_MAX:
            start = None  # to the Newton steps (u is a rough solve)
        else:
            u = None
    if u is None:
        fac.set(first)
        b = f + B.T @ (first * g)
        # the minimiser with the rows of the first set held (a sweep's values: b = f + t df or
        # f + Bᵀ diag(w)(g + t dg), in the span of the values' before on the same factor)
        span = getattr(fac, "solve_in_span", None) if kept() is not None else None  # (TrailingFactor: none)
        body = _body_motion(pb, first, b)
        if body is not None:  # the plate's move as a rigid body on the held springs, then the rest
            b = b - B.T @ (first * (B @ body))
        u = fac.solve(b) if span is None else span(b)
        if body is not None:
            u = u + body
        A = B @ u - g > 0
    return u, A, start


def _body_motion(pb: ReducedQP, w: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """Where the plate has rigid motions ``V`` (a floating plate), the rigid motion ``V c`` the
    springs ``w`` hold it at under ``b``: ``Vᵀ Bᵀ diag(w) B V c = Vᵀ b`` (K V = 0). The minimiser
    is then ``V c + H⁻¹(b − Bᵀ diag(w) B V c)``: the solve's rounding, about ε |H||u|, is that of
    the plate's deformation alone, not of its move as a body (a bed's plate that sinks or tilts
    far beside its bending: its reactions' balance along V then needed a correction of its own,
    one solve more). None where there is no V or the springs do not hold it (a singular 3 × 3)."""
    V = pb.rigid()
    if V is None or V.shape[1] == 0:
        return None
    BV = pb.rigid_rows()
    M = BV.T @ (w[:, None] * BV)
    ev = np.linalg.eigvalsh(M)
    if not ev[0] > BODY_HELD * ev[-1]:
        return None
    return V @ np.linalg.solve(M, V.T @ b)


#: the held springs hold the plate as a rigid body (:func:`_body_motion`) where the 3 × 3 matrix
#: of their stiffness along its rigid motions has its eigenvalues within this ratio
BODY_HELD = 1e-10

#: a warm start whose springs all changed: its set's minimiser is solved to this (relative, in
#: the preconditioned norm) on the kept factor, to judge whether it moves more than LOWRANK_MAX rows
WARM_PCG_TOL = 1e-3


def _springs_changed(fac: SpringFactor, first: np.ndarray, start: np.ndarray | None) -> bool:
    """A warm start whose rows' springs differ from the kept factor's on more rows than a
    low-rank correction takes (the factor would be made again for them)."""
    w = fac.w
    if start is None or w is None or w.shape != first.shape:
        return False
    return int(np.count_nonzero(first[start] != w[start])) > LOWRANK_MAX


def _pcg(pb: ReducedQP, fac: SpringFactor, WA: np.ndarray, sigma: float, b: np.ndarray,
         tol: float = PCG_TOL) -> tuple[np.ndarray, int]:
    """A rough solution (to ``tol``) of ``(K + σD + B_Aᵀ W_A B_A) x = b`` from ``x = 0``, by
    conjugate gradients with ``fac`` as preconditioner, and its iterations (at most PCG_MAX)."""
    B, K, D = pb.B, pb.K, pb.Kd

    def H(v):
        return K @ v + sigma * D * v + B.T @ (WA * (B @ v))

    x = np.zeros_like(b)
    res = np.array(b, dtype=float)
    z = fac.solve(res)
    d = z.copy()
    rz = rz0 = float(res @ z)
    j = 0
    for j in range(PCG_MAX):
        Hd = H(d)
        dHd = float(d @ Hd)
        if dHd <= 0 or rz0 <= 0:
            break
        a = rz / dHd
        x += a * d
        res -= a * Hd
        z = fac.solve(res)
        rz_new = float(res @ z)
        if rz_new <= tol**2 * rz0:
            break
        d = z + (rz_new / rz) * d
        rz = rz_new
    return x, j + 1


def _dual_energy(pb: ReducedQP, uf: np.ndarray, lam: np.ndarray, u: np.ndarray) -> float:
    """``ψ(λ) = ½λᵀMλ + dᵀλ`` from ``u = K⁻¹(f − Bᵀλ)`` and ``u_f = K⁻¹f`` (no ``M``):
    ``−½ (Bᵀλ)ᵀ(u_f + u) + ½ λᵀρλ + gᵀλ``."""
    return float(-0.5 * (pb.B.T @ lam) @ (uf + u) + 0.5 * lam @ (pb.rho * lam) + pb.g @ lam)


def _held_by(pb: ReducedQP, kfac: SpringFactor, w: np.ndarray, sigma: float) -> np.ndarray | None:
    """``K_w⁻¹ f`` with ``kfac`` set to ``K_w = K + Bᵀ diag(w) B``, or None where ``K_w`` is
    (nearly) singular: its softest mode's Rayleigh quotient (:func:`softest`) below
    DUAL_DEFINITE·σ."""
    kfac.set(w)
    uf = kfac.solve(pb.f)
    return None if softest(pb, kfac, w)[1] < DUAL_DEFINITE * sigma else uf


def held_plate(pb: ReducedQP, kfac: SpringFactor, sigma: float) -> np.ndarray | None:
    """``u_f = K⁻¹ f`` with ``kfac`` set to ``K`` alone, or None where ``K`` is (nearly)
    singular: a floating plate (:func:`_held_by`). The stiff rows' first phases need a held plate."""
    return _held_by(pb, kfac, np.zeros(pb.m), sigma)


def anchored_plate(pb: ReducedQP, kfac: SpringFactor, sigma: float) -> np.ndarray | None:
    """For a floating plate: ``u_a = K_a⁻¹ f`` with ``kfac`` set to ``K_a = K + Bᵀ diag(w) B``,
    each row held by a spring ``w_i = ANCHOR·k_i`` (a soft anchor: the anchored plate's contact
    set is the plate's but for rows within about ANCHOR of a change; the exact steps decide),
    or None where ``K_a`` is (nearly) singular too (:func:`_held_by`): the rows, held, do not
    hold the plate, or too few of them to lift its rigid motions above DUAL_DEFINITE·σ."""
    return _held_by(pb, kfac, ANCHOR * pb.k, sigma)


class _Columns:
    """The rows of the flexibility ``M = B K⁻¹ Bᵀ + diag(ρ)`` (symmetric: its columns) as
    Lawson–Hanson's method asks for them (:func:`lawson_hanson`): row ``j`` by a solve with the
    factor of ``K``, LH_BLOCK rows in one block solve (``j`` and the rows of most negative
    force after it, kept until asked for: a block of 8 cost 5 ms a row against 12 ms for one
    at 128²), one row a solve while more than LH_PRESSED of the rows are pressed.

    None (and ``why`` says which) once the method has taken ``budget`` seconds since this was
    made (its own steps included: on small plates they cost more than the solves); when,
    asked for its ``probe[0] + 1``-th row, more than ``probe[1]`` of all rows are still pressed
    (LH_PROBE and LH_PRESSED; LH_ANCHORED_PROBE for an anchored plate, which starts sunk: a broad
    contact, as on a stiff bed: most rows will end in contact, and one row a step is the wrong
    tool); or when the rows of M held (m doubles each: first_set's, in a buffer that
    doubles, and those computed ahead) would pass LH_MEMORY bytes per dof of the plate."""

    def __init__(self, pb: ReducedQP, kfac: SpringFactor, budget: float,
                 probe: tuple[int, float] = (LH_PROBE, LH_PRESSED)) -> None:
        self.pb, self.kfac, self.budget, self.probe = pb, kfac, budget, probe
        self.BT = pb.B.T.tocsc()
        self.kept: dict[int, np.ndarray] = {}
        self.start = time.perf_counter()
        self.spent = 0.0  # in the block solves
        self.columns = self.asked = 0
        self.why = None

    def __call__(self, j: int, force: np.ndarray) -> np.ndarray | None:
        t0 = time.perf_counter()
        self.asked += 1
        if t0 - self.start > self.budget:
            self.why = "time"
            return None
        m, n = force.size, self.pb.K.shape[0]
        if (2 * self.asked + len(self.kept)) * m * 8 > LH_MEMORY * n:
            self.why = "memory"
            return None
        pressed = np.flatnonzero(force < 0)
        broad = pressed.size > LH_PRESSED * force.size
        if self.asked == self.probe[0] + 1 and pressed.size > self.probe[1] * force.size:
            self.why = "pressed"
            return None
        row = self.kept.pop(j, None)
        if row is not None:
            return row
        # rows ahead only where few rows are pressed: while most are (a stiff bed; a post grid's
        # first rows) each row freed relieves the rows pressed next to it, and they are not asked for
        block = 1 if broad else LH_BLOCK
        nxt = pressed[np.argsort(force[pressed], kind="stable")[:2 * block]]
        rows = [j] + [i for i in nxt.tolist() if i != j and i not in self.kept][:block - 1]
        Wt = np.ascontiguousarray((self.pb.B @ self.kfac.solve(self.BT[:, rows].toarray())).T)
        Wt[np.arange(len(rows)), rows] += self.pb.rho[rows]
        for q, i in enumerate(rows[1:], 1):
            self.kept[i] = Wt[q]
        self.columns += len(rows)
        self.spent += time.perf_counter() - t0
        return Wt[0]


class FirstSet(NamedTuple):
    """A first phase's answer: the deflection ``u`` (None where it gave up), the reactions
    ``lam``, the set ``A`` (None where it gave up) and the ``steps`` (sets or Newton steps) it took."""

    u: np.ndarray | None
    lam: np.ndarray | None
    A: np.ndarray | None
    steps: int


def lawson_hanson(pb: ReducedQP, kfac: SpringFactor, uf: np.ndarray, feas_tol: float, steps,
                  info: dict, anchored: bool = False) -> FirstSet:
    """Phase 1 of the sparse method for stiff rows on a held plate: Lawson–Hanson's first set
    (:func:`.dense.first_set`) with the rows of the flexibility ``M`` computed as the method
    frees them (:class:`_Columns`), never all of ``M``: where few of many rows end in contact
    (a post at every node: 209 of 16 129 at 128²) that is about as many solves as contacts.
    Its time is held to LH_TIME factorisations of ``K`` (LH_ANCHORED on an ``anchored`` plate,
    :func:`anchored_plate`, whose probe for a broad contact is LH_ANCHORED_PROBE; measured as it
    goes), and it stops early where most rows stay pressed (:class:`_Columns`). Returns ``(u, λ, A, steps)``, or
    where it gave up ``(None, λ, None, steps)``, ``λ`` the reactions of the set it reached (the
    projected Newton phase starts from them). ``info`` receives ``lh_sets``, ``lh_columns`` (rows of ``M``
    computed), ``lh_s`` (their solves' time) and, where it gave up, ``lh_gave_up`` ("time",
    "pressed" or "memory")."""
    if anchored:
        cols = _Columns(pb, kfac, LH_ANCHORED * kfac.t_factor, LH_ANCHORED_PROBE)
    else:
        cols = _Columns(pb, kfac, LH_TIME * kfac.t_factor)
    d = pb.g - pb.B @ uf
    out: dict = {}
    A, n = first_set(cols, d, pb.c, feas_tol, 1e-12 * np.abs(pb.f).sum(), np.inf, out)
    info.update(lh_sets=n, lh_columns=cols.columns, lh_s=cols.spent)
    if A is None:
        info["lh_gave_up"] = cols.why
    if steps is not None:
        steps.append({"step": "lawson-hanson", "active": None if A is None else int(A.sum()), "sets": n,
                      "columns": cols.columns, "gave_up": cols.why})
    if A is None:
        return FirstSet(None, out.get("lam"), None, n)
    lam = out["lam"]
    return FirstSet(kfac.solve(pb.f - pb.B.T @ lam), lam, A, n)


def dual_newton(pb: ReducedQP, fac: SpringFactor, kfac: SpringFactor, W: np.ndarray, sigma: float,
                feas_tol: float, steps, uf: np.ndarray, lam0: np.ndarray | None = None) -> FirstSet | None:
    """Phase 1 of the sparse method for stiff rows on a held plate: projected Newton on the
    dual energy ``ψ(λ) = ½λᵀMλ + dᵀλ`` over ``λ ≥ 0`` (Bertsekas 1982), ``M`` never formed.

    From ``λ = 0`` (the plate without its rows), each step takes the free rows
    ``F = {λ_i > 0} ∪ {gap_i ≤ 0}`` (the others, ``λ_i = 0`` with an open gap, stay at zero),
    solves the step of active set ``F`` (the Newton step of ``ψ`` on that face; the factor of
    ``H_F`` as in the exact steps) and projects its reactions onto ``λ ≥ 0``. Where the
    projection clips nothing the step is the minimiser of ``ψ`` on the face and is taken;
    otherwise the projected arc is searched back from its full length until ``ψ`` falls
    (Armijo), each trial one solve with the factor of ``K`` alone (``kfac``: the
    displacements ``K⁻¹(f − Bᵀλ)`` and the gaps, the gradient of ``ψ``). ``ψ`` falls at every
    step, so no active set comes back: this replaces plain PDAS's block exchanges, which
    cycle on a plate's many stiff rows (its condensed stiffness is not an M-matrix), and
    Murty's one-row-per-step way out. It ends when a step clips nothing and no zero row has
    a negative gap (the exact steps then confirm the set), or after :data:`DUAL_STEPS` steps.

    ``uf = K⁻¹ f`` (:func:`held_plate`: the plate is held); ``lam0``: reactions ``≥ 0`` to
    start from instead of 0 (where Lawson–Hanson gave up). Returns ``(u, λ, A, steps)``, or
    None where a step's active rows do not hold the plate.
    """
    B, g, rho, f = pb.B, pb.g, pb.rho, pb.f
    if lam0 is None or not np.any(lam0 > 0):
        lam = np.zeros(pb.m)
        u = uf.copy()
        psi = 0.0  # ψ(0)
    else:
        lam = lam0.copy()
        u = kfac.solve(f - B.T @ lam)
        psi = _dual_energy(pb, uf, lam, u)
    best = (psi, lam, u)  # the lowest ψ met so far, and where
    rises = 0  # full steps that raised ψ
    flat = 0  # steps in a row that left ψ as it was
    nearest = (pb.m + 1, u, lam, None)  # the step that left the fewest rows infeasible
    settled = max(NEWTON_SETTLED, NEWTON_SETTLED_FRACTION * pb.m)
    for k in range(1, DUAL_STEPS + 1):
        monotone = rises > DUAL_RISES
        gap = g + rho * lam - B @ u
        F = (lam > 0) | (gap <= 0)
        fac.set(np.where(F, W, 0.0))
        step = solve_active(pb, fac, W, F, u, lam, sigma, exact=False)
        if step.ray is not None:
            return None
        neg = step.lam < 0
        bad = infeasible(pb, F, step.lam, g + rho * step.lam - B @ step.u, LOOSE_TOL)
        if bad.sum() < nearest[0]:
            nearest = (int(bad.sum()), step.u, step.lam, F)
        if bad.sum() <= settled:  # a few rows from the answer: the exact steps finish
            if steps is not None:
                steps.append({"step": f"dual {k}", "active": int(F.sum()), "infeasible": int(bad.sum()),
                              "solve": "loose", "solves": step.solves})
            return FirstSet(step.u, step.lam, F, k)
        dirn = step.lam - lam
        alpha = 1.0
        while True:
            lt = np.maximum(0.0, lam + alpha * dirn)
            if alpha == 1.0 and not neg.any():  # the step itself: its displacements are at hand
                ut = step.u
            else:
                ut = kfac.solve(f - B.T @ lt)
            pt = _dual_energy(pb, uf, lt, ut)
            if not monotone or pt <= psi + ARMIJO * float(gap @ (lt - lam)) or alpha < ALPHA_MIN:
                break
            alpha *= 0.5
        lam, u = lt, ut
        if steps is not None:
            steps.append({"step": f"dual {k}", "active": int(F.sum()), "infeasible": int(bad.sum()),
                          "solve": "loose", "solves": step.solves, "alpha": alpha, "energy": pt})
        rises += pt > psi + DUAL_ROUNDING * abs(psi)
        flat = flat + 1 if abs(pt - psi) <= DUAL_FLAT * abs(pt) else 0
        psi = pt
        if flat >= 3:  # ψ no longer moves: what is left is rows of (nearly) no force, for the exact steps
            return FirstSet(u, lam, (lam > 0) | (g + rho * lam - B @ u <= 0), k)
        if pt < best[0]:
            best = (pt, lam, u)
        if rises > DUAL_RISES and not monotone:  # from now on monotone, from the lowest point met
            psi, lam, u = best
    _, u, lam, F = nearest  # not settled within DUAL_STEPS: the exact steps start from the nearest set
    return FirstSet(u, lam, F, DUAL_STEPS)
