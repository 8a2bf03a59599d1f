"""The contact problem of a built model, from scaling to a checked Result.

====================  ==========================================================================
:mod:`.scaling`       :class:`Scaled`: the nondimensional data every form starts from
:mod:`.statics`       can the supports carry the load at all (solver-independent)
:mod:`.formulations`  primal, condensed and dual problems in standard form, and their recovery
:mod:`.kkt`           the KKT residuals on the plate's own terms
:mod:`.routing`       the "auto" rules: which backend and formulation
:mod:`.pipeline`      scale → route → formulate → solve → recover → check
====================  ==========================================================================
"""

from .formulations import FORMULATIONS, Condensed, ContactSolution, Dual, Formulation, Primal, formulate
from .kkt import kkt_report, local_stiffness
from .pipeline import finish, solve_bilateral, solve_contact, to_result
from .routing import choose, condensed_pays, formulations_for
from .scaling import Scaled
from .statics import NO_EQUILIBRIUM, equilibrium_possible

__all__ = [
    "FORMULATIONS", "NO_EQUILIBRIUM", "Condensed", "ContactSolution", "Dual", "Formulation", "Primal", "Scaled",
    "choose", "condensed_pays", "equilibrium_possible", "finish", "formulate", "formulations_for", "kkt_report",
    "local_stiffness", "solve_bilateral", "solve_contact", "to_result",
]
