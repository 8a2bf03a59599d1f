"""The shared words of a solve: how accurate an answer is asked to be, and how it ended.

An accuracy is parsed once, into :class:`Accuracy`, and passed on as that object: the contact
pipeline, every backend's settings table (:func:`plateqp.backends.base.preset`) and the KKT
report read the same parsed value. It is one of

* a preset, ``"low"``, ``"default"`` or ``"high"``: KKT tolerance 1e-3, 1e-6, 1e-9
  (:data:`PRESET_TOL`);
* a number, the KKT tolerance itself, in :data:`TOL_RANGE` (``"1e-7"`` from a command line
  or a TOML file is read as a number);
* ``"auto"`` (only where a solve is asked for: :func:`plateqp.solve` resolves it to a
  number from the mesh's own discretisation error before any backend sees it).

Anything else is a :class:`~plateqp.errors.ProblemError` that names the choices.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from .errors import ProblemError

ACCURACIES = ("low", "default", "high")

#: The KKT tolerance of each accuracy preset (:mod:`plateqp.contact.kkt` judges answers by it).
PRESET_TOL: dict[str, float] = {"low": 1e-3, "default": 1e-6, "high": 1e-9}

#: The range of a numeric accuracy: looser than 1e-1 is no answer, tighter than 1e-14 is
#: below what double precision can certify on a plate problem.
TOL_RANGE = (1e-14, 1e-1)

#: A load (or reactions) below this fraction of the heaves' force (the force that closes the
#: largest negative gap: plateqp.contact.kkt.heave_force, and pdas's own on its reduced problem)
#: does no work that double precision can show beside the heaves: a plate lifted as a body onto
#: heaved posts carries reactions of 1e-16 … 1e-15 of it. Only then are forces measured against
#: the heaves' force; any larger load keeps its own scale (measured against the heaves, a load
#: 1e-5 of them, the whole of a floating plate's reactions, would pass with any error below
#: tol × 1e5 of itself). Shared by the KKT check and the pdas backend.
NO_WORK = 1e-10


class Status(enum.Enum):
    """Outcome of a solve. ``INACCURATE`` marks an answer that missed the asked accuracy."""

    OPTIMAL = "optimal"
    INACCURATE = "inaccurate"
    INFEASIBLE = "infeasible"  # no equilibrium (primal infeasible / LCP ray termination)
    UNBOUNDED = "unbounded"  # dual infeasible: the load cannot be carried
    MAX_ITER = "max_iter"
    ERROR = "error"

    @property
    def solved(self) -> bool:
        return self in (Status.OPTIMAL, Status.INACCURATE)


@dataclass(frozen=True)
class Accuracy:
    """A parsed accuracy: ``asked`` as the user gave it (a preset name or a float), ``tol`` its
    KKT tolerance, ``preset`` the nearest preset (in decades; the preset itself for a name).

    Build it with :meth:`parse`, which also takes an Accuracy (returned as it is)."""

    asked: str | float
    tol: float
    preset: str

    @property
    def is_preset(self) -> bool:
        return isinstance(self.asked, str)

    @classmethod
    def parse(cls, accuracy: str | float | Accuracy) -> Accuracy:
        if isinstance(accuracy, Accuracy):
            return accuracy
        if isinstance(accuracy, str):
            if accuracy in PRESET_TOL:
                return cls(accuracy, PRESET_TOL[accuracy], accuracy)
            try:
                accuracy = float(accuracy)  # "1e-7" from a command line or a TOML file
            except ValueError:
                raise ProblemError(f"unknown accuracy {accuracy!r}; choose one of {ACCURACIES} or a "
                                   f"tolerance between {TOL_RANGE[0]:.0e} and {TOL_RANGE[1]:.0e}") from None
        if isinstance(accuracy, bool) or not isinstance(accuracy, (int, float, np.integer, np.floating)):
            raise ProblemError(f"accuracy must be one of {ACCURACIES} or a number, not {accuracy!r}")
        tol = float(accuracy)
        if not (TOL_RANGE[0] <= tol <= TOL_RANGE[1]):  # NaN fails this too
            raise ProblemError(f"accuracy {tol:g} is outside {TOL_RANGE[0]:.0e} … {TOL_RANGE[1]:.0e}")
        return cls(tol, tol, _nearest(tol))

    def __str__(self) -> str:
        return self.asked if isinstance(self.asked, str) else f"{self.asked:g}"


def _nearest(tol: float) -> str:
    return min(PRESET_TOL, key=lambda a: abs(np.log10(tol / PRESET_TOL[a])))


def accuracy_tol(accuracy: str | float | Accuracy) -> float:
    """The KKT tolerance of an accuracy (see :class:`Accuracy`); a ProblemError for a bad one."""
    return Accuracy.parse(accuracy).tol


def nearest_preset(accuracy: str | float | Accuracy) -> str:
    """The preset whose tolerance is nearest (in decades) to ``accuracy``'s."""
    return Accuracy.parse(accuracy).preset


__all__ = ["ACCURACIES", "PRESET_TOL", "TOL_RANGE", "Accuracy", "Status", "accuracy_tol", "nearest_preset"]
