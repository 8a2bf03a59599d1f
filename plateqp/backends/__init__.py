"""Backend registry: one module per backend family, one line each here.

Every module listed in ``_MODULES`` defines ``backends() -> list[Backend]``: instances of
:class:`~plateqp.backends.base.Backend`, each with its declared capabilities (``accepts``,
``formulations``, ``exact``, ``warm_start``). A module must import cleanly when its solver is
absent; its backends then report ``available() is False``.
"""

from __future__ import annotations

import importlib

from ..errors import SolverError
from .base import ACCURACIES, LCP, PRESET_TOL, QP, Backend, RawSolution, Status, accuracy_tol

# module name -> the backends it provides (a family such as qpsolvers provides many)
_MODULES = ("lemke", "bpp", "pgs", "pdas", "toggle", "osqp_", "clarabel_", "cvxpy_", "qpsolvers_")

_registry: dict[str, Backend] | None = None


def registry() -> dict[str, Backend]:
    """All known backends by name (installed or not), built once."""
    global _registry
    if _registry is None:
        reg: dict[str, Backend] = {}
        for mod_name in _MODULES:
            try:
                mod = importlib.import_module(f"{__name__}.{mod_name}")
            except ImportError:  # the module itself is missing: nothing to register
                continue
            for b in mod.backends():
                if not isinstance(b, Backend):
                    raise TypeError(f"plateqp.backends.{mod_name}.backends() must give Backend instances, "
                                    f"got {type(b).__name__}")
                reg[b.name] = b
        _registry = reg
    return _registry


def get_backend(name: str) -> Backend:
    """The backend called ``name``; a clear error listing what is installed otherwise."""
    reg = registry()
    if name not in reg:
        avail = sorted(n for n, b in reg.items() if b.available())
        raise SolverError(f"unknown backend {name!r}; installed backends: {', '.join(avail)}")
    b = reg[name]
    if not b.available():
        raise SolverError(
            f"backend {name!r} is not installed here (pip install 'plateqp[solvers]'); "
            f"installed: {', '.join(sorted(n for n, x in reg.items() if x.available()))}"
        )
    return b


def available_backends() -> list[str]:
    """Names of the backends that are installed and usable here."""
    return sorted(n for n, b in registry().items() if b.available())


__all__ = [
    "ACCURACIES",
    "PRESET_TOL",
    "accuracy_tol",
    "LCP",
    "QP",
    "Backend",
    "RawSolution",
    "Status",
    "available_backends",
    "get_backend",
    "registry",
]
