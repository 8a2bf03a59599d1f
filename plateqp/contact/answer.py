"""A contact solution of the scaled problem back in the user's units: the :class:`Result` every
route returns (:mod:`plateqp.contact.pipeline`, :mod:`plateqp.contact.pressures`)."""

from __future__ import annotations

import numpy as np

from ..accuracy import NO_WORK, Accuracy, Status
from ..linalg.products import times
from ..model.assembly import Model
from ..results import Result
from .formulations import ContactSolution
from .kkt import heave_bound, heave_force, reaction_scale
from .scaling import Scaled
from .statics import settle


def to_result(model: Model, data: Scaled, c: ContactSolution, status: Status, backend: str, formulation: str,
              accuracy: str | float | Accuracy) -> Result:
    """A contact solution of the scaled problem back in the user's units, as a :class:`Result`.

    A solved answer whose deflection is not unique (a rigid motion of a floating plate left free
    by the supports that carry load) is replaced by the canonical one, the same whatever the
    backend, and flagged ``deflection_unique = False`` (:func:`plateqp.contact.statics.settle`;
    the reactions and the KKT report are those of the backend's answer).
    """
    acc = Accuracy.parse(accuracy)
    tol = max(acc.tol, 1e-9)
    u_s, unique = c.u, True
    if status.solved and formulation != "bilateral" and np.all(np.isfinite(c.u)) and np.all(np.isfinite(c.R)):
        u_s, unique = settle(data, c.u, c.R, c.s, tol)
    u = data.dof_scale * u_s
    R = data.F0 * c.R
    s = data.W * c.s
    w = model.contacts.B @ u
    if model.n_soil:  # the soil's settlement v under a bed node: its compression; w the plate's (B u = w − v)
        v = np.zeros(R.shape)
        v[model.contacts.source == "bed"] = u[model.n_free:]
        s, w = s + v, w + v
    gaps = model.contacts.g0 + s - w
    BtR = model.contacts.B.T @ R
    if u_s is c.u and data.K_src is model.K and data.compliance is None:
        # K u − f + Bᵀ R = (F0 W / S) (K̃ ũ − f̃ + B̃ᵀ R̃) (Scaled: K̃ = S K S / (F0 W)): the scaled
        # product the KKT report made on this ũ (plateqp.linalg.products), not a second one
        stat = (data.F0 * data.W / data.dof_scale) * (times(data.K, u_s) - data.f + data.B.T @ c.R)
    else:
        stat = model.K @ u - model.f + BtR
    res = float(np.linalg.norm(stat) / max(np.linalg.norm(model.f), np.linalg.norm(BtR), 1e-300))
    # in contact: the reaction carries load, or the support touches (gap ≈ 0), both judged at
    # the tolerance of the asked accuracy (an iterative solver leaves R ~ tol · max R on open supports).
    # The gap is judged at each support's own deflection scale (the load's, its own initial gap, its
    # deflection and compression), not at W: for a floating plate W counts every gap, and one support
    # settled by 1000 would call every support within tol · 1000 of touching in contact
    local = np.maximum.reduce([np.full(R.shape, data.w_load * data.W), np.abs(model.contacts.g0), np.abs(w),
                               np.abs(s)]) if R.size else np.zeros(0)
    # (reactions all below tol of the load are zero to the asked accuracy: kkt.reaction_scale)
    # the heaves' force counts only where the load does no work beside it (accuracy.NO_WORK): its
    # Rayleigh quotients are not computed where a cheap bound says the load does
    heave = heave_force(data) if np.abs(data.f).sum() <= NO_WORK * heave_bound(data) else 0.0
    active = (c.R > tol * reaction_scale(c.R, data.f, tol, heave)) | (np.abs(gaps) <= tol * np.maximum(local, 1e-300))
    return Result(model.scene, model, model.expand(u), status=status, backend=backend, formulation=formulation,
                  accuracy=acc.asked, reactions=R, gaps=gaps, compressions=s, active=active, residual=res,
                  deflection_unique=unique)
