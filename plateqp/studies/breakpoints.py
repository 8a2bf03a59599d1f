"""Breakpoints of a sweep: where, between two values, the contact set (working scheme) changes.

Between two successive values whose contact sets differ, the change is located by bisection
on the parameter (geometric for positive parameters spanning a decade or more, e.g. a
stiffness; on integers for an integer field) until the bracket is within ``rtol`` relative.
Several changes in one bracket are each found. Towards a rigid end (c = ∞) the bracket is
first walked from the finite end by decades. Each solve warm-starts from a solve of the
bracket's end it continues (:func:`plateqp.studies.worker.next_start`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

from ..errors import ProblemError
from ..model.paths import as_number
from .worker import Context, next_start, solve_value


@dataclass
class Bisection:
    """How a bracket is halved: geometric or linear (or on integers), down to ``rtol``."""

    geometric: bool
    rtol: float
    floor: float  # absolute floor for linear bisection (a change at 0 still terminates)
    integer: bool
    max_steps: int = 200

    def __post_init__(self) -> None:
        # the user's tolerance: a bracket of width 0 never closes, and a NaN never compares
        ok = isinstance(self.rtol, (int, float)) and not isinstance(self.rtol, bool)
        if not ok or not (math.isfinite(self.rtol) and 0.0 < self.rtol < 1.0):
            raise ProblemError(f"rtol: the relative width of a breakpoint's bracket must be a number in (0, 1) "
                               f"(got {self.rtol!r})")
        if self.rtol < 1e-14:
            raise ProblemError(f"rtol: {self.rtol:g} is below what a bracket of floating-point numbers can "
                               "reach (use 1e-14 or more; for a parameter that enters linearly, "
                               "sweep --exact finds breakpoints to rounding)")


def _close(b: Bisection, x1: float, x2: float) -> bool:
    lo, hi = min(x1, x2), max(x1, x2)
    if b.integer:
        return hi - lo <= 1
    if b.geometric:
        return hi <= lo * (1.0 + b.rtol)
    return hi - lo <= b.rtol * max(abs(lo), abs(hi), b.floor)


def _mid(b: Bisection, x1: float, x2: float) -> float:
    if b.integer:
        return float(int((x1 + x2) // 2))
    return math.sqrt(x1 * x2) if b.geometric else 0.5 * (x1 + x2)


def contact_set(active) -> list[int]:
    """Indices of the contact points in contact."""
    return [i for i, a in enumerate(active) if a]


def refine_bracket(ctx: Context, bis: Bisection, v1, a1, v2, a2):
    """Breakpoints between sweep values v1 and v2 (contact sets a1 ≠ a2), in sweep order, and
    (solves, backend iterations) they took."""
    # "warm": contact set -> warm-start state of a solve that ended in it; "steps": backend iterations
    state = {"warm": {}, "solves": 0, "steps": 0}

    def at(x, warm_from):
        val = int(x) if bis.integer else x
        row, act, new = solve_value(ctx, val, next_start(ctx, state["warm"].get(warm_from)))
        state["solves"] += 1
        state["steps"] += row["iterations"] or 0
        if new is not None:
            state["warm"][act] = new
        return act, row

    def bp(x1, s1, x2, s2, note=None):
        at_v = None
        if math.isfinite(x1) and math.isfinite(x2) and not bis.integer:
            at_v = _mid(bis, x1, x2) if _close(bis, x1, x2) else None
        d = {"between": [v1, v2], "at": at_v,
             "bracket": [_out(x1), _out(x2)],
             "before": contact_set(s1), "after": contact_set(s2)}
        if note:
            d["note"] = note
        return d

    def rec(x1, s1, x2, s2, depth=0):
        if _close(bis, x1, x2) or depth > bis.max_steps:
            return [bp(x1, s1, x2, s2, None if depth <= bis.max_steps else "bisection stopped")]
        xm = _mid(bis, x1, x2)
        sm, row = at(xm, s1)
        if sm is None:
            return [bp(x1, s1, x2, s2, f"bisection stopped at {xm:g}: {row['error']}")]
        if sm == s1:
            return rec(xm, sm, x2, s2, depth + 1)
        if sm == s2:
            return rec(x1, s1, xm, sm, depth + 1)
        return rec(x1, s1, xm, sm, depth + 1) + rec(xm, sm, x2, s2, depth + 1)

    x1, x2 = as_number(v1), as_number(v2)
    if math.isinf(x1) or math.isinf(x2):
        # one end rigid: walk from the finite end towards it by decades, then bisect
        flip = math.isinf(x1)
        xf, sf, si = (x2, a2, a1) if flip else (x1, a1, a2)
        chain = [(xf, sf)]
        x = xf
        found = False
        for _ in range(12):
            x = x * 10.0 if x > 0 else 1.0
            s, _ = at(x, chain[-1][1])
            if s is None:
                break
            chain.append((x, s))
            if s == si:
                found = True
                break
        out = []
        for (xa, sa), (xb, sb) in itertools.pairwise(chain):
            if sa != sb:
                out += rec(xa, sa, xb, sb)
        if not found:
            out.append(bp(chain[-1][0], chain[-1][1], math.inf, si,
                          note=f"the contact set still differs from the rigid one at {chain[-1][0]:g}"))
            out[-1]["bracket"] = [_out(chain[-1][0]), "rigid"]
        if flip:  # sweep order: from rigid to the finite end
            out = [{**d, "before": d["after"], "after": d["before"], "bracket": d["bracket"][::-1]}
                   for d in reversed(out)]
        return out, (state["solves"], state["steps"])
    return rec(x1, a1, x2, a2), (state["solves"], state["steps"])


def _out(x):
    if isinstance(x, float) and math.isinf(x):
        return "rigid"
    return x


__all__ = ["Bisection", "contact_set", "refine_bracket"]
