"""One problem per .npz (plateqp.io.npz): dense and sparse matrices come back as they went in."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from plateqp.backends.base import QP
from plateqp.io import read_npz, write_npz


def test_npz_round_trip_dense_and_sparse(tmp_path):
    qp = QP(P=np.array([[2.0, 1.0], [1.0, 2.0]]), q=np.array([1.0, -1.0]), G=sp.csc_matrix(np.eye(2)),
            h=np.array([1.0, 2.0]), lb=np.array([-1.0, -np.inf]))
    path = write_npz(qp, tmp_path / "p.npz", meta={"note": "x"})
    back, meta = read_npz(path, with_meta=True)
    assert isinstance(back.P, np.ndarray) and np.array_equal(back.P, qp.P)
    assert sp.issparse(back.G) and np.array_equal(back.G.toarray(), np.eye(2))
    assert np.array_equal(back.lb, qp.lb) and back.ub is None and back.A is None and meta == {"note": "x"}
