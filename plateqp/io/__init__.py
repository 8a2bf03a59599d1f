"""Contact problems in standard formats, so that other people's solvers can be run on them.

=========================  ==========================================================================
:mod:`.export`             :class:`ExportedQP`, :func:`contact_qp`: the contact problem of a scene
                           exactly as the backends get it (scaled, formulated, in QP form), and
                           another solver's answer mapped back to a plateqp Result
:mod:`.qps`                :func:`write_qps`, :func:`read_qps`, :class:`QPSInfo`: Maros–Meszaros QPS
:mod:`.npz`                :func:`write_npz`, :func:`read_npz`: one problem per ``.npz``, never densified
:mod:`.qpbenchmark`        :func:`write_qpbenchmark`: a qpbenchmark test set (the ``.npz`` files and a
                           generated ``TestSet`` module that needs no plateqp)
:mod:`.files`              where an export may write, checked before any work
=========================  ==========================================================================

``plateqp export SCENE --format qps|qpbenchmark --out PATH`` is the command line to them.
"""

from .export import ExportedQP, contact_qp
from .npz import read_npz, write_npz
from .qpbenchmark import QPBENCHMARK_TOLERANCES, check_testset_dir, qpbenchmark_class_name, write_qpbenchmark
from .qps import QPSInfo, read_qps, write_qps

#: The formats of ``plateqp export --format``.
FORMATS = ("qps", "qpbenchmark")

__all__ = ["FORMATS", "QPBENCHMARK_TOLERANCES", "ExportedQP", "QPSInfo", "check_testset_dir", "contact_qp",
           "qpbenchmark_class_name", "read_npz", "read_qps", "write_npz", "write_qpbenchmark", "write_qps"]
