r"""Inverse design: the gaps that make supports carry prescribed reactions, and the support
stiffness that makes the contact pressure most uniform.

Gaps that regulate the reactions (:func:`regulate_gaps`)
--------------------------------------------------------
With the prescribed reactions R acting on the plate as forces, the deflection at the
supports w follows, and the gaps that make R the contact solution are those that close
each loaded support exactly: with gap = g0 + ρR − w = 0,

.. math::

    g_0 = w(R) - \rho R .

On a held plate (two-sided supports, K nonsingular) this is the dual relation
gap = F R + (g0 − B K⁻¹ f) solved for g0 with gap = 0, and every R ≥ 0 is reachable. On a
floating plate R must also balance the load (force and moments); the target is first
projected onto the reachable set (:func:`project_reactions`)

.. math::

    \min_R \tfrac12\|R_r - R^*\|^2 \quad\text{s.t.}\quad V^T(f - B^T R) = 0,\ R \ge 0,

(V the rigid motions), and the rigid-motion part of the gaps, free on a floating plate, is
chosen closest to the scene's own gaps.

The most uniform pressure (:func:`most_uniform_stiffness`)
----------------------------------------------------------
The stiffness c of every support that minimises a uniformity measure of the chosen supports'
reactions (:data:`UNIFORMITY_MEASURES`: "std/mean", the coefficient of variation, by default;
"peak/mean"; "range/mean" = (max − min)/mean), on log c: a coarse scan, then a bounded scalar
minimisation.
"""

from __future__ import annotations

import copy
import logging
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..model.assembly import Model, build_model
from ..backends import LCP, get_backend
from ..errors import NoEquilibriumError, PlateQPWarning, ProblemError, SceneError
from ..linalg import Factor, solve_saddle
from ..linalg.keep import sharing
from ..model.paths import set_param
from ..progress import Progress
from ..model.scene import PointLoad, Scene
from ..results import Result
from ..solving import solve
from .reuse import adapt_model

logger = logging.getLogger(__name__)

# =============================================================================================
# Regulating the interaction forces by the gaps
# =============================================================================================

@dataclass
class GapRegulation:
    """Gaps that make the regulated supports carry prescribed reactions.

    ``gaps``: new initial gap of every support (scene order); ``scene``: a copy with them;
    ``supports``: the regulated supports; ``target``: the reactions asked; ``aimed``: the
    reactions the gaps were computed for (the target, projected onto equilibrium on a floating
    plate); ``check``: the contact solve of ``scene`` (:func:`plateqp.solve`, accuracy "high"),
    with exactly these gaps; ``reactions`` and ``other_reactions``: the regulated and the
    other supports' reactions in that solve, so what the gaps give, not what they aim at;
    ``projection``: relative distance ‖aimed − target‖ / ‖target‖ (0 when the target is
    reachable).
    """

    gaps: np.ndarray
    scene: Scene
    supports: np.ndarray
    target: np.ndarray
    aimed: np.ndarray
    check: Result
    projection: float

    @property
    def reactions(self) -> np.ndarray:
        return self.check.reactions[self.supports]

    @property
    def other_reactions(self) -> np.ndarray:
        return np.delete(self.check.reactions, self.supports)

    @property
    def miss(self) -> float:
        """max |reactions − aimed|, relative to the largest of either."""
        scale = max(float(np.abs(self.aimed).max(initial=0.0)), float(np.abs(self.check.reactions).max(initial=0.0)),
                    1e-300)
        return float(np.abs(self.reactions - self.aimed).max(initial=0.0) / scale)

    @property
    def reachable(self) -> bool:
        return self.projection <= 1e-9


def project_reactions(A: np.ndarray, b: np.ndarray, target: np.ndarray, n_other: int) -> np.ndarray:
    r"""The reactions R = [R_r; R_u] ≥ 0 with A R = b closest to the target on the first part:

    .. math::

        \min_R \tfrac12\|R_r - R^*\|^2 \quad\text{s.t.}\quad A R = b,\ R \ge 0 .

    ``A`` has the ``target.size`` regulated supports' columns first, then ``n_other`` others.
    Solved exactly (pivoting, no tolerance) by Lemke's method from the backend registry, on
    the LCP of its KKT conditions with the equalities as two inequalities,

    .. math::

        z = \begin{bmatrix} R \\ y^+ \\ y^- \end{bmatrix},\quad
        M = \begin{bmatrix} P & -A^T & A^T \\ A & 0 & 0 \\ -A & 0 & 0 \end{bmatrix},\quad
        q = \begin{bmatrix} -P R^*_0 \\ -b \\ b \end{bmatrix},

    (P = diag(1 on R_r, 0 on R_u), R*_0 the target padded with zeros); M + Mᵀ = diag(2P, 0, 0)
    is positive semidefinite, so Lemke's method finds a solution or proves there is none
    (NoEquilibriumError). The rows of A are scaled to unit norm and R to the target's size.
    """
    r = target.size
    n = r + n_other
    A = np.asarray(A, dtype=float).reshape(-1, n)
    b = np.asarray(b, dtype=float).reshape(-1)
    scale = max(np.abs(target).max(initial=0.0), np.abs(b).max(initial=0.0), 1e-300)
    norms = np.linalg.norm(A, axis=1)
    norms[norms == 0] = 1.0  # a row no support reaches: infeasible unless its b is 0
    An, bn = A / norms[:, None], b / norms / scale
    k = An.shape[0]
    P = np.zeros((n, n))
    P[np.arange(r), np.arange(r)] = 1.0
    Z = np.zeros((k, k))
    M = np.block([[P, -An.T, An.T], [An, Z, Z], [-An, Z, Z]])
    t = np.concatenate([target / scale, np.zeros(n_other)])
    q = np.concatenate([-P @ t, -bn, bn])
    no_balance = "regulate_gaps: no reactions R ≥ 0 of these supports balance the load"
    try:
        raw = get_backend("lemke").solve(LCP(M, q), accuracy="high")
    except NoEquilibriumError as exn:
        raise NoEquilibriumError(no_balance) from exn
    if not raw.status.solved:
        raise NoEquilibriumError(f"{no_balance} (lemke: {raw.status.value})")
    R = np.maximum(raw.x[:n], 0.0) * scale
    if n_other == 0 and k and np.all(R[:r] > 1e-9 * R.max()):
        # polish: with no bound active, the exact projection onto {A R = b}
        R = target - A.T @ np.linalg.solve(A @ A.T, A @ target - b)
    return R


def regulate_gaps(scene: Scene, target_reactions, supports: Sequence[int] | None = None,
                  backend: str = "auto", formulation: str = "auto") -> GapRegulation:
    r"""Initial gaps that make the chosen supports carry the target reactions.

    Parameters
    ----------
    scene : the scene (its other supports keep their gaps)
    target_reactions : one value per regulated support, or one value for all
    supports : indices of the regulated supports (default: every support)

    Notes
    -----
    The regulated supports act on the plate as the forces R; the plate (with the other
    one-sided supports in contact as the contact problem says, solved with
    :func:`plateqp.solve`) deflects by w; the gap of each regulated support is then
    g0 = w − R/c (c its stiffness; R/c = 0 for a rigid one), so that it touches with exactly R.
    A target of 0 leaves that support touching with zero force (add a margin to lift it off).
    On a floating plate the target is first projected onto equilibrium (see module docs).
    The regulated scene is then solved (``backend``, ``formulation``, accuracy "high"): the
    reactions returned are that solve's (``result.check``), those the returned gaps give.
    """
    ns = len(scene.supports)
    if ns == 0:
        raise SceneError("supports: the scene has no one-sided supports to regulate")
    reg = np.arange(ns) if supports is None else np.asarray(list(supports), dtype=int)
    if reg.size == 0 or reg.min() < 0 or reg.max() >= ns or len(set(reg.tolist())) != reg.size:
        raise SceneError(f"supports: regulated supports must be distinct indices 0..{ns - 1} (got {list(reg)})")
    target = np.broadcast_to(np.asarray(target_reactions, dtype=float), reg.shape).copy()
    if np.any(target < 0) or not np.all(np.isfinite(target)):
        raise ProblemError("target_reactions: reactions must be finite and >= 0 (compression)")
    others = np.setdiff1d(np.arange(ns), reg)
    if scene.foundation is not None:
        raise ProblemError("regulate_gaps: a scene with a tensionless bed is not supported; "
                           "regulate discrete supports only")

    model = build_model(scene)
    c = model.contacts
    V = model.rigid_modes()
    order = np.concatenate([reg, others])
    if V.shape[1]:
        A = np.asarray((c.B[order] @ V).T)  # force/moment balance: (B V)ᵀ R = Vᵀ f
        R_reg = project_reactions(A, V.T @ model.f, target, others.size)[: reg.size]
    else:
        R_reg = target.copy()
    proj = float(np.linalg.norm(R_reg - target) / max(np.linalg.norm(target), 1e-300))

    # the plate under the load and the regulated reactions (as upward point forces)
    if others.size:
        sc = copy.deepcopy(scene)
        sc.supports = [scene.supports[k] for k in others]
        sc.loads = list(sc.loads) + [PointLoad(P=-float(R), x=scene.supports[k].x, y=scene.supports[k].y)
                                     for k, R in zip(reg, R_reg)]
        sc.validate()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlateQPWarning)
            res = solve(sc, backend=backend, formulation=formulation, accuracy="high")
        w_reg = np.asarray(res.deflection(np.array([scene.supports[k].x for k in reg]),
                                          np.array([scene.supports[k].y for k in reg])), dtype=float)
    else:
        rhs = model.f - c.B[reg].T @ R_reg
        u = _held_or_floating(model, rhs, V)
        g_scene = c.scene_gaps[reg]
        # actual deflection at the supports: B u plus the prescribed dofs' part
        w_reg = c.B[reg] @ u + c.shift[reg]
        if V.shape[1]:
            # a floating plate's rigid motion is free: choose it so the gaps are closest to the scene's
            BV = np.asarray(c.B[reg] @ V)
            alpha, *_ = np.linalg.lstsq(BV, g_scene - (w_reg - c.rho[reg] * R_reg), rcond=None)
            w_reg = w_reg + BV @ alpha
    gaps = np.array([s.gap for s in scene.supports], dtype=float)
    gaps[reg] = w_reg - c.rho[reg] * R_reg
    new = set_param(scene, "supports.*.gap", gaps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlateQPWarning)  # the check's status says it
        # the model built for the gaps, adapted to them: no second assembly
        check = solve(new, backend=backend, formulation=formulation, accuracy="high",
                      model=adapt_model(model, new))
    out = GapRegulation(gaps, new, reg, target, R_reg, check, proj)
    logger.info("regulate_gaps: %d supports regulated, relative distance to the target %.2e, the check solve "
                "%.1e off the reactions aimed at", reg.size, proj, out.miss)
    return out


def shim_sensitivity(result, supports) -> tuple[np.ndarray | None, str | None]:
    """dR_i/dg0_j among ``supports`` (0-based) at a solved, regulated scene: how much a shim
    error moves the regulated reactions (:func:`plateqp.sensitivity`, from its active set).

    Returns (matrix, note). Where a support sits at lift-off the matrix is the derivative as the
    gap grows (a shim too thin) and the note says so; where the active set leaves a rigid motion
    free (no unique answer) the matrix is None and the note says why.
    """
    from ..errors import PlateQPError
    from ..sensitivity import sensitivity

    try:
        s = sensitivity(result, "gaps")
    except PlateQPError as e:
        return None, f"not available ({e})"
    idx = np.asarray(supports, dtype=int)
    note = None if s.smooth else ("a support is at lift-off: the derivative as the gap grows (a shim too thin); "
                                  "as it shrinks the slope differs")
    return s.increasing.reactions[np.ix_(idx, idx)], note


def _held_or_floating(model: Model, rhs: np.ndarray, V: np.ndarray) -> np.ndarray:
    """K u = rhs; on a floating plate (rigid motions V) the solution orthogonal to V, from the
    bordered system [K V; Vᵀ 0] (:func:`plateqp.linalg.solve_saddle` with ρ = 0)."""
    if V.shape[1] == 0:
        return Factor(model.K).solve(rhs)
    k = V.shape[1]
    s = float(np.median(np.abs(model.K.diagonal())))
    Vn = V / np.linalg.norm(V, axis=0) * s  # columns of the size of K's entries
    u, _ = solve_saddle(model.K, sp.csr_matrix(Vn.T), np.zeros(k), rhs, np.zeros(k))
    return u


# =============================================================================================
# The most uniform contact pressure
# =============================================================================================

#: The uniformity measures of :func:`most_uniform_stiffness` (each 0 for equal reactions).
UNIFORMITY_MEASURES = ("std/mean", "peak/mean", "range/mean")


def uniformity(reactions, measure: str = "std/mean") -> float:
    """A measure of how far the reactions are from uniform (smaller is more uniform).

    "std/mean": the coefficient of variation std(R)/mean(R) (population std); "peak/mean":
    max(R)/mean(R) (1 for equal reactions); "range/mean": (max(R) − min(R))/mean(R). ``inf``
    when mean(R) ≤ 0. Raises :class:`~plateqp.errors.ProblemError` for an unknown measure.
    """
    if measure not in UNIFORMITY_MEASURES:
        raise ProblemError(f"measure must be one of {', '.join(map(repr, UNIFORMITY_MEASURES))} (got {measure!r})")
    R = np.asarray(reactions, dtype=float).reshape(-1)
    if R.size == 0:
        raise ProblemError("uniformity: no reactions")
    m = float(R.mean())
    if not m > 0:
        return math.inf
    if measure == "std/mean":
        return float(R.std() / m)
    if measure == "peak/mean":
        return float(R.max() / m)
    return float((R.max() - R.min()) / m)


@dataclass
class UniformStiffness:
    """The stiffness that makes the reactions of the chosen supports most uniform.

    ``c``: the stiffness; ``cv``: coefficient of variation std(R)/mean(R) there (whatever the
    measure); ``reactions``: of the chosen supports; ``evaluations``: every (c, value of the
    measure) tried; ``at_bound``: the best c lies within one scan step of an end of
    ``c_range`` (no interior optimum found: e.g. on a floating plate on equal springs the
    std/mean only falls as c falls towards the rigid-body distribution); ``measure``: the
    measure minimised (:func:`uniformity`) and ``value`` its value at ``c``.
    """

    c: float
    cv: float
    reactions: np.ndarray
    evaluations: list[tuple[float, float]]
    at_bound: bool = False
    measure: str = "std/mean"
    value: float = float("nan")


def most_uniform_stiffness(scene: Scene, c_range: tuple[float, float], supports: Sequence[int] | None = None,
                           backend: str = "auto", formulation: str = "auto", accuracy: str = "default",
                           scan: int = 17, xatol: float = 1e-4, measure: str = "std/mean") -> UniformStiffness:
    """The support stiffness c (all supports) that makes the contact pressure most uniform.

    Minimises ``measure`` (:func:`uniformity`: "std/mean", the coefficient of variation, by
    default; "peak/mean"; "range/mean") of the reactions over ``supports`` (default: every
    support, e.g. a contour) on log c: a coarse log scan of ``scan`` points first, then
    :func:`scipy.optimize.minimize_scalar` (bounded) around the best scan point. The model is
    built once; only the support flexibilities change.
    """
    from scipy.optimize import minimize_scalar

    uniformity(np.ones(1), measure)  # an unknown measure fails here, before any work
    lo, hi = (float(v) for v in c_range)
    if not (0 < lo < hi):
        raise ProblemError(f"c_range must be (low, high) with 0 < low < high (got {c_range!r})")
    sel = np.arange(len(scene.supports)) if supports is None else np.asarray(list(supports), dtype=int)
    base = build_model(scene)
    evals: list[tuple[float, float]] = []
    bar = Progress(None, "most uniform stiffness: solves")  # a scan, then a bounded search: no known end

    def cv_at(logc: float) -> float:
        c = float(np.exp(logc))
        sc = set_param(scene, "supports.*.stiffness", c)
        with warnings.catch_warnings(), sharing():  # K factorised once for every c
            warnings.simplefilter("ignore", PlateQPWarning)
            res = solve(sc, backend=backend, formulation=formulation, accuracy=accuracy,
                        model=adapt_model(base, sc))
        v = uniformity(res.reactions[sel], measure)
        evals.append((c, v))
        bar.update()
        logger.debug("most uniform stiffness: c = %.6g, %s = %.6g", c, measure, v)
        return v

    grid = np.linspace(np.log(lo), np.log(hi), max(scan, 3))
    cvs = [cv_at(x) for x in grid]
    k = int(np.argmin(cvs))
    a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    minimize_scalar(cv_at, bounds=(a, b), method="bounded", options={"xatol": xatol})  # records in evals
    bar.close()
    best = min(evals, key=lambda e: e[1])
    logger.info("most uniform stiffness: c = %.6g after %d solves (%s = %.6g)", best[0], len(evals), measure, best[1])
    sc = set_param(scene, "supports.*.stiffness", best[0])
    with warnings.catch_warnings(), sharing():
        warnings.simplefilter("ignore", PlateQPWarning)
        res = solve(sc, backend=backend, formulation=formulation, accuracy=accuracy, model=adapt_model(base, sc))
    step = grid[1] - grid[0]
    at_bound = bool(min(np.log(best[0]) - grid[0], grid[-1] - np.log(best[0])) < step)
    R = res.reactions[sel].copy()
    return UniformStiffness(best[0], uniformity(R, "std/mean"), R, evals, at_bound, measure, best[1])


__all__ = ["UNIFORMITY_MEASURES", "GapRegulation", "UniformStiffness", "uniformity", "most_uniform_stiffness", "project_reactions", "regulate_gaps",
           "shim_sensitivity"]
