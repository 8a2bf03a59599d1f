r"""Exact sensitivities of a solved contact problem, from its active set.

On a solved scene the supports in contact (the active set H) satisfy, with the other supports
open (R = 0), the linear KKT system of the plate held at H

.. math::

    K u + B_H^T R_H = f, \qquad B_H u - \rho_H R_H = g_{0,H}

(gap = g0 + ρR − B u = 0 on H). Differentiating it with respect to a parameter p gives the
derivatives of u and R: the same saddle-point matrix for every parameter, only the right-hand
side changes (:func:`plateqp.linalg.solve_saddle`, one factorisation for all of them, in the
nondimensional variables of :class:`plateqp.contact.scaling.Scaled`). Parameters:

- ``"gaps"``: the initial gap g0_j of every contact point (discrete supports in scene order,
  then foundation nodes), so ``sensitivity(result, "gaps")`` holds the (m, m) matrix
  dR_i/dg0_j. A gap g0 > 0 is settlement: settling a support unloads it (dR_j/dg0_j ≤ 0).
- ``"stiffness"``: the stiffness c_j of every elastic discrete support (``supports.j.stiffness``),
  then the bed modulus (``foundation.k``) of a Winkler bed (a Pasternak or half-space soil holds
  its parameters in K, not on its rows: not offered).
- ``"loads"``: the factor λ of each entry of ``scene.loads`` (the load scaled by λ, at λ = 1),
  labelled ``loads.j``: the response to that load alone, d/dλ = q·d/dq.

**Degenerate points.** A support exactly at lift-off (gap 0 and R 0 to the tolerance) is a
kink: the solution is piecewise linear there, with different slopes on either side. The
one-sided derivatives are then both computed, as the parameter increases (``increasing``) and
as it decreases (``decreasing``, the slope of the piece below), from the small complementarity
problem on the degenerate supports (dR ≥ 0, d(gap) ≥ 0, dR·d(gap) = 0), solved exactly by
enumeration with the same factorisation. Asking such a result for a two-sided derivative where
the two differ is a :class:`~plateqp.errors.ProblemError` that names the kinked parameters.

Errors: a result without a contact solution (two-sided scene, the two-sided comparison, a
failed solve) or an unknown ``wrt`` is a :class:`~plateqp.errors.ProblemError`; an active set
that leaves a rigid motion free (the answer is not unique) a
:class:`~plateqp.errors.MechanismError`.
"""

from __future__ import annotations

import copy
import itertools
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .accuracy import Status
from .contact.scaling import Scaled
from .errors import MechanismError, PlateQPWarning, ProblemError
from .linalg import SingularMatrixError, solve_saddle  # the linear algebra of the active-set calculus

WRT = ("gaps", "stiffness", "loads")
#: Most degenerate supports whose one-sided derivative is found by enumeration (2^n sets).
MAX_DEGENERATE = 12


# -- the held system and its derivatives (scaled variables) ----------------------------------
@dataclass
class Piece:
    """Derivatives of a held system (scaled): du (n, p), dR (m, p), dgap (m, p)."""

    du: np.ndarray
    dR: np.ndarray
    dgap: np.ndarray


def held_solve(data: Scaled, held: np.ndarray, R: np.ndarray, df: np.ndarray, dg: np.ndarray,
               drho: np.ndarray, extra: np.ndarray | None = None, solver=None):
    """Solve the KKT system of the plate held at ``held`` for several right-hand sides at once.

    Parameters
    ----------
    data : the scaled contact data
    held : bool (m,), the contact points held (gap = 0)
    R : (m,) current scaled reactions (enter through the derivative of ρ)
    df, dg, drho : (n, p), (m, p), (m, p) derivatives of the load, gaps and flexibilities
    extra : indices of held points whose unit gap responses are wanted too (columns appended)
    solver : a callable ``(H, F, G) -> (u, R_H)`` that solves the held system on the rows ``H``
        (:class:`plateqp.studies.held.HeldFactor`: one factorisation kept between the pieces of
        an exact path); where it raises SingularMatrixError, or where none is given, the
        saddle-point system is solved by sparse LU (:func:`plateqp.linalg.solve_saddle`)

    Returns
    -------
    (Piece of the p parameter columns, Piece of the ``extra`` unit-gap columns)
    """
    held = np.asarray(held, dtype=bool)
    H = np.flatnonzero(held)
    check_holds(data, H)
    extra = np.zeros(0, dtype=int) if extra is None else np.asarray(extra, dtype=int)
    p, q = df.shape[1], extra.size
    rhs_g = np.zeros((H.size, p + q))
    rhs_g[:, :p] = dg[H] + drho[H] * R[H, None]
    pos = np.searchsorted(H, extra)
    rhs_g[pos, p + np.arange(q)] = 1.0
    rhs_f = np.zeros((data.n, p + q))
    rhs_f[:, :p] = df
    if p + q == 0:
        z = np.zeros((data.n, 0))
        return Piece(z, np.zeros((data.m, 0)), np.zeros((data.m, 0))), Piece(z, np.zeros((data.m, 0)), np.zeros((data.m, 0)))
    try:
        got = None
        if solver is not None:
            try:
                got = solver(H, rhs_f, rhs_g)
            except SingularMatrixError:
                got = None  # the saddle-point system decides (its answer, or its own error)
        du, dRH = got if got is not None else solve_saddle(data.K, data.B.tocsr()[H], data.rho[H], rhs_f, rhs_g)
    except MechanismError as exn:
        raise MechanismError(f"the supports in contact do not hold the plate ({exn}): the answer is not unique") from exn
    du = du.reshape(data.n, p + q)
    dR = np.zeros((data.m, p + q))
    dR[H] = dRH.reshape(H.size, p + q)
    dgap = np.zeros((data.m, p + q))
    dgap[:, :p] = dg + drho * R[:, None]
    dgap += data.rho[:, None] * dR - data.B @ du
    dgap[H] = 0.0  # held: the gap stays closed (exactly, not to rounding)
    return (Piece(du[:, :p], dR[:, :p], dgap[:, :p]), Piece(du[:, p:], dR[:, p:], dgap[:, p:]))


def check_holds(data: Scaled, H: np.ndarray) -> None:
    """MechanismError if the two-sided supports and the contact points H leave a rigid motion free."""
    k = data.modes.shape[1]
    if k == 0:
        return
    if H.size < k:
        raise MechanismError(f"only {H.size} support(s) in contact on a plate with {k} free rigid motion(s): "
                             "the deflection is not unique (a rigid motion is free)")
    A = data.B.tocsr()[H] @ data.modes
    s = np.linalg.svd(A, compute_uv=False)
    if s[-1] <= 1e-9 * max(s[0], 1e-300):
        raise MechanismError("the supports in contact leave a rigid motion of the plate free (they lie on "
                             "one line, or too few touch): the deflection is not unique")


def directional(a: Piece, unit: Piece, D: np.ndarray, sign: float) -> tuple[Piece, np.ndarray]:
    """One-sided derivatives along ``sign`` × each parameter (column of ``a``), with the
    degenerate points D held in ``a`` and ``unit``: per column the complementarity problem on D
    (dR_D ≥ 0, opened gaps z ≥ 0, dR_D·z = 0), solved exactly by enumeration of the opened set.
    Returns the slopes d/dp on that side (for sign −1: the slope of the piece below) and, per
    column, whether they are unique (see :func:`one_direction`).

    Opening a held point d by z is the same as lowering its gap g0_d by z, so
    dR = a − Y z with Y the unit-gap responses (``unit``).
    """
    out = [one_direction(Piece(a.du[:, j], a.dR[:, j], a.dgap[:, j]), unit, D, sign)
           for j in range(a.dR.shape[1])]
    if not out:
        return a, np.ones(0, dtype=bool)
    cols = [o[0] for o in out]
    return (Piece(np.column_stack([c.du for c in cols]), np.column_stack([c.dR for c in cols]),
                  np.column_stack([c.dgap for c in cols])), np.array([o[2] for o in out]))


def one_direction(a: Piece, unit: Piece, D: np.ndarray, sign: float) -> tuple[Piece, np.ndarray, bool]:
    """:func:`directional` for one parameter (1-D ``a``). Returns (slopes, mask over D of the
    points that open, unique): ``unique`` is False where two opened sets both solve the
    problem with different deflections (the plate may rock: a rigid motion is free on that
    side; the reactions' slopes are the same in both, the one of least motion ‖du‖ is returned)."""
    aR = sign * a.dR[D]
    Hm = unit.dR[D]  # (|D|, |D|): dR_D per unit gap at D (negative semi-definite)
    nD = D.size
    found: list[tuple[Piece, np.ndarray]] = []
    for size in range(nD + 1):
        for T in itertools.combinations(range(nD), size):
            T = list(T)
            z = np.zeros(nD)
            if T:
                M = Hm[np.ix_(T, T)]
                if np.linalg.cond(M) > 1e12:
                    continue
                z[T] = np.linalg.solve(M, aR[T])
            dRD = aR - Hm @ z
            ez = 1e-9 * max(np.abs(z).max(initial=0.0), 1e-300)
            eR = 1e-9 * max(np.abs(aR).max(initial=0.0), (np.abs(Hm) @ np.abs(z)).max(initial=0.0), 1e-300)
            if np.all(z >= -ez) and np.all(np.delete(dRD, T) >= -eR):
                opened = np.zeros(nD, dtype=bool)
                opened[T] = True
                z = np.maximum(z, 0.0)
                du = sign * a.du - unit.du @ z
                dR = sign * a.dR - unit.dR @ z
                dgap = sign * a.dgap - unit.dgap @ z
                dR[D[opened]] = 0.0
                dgap[D] = np.where(opened, z, 0.0)
                found.append((Piece(sign * du, sign * dR, sign * dgap), opened))
    if not found:
        raise MechanismError(f"no one-sided derivative exists at the contact points at lift-off {(D + 1).tolist()}: "
                             "releasing them leaves a rigid motion free, the answer is not unique")
    first = found[0][0]
    scale = max(np.abs(first.dgap).max(initial=0.0), 1.0)
    unique = all(np.abs(p.dgap - first.dgap).max(initial=0.0) <= 1e-8 * scale for p, _ in found[1:])
    # where the plate may rock, the least motion (smallest ‖du‖): a settling support lifts off
    # and the plate stays, rather than the plate rolling over onto it
    best = min(found, key=lambda pf: float(np.linalg.norm(pf[0].du)))
    return best[0], best[1], unique


def classify(data: Scaled, R: np.ndarray, gap: np.ndarray, tol: float):
    """(held, degenerate) bool masks from scaled reactions and gaps: held if R > tol·max R or
    the gap is closed; degenerate if both R and the gap are zero within ``tol``."""
    rs = max(np.abs(R).max(initial=0.0), 1e-300)
    zero_R = R <= tol * rs
    zero_g = np.abs(gap) <= tol  # gaps are in units of the deflection scale W
    degenerate = zero_R & zero_g
    held = ~zero_R | degenerate
    return held, degenerate


# -- the public object ---------------------------------------------------------------------
@dataclass
class Derivatives:
    """One-sided (or two-sided) derivatives with respect to each parameter (columns), in the
    user's units: ``reactions``, ``deflections`` (w at each contact point) and ``gaps`` are
    (m, p); ``u`` is (n_dofs, p), the full dof vector's derivative (prescribed dofs 0).
    ``unique`` (p,): False where, on this side, the plate may rock (a rigid motion is free
    between touching supports): the reactions' slopes are still unique, the deflections',
    gaps' and u's are NaN there."""

    reactions: np.ndarray
    deflections: np.ndarray
    gaps: np.ndarray
    u: np.ndarray
    unique: np.ndarray
    model: Any = field(repr=False, default=None)

    def deflection(self, x, y) -> np.ndarray:
        """dw/dp at points (npts, p); w positive downward."""
        x, y = np.atleast_1d(np.asarray(x, dtype=float)), np.atleast_1d(np.asarray(y, dtype=float))
        return np.asarray(self.model.interpolation(x, y) @ self.u)

    def as_dict(self) -> dict:
        """Nested lists (None for NaN, so that the JSON is strict)."""
        def lst(a):
            return [[None if np.isnan(v) else float(v) for v in row] for row in a]

        return {"reactions": lst(self.reactions), "deflections": lst(self.deflections), "gaps": lst(self.gaps),
                "unique": [bool(v) for v in self.unique]}


@dataclass
class Sensitivity:
    """Derivatives of a solved contact problem with respect to the parameters ``labels``.

    Behaves as the (m, p) array dR_i/dp_j of the reactions (``np.asarray(s)``, ``s[i, j]``,
    ``s.shape``) where that derivative is two-sided.

    Attributes
    ----------
    wrt : "gaps", "stiffness" or "loads"
    labels : one name per parameter (column): ``supports.3.gap`` (numbered from 1, as in paths), ``bed.17.gap`` (a foundation
        node), ``supports.2.stiffness``, ``foundation.k``, ``loads.0``
    increasing, decreasing : :class:`Derivatives` as the parameter increases (right derivative)
        and as it decreases (the slope of the piece below, left derivative); the same object
        where no contact point is degenerate
    degenerate : indices of the contact points at lift-off (gap and reaction both zero)
    contact : bool (m,), the contact points held at the solution (gap closed)
    kinked : bool (p,), the parameters whose left and right derivatives differ
    """

    wrt: str
    labels: list[str]
    increasing: Derivatives
    decreasing: Derivatives
    degenerate: np.ndarray
    contact: np.ndarray
    kinked: np.ndarray

    @property
    def smooth(self) -> bool:
        """True if every derivative is two-sided (no parameter at a kink)."""
        return not bool(np.any(self.kinked))

    def _two_sided(self, name: str) -> np.ndarray:
        if not self.smooth:
            bad = [self.labels[j] for j in np.flatnonzero(self.kinked)]
            pts = ", ".join(str(int(i) + 1) for i in self.degenerate)  # numbered from 1
            raise ProblemError(f"not differentiable: contact point(s) {pts} are at lift-off, so the derivative "
                               f"with respect to {', '.join(bad[:4])}{' …' if len(bad) > 4 else ''} differs on "
                               f"either side; use .increasing.{name} or .decreasing.{name}")
        return getattr(self.increasing, name)

    @property
    def reactions(self) -> np.ndarray:
        """(m, p) dR_i/dp_j (two-sided; ProblemError at a kink)."""
        return self._two_sided("reactions")

    @property
    def deflections(self) -> np.ndarray:
        """(m, p) dw_i/dp_j at the contact points (two-sided)."""
        return self._two_sided("deflections")

    @property
    def gaps(self) -> np.ndarray:
        """(m, p) d(gap_i)/dp_j (two-sided)."""
        return self._two_sided("gaps")

    @property
    def u(self) -> np.ndarray:
        """(n_dofs, p) derivative of the full dof vector (two-sided)."""
        return self._two_sided("u")

    def deflection(self, x, y) -> np.ndarray:
        """dw/dp_j at points, (npts, p) (two-sided)."""
        self._two_sided("u")
        return self.increasing.deflection(x, y)

    # array behaviour: the reaction derivatives
    def __array__(self, dtype=None, copy=None):
        a = self.reactions
        return a.astype(dtype) if dtype is not None else a.copy()

    def __getitem__(self, key):
        return self.reactions[key]

    @property
    def shape(self) -> tuple[int, int]:
        return self.increasing.reactions.shape

    def to_dict(self) -> dict:
        """JSON shape: {wrt, parameters, degenerate, smooth, reactions, deflections, gaps} where
        smooth, else {..., increasing: {...}, decreasing: {...}} with the one-sided ones;
        ``degenerate`` numbers the contact points from 1, as the tables do."""
        d = {"wrt": self.wrt, "parameters": list(self.labels), "degenerate": [int(i) + 1 for i in self.degenerate],
             "smooth": self.smooth}
        if self.smooth:
            d.update(self.increasing.as_dict())
        else:
            d["increasing"] = self.increasing.as_dict()
            d["decreasing"] = self.decreasing.as_dict()
        return d


def contact_names(model) -> list[str]:
    c = model.contacts
    return [f"supports.{int(i) + 1}" if s == "support" else f"bed.{int(i)}" for s, i in zip(c.source, c.index)]


def parameters(model, data: Scaled, R: np.ndarray, wrt: str):
    """(labels, df (n, p), dg (m, p), drho (m, p)): the derivative of the scaled data with
    respect to each parameter, per unit of the parameter in the user's units."""
    c = model.contacts
    scene = model.scene
    n, m = data.n, data.m
    names = contact_names(model)
    if wrt == "gaps":
        return [f"{nm}.gap" for nm in names], np.zeros((n, m)), np.eye(m) / data.W, np.zeros((m, m))
    if wrt == "stiffness":
        L2 = data.L**2
        D = scene.plate.D
        cols, labels = [], []
        for k in range(m):
            if c.source[k] == "support" and not scene.supports[int(c.index[k])].rigid:
                col = np.zeros(m)
                cval = float(scene.supports[int(c.index[k])].stiffness)
                col[k] = -(D / L2) / cval**2  # ρ̃ = (D/L²)/c
                cols.append(col)
                labels.append(f"supports.{int(c.index[k]) + 1}.stiffness")
        bed = c.source == "bed"
        if np.any(bed) and not model.n_soil:  # a coupled soil's k is in K, not on its rows: not offered
            col = np.where(bed, -data.rho / scene.foundation.k, 0.0)  # ρ ∝ 1/k
            cols.append(col)
            labels.append("foundation.k")
        drho = np.column_stack(cols) if cols else np.zeros((m, 0))
        return labels, np.zeros((n, len(cols))), np.zeros((m, len(cols))), drho
    if wrt == "loads":
        cols = []
        for ld in scene.loads:
            one = copy.copy(scene)  # the scene with this load alone (a shallow copy: nothing else changes)
            one.loads = [ld]
            f_full = model.load_vector(one)  # the load vector of one load alone (no stiffness assembly)
            cols.append(data.dof_scale * model.on_unknowns(f_full) / (data.F0 * data.W))
        df = np.column_stack(cols) if cols else np.zeros((n, 0))
        p = df.shape[1]
        return [f"loads.{j}" for j in range(p)], df, np.zeros((m, p)), np.zeros((m, p))
    raise ProblemError(f"sensitivity: unknown wrt {wrt!r}; choose one of {', '.join(WRT)}")


def scaled_state(result) -> tuple[Scaled, np.ndarray, np.ndarray, np.ndarray]:
    """(data, ũ, R̃, g̃ap) of a solved contact result; ProblemError if it has none."""
    model = getattr(result, "model", None)
    if model is None or getattr(model, "contacts", None) is None:
        raise ProblemError("sensitivity: the result has no contact solution (the scene has no one-sided supports)")
    if result.formulation == "bilateral":
        raise ProblemError("sensitivity: the two-sided comparison (solve_bilateral) has no contact set; "
                           "use the result of plateqp.solve")
    if not result.status.solved or np.size(result.reactions) != model.contacts.m:
        raise ProblemError(f"sensitivity: the result has no contact solution (status {result.status.value})")
    if result.status is not Status.OPTIMAL:
        warnings.warn("sensitivity: the result missed its asked accuracy; its contact set may be wrong",
                      PlateQPWarning, stacklevel=3)
    data = Scaled.from_model(model)
    u = model.unknowns(result.u, result.compressions) / data.dof_scale
    return data, u, np.asarray(result.reactions) / data.F0, np.asarray(result.gaps) / data.W


def sensitivity(result, wrt: str = "gaps", tol: float | None = None) -> Sensitivity:
    """Exact derivatives of a solved contact problem with respect to gaps, stiffnesses or loads.

    Parameters
    ----------
    result : a :class:`~plateqp.results.Result` of :func:`plateqp.solve` on a scene with
        one-sided supports
    wrt : "gaps" (every contact point's g0: an (m, m) matrix), "stiffness" (every elastic
        support's c, then ``foundation.k``) or "loads" (the factor of each entry of
        ``scene.loads``)
    tol : a support is at lift-off (degenerate) if its reaction is within ``tol`` × max R of 0
        and its gap within ``tol`` × the deflection scale of 0 (default: the result's KKT
        tolerance, at least 1e-10)

    Returns
    -------
    Sensitivity: ``.reactions`` (m, p) dR_i/dp_j, ``.deflections``, ``.gaps``, ``.u``, and the
    one-sided ``.increasing`` / ``.decreasing`` at a support at lift-off.

    Examples
    --------
    >>> r = pq.solve(scene, backend="lemke")
    >>> S = pq.sensitivity(r, "gaps")
    >>> S[0, 2]          # dR_0 / dg0_2
    """
    if wrt not in WRT:
        raise ProblemError(f"sensitivity: unknown wrt {wrt!r}; choose one of {', '.join(WRT)}")
    data, _, R, gap = scaled_state(result)
    if tol is None:
        tol = max(result.kkt.tol if result.kkt is not None else 1e-9, 1e-10)
    held, deg = classify(data, R, gap, float(tol))
    D = np.flatnonzero(deg)
    if D.size > MAX_DEGENERATE:
        raise ProblemError(f"sensitivity: {D.size} contact points are at lift-off (more than {MAX_DEGENERATE}); "
                           "the one-sided derivatives would need 2^n trials")
    model = result.model
    labels, df, dg, drho = parameters(model, data, R, wrt)
    a, unit = held_solve(data, held, R, df, dg, drho, extra=D)
    ones = np.ones(len(labels), dtype=bool)
    up, u_up = directional(a, unit, D, 1.0) if D.size else (a, ones)
    down, u_down = directional(a, unit, D, -1.0) if D.size else (a, ones)
    inc, dec = _user(model, data, up, u_up), _user(model, data, down, u_down)
    if D.size:
        scale = np.maximum(np.abs(inc.reactions).max(axis=0, initial=0.0), 1e-300)
        gs = np.maximum(np.nan_to_num(np.abs(inc.gaps)).max(axis=0, initial=0.0), 1e-300)
        kinked = (np.any(np.abs(inc.reactions - dec.reactions) > 1e-8 * scale, axis=0)
                  | np.any(np.abs(np.nan_to_num(inc.gaps - dec.gaps)) > 1e-8 * gs, axis=0) | ~u_up | ~u_down)
    else:
        kinked = np.zeros(len(labels), dtype=bool)
        dec = inc
    return Sensitivity(wrt, labels, inc, dec, D, held, kinked)


def _user(model, data: Scaled, d: Piece, unique: np.ndarray) -> Derivatives:
    """Scaled derivatives per user-unit parameter → user units (NaN deflections, gaps and u in
    the columns that are not ``unique``)."""
    du = data.dof_scale[:, None] * d.du
    u = np.zeros((model.n_full, du.shape[1]))
    u[model.free] = du[:model.n_free]
    w = data.W * np.asarray(data.B @ d.du)
    if model.n_soil:  # B u = w − v on the bed's rows: the plate's deflection is w
        w[model.contacts.source == "bed"] += data.W * d.du[model.n_free:]
    gaps = data.W * d.dgap
    for arr in (u, w, gaps):
        arr[:, ~unique] = np.nan
    return Derivatives(reactions=data.F0 * d.dR, deflections=w, gaps=gaps, u=u, unique=unique, model=model)


__all__ = ["Derivatives", "Sensitivity", "WRT", "sensitivity"]
