"""Backend registry: one module per backend family, one line each here, imported on first need.

Every module listed in ``_MODULES`` defines ``backends() -> list[Backend]``: instances of
:class:`~plateqp.backends.base.Backend`, each with its declared capabilities (``accepts``,
``formulations``, ``exact``, ``warm_start``). A module must import cleanly when its solver is
absent; its backends then report ``available() is False``.
"""

from __future__ import annotations

import importlib
import threading

from ..errors import SolverError
from .base import ACCURACIES, LCP, PRESET_TOL, QP, Backend, RawSolution, Status, accuracy_tol

# module name -> the backends it provides (a family such as qpsolvers provides many), in the
# order they are imported and listed: plateqp's own first
_MODULES = ("lemke", "bpp", "pgs", "pdas", "toggle", "mprgp", "osqp_", "clarabel_", "cvxpy_", "qpsolvers_")
#: plateqp's own backends (the first modules of ``_MODULES``): their modules import no
#: third-party solver. Every backend declared ``exact`` is among them (tests/backends/test_backends.py
#: checks), so ``backend="auto"`` chooses from these alone and a solve with one of them never
#: imports cvxpy, qpsolvers, OSQP or Clarabel (cvxpy's import alone took 0.3-0.5 s of a fresh
#: process's first solve).
IN_HOUSE = _MODULES[:6]
# the other modules by the family a backend's name starts with ("cvxpy:SCS" -> cvxpy_)
_FAMILY = {"osqp": "osqp_", "clarabel": "clarabel_", "cvxpy": "cvxpy_", "qpsolvers": "qpsolvers_"}

_known: dict[str, Backend] = {}  # the backends of the modules imported so far, by name, in module order
_names: dict[str, list[str]] = {}  # module name -> the names of its backends, once imported
_LOCK = threading.RLock()  # one thread imports and registers at a time; readers see a dict that only grows


def _load(upto: int) -> None:
    """Import the first ``upto`` modules of ``_MODULES`` (those not imported yet), in that order,
    and register their backends: the registry's order never depends on which name was asked first."""
    with _LOCK:
        for mod_name in _MODULES[:upto]:
            if mod_name in _names:
                continue
            try:
                mod = importlib.import_module(f"{__name__}.{mod_name}")
            except ImportError:  # the module itself is missing: nothing to register
                found: list = []
            else:
                found = list(mod.backends())
                for b in found:
                    if not isinstance(b, Backend):
                        raise TypeError(f"plateqp.backends.{mod_name}.backends() must give Backend instances, "
                                        f"got {type(b).__name__}")
            for b in found:
                _known.setdefault(b.name, b)
            _names[mod_name] = [b.name for b in found]


def registry() -> dict[str, Backend]:
    """All known backends by name (installed or not), in the order of ``_MODULES``; imports every
    backend module the first time. The same dict every call (an entry set in it is what
    :func:`get_backend` finds)."""
    _load(len(_MODULES))
    return _known


def in_house() -> dict[str, Backend]:
    """plateqp's own backends by name (:data:`IN_HOUSE`; no third-party solver imported)."""
    _load(len(IN_HOUSE))
    return {n: _known[n] for m in IN_HOUSE for n in _names[m] if n in _known}


def get_backend(name: str) -> Backend:
    """The backend called ``name``; a clear error listing what is installed otherwise. Imports
    plateqp's own backend modules and, for another family's name ("osqp", "cvxpy:SCS"), the
    modules up to that family's, not every backend's."""
    family = _FAMILY.get(name.split(":")[0])
    _load(_MODULES.index(family) + 1 if family else len(IN_HOUSE))
    b = _known.get(name)
    if b is None:
        reg = registry()
        if name not in reg:
            avail = sorted(n for n, x in reg.items() if x.available())
            raise SolverError(f"unknown backend {name!r}; installed backends: {', '.join(avail)}")
        b = reg[name]
    if not b.available():
        reg = registry()
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
    "in_house",
    "registry",
]
