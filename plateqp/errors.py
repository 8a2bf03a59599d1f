"""The exception tree of plateqp.

Every error plateqp raises on purpose derives from :class:`PlateQPError`, so one
``except pq.PlateQPError`` catches them all. Backend failures are wrapped with
``raise ... from exn`` so the solver's own message is kept.
"""

from __future__ import annotations


class PlateQPError(Exception):
    """Base class of every plateqp error."""


class SceneError(PlateQPError, ValueError):
    """A scene is invalid: the message names the field (and the file, if any)."""


class ResourceError(SceneError):
    """A scene would need more memory (or work) than allowed: the message gives the estimate and
    the limit, and how to raise it."""


class MechanismError(PlateQPError):
    """The plate is a mechanism: its supports cannot prevent a rigid motion."""


class SingularMatrixError(MechanismError):
    """A matrix that must be positive definite (or a saddle-point system that must be
    nonsingular) is singular to working precision: :mod:`plateqp.linalg`'s error, in matrix
    words. A caller that knows what the matrix stands for adds that (a plate that is a
    mechanism); it derives from :class:`MechanismError` so that such callers catch it as one.
    ``column``: where the factorisation stopped, when known (in the order it factorised)."""

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message)
        self.column = column


class ProblemError(PlateQPError, ValueError):
    """A QP or LCP is malformed, or a formulation cannot be built for a scene."""


class ArgumentError(PlateQPError, ValueError):
    """A public function or method was given an argument it cannot take (a wrong type, a value
    outside its range): the message names the argument."""


class SolverError(PlateQPError):
    """A backend failed, is unknown, is not installed, or rejected the problem."""


class NoEquilibriumError(PlateQPError):
    """The one-sided supports cannot carry the load (the contact problem has no solution).

    Physically: net uplift, or a load resultant outside the reach of the supports,
    so the plate would lift off as a rigid body.
    """


class PlateQPWarning(UserWarning):
    """Warnings raised by plateqp (e.g. an inaccurate solve)."""


class ExportError(PlateQPError, ValueError):
    """An export was asked for something it cannot do (bad name, existing output, bad file)."""


class ClusterError(PlateQPError):
    """A Dask cluster was asked for and cannot be used: dask.distributed is not installed, or
    no scheduler answered at the address within the timeout."""
