"""The half-space's matrix-free flexibility on a bed over the whole grid: four FFTs a product.

References: the dense flexibility the model builds (Boussinesq's integral exact over every
quarter polygon, point by point, then ½(H + Hᵀ)), independent of the FFT route; the count of
FFT calls a product makes (a fact of the code path, read by wrapping scipy.fft).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.fft

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.soil import halfspace_flexibility
from test_halfspace_grid import operator_of  # the model's own operator for its bed

E_SOIL, NU_SOIL = 3e7, 0.3


def scene(a, b, nx, ny, **kw) -> pq.Scene:
    return pq.Scene(plate=pq.Plate(a=a, b=b, h=0.1, E=3e10, nu=0.2), mesh=pq.MeshSpec(nx=nx, ny=ny),
                    loads=[pq.UniformLoad(1e3)], foundation=pq.Foundation(model="halfspace", E=E_SOIL, nu=NU_SOIL),
                    **kw)


#: whole-plate beds: every edge free (every edge node presses), two edges held (their nodes do
#: not), a pin inside, oblong cells, an odd padded size
CASES = [
    ("free-square", lambda: scene(1.0, 1.0, 6, 6)),
    ("free-oblong", lambda: scene(2.0, 0.6, 7, 5)),
    ("held-left-right", lambda: scene(1.0, 1.0, 8, 8, edges={"left": "simple", "right": "simple"})),
    ("clamped-bottom-pin", lambda: scene(2.0, 1.0, 10, 5, edges={"bottom": pq.Edge("clamped")},
                                          pins=[pq.Pin(1.0, 0.6)])),
]


@pytest.mark.parametrize("make", [c[1] for c in CASES], ids=[c[0] for c in CASES])
def test_the_whole_bed_operator_is_the_dense_flexibility(make):
    model = build_model(make())
    nodes = model.soil_nodes
    H = halfspace_flexibility(model, nodes)
    op = operator_of(model)
    m = nodes.size
    full = op @ np.eye(m)
    assert np.abs(full - H).max() <= 1e-10 * np.abs(H).max()
    x = np.random.default_rng(3).standard_normal(m)
    assert np.abs(op @ x - H @ x).max() <= 1e-10 * np.abs(H @ x).max()


def test_a_product_on_a_whole_bed_takes_four_ffts(monkeypatch):
    model = build_model(scene(1.0, 1.0, 16, 16, edges={"left": "simple", "right": "simple"}))
    op = operator_of(model)
    x = np.random.default_rng(1).standard_normal(op.shape[0])
    op @ x  # any set-up on the first product is not counted
    calls = []
    for name in ("fft", "ifft", "rfft", "irfft", "fft2", "ifft2", "rfft2", "irfft2", "rfftn", "irfftn"):
        real = getattr(scipy.fft, name)

        def counted(a, *args, _real=real, _name=name, **kw):
            b = np.asarray(a)
            if b.ndim >= 3:  # (columns, [quarters,] rows, cols): each plane transformed along one axis
                calls.append(int(np.prod(b.shape[1:-2])))  # (a line, (columns, n): not counted)
            return _real(a, *args, **kw)
        monkeypatch.setattr(scipy.fft, name, counted)
    op @ x
    # a 2-D transform is two passes over its plane: one forward and one inverse for H, the same for Hᵀ
    assert sum(calls) / 2 <= 4, calls
