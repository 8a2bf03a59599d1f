"""``pattern.scaled`` makes one array of K's values and nothing else of that size: the scales are
gathered a block at a time (a gather of K's size was a second array as large, new pages each)."""

import tracemalloc

import numpy as np
import scipy.sparse as sp

from plateqp.linalg import pattern
from plateqp.model.assembly import build_model
from plateqp.scenes import families


def test_scaled_allocates_its_values_once_and_scales_each_entry_as_before():
    K = sp.csc_matrix(build_model(families.grid_rigid(200, 3)).K)
    assert K.nnz > 8 * pattern.SCALE_BLOCK  # several blocks
    s = 1.0 / np.sqrt(K.diagonal())
    ref = np.repeat(s, np.diff(K.indptr))
    ref *= s[K.indices]
    ref *= 0.37
    ref *= K.data
    tracemalloc.start()
    out = pattern.scaled(K, s, 0.37)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert np.array_equal(out.data, ref)  # (s_j s_i)·factor·K_ij, to the bit
    # the values, and a block's scratch (its scales and its indices widened): no second array of K's size
    assert peak < K.data.nbytes + 4 * 8 * pattern.SCALE_BLOCK
