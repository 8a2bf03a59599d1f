"""Contact problems and results in standard formats: other people's solvers on plate contact,
and plateqp's answers in the tools users already work with.

=========================  ==========================================================================
:mod:`.export`             :class:`ExportedQP`, :func:`contact_qp`: the contact problem of a scene
                           exactly as the backends get it (scaled, formulated, in QP form), and
                           another solver's answer mapped back to a plateqp Result
:mod:`.qps`                :func:`write_qps`, :func:`read_qps`, :class:`QPSInfo`: Maros–Meszaros QPS
:mod:`.npz`                :func:`write_npz`, :func:`read_npz`: one problem per ``.npz``, never densified
:mod:`.qpbenchmark`        :func:`write_qpbenchmark`: a qpbenchmark test set (the problems, their reference
                           solutions and a generated ``TestSet`` module that needs no plateqp)
:mod:`.graded`             the graded family of that test set: mesh × support kind × gap pattern, each
                           instance in the three forms with an exact reference (``n08_rigid_heave_dual``)
:mod:`.files`              where an export may write, checked before any work; safe file names
:mod:`.fields`             :func:`to_xarray`, :func:`supports_frame`: a result's nodal fields as an
                           xarray Dataset, its supports as a pandas DataFrame (``Result.to_xarray``,
                           ``Result.supports``)
:mod:`.vtk`                :func:`write_vtu`: the plate and its supports as VTK files (meshio) for
                           ParaView or pyvista (``Result.write_vtu``, ``plateqp solve --out``)
=========================  ==========================================================================

``plateqp export SCENE --format qps|qpbenchmark --out PATH`` is the command line to them.
"""

from .export import ExportedQP, contact_qp
from .fields import supports_frame, to_xarray
from .npz import read_npz, write_npz
from .qpbenchmark import QPBENCHMARK_TOLERANCES, check_testset_dir, qpbenchmark_class_name, write_qpbenchmark
from .qps import QPSInfo, read_qps, write_qps
from .vtk import write_vtu

#: The formats of ``plateqp export --format``.
FORMATS = ("qps", "qpbenchmark")

__all__ = ["FORMATS", "QPBENCHMARK_TOLERANCES", "ExportedQP", "QPSInfo", "check_testset_dir", "contact_qp",
           "qpbenchmark_class_name", "read_npz", "read_qps", "supports_frame", "to_xarray", "write_npz",
           "write_qpbenchmark", "write_qps", "write_vtu"]
