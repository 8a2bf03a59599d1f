"""Backend registry: one module per backend family, one line each here, imported on first need.

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
#: plateqp's own backends: their modules import no third-party solver. Every backend declared
#: ``exact`` is among them (tests/test_backends.py checks), so ``backend="auto"`` chooses from
#: these alone and a solve with one of them never imports cvxpy, qpsolvers, OSQP or Clarabel
#: (cvxpy's import alone took 0.5 s of a fresh process's first solve).
IN_HOUSE = ("lemke", "bpp", "pgs", "pdas", "toggle")
# the other modules by the family a backend's name starts with ("cvxpy:SCS" -> cvxpy_)
_FAMILY = {"osqp": "osqp_", "clarabel": "clarabel_", "cvxpy": "cvxpy_", "qpsolvers": "qpsolvers_"}

_loaded: dict[str, list[Backend]] = {}  # module name -> its backends, once imported
_registry: dict[str, Backend] | None = None


def _backends_of(mod_name: str) -> list[Backend]:
    if mod_name not in _loaded:
        try:
            mod = importlib.import_module(f"{__name__}.{mod_name}")
        except ImportError:  # the module itself is missing: nothing to register
            found: list[Backend] = []
        else:
            found = list(mod.backends())
            for b in found:
                if not isinstance(b, Backend):
                    raise TypeError(f"plateqp.backends.{mod_name}.backends() must give Backend instances, "
                                    f"got {type(b).__name__}")
        _loaded[mod_name] = found
    return _loaded[mod_name]


def _by_name(modules) -> dict[str, Backend]:
    """The backends of ``modules`` by name, in the order of ``_MODULES`` (importing them)."""
    return {b.name: b for m in _MODULES if m in modules for b in _backends_of(m)}


def registry() -> dict[str, Backend]:
    """All known backends by name (installed or not), built once: imports every backend module."""
    global _registry
    if _registry is None:
        _registry = _by_name(_MODULES)
    return _registry


def in_house() -> dict[str, Backend]:
    """plateqp's own backends by name (:data:`IN_HOUSE`; no third-party solver imported)."""
    return _by_name(IN_HOUSE)


def get_backend(name: str) -> Backend:
    """The backend called ``name``; a clear error listing what is installed otherwise. Imports
    only the module that provides it (and plateqp's own), not every backend's."""
    family = _FAMILY.get(name.split(":")[0])
    b = _by_name(IN_HOUSE + ((family,) if family else ())).get(name)
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
