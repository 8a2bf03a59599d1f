"""One load integration on every mesh: uniform, patch and point loads through the element's cell
protocol (``cell_load``, ``region_load``, ``basis``), checked by statics and between meshes."""

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
pytest.importorskip("gmsh")

BOX = (0.3, 0.9, 0.2, 0.7)  # a patch with no side on a grid line of 8 or 16 cells


def square(element, loads, n=16, **kw):
    mesh = pq.MeshSpec(n, n, element) if element != "dkt" else pq.MeshSpec(element="dkt", size=1.0 / n)
    return pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.02, E=1e7, nu=0.3), mesh=mesh, loads=loads, **kw)


@pytest.mark.parametrize("element", ["acm", "bfs", "dkt"])
def test_load_vectors_are_statically_exact(element):
    """Σ of the w-dof loads is the total force and Σ x·f its moment, for each load alone:
    q × the area, q × the patch's area (cut across cells), P."""
    xy = None
    for ld, force, xc in ((pq.UniformLoad(3.0), 3.0, 0.5), (pq.PatchLoad(2.0, *BOX), 2.0 * 0.6 * 0.5, 0.6),
                          (pq.PointLoad(5.0, 0.37, 0.61), 5.0, 0.37)):
        m = build_model(square(element, [ld], supports=[pq.Support(0.37, 0.61)]))
        nd = m.element.ndof_node
        f = m.load_vector(m.scene)
        if xy is None:
            xy = m.grid.node_xy()
        fw = f[0::nd][: len(xy)]
        assert fw.sum() == pytest.approx(force, rel=1e-12)
        # the moment about y: the work of the loads on the rigid rotation w = x (w,x = 1 at every
        # node): Σ x f_w + Σ f_wx (a consistent load's couples on the slope dofs)
        couple = f[1::nd][: len(xy)].sum()
        assert (xy[:, 0] * fw).sum() + couple == pytest.approx(force * xc, rel=1e-12)


def test_a_patch_load_is_the_same_plate_on_every_mesh():
    """A simply supported square under a patch: w at the centre on ACM and BFS 32², and DKT
    (h = 1/32), within 1 % of each other."""
    w = {}
    for element in ("acm", "bfs", "dkt"):
        sc = square(element, [pq.PatchLoad(1.0, *BOX)], n=32, edges={"all": pq.Edge("simple")})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pq.PlateQPWarning)
            w[element] = pq.solve(sc).deflection(0.5, 0.5)
    assert w["acm"] == pytest.approx(w["dkt"], rel=0.01) and w["bfs"] == pytest.approx(w["dkt"], rel=0.01)


def test_load_sensitivities_on_triangles():
    """dR/dλ_j of each load factor on a DKT plate on three posts (no gaps, so R is linear in
    the load factors for the contact set: R = Σ_j dR/dλ_j exactly), each column in vertical
    equilibrium with its load alone."""
    loads = [pq.UniformLoad(2.0), pq.PatchLoad(3.0, *BOX), pq.PointLoad(1.5, 0.6, 0.4)]
    posts = [pq.Support(0.2, 0.2), pq.Support(0.8, 0.25), pq.Support(0.5, 0.8)]
    res = pq.solve(square("dkt", loads, n=8, supports=posts), accuracy="high")
    S = pq.sensitivity(res, "loads")
    assert np.allclose(S.reactions.sum(axis=1), res.reactions, rtol=1e-9, atol=1e-9 * res.reactions.max())
    assert np.allclose(S.reactions.sum(axis=0), [2.0, 3.0 * 0.6 * 0.5, 1.5], rtol=1e-9)
