"""Memory the C heap holds back, given back to the system before a factor is allocated.

NumPy's arrays below glibc's mmap threshold (which grows to 32 MB once a larger block is freed)
come from the process's heap, and freed they stay resident: the heap keeps them for the next
allocation. A CHOLMOD factor is one allocation far above the threshold, mapped apart, so that
memory is never re-used for it and counts beside it in the process's peak (docs/design/pdas.md).
:func:`release` returns it (glibc's ``malloc_trim``).
"""

from __future__ import annotations

import ctypes
import ctypes.util

#: Stored entries of a matrix (one triangle) from which its factor is worth the release: the
#: returned pages are faulted in again by the next allocations, which on small plates cost more
#: than the memory saved (the 64² grid of posts took 0.37 s → 0.42 s); 2²⁰ is a 180² plate.
RELEASE_FROM = 1 << 20

_TRIM = None  # glibc's malloc_trim, or False where there is none


def _trim():
    global _TRIM
    if _TRIM is None:
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
            _TRIM = libc.malloc_trim
            _TRIM.argtypes, _TRIM.restype = [ctypes.c_size_t], ctypes.c_int
        except (OSError, AttributeError):  # not glibc: nothing to release this way
            _TRIM = False
    return _TRIM


def release() -> bool:
    """Return the heap's free memory to the system (``malloc_trim(0)``); False where the C
    library has no such call."""
    trim = _trim()
    if not trim:
        return False
    trim(0)
    return True
