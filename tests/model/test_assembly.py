"""Assembly: the memory check before it, and the contact operator's gap shift.

References: the memory estimate is checked against its own definition and the limit's
sources (environment, physical memory); the gap shift against an independent build of the
same scene with the new gaps (the deflection the prescribed dofs give each support is
B_full u_c, computed here by the interpolation of the prescribed field).
"""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
from plateqp.model.memory import MEMORY_ENV, check_memory, estimate_memory, memory_limit, parse_bytes
def plate(nx=8, ny=8, **kw):
    return pq.Scene(name="t", mesh=pq.MeshSpec(nx, ny), loads=[pq.UniformLoad(1.0)],
                    edges={"left": pq.Edge("simple", w=0.002), "right": "clamped"}, **kw)


def test_a_mesh_too_large_is_refused_before_assembly(monkeypatch):
    monkeypatch.delenv(MEMORY_ENV, raising=False)
    big = plate(1000, 1000)
    assert estimate_memory(big) > memory_limit() or memory_limit() > 40 * 2**30  # this machine: 24 GiB
    if estimate_memory(big) <= memory_limit():
        pytest.skip("this machine could hold a 1000 x 1000 mesh")
    with pytest.raises(pq.ResourceError, match=r"^mesh: a 1000 x 1000 acm mesh needs about .* GiB .*--max-memory"):
        build_model(big)


def test_the_limit_comes_from_the_environment(monkeypatch):
    sc = plate(16, 16)
    monkeypatch.setenv(MEMORY_ENV, "1M")
    assert memory_limit() == 2**20
    with pytest.raises(pq.ResourceError, match="above the limit of 1.0 MiB"):
        pq.solve(sc)
    monkeypatch.setenv(MEMORY_ENV, "64G")
    check_memory(sc)  # no error
    monkeypatch.setenv(MEMORY_ENV, "lots")
    with pytest.raises(pq.SceneError, match=MEMORY_ENV):
        memory_limit()


@pytest.mark.parametrize("text, value", [("8G", 8 * 2**30), ("512M", 512 * 2**20), ("2e9", 2e9), ("1.5GB", 1.5 * 2**30)])
def test_parse_bytes(text, value):
    assert parse_bytes(text, "x") == int(value)


@pytest.mark.parametrize("text", ["", "G", "-1G", "nan", "inf"])
def test_parse_bytes_refuses(text):
    with pytest.raises(pq.SceneError):
        parse_bytes(text, "x")


def test_estimate_grows_with_the_dofs():
    acm, bfs = plate(10, 10), plate(10, 10)
    bfs.mesh.element = "bfs"
    assert estimate_memory(bfs) == estimate_memory(acm) * 4 // 3  # 4 dofs a node instead of 3
    assert estimate_memory(plate(20, 20)) == estimate_memory(acm) * 441 // 121


def test_contact_operator_shift_is_the_prescribed_deflection():
    """g0 (as the free dofs see it) = scene gap − the deflection the prescribed dofs give there."""
    sups = [pq.Support(0.05, 0.5, gap=0.001), pq.Support(0.5, 0.5, gap=-0.001), pq.Support(0.3, 0.7)]
    m = build_model(plate(supports=sups))
    c = m.contacts
    u_c = np.zeros(m.n_full)
    u_c[m.fixed] = m.values
    shift = m.interpolation(c.xy[:, 0], c.xy[:, 1]) @ u_c
    np.testing.assert_allclose(c.shift, shift, atol=1e-15)
    assert c.shift[0] > 1e-4 and c.shift[1] == 0.0  # next to the moved edge; far from it
    np.testing.assert_allclose(c.scene_gaps, [0.001, -0.001, 0.0], atol=1e-15)


def test_with_gaps_equals_a_fresh_build():
    sups = [pq.Support(0.05, 0.5, gap=0.001), pq.Support(0.5, 0.5, gap=-0.001), pq.Support(0.3, 0.7, stiffness=50.0)]
    new = [pq.Support(0.05, 0.5, gap=-0.003), pq.Support(0.5, 0.5, gap=0.002), pq.Support(0.3, 0.7, stiffness=80.0)]
    a = build_model(plate(supports=sups)).contacts
    b = build_model(plate(supports=new)).contacts
    moved = a.with_gaps([s.gap for s in new], rho=[0.0, 0.0, 1 / 80.0])
    np.testing.assert_allclose(moved.g0, b.g0, atol=1e-15)
    np.testing.assert_allclose(moved.rho, b.rho)
    assert moved.B is a.B  # shared, not rebuilt


def test_cells_centred_in_matches_the_bed():
    sc = plate(8, 8, foundation=pq.Foundation(k=10.0, region=[0.0, 0.5, 0.0, 1.0]))
    m = build_model(sc)
    cells = m.grid.cells_centred_in(0.0, 0.5, 0.0, 1.0)
    assert cells.size == 4 * 8  # the left half: 4 columns of 8 cells
    nodes = np.unique(m.grid.cell_nodes()[cells])
    w_free = np.isin(nodes * m.element.ndof_node, m.free)  # nodes with w prescribed give their force to the edge
    assert sorted(m.contacts.index[m.contacts.source == "bed"]) == sorted(nodes[w_free])


@pytest.mark.parametrize("element", ["acm", "bfs"])
def test_the_rectangular_stiffness_is_exactly_symmetric_so_its_csr_is_its_csc(element):
    """The rectangular assembly adds the (p, q) and (q, p) blocks in the same order, so K is
    symmetric value for value and ``Model.symmetric`` says so; its CSR arrays read as CSC are
    then SciPy's own conversion, bit for bit (an opening, a pin, clamped and simple edges, a
    partly kept cell pattern)."""
    import scipy.sparse as sp

    import plateqp as pq
    from plateqp.linalg.pattern import csc_of_symmetric

    sc = pq.Scene(name="sym", plate=pq.Plate(1.0, 0.8, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(12, 10, element),
                  edges={"left": "clamped", "bottom": "simple"}, openings=[pq.Opening(0.5, 0.75, 0.4, 0.64)],
                  pins=[pq.Pin(1.0, 0.8)], loads=[pq.UniformLoad(1.0)], supports=[pq.Support(0.9, 0.1, gap=0.0)])
    sc.validate()
    model = build_model(sc)
    K = model.K
    assert model.symmetric and sp.isspmatrix_csr(K)
    assert abs(K - K.T).max() == 0.0
    ref = sp.csc_matrix(K)
    ref.sort_indices()
    got = csc_of_symmetric(K, model.symmetric)
    assert np.array_equal(got.indptr, ref.indptr) and np.array_equal(got.indices, ref.indices)
    assert np.array_equal(got.data, ref.data)
    # not vouched for: converted
    Ka = sp.csr_matrix(np.array([[2.0, 1.0], [0.0, 3.0]]))
    assert np.array_equal(csc_of_symmetric(Ka, False).toarray(), Ka.toarray())
