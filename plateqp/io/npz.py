"""One QP per ``.npz`` file: vectors as arrays, sparse matrices as their CSC components.

Keys: ``q`` and, where present, ``h``, ``b``, ``lb``, ``ub``; a matrix M in P, G, A is either
``M`` (a dense 2-D array) or ``M_data``, ``M_indices``, ``M_indptr``, ``M_shape`` (its CSC
components: a sparse matrix is never densified); ``meta``: a JSON string (names, scales).

:func:`npz_arrays` is the one reader of this layout. It needs numpy and scipy only, so the
test-set modules :mod:`plateqp.io.qpbenchmark` generates carry its source verbatim and load the
files without plateqp.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..backends.base import QP
from .export import unpack


def write_npz(qp, path, meta: dict | None = None) -> Path:
    """Write one problem as ``.npz`` (the layout of this module's docstring).

    Parameters
    ----------
    qp : a :class:`~plateqp.backends.base.QP` or an :class:`~plateqp.io.export.ExportedQP`
        (then its metadata and names go into ``meta``)
    path : the file to write
    meta : more metadata (JSON-able), merged over the exported problem's
    """
    qp, vn, rn, emeta = unpack(qp)
    meta = dict(emeta or {}, **(meta or {}))
    if vn is not None:
        meta.setdefault("var_names", vn)
        meta.setdefault("row_names", rn)
    arrays: dict[str, np.ndarray] = {"q": qp.q}
    for key in ("h", "b", "lb", "ub"):
        v = getattr(qp, key)
        if v is not None:
            arrays[key] = np.asarray(v, dtype=float)
    for key in ("P", "G", "A"):
        M = getattr(qp, key)
        if M is None:
            continue
        if sp.issparse(M):
            M = sp.csc_matrix(M, copy=True)
            M.sort_indices()
            arrays[f"{key}_data"] = M.data.astype(float)
            arrays[f"{key}_indices"] = M.indices.astype(np.int64)
            arrays[f"{key}_indptr"] = M.indptr.astype(np.int64)
            arrays[f"{key}_shape"] = np.array(M.shape, dtype=np.int64)
        else:
            arrays[key] = np.asarray(M, dtype=float)
    arrays["meta"] = np.array(json.dumps(meta, sort_keys=True))
    from .safe import write

    path = Path(path if str(path).endswith(".npz") else f"{path}.npz")  # numpy's rule

    def save(tmp):
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    return write(path, save, force=True)  # over a file, never through a link


def npz_arrays(path) -> dict:
    """The problem in a ``.npz`` file: P, q, G, h, A, b, lb, ub (None where absent; a matrix
    dense or CSC as it was written) and ``meta`` (its JSON text, ``"{}"`` if absent).

    Written for numpy and scipy (as ``np``, ``sp``) alone: generated test-set modules carry
    this function's source.
    """
    with np.load(path, allow_pickle=False) as f:
        keys = set(f.files)

        def mat(key):
            if key in keys:
                return np.array(f[key])
            if key + "_data" in keys:
                shape = tuple(int(s) for s in f[key + "_shape"])
                return sp.csc_matrix((np.array(f[key + "_data"]), np.array(f[key + "_indices"]),
                                      np.array(f[key + "_indptr"])), shape=shape)
            return None

        def vec(key):
            return np.array(f[key]) if key in keys else None

        out = {key: mat(key) for key in ("P", "G", "A")}
        out.update({key: vec(key) for key in ("q", "h", "b", "lb", "ub")})
        out["meta"] = str(f["meta"]) if "meta" in keys else "{}"
    return out


def read_npz(path, with_meta: bool = False):
    """Read a problem written by :func:`write_npz` as a QP (and its metadata, a dict)."""
    arrays = npz_arrays(path)
    meta = json.loads(arrays.pop("meta"))
    qp = QP(**arrays)
    return (qp, meta) if with_meta else qp
