r"""Free rigid motions of a floating plate's active set: found (the softest mode of ``H_A`` by
inverse iteration), sharpened, replaced by the exact rigid motion nearest them where the QP
names the plate's rigid motions, and kept out of the exact steps' corrections (see the package
docstring: "Singular steps and no equilibrium")."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .factor import SpringFactor
from .options import FREE_RIGID, FREE_SHARPEN, HOLD_MARGIN, RIGID_RANK, SINGULAR_QUOTIENT
from .reduced import ReducedQP


def project(null: list, D: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``v`` without its components along the (``D``-orthonormal) free rigid motions ``null``."""
    for n in null:
        v = v - n * float(n @ (D * v))
    return v


def deflate(null: list, D: np.ndarray, r: np.ndarray) -> np.ndarray:
    """``r`` without its work along the free rigid motions ``null`` (``nᵀr = 0`` after)."""
    for n in null:
        r = r - (D * n) * float(n @ r)
    return r


def softest(pb: ReducedQP, fac: SpringFactor, w: np.ndarray, null: list = ()) -> tuple[np.ndarray, float]:
    """The softest mode of ``K + Bᵀ diag(w) B`` (besides ``null``), as two inverse iterations with
    ``fac`` (a factor of that matrix plus ``σD``) from a fixed start find it, and its Rayleigh
    quotient ``vᵀ(K + Bᵀ diag(w) B)v / vᵀDv`` (a rigid motion left free: about 0; a held plate:
    ``λ_min ≫ σ``)."""
    v = np.cos(np.arange(pb.K.shape[0], dtype=float))
    for _ in range(2):
        v = project(null, pb.Kd, fac.solve(pb.Kd * v))
    Dv = float(v @ (pb.Kd * v))
    Bv = pb.B @ v
    energy = float(v @ (pb.K @ v)) + float(Bv @ (w * Bv))
    return v, (energy / Dv if Dv > 0 else np.inf)


def free_mode(pb: ReducedQP, fac: SpringFactor, W: np.ndarray, A: np.ndarray, null: list,
               sigma: float) -> np.ndarray | None:
    """A rigid motion the active rows ``A`` leave free (besides ``null``), or None: the softest
    mode of ``H_A`` (:func:`softest`), judged by its Rayleigh quotient as :func:`solve_active`
    judges its first correction (below SINGULAR_QUOTIENT·σ)."""
    v, quotient = softest(pb, fac, np.where(A, W, 0.0), null)
    return v / np.abs(v).max() if quotient < SINGULAR_QUOTIENT * sigma else None


def rows_hold(pb: ReducedQP, W: np.ndarray, A: np.ndarray, sigma: float) -> bool:
    """True where the QP names the plate's rigid motions ``N`` (:meth:`ReducedQP.rigid`) and the
    active rows ``A`` hold every one of them: ``B_A N`` of full column rank (its singular
    values above RIGID_RANK of the largest, :func:`exact_motion`'s test) and the least held,
    ``N a``, stiffer than HOLD_MARGIN times :func:`free_mode`'s threshold (its Rayleigh quotient
    ``Σ_A W_i (B_i N a)² / (N a)ᵀD(N a)``, ``K N = 0``: the smallest eigenvalue of
    ``(NᵀB_AᵀW_A B_A N, NᵀDN)``). A free motion of ``H_A`` is a rigid motion the rows do not
    hold (``N`` spans ``K``'s null space, piece by piece), so :func:`free_mode`'s two solves are
    not needed; False gives no verdict (:func:`free_mode` decides)."""
    N = pb.rigid()
    if N is None or N.shape[1] == 0 or not A.any():
        return False
    BN = pb.rigid_rows()[A]
    sv = np.linalg.svd(BN, compute_uv=False)
    if sv.size < N.shape[1] or not sv[-1] > RIGID_RANK * sv[0]:
        return False
    G = BN.T @ (W[A][:, None] * BN)
    mu = sla.eigh(G, pb.rigid_mass(), eigvals_only=True)[0]
    return bool(mu > HOLD_MARGIN * SINGULAR_QUOTIENT * sigma)


def free_motion(pb: ReducedQP, fac: SpringFactor, null: list, d: np.ndarray) -> np.ndarray:
    """The rigid motion ``d`` sharpened by inverse iteration with ``H_A`` (its error in the held
    modes falls by ``σ/λ`` each time) and ``D``-normalised against ``null``."""
    for _ in range(FREE_SHARPEN):
        d = project(null, pb.Kd, fac.solve(pb.Kd * d))
        d /= np.sqrt(float(d @ (pb.Kd * d)))
    return d


def exact_motion(pb: ReducedQP, A: np.ndarray, null: list, d: np.ndarray) -> np.ndarray | None:
    """The free rigid motion ``d`` (from :func:`free_motion`) replaced by the exact one nearest
    it, where the QP names the plate's rigid motions ``N`` (:meth:`ReducedQP.rigid`): its
    ``D``-projection onto ``N Z``, ``Z`` spanning the null space of ``B_A N`` (the rigid
    motions that move no active row), projected off ``null`` and ``D``-normalised as ``d`` is.
    None where there is no hint or ``d`` is not such a motion to FREE_RIGID. The load's work
    along it is then its work along an exact rigid motion, rounding of the sum only: ``d``'s
    own rounding (the plate's softest elastic modes, left in by the inverse iterations) grows
    with the mesh, and for a point load on ``d``'s axis it was all of ``fᵀd`` (2.7e-11 of
    ``Σ|f_j| max|d_j|`` at 128²: above FREE_FLOOR)."""
    N = pb.rigid()
    if N is None:
        return None
    F = N
    if A.any():  # the rigid motions that move no active row: N times the null space of B_A N
        F = N @ null_space(pb.rigid_rows()[A], RIGID_RANK).T
    if F.shape[1] == 0:
        return None
    DF = pb.Kd[:, None] * F
    df = F @ np.linalg.solve(F.T @ DF, DF.T @ d)
    df = project(null, pb.Kd, df)
    e = d - df
    size = float(df @ (pb.Kd * df))
    if size == 0.0 or float(e @ (pb.Kd * e)) > FREE_RIGID**2 * float(d @ (pb.Kd * d)):
        return None
    return df / np.sqrt(size)


def null_space(X: np.ndarray, rtol: float) -> np.ndarray:
    """(r, k) orthonormal rows spanning the null space of the tall (m, k) matrix ``X`` (k small:
    the rigid motions), singular values below ``rtol`` of the largest counted as zero. Through
    the k × k triangle of X's QR where m > k, so that no m × m factor is ever formed (a full SVD
    of a bed's 31 000 active rows asked for 28 GiB)."""
    X = np.asarray(X, dtype=float)
    if X.shape[0] > X.shape[1]:
        X = np.linalg.qr(X, mode="r")
    _, sv, Vt = np.linalg.svd(X)
    if sv.size == 0 or sv.max() == 0.0:
        return Vt
    return Vt[int(np.sum(sv > rtol * sv.max())):]

