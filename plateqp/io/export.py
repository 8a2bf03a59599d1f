r"""The contact problem of a scene exactly as plateqp's backends get it, in standard QP form.

The problem exported (:func:`contact_qp`; rectangle grids and triangle meshes alike) is the
nondimensional data of :class:`plateqp.contact.scaling.Scaled` (deflections by W, forces by F0, lengths by L),
formulated as ``primal``, ``condensed`` or ``dual`` and taken in its QP form (the condensed and
dual LCPs as the bound-constrained QPs ½ zᵀMz + qᵀz, z ≥ 0). The scales and the variables'
names travel with it (:attr:`ExportedQP.meta`; the writers put them in QPS comment lines and
the ``meta`` entry of an ``.npz``), and :meth:`ExportedQP.result` maps any solver's x back to a
plateqp :class:`~plateqp.results.Result` with its KKT report on the plate's own terms.

The writers (:mod:`plateqp.io.qps`, :mod:`plateqp.io.npz`, :mod:`plateqp.io.qpbenchmark`) take
an :class:`ExportedQP` or a bare :class:`~plateqp.backends.base.QP`; :func:`unpack` gives them
both the same way.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..accuracy import Status
from ..backends.base import QP, RawSolution
from ..errors import ExportError, ProblemError

_NAME_OK = re.compile(r"[^A-Za-z0-9_.\-]")


@dataclass
class ExportedQP:
    """A contact problem in standard QP form, with what maps a solution back to the plate.

    Attributes
    ----------
    name : problem name (safe for file names and MPS)
    formulation : "primal", "condensed" or "dual"
    qp : the :class:`~plateqp.backends.base.QP` handed to QP backends
    var_names : one name per variable (primal: ``w_17``, ``wx_17``, … node dofs, ``t_3``
        scaled spring variables; condensed: ``z_3`` gaps; dual: ``R_3`` reactions)
    row_names : one name per row of G (primal: ``gap_3``); empty for the bound-constrained forms
    meta : scene name, formulation, scales L, W, F0 and what x means (JSON-able)
    """

    name: str
    formulation: str
    qp: QP
    var_names: list[str]
    row_names: list[str]
    meta: dict
    model: object = field(default=None, repr=False)
    data: object = field(default=None, repr=False)
    form: object = field(default=None, repr=False)

    def objective(self, x: np.ndarray) -> float:
        """½ xᵀ P x + qᵀ x."""
        x = np.asarray(x, dtype=float)
        return float(0.5 * x @ (self.qp.P @ x) + self.qp.q @ x)

    def x_from_result(self, result) -> np.ndarray:
        """The standard-form x of a plateqp :class:`~plateqp.results.Result` of the same scene.

        Primal: (u / S, t) with S the dof scales and t = √ρ̃ R̃ for the elastic supports;
        condensed: the scaled gaps gap / W; dual: the scaled reactions R / F0.
        """
        d = self.data
        if self.formulation == "primal":
            u = self.model.unknowns(result.u, result.compressions) / d.dof_scale
            el = np.flatnonzero(d.rho > 0)
            return np.concatenate([u, np.sqrt(d.rho[el]) * result.reactions[el] / d.F0])
        if self.formulation == "condensed":
            return np.asarray(result.gaps) / d.W
        return np.asarray(result.reactions) / d.F0

    def result(self, x, z=None, accuracy: str = "default", solver: str = "external"):
        """A plateqp Result (user units, KKT report) from a solution of the exported QP.

        ``x``: the primal solution; ``z``: the multipliers of G x ≤ h, needed for the primal
        form only (they are the scaled reactions). The status is OPTIMAL if the KKT residuals
        meet ``accuracy``, else INACCURATE.
        """
        from ..contact import finish

        if self.form is None:
            raise ExportError("this problem was read from a file: build it with contact_qp() to map solutions back")
        x = np.asarray(x, dtype=float).reshape(-1)
        if x.shape[0] != self.qp.n:
            raise ExportError(f"x has length {x.shape[0]}, expected {self.qp.n}")
        if self.formulation == "primal" and z is None:
            raise ExportError("the primal form needs z, the multipliers of G x <= h (the scaled reactions)")
        raw = RawSolution(Status.OPTIMAL, x=x, z=None if z is None else np.asarray(z, dtype=float))
        return finish(self.model, self.form, raw, accuracy, solver)


def safe_name(name: str) -> str:
    """A problem name safe for file names and MPS records: letters, digits, ``_``, ``.`` and ``-`` only."""
    out = _NAME_OK.sub("_", str(name)).strip("_")
    return out or "plateqp"


def contact_qp(scene_or_model, formulation: str = "primal", name: str | None = None) -> ExportedQP:
    """The contact problem of a scene (or a built Model) in standard QP form.

    The very problem :func:`plateqp.solve` hands a QP backend for this formulation: the data
    are scaled by :meth:`Scaled.from_model <plateqp.contact.scaling.Scaled.from_model>` and
    formulated by :func:`plateqp.contact.formulations.formulate`. One difference, for the dual:
    its flexibility G is built here by refined column solves (accurate to ε; m solves), where
    :func:`plateqp.solve` takes it from a factor's trailing block (to cond(K)·ε) and corrects
    the backend's answer by re-solves (:meth:`plateqp.contact.formulations.Dual.defect`).

    Parameters
    ----------
    scene_or_model : a :class:`~plateqp.model.scene.Scene` or a :class:`~plateqp.model.assembly.Model`
    formulation : "primal", "condensed" or "dual" (no "auto": an export says what it is)
    name : problem name (default: the scene's name and the formulation)
    """
    from ..model.assembly import Model, build_model
    from ..contact import FORMULATIONS, Scaled, equilibrium_possible, formulate

    if formulation not in FORMULATIONS:
        raise ProblemError(f"unknown formulation {formulation!r}; choose one of {FORMULATIONS}")
    model = scene_or_model if isinstance(scene_or_model, Model) else build_model(scene_or_model)
    if model.contacts is None or model.contacts.m == 0:
        raise ProblemError(f"scene {model.scene.name!r} has no one-sided supports: there is no contact problem to export")
    data = Scaled.from_model(model)
    # the dual's G by refined column solves: the file's data are all another solver sees, and
    # plateqp.solve's G (the trailing block's, to cond(K)·ε) is corrected by re-solves instead
    form = formulate(data, formulation, exact_data=True)
    qp = form.problem(frozenset({"qp"}))
    c = model.contacts
    # contact point i: a discrete support (its index in the scene) or a bed node
    tags = [f"{i}" if src == "support" else f"bed{j}" for i, (src, j) in enumerate(zip(c.source, c.index))]
    if formulation == "primal":
        el = np.flatnonzero(data.rho > 0)
        nd = model.element.ndof_node
        dn = model.element.dof_names
        var_names = [f"{dn[k % nd]}_{k // nd}" for k in model.free] + [f"t_{tags[i]}" for i in el]
        row_names = [f"gap_{t}" for t in tags]
        meaning = ("x = (u / S, t): free dofs u (w, slopes, twist per node) over their scales S "
                   "(W, W/L, W/L^2), then t = sqrt(rho~) R~ for each elastic support; "
                   "the multipliers of the G rows are the reactions R / F0")
    elif formulation == "condensed":
        var_names, row_names = [f"z_{t}" for t in tags], []
        meaning = "x = gaps / W at the contact points; reactions R / F0 = P x + q"
    else:
        var_names, row_names = [f"R_{t}" for t in tags], []
        meaning = "x = reactions / F0 at the contact points; gaps / W = P x + q"
    possible, why = equilibrium_possible(data)
    sc = model.scene
    meta = {
        "generator": f"plateqp {version()} (plateqp.io.export.contact_qp)",
        "scene": sc.name,
        "formulation": formulation,
        "plate": {"a": sc.plate.a, "b": sc.plate.b, "h": sc.plate.h, "E": sc.plate.E, "nu": sc.plate.nu},
        "mesh": model.grid.summary(sc.mesh.element),
        "n_dofs": int(data.n),
        "n_contacts": int(data.m),
        "n_elastic": int(np.count_nonzero(data.rho > 0)),
        "floating": bool(data.floating),
        "equilibrium_possible": bool(possible),
        "L": float(data.L),
        "W": float(data.W),
        "F0": float(data.F0),
        "x": meaning,
        "objective": "scaled potential energy / (F0 W)" if formulation == "primal" else
                     "scaled complementary form (not the potential energy)",
    }
    if not possible:
        meta["why_no_equilibrium"] = why
    return ExportedQP(safe_name(name or f"{sc.name}_{formulation}"), formulation, qp, var_names, row_names,
                      meta, model=model, data=data, form=form)


def version() -> str:
    """plateqp's version, for the ``generator`` lines of what is written."""
    from .. import __version__

    return __version__


def unpack(problem) -> tuple[QP, list[str] | None, list[str] | None, dict | None]:
    """(QP, variable names, G-row names, metadata) of an :class:`ExportedQP`; (QP, None, None,
    None) of a bare QP."""
    if isinstance(problem, ExportedQP):
        return problem.qp, problem.var_names, problem.row_names, problem.meta
    return problem, None, None, None
