"""Executors of a sweep (plateqp.studies.parallel): worker processes and a Dask cluster give
exactly the serial answers."""

from __future__ import annotations

import numpy as np
import pytest

from plateqp.studies import sweep
from study_scenes import STIFF, fig5


def test_dask_local_cluster_equals_serial():
    distributed = pytest.importorskip("distributed")
    sc = fig5()
    values = [1e5, 5e4, 2e4, 1e4]
    serial = sweep(sc, STIFF, values, executor="serial", progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        par = sweep(sc, STIFF, values, executor=client, progress=False)
    assert par.times["executor"] == "dask"
    np.testing.assert_array_equal(par.reactions, serial.reactions)
    assert par.breakpoints == serial.breakpoints


def test_process_pool_equals_serial():
    sc = fig5()
    values = [1e5, 3e4, 1e4, 3e3]
    serial = sweep(sc, STIFF, values, executor="serial", progress=False, refine_breakpoints=False)
    par = sweep(sc, STIFF, values, executor="process", progress=False, refine_breakpoints=False)
    assert par.times["executor"] == "futures"
    np.testing.assert_array_equal(par.reactions, serial.reactions)
    assert [r["active"] for r in par.rows] == [r["active"] for r in serial.rows]
