"""Statics, independent of any solver: can the one-sided supports carry the load at all?"""

from __future__ import annotations

import numpy as np

from .scaling import Scaled

NO_EQUILIBRIUM = ("the one-sided supports cannot carry this load: net uplift, or the load "
                  "resultant lies outside the supports' reach, so the plate would lift off")


def equilibrium_possible(data: Scaled) -> tuple[bool, str]:
    """Can the one-sided supports carry the load at all? (statics, independent of any solver)

    A plate held by its two-sided supports (K nonsingular) always has an equilibrium. A
    floating plate, with rigid motions V left free, has one iff some reactions R ≥ 0 balance
    the load in every rigid motion: Vᵀ Bᵀ R = Vᵀ f (force and moment balance). By Farkas'
    lemma this is exactly the condition for the primal QP to be bounded below. Checked as a
    small LP with SciPy's HiGHS.
    """
    V = data.modes
    if V.shape[1] == 0:
        return True, ""
    from scipy.optimize import linprog

    A = (data.B @ V).T  # (k, m)
    b = V.T @ data.f
    scale = max(np.abs(A).max(initial=0.0), 1e-300)
    res = linprog(np.zeros(A.shape[1]), A_eq=A / scale, b_eq=b / scale, bounds=(0, None), method="highs")
    if res.status == 0:
        return True, ""
    total = float(data.f[data.is_w].sum())  # net downward load (the two-sided supports hold none of it)
    why = ("net uplift: the load pulls the plate off its supports" if total <= 0 else
           "the load resultant lies outside the reach of the supports, so the plate would tip off them")
    return False, why
