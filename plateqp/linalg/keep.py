"""Factorisations kept between solves of one plate: a list a caller lends to the solves it runs.

A sweep over gaps, support stiffnesses, the bed's modulus or loads solves one plate's K many
times (:func:`plateqp.studies.reuse.adapt_model` shares K and the contact operator between the
values). Inside :func:`sharing` (a sweep's solves, the stiffness design's) the contact pipeline
lends each solve the list its model keeps for that K and B (:func:`keeping`); a backend that factorises K looks there first (:func:`kept`) and keeps what it
built there (its factorisation; pdas also its reading of the QP, checked against the next QP).
What is kept must depend on K and B alone: gaps, flexibilities and loads are each solve's own. The list lives as long as the model (and the models adapted from it), never
longer: a new K (thickness, modulus, mesh) is a new model with a new list.
"""

from __future__ import annotations

import contextlib
import contextvars

#: how many factorisations one list keeps, most recent last
KEEP = 2

_SHARING: contextvars.ContextVar[bool] = contextvars.ContextVar("plateqp_sharing_factors", default=False)
_LENT: contextvars.ContextVar[list | None] = contextvars.ContextVar("plateqp_kept_factors", default=None)


@contextlib.contextmanager
def sharing():
    """Within this block, solves of a model keep their factorisations for the next solve of the
    same K and B (outside it a solve keeps nothing alive beside its Result)."""
    token = _SHARING.set(True)
    try:
        yield
    finally:
        _SHARING.reset(token)


def shared() -> bool:
    """True inside :func:`sharing`."""
    return _SHARING.get()


@contextlib.contextmanager
def keeping(store: list | None):
    """Lend ``store`` (a list, or None: nothing kept) to the solves run inside."""
    token = _LENT.set(store)
    try:
        yield store
    finally:
        _LENT.reset(token)


def kept() -> list | None:
    """The list lent to this solve, or None."""
    return _LENT.get()


def remember(store: list, entry) -> None:
    """Keep ``entry`` in ``store``, the oldest of its type dropped past :data:`KEEP` (a backend
    keeps things of several types: a factorisation, the problem read from the QP)."""
    store.append(entry)
    drop = {id(e) for e in [e for e in store if type(e) is type(entry)][:-KEEP]}
    store[:] = [e for e in store if id(e) not in drop]


__all__ = ["KEEP", "keeping", "kept", "remember", "shared", "sharing"]
