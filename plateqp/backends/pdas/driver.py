"""The pdas function: options read, the method chosen (dense where it applies, else sparse),
the answer checked and returned as a RawSolution (see the package docstring: "Warm start and
output", "Accuracy")."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...errors import ProblemError, SolverError
from ...linalg.keep import kept, remember
from ...linalg.products import times
from ..base import QP, RawSolution, Status, preset
from .dense import DenseDual, NotApplicable, anchored_set, run_dense
from .factor import TrailingFactor
from .options import (
    ACCURACY,
    ANCHOR,
    MAX_DENSE_AUTO,
    MAX_DENSE_SOFT,
    OPTIONS,
    SETTINGS,
    TRAILING_MAX,
    TRAILING_SHARE,
)
from .reduced import ReducedQP, force_scale, natural_residuals
from .exact import run_sparse
from .motions import rows_hold
from .sparse import SpringFactor

__all__ = ["pdas"]


def _option(settings: dict, key: str, ok, what: str):
    val = settings[key]
    if not ok(val):
        raise ProblemError(f"option {key} must be {what}, got {val!r}")
    return val


def _is_int(v, lo):
    return not isinstance(v, bool) and isinstance(v, (int, np.integer)) and v >= lo


def auto_max_dense(n: int, soft: bool = False) -> int:
    """``max_dense="auto"`` for ``n`` coupled dofs (:data:`.options.MAX_DENSE_AUTO`), or where
    every row is ``soft`` (:data:`.options.MAX_DENSE_SOFT`)."""
    lo, hi, per_root = MAX_DENSE_AUTO
    if soft:
        return min(hi, int(MAX_DENSE_SOFT * np.sqrt(n)))
    return max(lo, min(hi, int(per_root * np.sqrt(n))))


#: the loads (and their first half-solves) a kept condensed factorisation keeps (:class:`_Kept`)
REFS = 3

#: the linear-algebra counts of :attr:`.dense.DenseDual.stats` that add up over the solves of a factor
_COUNTS = ("analyse_s", "factor_s", "extract_s", "factorisations", "solves", "solve_s")


@dataclass
class _Kept:
    """A condensed method's factorisation kept for the next solve of the same K and B
    (:mod:`plateqp.linalg.keep`): its DenseDual, the K diagonal and B it was built from, and
    the flexibilities ρ its M holds on the diagonal now."""

    cond: DenseDual
    Kd: np.ndarray
    B: object
    rho: np.ndarray
    #: loads solved before and their first half-solves (``DenseDual.yf``), each load past the
    #: first the part of one orthogonal to the loads before it (at most REFS): a load that is a
    #: combination of them to rounding takes that combination of their first halves
    refs: list = field(default_factory=list)

    def _new_direction(self, f: np.ndarray) -> np.ndarray:
        """``yf`` of a load outside the span of :attr:`refs`: the first half of its part ``d``
        orthogonal to them (half a solve), plus the combination of theirs for the rest; ``d``
        joins them (no cancellation between the parts: each no larger than the load)."""
        cond = self.cond
        refs = [r for r in self.refs if r[0].shape == f.shape]
        alpha = np.linalg.lstsq(np.column_stack([r for r, _ in refs]), f, rcond=None)[0] if refs else []
        d = f - sum((a * r for a, (r, _) in zip(alpha, refs)), np.zeros_like(f))
        yd = cond._forward(d)
        if np.linalg.norm(d) > 1e-8 * np.linalg.norm(f):
            self.refs = (refs + [(d, yd)])[-REFS:]
        return yd + sum((a * y for a, (_, y) in zip(alpha, refs)), np.zeros_like(yd))

    def fits(self, pb: ReducedQP, max_dense: int) -> bool:
        """The same K (its diagonal, to rounding: the scaling of K differs by an ulp between
        the solves of a sweep) and the same rows B; their dofs within ``max_dense``."""
        B, c = pb.B, self.cond.fac.last
        return (pb.K.shape == self.cond.pb.K.shape and pb.m == self.rho.size and c.size <= max_dense
                and np.allclose(pb.Kd, self.Kd, rtol=1e-12, atol=0.0)
                and B.shape == self.B.shape and np.array_equal(B.indptr, self.B.indptr)
                and np.array_equal(B.indices, self.B.indices) and np.allclose(B.data, self.B.data, rtol=1e-12, atol=0.0))

    def again(self, pb: ReducedQP) -> DenseDual:
        """The kept DenseDual for this solve's flexibilities, gaps and loads: its M's diagonal
        moved to the new ρ, ``d = g − B K⁻¹ f`` from the kept factor (half a solve, none where the
        load is the last solve's: its first half ``yf`` is kept, nor where it is a combination of
        loads solved before to rounding, one load's magnitude swept beside others: ``yf`` is
        that combination of their first halves, :func:`combination`; a load outside their span
        costs half a solve, :meth:`_new_direction`)."""
        cond = self.cond
        diag = np.diag_indices(pb.m)
        cond.M[diag] += pb.rho - self.rho
        self.rho = pb.rho.copy()
        same_load = cond.yf is not None and np.array_equal(pb.f, cond.pb.f)  # a gap or spring sweep
        if not self.refs and cond.yf is not None:
            self.refs.append((cond.pb.f, cond.yf))
        cond.pb, cond._chol, cond.first, cond._dense_s = pb, None, {}, 0.0
        cond.Bc = pb.B[:, cond.fac.last].tocsr()
        if not same_load:
            alpha = combination(pb.f, [f for f, _ in self.refs])
            if alpha is None:
                cond.yf = self._new_direction(pb.f)
            else:
                cond.yf = sum(a * y for a, (_, y) in zip(alpha, self.refs))
        cond.d = pb.g - cond.Bc @ cond._tail(cond.yf)
        return cond


def combination(f: np.ndarray, refs: list, grow: float = 16.0) -> list | None:
    """Coefficients α with ``f = Σ α_j refs_j`` entry by entry to rounding (within 32 ε of
    ``Σ |α_j| |refs_j|``, itself at most ``grow`` times ``|f|`` at its largest: no cancellation
    that would cost the combined half-solve its digits), or None."""
    if not refs or any(r.shape != f.shape for r in refs) or not np.any(f):
        return None
    R = np.column_stack(refs)
    alpha = np.linalg.lstsq(R, f, rcond=None)[0]
    size = np.abs(R) @ np.abs(alpha)
    if not np.all(np.isfinite(alpha)) or size.max() > grow * np.abs(f).max():
        return None
    ok = np.abs(f - R @ alpha) <= 32.0 * np.finfo(float).eps * size
    return [float(a) for a in alpha] if bool(np.all(ok)) else None


def _dense_dual(pb: ReducedQP, max_dense: int) -> tuple[DenseDual, _Kept | None, dict | None]:
    """``DenseDual(pb, max_dense)``, or the one a solve before built on the same K and B where
    the caller lent a list of kept factorisations (:func:`plateqp.linalg.keep.kept`: a sweep
    over gaps, flexibilities or loads). Returns (it, its entry to keep again after the solve or
    None, its factor's counts before this solve where it was kept)."""
    store = kept()
    if store is None:
        return DenseDual(pb, max_dense), None, None
    for entry in list(store):
        if isinstance(entry, _Kept) and entry.fits(pb, max_dense):
            store.remove(entry)  # in use: not lent to another solve at the same time
            before = {k: entry.cond.fac.stats[k] for k in _COUNTS}
            return entry.again(pb), entry, before
    cond = DenseDual(pb, max_dense)
    return cond, _Kept(cond, pb.Kd.copy(), pb.B.copy(), pb.rho.copy()), None


@dataclass
class _KeptSprings:
    """The sparse method's factor kept for the next solve of the same K and B: its
    :class:`.factor.SpringFactor` (of ``K + σ diag(K) + Bᵀ diag(w) B`` at the last solve's
    ``w``: the next solve's first set, warm-started from it, needs no new factorisation, and a
    few rows changed are a low-rank correction) and what it was built from."""

    fac: SpringFactor
    Kd: np.ndarray
    B: object
    c: np.ndarray  # the rows' stiffnesses in series with their springs: each solve's own
    sigma: float
    method: str
    #: the unshifted factor's (σ = 0) last final set, its springs and the margin at which the
    #: rows were judged to hold the plate (:func:`_unshifted`): the next solve starting from
    #: that set with those springs needs no new judgement
    held: tuple | None = None

    def fits(self, pb: ReducedQP, sigma: float, method: str) -> bool:
        B = pb.B
        return (sigma == self.sigma and method == self.method and pb.Kd.shape == self.Kd.shape
                and np.allclose(pb.Kd, self.Kd, rtol=1e-12, atol=0.0) and pb.c.shape == self.c.shape
                and B.shape == self.B.shape and np.array_equal(B.indptr, self.B.indptr)
                and np.array_equal(B.indices, self.B.indices) and np.allclose(B.data, self.B.data, rtol=1e-12, atol=0.0))


def _spring_factor(pb: ReducedQP, sigma: float, method: str) -> tuple[SpringFactor, _KeptSprings | None]:
    """``SpringFactor(pb.K, pb.B, pb.Kd, pb.c, σ, method)``, or the one a solve before kept for
    the same K and B (:func:`plateqp.linalg.keep.kept`), its counts started afresh; with the
    entry to keep again after the solve (None where nothing is kept)."""
    store = kept()
    if store is not None:
        for entry in list(store):
            if isinstance(entry, _KeptSprings) and entry.fits(pb, sigma, method):
                store.remove(entry)  # in use: not lent to another solve at the same time
                entry.fac.again(pb.c)
                return entry.fac, entry
    fac = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, method)
    if store is None:
        return fac, None
    return fac, _KeptSprings(fac, pb.Kd.copy(), pb.B.copy(), np.array(pb.c, copy=True), sigma, method)


def _unshifted(pb: ReducedQP, A: np.ndarray, sigma: float, method: str, feas_tol: float, max_iter: int, p: int,
               steps, singular: bool):
    """The sparse method on ``K + B_Aᵀ ρ_A⁻¹ B_A`` itself, with no proximal shift (σ = 0) and each
    row's own spring (W = 1/ρ, no penalty in series), where that matrix is definite: every row
    soft (ρ k ≥ 1), and the plate held by its two-sided supports or by the rows of the start
    (``A``, a warm start, or every row on a cold one; :func:`.motions.rows_hold`, at the
    shift's margin), and by those of the final set (then OPTIMAL is kept). The step of a set
    is then one solve, exact to rounding: a warm start whose set is the answer's (the next
    value of a sweep, or a set predicted right) costs one solve, where the shifted matrix
    needed a second (the shift's σ D u and the penalty's share of each row left a residual
    above rounding). ``(outcome, counts)``, or None where it does not apply or does not end
    on a held set, OPTIMAL (the shifted method then runs from the same start)."""
    if not np.all(pb.rho * pb.k >= 1.0):
        return None
    # a cold start: every row active, as the Newton phase starts (each spring bonded holds a plate)
    A = np.ones(pb.m, dtype=bool) if A is None else A
    if not A.any():
        return None
    W = 1.0 / pb.rho
    if singular and not (_held_before(A, W, sigma) or rows_hold(pb, W, A, sigma)):
        return None
    mark = len(steps) if steps is not None else 0
    fac, spring = _spring_factor(pb, 0.0, method)
    info: dict = {}
    try:
        out = run_sparse(pb, fac, W, 0.0, A, feas_tol, max_iter, p, steps, None, info, False, False, False, False)
    except SolverError:  # not definite after all (a set that lets the plate move)
        out = None
    held = out is not None and (not singular or np.array_equal(out.A, A) or rows_hold(pb, W, out.A, sigma))
    if out is None or out.status is not Status.OPTIMAL or not held:
        if steps is not None:
            del steps[mark:]
        return None
    if singular:
        info["hold_check"] = "rigid motions"  # the final set's hold, judged by rows_hold above
    if spring is not None:
        spring.held = (out.A.copy(), W.copy(), sigma) if singular else None
        remember(kept(), spring)
    return out, dict(fac.stats, factor=fac.method, **info)


def _held_before(A: np.ndarray, W: np.ndarray, sigma: float) -> bool:
    """The kept unshifted factor (of this model's K and B: the list is the model's) ended its
    last solve on the set ``A`` with the springs ``W``, judged then to hold the plate at the
    margin of ``sigma`` (a sweep's next value, from that set)."""
    for entry in kept() or ():
        if isinstance(entry, _KeptSprings) and entry.sigma == 0.0 and entry.held is not None:
            a, w, s = entry.held
            if s == sigma and np.array_equal(a, A) and np.array_equal(w, W):
                return True
    return False


def _reduced(qp: QP, max_rows) -> ReducedQP:
    """``ReducedQP(qp, max_rows)``, or where the caller lent a list of kept factorisations
    (:func:`plateqp.linalg.keep.kept`: a sweep) and a solve before read the same Hessian, that
    problem with this QP's loads, gaps and springs (:meth:`.reduced.ReducedQP.again`)."""
    store = kept()
    if store is not None:
        for entry in list(store):
            if isinstance(entry, ReducedQP):
                pb = entry.again(qp, max_rows)
                if pb is not None:
                    store[:] = [e for e in store if e is not entry]
                    remember(store, pb)
                    return pb
    pb = ReducedQP(qp, max_rows)
    if store is not None:
        remember(store, pb)
    return pb


def _anchored(pb: ReducedQP, max_dense: int, feas_tol: float, max_iter: int, p: int, steps, sigma: float):
    """``((A, sets, seconds, how its first set was found), its SchurFactor)``: the anchored
    plate's contact set (:func:`.dense.anchored_set`), a first set for a floating plate, and
    the factorisation it was found on; None where the anchored plate is singular too (the rows,
    held, do not hold it) or the condensed method does not apply to it."""
    t0 = time.perf_counter()
    try:
        cond = DenseDual(pb, max_dense, anchor=ANCHOR, prox=sigma)  # σ: its factor serves the exact steps
    except NotApplicable:
        return None
    A, sets = anchored_set(pb, cond, feas_tol, max_iter, p, steps)
    return (A, sets, time.perf_counter() - t0, cond.first.get("first_set")), cond.fac


def _trailing_pays(schur) -> bool:
    """The exact steps on the anchored factorisation, its trailing block replaced
    (:class:`.factor.TrailingFactor`), cost less than on a sparse factorisation of their own
    (:data:`.options.TRAILING_SHARE`)."""
    if schur.chol is None or schur.chol.spent:
        return False
    flops = schur.chol.flops()
    dense = schur.nl**3 / 3
    return dense <= TRAILING_SHARE * flops if flops else schur.nl <= TRAILING_MAX


def pdas(qp: QP, active=None, trace=False, *, accuracy="default", **options) -> RawSolution:
    """Solve the primal contact QP by the primal–dual active set method.

    Parameters
    ----------
    qp : QP
        ``min ½ xᵀPx + qᵀx  s.t.  G x ≤ h`` with sparse ``P``, ``G`` (few rows), nothing else.
    active : array_like of bool, optional
        First active set, one entry per row of ``G`` (defaults: see the module docstring).
    trace : bool
        Record each step in ``extras["trace"]``: ``{"step", "active", "infeasible", "solve", "exchange"}``.
    accuracy : {"low", "default", "high"} or float (a KKT tolerance; see base.preset)
        Preset of :data:`ACCURACY`; ``feas_tol`` and ``accept_tol`` override it.
    **options
        ``feas_tol``, ``accept_tol`` and the keys of :data:`SETTINGS`.

    Returns
    -------
    RawSolution
        ``x``, ``z`` (reactions ``λ ≥ 0``), ``status`` (``OPTIMAL``; ``INACCURATE`` if the
        residuals exceed ``accept_tol``; ``UNBOUNDED`` with ``extras["ray"]`` when the QP is
        unbounded below; ``MAX_ITER`` with the last iterate), ``iterations``, ``solve_time``,
        ``extras["active"]``, ``extras["method"]`` and the counts of the linear algebra.

    Raises
    ------
    SolverError
        The QP is not of the primal formulation's shape; ``method="condensed"`` where it
        does not apply.
    ProblemError
        A bad option value.
    """
    t0 = time.perf_counter()
    tol = preset(ACCURACY, accuracy, scale=("feas_tol", "accept_tol"))
    settings = dict(SETTINGS)
    for key, val in options.items():
        if key in tol:
            tol[key] = val
        elif key in settings:
            settings[key] = val
        else:
            raise ProblemError(f"unknown option {key!r} for backend pdas; known: {list(OPTIONS)}")
    for key in ("feas_tol", "accept_tol"):
        if not (np.isscalar(tol[key]) and np.isfinite(tol[key]) and 0 <= tol[key] < 1):
            raise ProblemError(f"option {key} must be a number in [0, 1), got {tol[key]!r}")
    number = (lambda lo: lambda v: np.isscalar(v) and not isinstance(v, (bool, str)) and np.isfinite(v) and v > lo)
    method = _option(settings, "method", lambda v: v in ("auto", "condensed", "sparse"),
                     "'auto', 'condensed' or 'sparse'")
    kappa = _option(settings, "penalty", number(1.0), "a number > 1")
    sigma = _option(settings, "prox", number(0.0), "a number > 0")
    p = _option(settings, "p", lambda v: _is_int(v, 0), "an integer ≥ 0")
    max_dense = _option(settings, "max_dense", lambda v: (isinstance(v, str) and v == "auto") or _is_int(v, 0),
                        "'auto' or an integer ≥ 0")
    max_rows = _option(settings, "max_rows", lambda v: v is None or _is_int(v, 1), "None or a positive integer")
    for key in ("dual_start", "lh_start", "anchor_start"):
        _option(settings, key, lambda v: isinstance(v, (bool, np.bool_)), "True or False")
    if not isinstance(trace, (bool, np.bool_)):
        raise ProblemError(f"option trace must be True or False, got {trace!r}")

    pb = _reduced(qp, max_rows)
    m = pb.m
    if max_dense == "auto":
        max_dense = auto_max_dense(pb.K.shape[0], soft=bool(np.all(pb.rho * pb.k >= 1.0)))
    max_iter = settings["max_iter"] if settings["max_iter"] is not None else 50 + 2 * m
    if not _is_int(max_iter, 1):
        raise ProblemError(f"option max_iter must be a positive integer, got {max_iter!r}")
    A = None
    if active is not None:
        A = np.asarray(active)
        if A.shape != (m,) or A.dtype != bool:
            raise ProblemError(f"option active must be a bool array with one entry per row of G ({m})")
    steps: list[dict] | None = [] if trace else None

    out = anchored = schur = None
    singular = qp.singular is True  # K known singular: the caller's hint, or a failed factorisation
    extras: dict = {"max_dense": max_dense}
    if method in ("auto", "condensed"):
        try:
            if method == "auto" and qp.singular is True:  # a floating plate: its factorisation would fail
                raise NotApplicable("K is singular (the QP says so: a floating plate)", singular=True)
            cond, keep, before = _dense_dual(pb, max_dense)
        except NotApplicable as why:
            if method == "condensed":
                raise SolverError(f"pdas: the condensed method does not apply here: {why}") from None
            extras["condensed_skipped"] = str(why)
            singular = singular or why.singular
            if (why.singular and method == "auto" and A is None and settings["anchor_start"]
                    and np.median(pb.rho * pb.k) < 1.0):
                got = _anchored(pb, max_dense, tol["feas_tol"], max_iter, p, steps, sigma)
                if got is not None:
                    anchored, schur = got
                    A = anchored[0]
        else:
            out = run_dense(pb, cond, A, tol["feas_tol"], max_iter, p, steps)
            stats = cond.stats
            if before is not None:  # a kept factorisation: this solve's own counts
                stats.update({k: stats[k] - before[k] for k in _COUNTS}, kept=True)
            extras.update(method="condensed", **stats)
            if keep is not None:
                remember(kept(), keep)
    if out is None and anchored is None:
        got = _unshifted(pb, A, sigma, settings["factor"], tol["feas_tol"], max_iter, p, steps, singular)
        if got is not None:
            out, fac_stats = got
            extras.update(method="sparse", shift=0.0, **fac_stats)
    if out is None:
        W = 1.0 / (pb.rho + 1.0 / (kappa * pb.k_penalty))  # κ times the row's softest unknown at most
        spring = None
        if schur is not None and settings["factor"] == "auto" and _trailing_pays(schur):
            # the exact steps on the anchored factorisation, its trailing block replaced
            fac = TrailingFactor(schur, pb.B)
        else:
            schur = None  # released: the anchored factorisation is not kept beside a sparse one
            fac, spring = _spring_factor(pb, sigma, settings["factor"])
        kfac = None
        lh, dual = bool(settings["lh_start"]), bool(settings["dual_start"])
        if (lh or dual) and A is None and not np.all(pb.rho * pb.k >= 1.0):
            kfac = fac.twin()  # K alone: the same pattern, not built again
        info: dict = {}
        try:
            out = run_sparse(pb, fac, W, sigma, A, tol["feas_tol"], max_iter, p, steps, kfac, info, lh, dual,
                             singular, bool(settings["anchor_start"]))
        except SolverError as exn:
            if anchored is None:
                raise
            # the anchored plate's set leaves the plate free to move (no load presses it onto more
            # rows: one heaved post), and its factor with a rigid row's penalty (κ k) beside the
            # proximal shift (σ diag K) on those motions is not definite to working precision:
            # the exact steps start again from every row, without the anchored phases
            extras["anchored_dropped"] = str(exn)
            anchored = schur = None
            fac = SpringFactor(pb.K, pb.B, pb.Kd, pb.c, sigma, settings["factor"])
            kfac = fac.twin() if (lh or dual) and not np.all(pb.rho * pb.k >= 1.0) else None
            info = {}
            out = run_sparse(pb, fac, W, sigma, None, tol["feas_tol"], max_iter, p, steps, kfac, info, lh, dual,
                             singular, False)
        if spring is not None and anchored is None:
            remember(kept(), spring)
        stats = dict(fac.stats, **info)
        if kfac is not None:  # the factor of K alone (phase 1's line search) counts too
            for key, val in kfac.stats.items():
                stats[key] += val
        if anchored is not None:  # its set started the exact steps; its factorisation counts
            stats.update(first_phase="anchored", first_phase_steps=anchored[1], anchored_s=anchored[2],
                         anchored_first_set=anchored[3])
            stats["factorisations"] += 1
            out.it += anchored[1]
        extras.update(method="sparse", factor=fac.method, **stats)

    extras["active"] = out.A.copy()
    if steps is not None:
        extras["trace"] = steps
    if out.u is None:  # UNBOUNDED or ERROR: no answer
        if out.ray is not None:
            extras["ray"] = out.ray
        return RawSolution(status=out.status, iterations=out.it, solve_time=time.perf_counter() - t0,
                           solver_status=out.message, extras=extras)
    lam = out.lam.copy()
    lam[(lam < 0) & (lam >= -tol["feas_tol"] * force_scale(pb, lam, tol["feas_tol"]))] = 0.0
    nat, st = natural_residuals(pb, out.u, lam, tol["accept_tol"])
    extras.update(natural_residual=nat, stationarity=st)
    status = out.status
    if status is Status.OPTIMAL and max(nat, st) > tol["accept_tol"]:
        status = Status.INACCURATE
    x = pb.x(out.u, lam)
    # xᵀ P x = uᵀ K u + Σ p_j x_j² over the separable variables (each alone in its column of P)
    obj = float(0.5 * (out.u @ times(pb.K, out.u) + pb.sep_p @ x[pb.sep] ** 2) + pb.q @ x)
    return RawSolution(status=status, x=x, z=lam, obj=obj, iterations=out.it,
                       solve_time=time.perf_counter() - t0, solver_status=out.message, extras=extras)
