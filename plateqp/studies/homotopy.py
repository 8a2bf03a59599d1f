r"""Exact working-scheme paths: parametric pivoting along a parameter that enters linearly.

A support's gap, a load's magnitude, a prescribed edge or pin displacement enter the contact
problem linearly (the right-hand side f, g0 moves along a line; K, B and the flexibilities ρ
stay). The solution is then piecewise linear in the parameter t: on each piece the contact
set H is fixed and (u, R_H) solve the held system of :mod:`plateqp.sensitivity`

.. math::

    K u + B_H^T R_H = f(t), \qquad B_H u - \rho_H R_H = g_{0,H}(t).

:func:`exact_path` follows it (an active-set homotopy, the parametric LCP of Murty, *Linear
complementarity, linear and nonlinear programming*, ch. 5): at the start of a piece one
solve of the held system gives both the state and its slope (on one factorisation kept along
the whole path, :mod:`plateqp.studies.held`); it moves along the piece until a reaction
in contact falls to zero (lift-off) or an open gap closes (a support comes into contact), at
a parameter value found exactly (a ratio of two numbers, to rounding); there the contact
points at the event are degenerate, the one-sided slope onward is the solution of the small
complementarity problem on them (:func:`plateqp.sensitivity.directional`), and the next piece
starts. Every change of the contact set is reported with the sets on both sides, in the
shape of the bisection's breakpoints (:mod:`plateqp.studies.breakpoints`).

A parameter that does not enter linearly (a stiffness, the plate's thickness, the mesh) is
refused with a :class:`~plateqp.errors.ProblemError` that says so: bracket it by bisection
(:func:`plateqp.studies.sweep`). Linearity is checked on the scene itself, not on the path's
name: the model is built at the start, the middle and the end of the range, and K, B, ρ must
agree and f, g0 be affine to rounding.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from ..model.assembly import Model, build_model
from ..contact.routing import repeated_solves
from ..contact.scaling import Scaled
from ..errors import MechanismError, ProblemError, SolverError
from ..linalg import SingularMatrixError
from ..linalg.keep import sharing
from ..model.paths import as_number, get_param, set_param
from ..progress import Progress
from ..model.scene import Scene
from ..sensitivity import MAX_DEGENERATE, classify, held_solve, one_direction
from ..solving import solve
from .held import HeldFactor
from .reuse import adapt_model
from .sweep import SweepResult, numbered, sweep

logger = logging.getLogger(__name__)

#: Relative agreement asked of K, B, ρ and of the affine f, g0 for a parameter to count as linear.
LINEAR_RTOL = 1e-11


@dataclass
class ExactPath:
    """The piecewise-linear solution along a parameter, from :func:`exact_path`.

    Attributes
    ----------
    path : the scene field (e.g. ``supports.2.gap``, ``loads.0.q``)
    start, stop : the range followed, in that direction
    breakpoints : ``{at, before, after, comes_into_contact, lifts_off}`` where the contact set
        (indices of the contact points in contact, 0-based as in a sweep) changes, at ``at``
        exactly (to rounding); in path order
    pieces : ``{from, to, contact, unique}`` per piece: ``unique`` False where the plate may rock
        (a rigid motion free between touching supports: reactions unique, deflections not)
    method : "exact"
    """

    path: str
    start: float
    stop: float
    breakpoints: list[dict]
    pieces: list[dict]
    method: str = "exact"
    _data: Scaled | None = field(default=None, repr=False)
    _model: Model | None = field(default=None, repr=False)
    _affine: list[tuple] = field(default_factory=list, repr=False)  # (t0, t1, R, gap, u, dR, dgap, du) scaled
    _dshift: np.ndarray | None = field(default=None, repr=False)  # d(shift)/dt (prescribed displacements)

    def _piece(self, t: float):
        lo, hi = min(self.start, self.stop), max(self.start, self.stop)
        if not lo - 1e-12 * max(abs(lo), abs(hi), 1.0) <= t <= hi + 1e-12 * max(abs(lo), abs(hi), 1.0):
            raise ProblemError(f"{self.path} = {t}: outside the path's range [{lo}, {hi}]")
        for p in self._affine:
            if min(p[0], p[1]) <= t <= max(p[0], p[1]):
                return p
        return min(self._affine, key=lambda p: min(abs(t - p[0]), abs(t - p[1])))

    def reactions(self, t: float) -> np.ndarray:
        """The reactions at parameter value ``t`` (one per contact point)."""
        p = self._piece(t)
        return self._data.F0 * np.maximum(p[2] + (t - p[0]) * p[5], 0.0)

    def gaps(self, t: float) -> np.ndarray:
        """The gaps at ``t``."""
        p = self._piece(t)
        return self._data.W * np.maximum(p[3] + (t - p[0]) * p[6], 0.0)

    def deflections(self, t: float) -> np.ndarray:
        """w at the contact points at ``t`` (including the prescribed dofs' share)."""
        p = self._piece(t)
        u = p[4] + (t - p[0]) * p[7]
        shift = self._model.contacts.shift + (t - self.start) * (0.0 if self._dshift is None else self._dshift)
        return self._data.W * np.asarray(self._data.B @ u) + shift

    def contact(self, t: float) -> list[int]:
        """The contact set on the piece holding ``t``."""
        p = self._piece(t)
        for piece in self.pieces:
            if piece["from"] == p[0]:
                return piece["contact"]
        return []

    def to_dict(self) -> dict:
        return {"path": self.path, "start": self.start, "stop": self.stop, "method": self.method,
                "breakpoints": self.breakpoints, "pieces": self.pieces}

    def __str__(self) -> str:
        lines = [f"exact path of {self.path} from {self.start:g} to {self.stop:g}: {len(self.pieces)} piece(s)"]
        if self.breakpoints:
            lines.append("  (contact points numbered from 1: the supports in scene order, then bed nodes)")
        for b in self.breakpoints:
            on = [i + 1 for i in b["comes_into_contact"]]
            off = [i + 1 for i in b["lifts_off"]]
            lines.append(f"  at {b['at']:.12g}: comes into contact {on or '-'}, lifts off {off or '-'}")
        if not self.breakpoints:
            lines.append("  the contact set is the same along the whole path")
        return "\n".join(lines)


def linear_data(scene: Scene, path: str, start: float, stop: float):
    """(model at ``start``, df/dt on the free dofs, dg0/dt at the contact points, d(shift)/dt)
    if PATH enters the problem linearly between ``start`` and ``stop``; a ProblemError saying
    why not otherwise. ``shift`` is the deflection the prescribed dofs give each contact point
    (:class:`plateqp.model.assembly.ContactOperator`): it moves with a prescribed displacement."""
    get_param(scene, path)  # a bad path names what exists
    leaf = path.rsplit(".", 1)[-1]
    if leaf == "stiffness" or path.startswith("foundation.k"):
        raise ProblemError(f"--exact: {path} does not enter the problem linearly (a stiffness changes the "
                           "supports' flexibility 1/c); sweep it without --exact (bisection)")
    x0, x1 = as_number(start), as_number(stop)
    if not (math.isfinite(x0) and math.isfinite(x1)):
        raise ProblemError(f"--exact: {path} needs finite start and stop values (got {start}, {stop})")
    scenes = [set_param(scene, path, v) for v in (x0, 0.5 * (x0 + x1), x1)]
    m0 = build_model(scenes[0])
    models = [m0] + [adapt_model(m0, s) or build_model(s) for s in scenes[1:]]
    if m0.contacts is None:
        raise ProblemError("--exact: the scene has no one-sided supports (no working scheme to follow)")
    for mk, where in zip(models[1:], ("the middle", "the end")):
        why = _differs(m0, mk)
        if why:
            raise ProblemError(f"--exact: {path} does not enter the problem linearly ({why} changes between "
                               f"{start} and {where} of the range); sweep it without --exact (bisection)")
    if x1 == x0:
        return m0, np.zeros(m0.n_free), np.zeros(m0.contacts.m), np.zeros(m0.contacts.m)
    df = (models[2].f - m0.f) / (x1 - x0)
    dg = (models[2].contacts.g0 - m0.contacts.g0) / (x1 - x0)
    dshift = (models[2].contacts.shift - m0.contacts.shift) / (x1 - x0)
    fm = m0.f + 0.5 * (x1 - x0) * df
    gm = m0.contacts.g0 + 0.5 * (x1 - x0) * dg
    fs = max(np.abs(m0.f).max(initial=0.0), np.abs(models[2].f).max(initial=0.0), 1e-300)
    gs = max(np.abs(m0.contacts.g0).max(initial=0.0), np.abs(models[2].contacts.g0).max(initial=0.0), 1e-300)
    if (np.abs(models[1].f - fm).max(initial=0.0) > 1e3 * LINEAR_RTOL * fs
            or np.abs(models[1].contacts.g0 - gm).max(initial=0.0) > 1e3 * LINEAR_RTOL * gs):
        raise ProblemError(f"--exact: {path} does not enter the problem linearly (the load or the gaps are not "
                           "affine in it); sweep it without --exact (bisection)")
    return m0, df, dg, dshift


def _differs(a: Model, b: Model) -> str | None:
    """What differs between two models besides f and g0 (None if nothing)."""
    if a.K.shape != b.K.shape or not np.array_equal(a.free, b.free):
        return "the mesh or the two-sided supports"
    if a.K is not b.K and abs(a.K - b.K).max() > LINEAR_RTOL * abs(a.K).max():
        return "the stiffness matrix"
    ca, cb = a.contacts, b.contacts
    if cb is None or ca.B.shape != cb.B.shape or (ca.B is not cb.B and abs(ca.B - cb.B).max() > LINEAR_RTOL):
        return "the contact points"
    if not np.allclose(ca.rho, cb.rho, rtol=LINEAR_RTOL, atol=0.0):
        return "the supports' flexibility"
    return None


def exact_path(scene: Scene, path: str, start, stop, backend: str = "auto", formulation: str = "auto",
               tol: float = 1e-9, max_pieces: int | None = None) -> ExactPath:
    """Follow the solution exactly as PATH goes from ``start`` to ``stop``; every breakpoint.

    Parameters
    ----------
    scene, path : the scene and a field that enters linearly (a gap such as ``supports.3.gap``
        or ``supports.*.gap``, ``foundation.gap``, a load ``loads.0.q`` / ``loads.1.P``, a
        prescribed displacement ``pins.0.w``, ``edges.left.w``)
    start, stop : the range, followed from ``start`` towards ``stop``
    backend, formulation : the solve at ``start`` (at accuracy "high"; an exact backend,
        lemke, bpp or pdas, gives the start to rounding: "auto" picks one)
    tol : contact points whose reaction (relative to the largest) and gap (relative to the
        deflection scale) are both within ``tol`` of zero at the start are degenerate
    max_pieces : stop with a ProblemError after this many steps along the path (default 4 m + 50)

    Returns
    -------
    ExactPath, with its breakpoints and, at any t in the range, ``reactions(t)``,
    ``gaps(t)``, ``deflections(t)``.
    """
    x0, x1 = as_number(start), as_number(stop)
    model, df_user, dg_user, dshift = linear_data(scene, path, start, stop)
    res = solve(model.scene, backend=backend, formulation=formulation, accuracy="high", model=model)
    data = Scaled.from_model(model)
    df = data.dof_scale * df_user / (data.F0 * data.W)
    dg = dg_user / data.W
    m = data.m
    R = np.asarray(res.reactions) / data.F0
    gap = np.asarray(res.gaps) / data.W
    held, deg = classify(data, R, gap, tol)
    D = np.flatnonzero(deg)
    sign = 1.0 if x1 >= x0 else -1.0
    t = x0
    limit = max_pieces or 4 * m + 50
    pieces, breaks, affine = [], [], []
    prev_contact = None
    steps_taken = 0
    bar = Progress(100, f"exact path of {path}, % of the range")
    solver = _held_factor(data)  # one factorisation kept current along the pieces
    while True:
        steps_taken += 1
        if steps_taken > limit:  # counts every step (pieces that change nothing are merged)
            raise ProblemError(f"exact path of {path}: more than {limit} pieces before {stop} (stopped at {t:g})")
        if D.size > MAX_DEGENERATE:
            raise ProblemError(f"exact path of {path}: {D.size} contact points degenerate at {t:g} "
                               f"(more than {MAX_DEGENERATE})")
        f_t = data.f + (t - x0) * df
        g_t = data.g0 + (t - x0) * dg
        try:
            cols, unit = held_solve(data, held, np.zeros(m), np.column_stack([f_t, df]),
                                    np.column_stack([g_t, dg]), np.zeros((m, 2)), extra=D, solver=solver)
        except MechanismError as exn:
            if not pieces:
                raise ProblemError(f"exact path of {path}: at the start {t:g} the supports in contact leave a rigid "
                                   "motion free (the plate may rock, its deflection is not unique); start the path "
                                   f"where it is held ({exn})") from exn
            raise ProblemError(f"exact path of {path}: at {t:g} the supports in contact no longer hold the plate "
                               f"({exn})") from exn
        state_u, state_R, state_gap = cols.du[:, 0], cols.dR[:, 0], np.maximum(cols.dgap[:, 0], 0.0)
        slope = type(cols)(cols.du[:, 1], cols.dR[:, 1], cols.dgap[:, 1])
        unique = True
        if D.size:
            slope, opened, unique = one_direction(slope, unit, D, sign)
            held = held.copy()
            held[D[opened]] = False
            state_R = state_R.copy()
            state_R[D] = np.where(opened, 0.0, np.maximum(state_R[D], 0.0))
        contact = [int(i) for i in np.flatnonzero(held)]
        if prev_contact is not None and contact != prev_contact:
            on = sorted(set(contact) - set(prev_contact))
            off = sorted(set(prev_contact) - set(contact))
            breaks.append({"at": t, "before": prev_contact, "after": contact, "comes_into_contact": on,
                           "lifts_off": off})
            logger.debug("exact path of %s: at %.12g comes into contact %s, lifts off %s", path, t, on, off)
        # the next event: a held reaction falls to zero, or an open gap closes
        remaining = abs(x1 - t)
        # slopes that move a reaction (a gap) by less than 1e-8 of the largest (of the deflection
        # scale) over the whole range are rounding, not events
        span = max(abs(x1 - x0), 1e-300)
        rs = max(np.abs(slope.dR).max(initial=0.0), np.abs(state_R).max(initial=0.0) / span, 1e-300)
        gs = max(np.abs(slope.dgap).max(initial=0.0), max(np.abs(state_gap).max(initial=0.0), 1.0) / span)
        steps = np.full(m, np.inf)
        falling = held & (sign * slope.dR < -1e-8 * rs)
        steps[falling] = np.maximum(state_R[falling], 0.0) / (-sign * slope.dR[falling])
        closing = ~held & (sign * slope.dgap < -1e-8 * gs)
        steps[closing] = np.maximum(state_gap[closing], 0.0) / (-sign * slope.dgap[closing])
        step = min(float(steps.min(initial=np.inf)), remaining)
        t_next = x1 if step >= remaining else t + sign * step
        if pieces and pieces[-1]["contact"] == contact and pieces[-1]["unique"] == unique:
            pieces[-1]["to"] = t_next  # the same contact set goes on (an event that changed nothing)
        else:
            pieces.append({"from": t, "to": t_next, "contact": contact, "unique": bool(unique)})
        affine.append((t, t_next, state_R, state_gap, state_u, slope.dR, slope.dgap, slope.du))
        prev_contact = contact
        bar.moveto(int(100 * abs(t_next - x0) / max(abs(x1 - x0), 1e-300)))
        if step >= remaining:
            break
        events = np.flatnonzero(steps <= step * (1.0 + 1e-9) + 1e-300)
        held = held.copy()
        # degenerate at the event: the event's points, and any other touching one with no reaction
        R_next = np.maximum(state_R + sign * step * slope.dR, 0.0)
        g_next = np.maximum(state_gap + sign * step * slope.dgap, 0.0)
        R_next[events] = 0.0
        g_next[events] = 0.0
        _, deg = classify(data, R_next, g_next, tol)
        deg[events] = True
        held |= deg  # the event's points (closing gaps, vanishing reactions) and any touching point without
        # force are held here, then released by the one-sided step if they open
        D = np.flatnonzero(deg)
        t = t_next
    bar.close()
    logger.info("exact path of %s from %g to %g: %d piece(s), %d step(s)", path, x0, x1, len(pieces), steps_taken)
    return ExactPath(path, x0, x1, breaks, pieces, _data=data, _model=model, _affine=affine, _dshift=dshift)


def _held_factor(data: Scaled):
    """The held systems' solver of the path (:class:`plateqp.studies.held.HeldFactor`), or None
    where its factor cannot be built (each piece is then solved by sparse LU)."""
    try:
        return HeldFactor(data)
    except (SingularMatrixError, SolverError):
        return None


@dataclass
class ExactSweepResult(SweepResult):
    """A sweep whose breakpoints come from :func:`exact_path` (``method`` "exact"): each at its
    exact value, ``bracket`` [at, at]; ``exact`` holds the path itself (its pieces)."""

    exact: ExactPath | None = None
    method: str = "exact"

    def to_dict(self) -> dict:
        """{rows, breakpoints, method: "exact", pieces}; contact points numbered from 1, as in
        :meth:`SweepResult.to_dict`."""
        return {**super().to_dict(), "method": self.method,
                "pieces": [{**p, "contact": numbered(p["contact"])} for p in self.exact.pieces]
                if self.exact is not None else []}

    def __str__(self) -> str:
        text = super().__str__()
        if self.breakpoints:
            text += "\nbreakpoints found exactly (parametric pivoting): " + ", ".join(
                f"{b['at']:.12g}" for b in self.breakpoints)
        return text


def exact_sweep(scene: Scene, path: str, values, backend: str = "auto", formulation: str = "auto",
                **kw) -> ExactSweepResult:
    """:func:`plateqp.studies.sweep` of a parameter that enters linearly, with the breakpoints of
    :func:`exact_path` from the first value to the last instead of bisection.

    ``values`` must be monotone (the path is followed from the first to the last). Other keywords
    go to :func:`~plateqp.studies.sweep` (its bisection is not run). A parameter that does not
    enter linearly is refused (ProblemError) before any sweep.
    """
    values = [v.item() if isinstance(v, np.generic) else v for v in values]
    if not values:
        raise ProblemError("sweep: no values given")
    nums = [as_number(v) for v in values]
    diffs = np.diff(nums)
    if not (np.all(diffs >= 0) or np.all(diffs <= 0)):
        raise ProblemError("--exact: the values must be in increasing or decreasing order (the path is followed "
                           "from the first to the last)")
    # the path's start solve on the route the sweep's solves take (repeated_solves), keeping its
    # factorisation and scaled data in its model (sharing), which the sweep's values then adapt
    with repeated_solves(), sharing():
        ep = exact_path(scene, path, nums[0], nums[-1], backend=backend, formulation=formulation)
    kw["refine_breakpoints"] = False
    res = sweep(scene, path, values, backend=backend, formulation=formulation, model=ep._model, **kw)
    out = []
    for b in ep.breakpoints:
        i = next((k for k in range(len(nums) - 1) if min(nums[k], nums[k + 1]) <= b["at"] <= max(nums[k], nums[k + 1])),
                 max(len(nums) - 2, 0))
        out.append({"between": [values[i], values[min(i + 1, len(values) - 1)]], "at": b["at"],
                    "bracket": [b["at"], b["at"]], "before": b["before"], "after": b["after"]})
    return ExactSweepResult(res.path, res.values, res.rows, out, times=res.times, exact=ep)


__all__ = ["ExactPath", "ExactSweepResult", "exact_path", "exact_sweep", "linear_data"]
