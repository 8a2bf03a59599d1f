"""Studies on top of :func:`plateqp.solve`.

=====================  ==========================================================================
module                 job
=====================  ==========================================================================
:mod:`.refinement`     meshes that halve: :func:`convergence` (the paper's table), and
                       :func:`solve_to_target` / :func:`auto_tolerance` (the coarsest mesh, the
                       loosest solver tolerance for an estimated error)
:mod:`.sweep`          :func:`sweep` of one scene field, with the breakpoints where the contact
                       set changes (:mod:`.breakpoints`), the work of a worker (:mod:`.worker`),
                       executors (:mod:`.parallel`; progress bars: :mod:`plateqp.progress`)
:mod:`.reuse`          :func:`adapt_model`: a model for a scene that changes only gaps,
                       stiffnesses or loads, without re-assembly
:mod:`.design`         :func:`regulate_gaps` (gaps for prescribed reactions) and
                       :func:`most_uniform_stiffness`
:mod:`.homotopy`       :func:`exact_path`: the exact piecewise-linear path along a parameter that
                       enters linearly (gap, load, prescribed displacement), every breakpoint
:mod:`.store`          :class:`RowStore`: a sweep's rows on disk as they are solved (JSON Lines),
                       so that a stopped sweep resumes; ``SweepResult.to_xarray`` for netCDF
=====================  ==========================================================================

Scene fields are named by dotted paths (:mod:`plateqp.model.paths`: :func:`get_param`,
:func:`set_param`, re-exported here).
"""

from __future__ import annotations

from ..model.paths import get_param, set_param
from .homotopy import ExactPath, ExactSweepResult, exact_path, exact_sweep
from .design import GapRegulation, UniformStiffness, most_uniform_stiffness, regulate_gaps
from .refinement import (ConvergenceTable, TargetResult, auto_tolerance, convergence, quantity, solve_to_target,
                         start_mesh)
from .reuse import adapt_model
from .sweep import SERIAL_BELOW, WARM_START_BACKENDS, SweepInterrupted, SweepResult, sweep

__all__ = [
    "SERIAL_BELOW",
    "WARM_START_BACKENDS",
    "ConvergenceTable",
    "ExactPath",
    "ExactSweepResult",
    "GapRegulation",
    "SweepInterrupted",
    "SweepResult",
    "TargetResult",
    "UniformStiffness",
    "adapt_model",
    "auto_tolerance",
    "convergence",
    "exact_path",
    "exact_sweep",
    "get_param",
    "most_uniform_stiffness",
    "quantity",
    "regulate_gaps",
    "set_param",
    "solve_to_target",
    "start_mesh",
    "sweep",
]
