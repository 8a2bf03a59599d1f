"""Statics, independent of any solver: can the one-sided supports carry the load at all, and
which rigid motions of the plate does an answer leave free?

A floating plate (its two-sided supports leave rigid motions V free: K singular) has an
equilibrium iff some reactions R ≥ 0 balance the load in every rigid motion,
Vᵀ Bᵀ R = Vᵀ f (force and moment balance; by Farkas' lemma exactly the condition for the
primal QP to be bounded below). :func:`supports_reach` measures how far the load's resultant
lies from the set of resultants the supports can carry (the cone {Vᵀ Bᵀ R : R ≥ 0}):
outside it, there is no equilibrium; on its edge, within a band set by the asked accuracy,
statics cannot tell a solver that finds no equilibrium from one that finds one, and the
solver's own verdict stands (:func:`plateqp.contact.pipeline.solve_contact`).

Where there is an equilibrium the reactions are unique but the deflection need not be: if
the supports that carry load leave a rigid motion of the plate free (a load exactly on a
support of a floating plate, or on the line between two), every backend may return another
tilt. :func:`settle` detects that and picks one answer that does not depend on the backend.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .scaling import Scaled

NO_EQUILIBRIUM = ("the one-sided supports cannot carry this load: net uplift, or the load "
                  "resultant lies outside the supports' reach, so the plate would lift off")

#: Relative distance (of the load's resultant from the supports' reach) below which statics
#: calls it "inside, to rounding": NNLS's residual is exact to about 1e-15 of the load.
ROUNDING = 1e-13
#: Outside the supports' reach by less than this (relative to the load), statics leaves the
#: verdict to the solver. Measured on a plate on four posts with a point load 1e-12 … 1e-4 of
#: the plate's size outside their hull: BPP, Lemke and PDAS prove "no equilibrium" from 1e-10
#: (at accuracy "default"; from 1e-8 at "low") and return an answer at 1e-12, while SciPy's
#: HiGHS LP, the statics check before this one, still found reactions at 1e-10 and the user was
#: told that a solver which was right had failed.
EDGE = 1e-10


@dataclass(frozen=True)
class Reach:
    """Where the load's resultant lies with respect to what the supports can carry.

    ``possible``: reactions R ≥ 0 balance the load (to rounding); ``distance``: how far the
    resultant lies outside the supports' reach, relative to the load (0 inside);
    ``marginal``: the resultant lies on the edge of the reach: outside by at most :data:`EDGE`,
    or inside by less than ``band`` (the asked accuracy), where a solver's "no equilibrium" is
    within its tolerance; ``why``: words.
    """

    possible: bool
    marginal: bool
    distance: float
    band: float
    why: str = ""

    @property
    def certain(self) -> bool:
        """An equilibrium exists, by a margin: a solver that finds none has failed."""
        return self.possible and not self.marginal


def _outside(A: np.ndarray, b: np.ndarray) -> float:
    """min ‖A R − b‖ over R ≥ 0: the distance of b from the cone of A's columns (NNLS,
    Lawson–Hanson); the ℓ1 distance by an LP if NNLS does not converge."""
    from scipy.optimize import linprog, nnls

    if A.shape[1] == 0:
        return float(np.linalg.norm(b))
    try:
        return float(nnls(A, b, maxiter=50 * A.shape[1] + 100)[1])
    except RuntimeError:  # pragma: no cover - NNLS gave up: the LP's ℓ1 distance, an upper bound
        k, m = A.shape
        c = np.r_[np.zeros(m), np.ones(k)]
        Aub = np.block([[A, -np.eye(k)], [-A, -np.eye(k)]])
        res = linprog(c, A_ub=Aub, b_ub=np.r_[b, -b], bounds=(0, None), method="highs")
        return float(res.fun) if res.status == 0 else float(np.linalg.norm(b))


def _generators(A: np.ndarray) -> np.ndarray:
    """Columns of ``A`` that generate the same cone {A R : R ≥ 0}, fewer where that is cheap to
    tell: a cone in at most three dimensions with every column on one side of a plane (the
    supports all push up) is the cone over the convex hull of the columns projected onto
    that plane, so only the columns on or near the hull's boundary are kept (a bed of 66 049
    springs: the 4 at the plate's corners). Otherwise, or where the hull is degenerate, all."""
    k, m = A.shape
    if m <= 64 or not 1 <= k <= 3:
        return A
    norms = np.linalg.norm(A, axis=0)
    A = A[:, norms > 0]  # a row that moves no rigid motion carries nothing
    d = (A / norms[norms > 0]).sum(axis=1)
    if not np.linalg.norm(d):
        return A
    d /= np.linalg.norm(d)
    t = d @ A
    if np.any(t <= 1e-6 * np.linalg.norm(A, axis=0)):
        return A  # not every column on one side of d's plane: no projection here
    if k == 1:
        return A[:, :1]
    E = np.linalg.svd(d[None, :])[2][1:]  # an orthonormal basis of the plane ⊥ d
    Y = E @ (A / t)  # (k − 1) × m: the columns where their rays cross the plane x·d = 1
    tol = 1e-8 * max(float(np.ptp(Y, axis=1).max()), 1e-300)  # (k = 2: the ends, within rounding)
    if k == 2:
        keep = (Y[0] <= Y[0].min() + tol) | (Y[0] >= Y[0].max() - tol)
        return A[:, keep]
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(Y.T)
    except (QhullError, ValueError):
        return A
    # the hull's vertices are the cone's extreme rays (a point on an edge between two is a
    # combination of them); one qhull merged as coplanar is within its precision (~1e-15 of the
    # spread) of the hull, far inside ROUNDING
    return A[:, np.sort(hull.vertices)]


def supports_reach(data: Scaled, band: float = 1e-9) -> Reach:
    """Can the one-sided supports carry the load, and by what margin? (statics, no solver)

    A plate held by its two-sided supports always has an equilibrium. For a floating plate,
    with Q an orthonormal basis of its rigid motions, the resultant b = Qᵀf must lie in the
    cone {Qᵀ Bᵀ R : R ≥ 0}. Its distance from the cone (NNLS) relative to the load's size
    ‖|Q|ᵀ|f|‖ is ``distance``: above :data:`EDGE`, there is no equilibrium. Inside, the
    resultant is ``marginal`` when one of the points b ± band·size·e_j (e_j the axes; ``band``
    at least EDGE) is outside: it is then within about ``band`` of the edge.
    """
    band = max(float(band), EDGE)
    V = data.modes
    if V.shape[1] == 0:
        return Reach(True, False, 0.0, band)
    memo = data.memo if data.memo is not None else {}
    if "reach_generators" not in memo:  # the rigid motions and B alone: once per sweep
        Q, _ = np.linalg.qr(V)
        memo["reach_generators"] = (Q, _generators(np.asarray((data.B @ Q).T)))
    Q, A = memo["reach_generators"]
    b = Q.T @ data.f
    size = float(np.linalg.norm(np.abs(Q).T @ np.abs(data.f)))
    if size == 0.0:  # no load on any rigid motion: nothing to carry
        return Reach(True, False, 0.0, band)
    dist = _outside(A, b) / size
    if dist > ROUNDING:
        total = float(data.f[data.is_w].sum())  # net downward load (the two-sided supports hold none)
        why = ("net uplift: the load pulls the plate off its supports" if total <= 0 else
               "the load resultant lies outside the reach of the supports, so the plate would tip off them")
        if dist <= EDGE:
            why = (f"the load resultant lies {dist:.1e} (relative) outside the supports' reach, on its edge: "
                   f"statics leaves the verdict to the solver; {why}")
        else:
            why = f"{why} ({dist:.1e} of the load outside their reach)"
        return Reach(False, dist <= EDGE, dist, band, why)
    step = band * size
    for j in range(b.size):
        for sign in (1.0, -1.0):
            e = np.zeros(b.size)
            e[j] = sign * step
            if _outside(A, b + e) / size > ROUNDING:
                return Reach(True, True, 0.0, band,
                             f"the load resultant lies on the edge of the supports' reach (within {band:.0e}, the "
                             "accuracy asked): the plate is about to tip off or lift off them")
    return Reach(True, False, 0.0, band)


def equilibrium_possible(data: Scaled) -> tuple[bool, str]:
    """Can the one-sided supports carry the load at all? (statics, independent of any solver)

    True (and "") if some reactions R ≥ 0 balance the load to rounding; else False and why
    (net uplift, or the load resultant outside the supports' reach). See :func:`supports_reach`
    for the margin.
    """
    r = supports_reach(data)
    return r.possible, r.why


def _null_space(A: np.ndarray, k: int) -> np.ndarray:
    """An orthonormal basis (k, r) of {z : A z = 0} (A may have no rows)."""
    if A.shape[0] == 0:
        return np.eye(k)
    # the thin SVD where A has at least k rows: vt is k × k either way, U (m × m) never formed
    # (a bed of 66 049 nodes at 256² took 18.6 GB for it)
    _, sv, vt = np.linalg.svd(A, full_matrices=A.shape[0] < k)
    rank = int(np.sum(sv > 1e-9 * max(sv.max(initial=0.0), 1e-300)))
    return vt[rank:].T


def _least_distance(E: np.ndarray, f: np.ndarray) -> np.ndarray | None:
    """min ‖x‖ subject to E x ≥ f (Lawson and Hanson's least distance programming, by NNLS on
    [Eᵀ; fᵀ] y ≈ e_last); None if the constraints are infeasible."""
    from scipy.optimize import nnls

    p, r = E.shape
    if p == 0:
        return np.zeros(r)
    M = np.vstack([E.T, f[None, :]])
    e = np.zeros(r + 1)
    e[-1] = 1.0
    y, _ = nnls(M, e, maxiter=50 * p + 100)
    res = M @ y - e
    if abs(res[-1]) <= 1e-14:
        return None
    return -res[:r] / res[-1]


def _cone_is_zero(M: np.ndarray, r: int) -> bool:
    """True if d = 0 is the only solution of M d ≤ 0 (d in R^r): no direction is left free."""
    from scipy.optimize import linprog

    if r == 0:
        return True
    if M.shape[0] == 0:
        return False
    scale = np.maximum(np.linalg.norm(M, axis=1, keepdims=True), 1e-300)
    for j in range(r):
        for sign in (1.0, -1.0):
            c = np.zeros(r)
            c[j] = -sign
            res = linprog(c, A_ub=M / scale, b_ub=np.zeros(M.shape[0]), bounds=(-1.0, 1.0), method="highs")
            if res.status == 0 and -res.fun > 1e-7:
                return False
    return True


def _least_norm(A: np.ndarray, b: np.ndarray, C: np.ndarray, d: np.ndarray) -> np.ndarray | None:
    """min ‖b + A y‖ subject to C y ≤ d (A of full column rank, d ≥ 0 so that y = 0 is
    feasible): with A = Q T and x = T y + Qᵀb a least distance problem in x. None if that
    fails, or if its answer misses the constraints (least distance programming is delicate
    where the feasible set is thin)."""
    r = A.shape[1]
    Qm, T = np.linalg.qr(A)
    if r == 0 or np.linalg.matrix_rank(T) < r:
        return None
    Ti = np.linalg.inv(T)
    a = Qm.T @ b
    CT = C @ Ti
    x = _least_distance(-CT, -(d + CT @ a))
    if x is None:
        return None
    y = Ti @ (x - a)
    if C.shape[0] and np.any(C @ y > d + 1e-9 * (1.0 + np.abs(d).max())):
        return None
    return y


def settle(data: Scaled, u: np.ndarray, R: np.ndarray, s: np.ndarray, tol: float) -> tuple[np.ndarray, bool]:
    """The canonical deflection of a floating plate, and whether the deflection is unique.

    An answer u is one of many when the supports that carry load (R > tol·max R) leave a rigid
    motion of the plate free: every u + V z that keeps those supports where they are and opens
    no gap (gap − B V z ≥ 0 elsewhere) is an answer too, with the same reactions (K V = 0).
    This returns the one a vanishing uniform load would choose, the lowest position (the
    largest mean nodal deflection over that set; an LP), and among equally low ones the one
    nearest the level (least ‖w‖ over the nodes; least-distance programming): it depends on
    the set of answers only, so every backend gives the same. ``unique`` is False when some
    rigid motion stays free at it (none of the supports that touch stops it).

    All quantities scaled (:class:`Scaled`); u, R, s from a formulation's ``recover``.
    """
    from scipy.optimize import linprog

    V = data.modes
    k = V.shape[1]
    if k == 0 or data.m == 0:
        return u, True
    BV = np.asarray(data.B @ V)
    gap = data.g0 + s - data.B @ u
    carries = R > tol * max(np.abs(R).max(initial=0.0), 1e-300)
    N = _null_space(BV[carries], k)  # rigid motions that keep the loaded supports where they are
    r = N.shape[1]
    if r == 0:
        return u, True
    G = BV[~carries] @ N  # a motion z closes the other gaps by G z
    h = np.maximum(gap[~carries], 0.0)
    near = 1e-9 * (1.0 + h.max(initial=0.0))
    L = V[data.is_w] @ N  # the motion's deflections at the nodes
    w0 = u[data.is_w]
    z = np.zeros(r)
    face = np.eye(r)  # the directions in which the lowest positions extend (ties)
    c = L.mean(axis=0)
    if np.linalg.norm(c) > 1e-12 * max(np.linalg.norm(L), 1e-300):
        lp = linprog(-c, A_ub=G if G.shape[0] else None, b_ub=h if G.shape[0] else None,
                     bounds=(None, None), method="highs")
        if lp.status == 0:  # else: no lowest position (the plate would topple under its own weight)
            z = lp.x
            face = _null_space(c[None, :], r)
            tight = h - G @ z <= near
            if face.shape[1] == 0 or _cone_is_zero(G[tight] @ face, face.shape[1]):
                face = np.zeros((r, 0))  # one lowest position
    if face.shape[1]:
        y = _least_norm(L @ face, w0 + L @ z, G @ face, np.maximum(h - G @ z, 0.0))
        if y is not None:
            z = z + face @ y
    u_new = u + V @ (N @ z)
    gap_new = gap - BV @ (N @ z)
    delta = max(np.abs(u_new[data.is_w]).max(initial=0.0), np.abs(data.g0).max(initial=0.0), 1e-300)
    touching = ~carries & (gap_new <= 1e-7 * delta)
    return u_new, _cone_is_zero(G[touching[~carries]], r)
