"""Memory the C heap holds back (freed, not returned) is given back to the system before a
numeric factorisation, whose factor is a new allocation of its own: it would otherwise count
beside that factor in the process's peak."""

import ctypes
import ctypes.util

import numpy as np
import pytest
import scipy.sparse as sp

from plateqp.linalg import Cholesky, bindings, heap
from plateqp.linalg.cholmod import lower
from plateqp.model.assembly import build_model
from plateqp.scenes import families


def _mallinfo_free() -> int:
    """glibc's free bytes held in the main heap (mallinfo2's ``fordblks``)."""

    class MallInfo2(ctypes.Structure):
        _fields_ = [(name, ctypes.c_size_t) for name in ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks",
                                                         "fsmblks", "uordblks", "fordblks", "keepcost")]

    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
    if not hasattr(libc, "mallinfo2"):
        pytest.skip("not glibc ≥ 2.33")
    libc.mallinfo2.restype = MallInfo2
    return int(libc.mallinfo2().fordblks)


def _heap_garbage() -> None:
    """Freed blocks in the main heap: many small arrays (below the mmap threshold) with a live
    one after them, so the heap cannot shrink from its top."""
    blocks = [np.ones(8_000) for _ in range(400)]  # 64 kB each, 25 MB in all
    keep = np.ones(8_000)
    del blocks
    return keep


def _rss_kb() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS"):
                return int(line.split()[1])
    pytest.skip("no /proc/self/status")


def test_release_shrinks_the_resident_set():
    keep = _heap_garbage()
    if _mallinfo_free() < 10_000_000:
        pytest.skip("this allocator left no free memory in the heap to return")
    r0 = _rss_kb()
    heap.release()
    assert r0 - _rss_kb() > 10_000  # kB: most of the 25 MB freed above
    del keep


def test_a_first_numeric_factorisation_releases_the_heap_first(monkeypatch):
    if "cvxopt" not in bindings():
        pytest.skip("cvxopt's CHOLMOD is not installed")
    calls = []
    monkeypatch.setattr(heap, "release", lambda: calls.append(1) or True)
    K = sp.csc_matrix(build_model(families.grid_rigid(8, 3)).K)
    chol = Cholesky("cvxopt")
    A = lower(K, 1.0 / np.sqrt(K.diagonal()), upper=chol.upper)
    chol.analyse(A)
    chol.factor(A)
    assert calls == []  # a small factor: not worth it
    monkeypatch.setattr(heap, "RELEASE_FROM", A.nnz)
    chol = Cholesky("cvxopt")
    chol.analyse(A)
    assert calls == []
    chol.factor(A)
    assert calls == [1]
    chol.factor(A)  # a refactorisation re-uses the factor's own memory: nothing to release
    assert calls == [1]
