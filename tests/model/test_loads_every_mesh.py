"""One load integration on every mesh: uniform, patch and point loads through the element's cell
protocol (``cell_load``, ``region_load``, ``basis``), checked by statics and between meshes.

A patch load [x0, x1] × [y0, y1] is integrated exactly over the parts of the cells it covers (on
triangles each triangle clipped by the box): its total is q × the patch's area on the plate,
exactly, and its moment that of the pressure. External references: the patch's area and centroid
by elementary geometry; Navier's double series for a simply supported rectangle under a
rectangular patch (Timoshenko & Woinowsky-Krieger, Theory of plates and shells, § 30, eq. 137).
"""

import warnings

import numpy as np
import pytest

import plateqp as pq
from plateqp.model.assembly import build_model
pytest.importorskip("gmsh")

BOX = (0.3, 0.9, 0.2, 0.7)  # a patch with no side on a grid line of 8 or 16 cells
Q = 2.0
SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]


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


def load_resultant(model):
    """Total force and its centroid: the work of the loads in a rigid translation w = 1 and in
    the rigid rotations w = x, w = y (nodal slopes 1 where the element carries them)."""
    names = list(model.element.dof_names)
    f = model.f_full.reshape(-1, len(names))
    xy = model.grid.node_xy()
    F = f[:, 0].sum()
    mx = f[:, 0] @ xy[:, 0] + f[:, names.index("wx")].sum()
    my = f[:, 0] @ xy[:, 1] + f[:, names.index("wy")].sum()
    return F, np.array([mx, my]) / F


def patch_scene(element, box, holes=(), n=16, **kw) -> pq.Scene:
    """The unit square under Q on ``box``: n × n cells, or triangles of size 1/n on the square
    given as a polygon (with ``holes``)."""
    if element != "dkt":
        return square(element, [pq.PatchLoad(Q, *box)], n=n, **kw)
    return pq.Scene(name="sq", plate=pq.Plate(shape={"polygon": SQ}, h=0.01, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=1 / n), loads=[pq.PatchLoad(Q, *box)],
                    holes=[{"polygon": h} for h in holes], **kw)


def w_rows_resultant(model):
    """On triangles: total force and centroid from the w rows of f alone."""
    f = model.f_full[0::3]
    return f.sum(), (f[:, None] * model.grid.nodes).sum(axis=0) / f.sum()


# (box, its area on the plate, its centroid, holes)
PATCHES = {"inside": ((0.3, 0.55, 0.2, 0.45), 0.0625, (0.425, 0.325), []),  # its outline cutting cells
           "over-a-corner": ((0.8, 1.4, -0.2, 0.3), 0.2 * 0.3, (0.9, 0.15), [])}  # the part on the plate
AROUND_A_HOLE = ((0.2, 0.8, 0.2, 0.8), 0.36 - 0.04, (0.5 - 0.04 * 0.1 / 0.32, 0.5),
                 [[[0.5, 0.4], [0.7, 0.4], [0.7, 0.6], [0.5, 0.6]]])  # a hole: triangles only


@pytest.mark.parametrize("element, box, area, centroid, holes",
                         [pytest.param(el, *p, id=f"{el}-{name}") for el in ("acm", "bfs", "dkt")
                          for name, p in PATCHES.items()] + [pytest.param("dkt", *AROUND_A_HOLE, id="dkt-around-a-hole")])
def test_patch_total_is_q_times_its_area_exactly(element, box, area, centroid, holes):
    F, c = load_resultant(build_model(patch_scene(element, box, holes)))
    assert F == pytest.approx(Q * area, rel=1e-12)
    np.testing.assert_allclose(c, centroid, atol=1e-12)


def test_patch_on_triangles_is_carried_by_the_w_rows():
    """On triangles the patch's total and centroid are those of the w rows of f alone."""
    for box, area, centroid, holes in [*PATCHES.values(), AROUND_A_HOLE]:
        F, c = w_rows_resultant(build_model(patch_scene("dkt", box, holes)))
        assert F == pytest.approx(Q * area, rel=1e-12)
        np.testing.assert_allclose(c, centroid, atol=1e-12)


def navier_patch(x, y, box, D, q=Q, a=1.0, b=1.0, n=301):
    """SS rectangle under q on the patch of centre (ξ, η) and sides u × v (Timoshenko § 30):
    q_mn = 16 q / (π² m n) sin(mπξ/a) sin(mπu/2a) sin(nπη/b) sin(nπv/2b),
    w = Σ q_mn sin(mπx/a) sin(nπy/b) / (π⁴ D (m²/a² + n²/b²)²)."""
    x0, x1, y0, y1 = box
    xi, eta, u, v = (x0 + x1) / 2, (y0 + y1) / 2, x1 - x0, y1 - y0
    m = np.arange(1, n + 1)[:, None]
    k = np.arange(1, n + 1)[None, :]
    qmn = 16 * q / (np.pi**2 * m * k) * np.sin(m * np.pi * xi / a) * np.sin(m * np.pi * u / (2 * a)) \
        * np.sin(k * np.pi * eta / b) * np.sin(k * np.pi * v / (2 * b))
    return float(np.sum(qmn * np.sin(m * np.pi * x / a) * np.sin(k * np.pi * y / b)
                        / (np.pi**4 * D * (m**2 / a**2 + k**2 / b**2) ** 2)))


@pytest.mark.parametrize("element", ["acm", "dkt"])
def test_patch_on_a_simply_supported_square_against_navier(element):
    """An off-centre patch: w within 0.7 % of Navier's series at four points on h = 1/16 (16²
    cells or triangles of size 1/16), and the error converging with order ≈ 2 in h (ACM, DKT)."""
    box = (0.3, 0.55, 0.2, 0.45)
    pts = [(0.5, 0.5), (0.425, 0.325), (0.2, 0.7), (0.8, 0.3)]
    errs = []
    for n in (8, 16, 32):
        res = pq.solve(patch_scene(element, box, n=n, edges={"all": pq.Edge("simple")}))
        ref = np.array([navier_patch(x, y, box, res.scene.plate.D) for x, y in pts])
        errs.append(np.abs(res.deflection(*np.array(pts).T) / ref - 1).max())
    assert errs[1] < 0.007 and errs[2] < 0.002
    order = np.polyfit(np.log([1 / 8, 1 / 16, 1 / 32]), np.log(errs), 1)[0]
    assert 1.6 < order < 2.6, (errs, order)


def test_patch_on_a_triangle_meshed_rectangle():
    """The same patch on a rectangle (a, b; no shape) meshed with triangles: the same answer as
    Navier (the rectangle's edge names)."""
    box = (0.3, 0.55, 0.2, 0.45)
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0, h=0.01, E=1e7, nu=0.3), mesh=pq.MeshSpec(element="dkt", size=1 / 16),
                  edges={k: "simple" for k in ("left", "right", "bottom", "top")}, loads=[pq.PatchLoad(Q, *box)])
    res = pq.solve(sc)
    assert res.deflection(0.5, 0.5) == pytest.approx(navier_patch(0.5, 0.5, box, sc.plate.D), rel=0.007)


def test_patch_anywhere_on_a_disc():
    """A disc centred at the origin (triangles): a patch at negative x (left of the bounding box's
    corner) is on the plate; its total is q × its area exactly, its centroid the patch's."""
    sc = pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.01, E=1e7, nu=0.3),
                  mesh=pq.MeshSpec(element="dkt", size=1 / 8), edges={"all": "clamped"},
                  loads=[pq.PatchLoad(Q, -0.9, -0.5, -0.2, 0.2)])
    model = build_model(sc)
    for F, c in (w_rows_resultant(model), load_resultant(model)):
        assert F == pytest.approx(Q * 0.4 * 0.4, rel=1e-12)
        np.testing.assert_allclose(c, (-0.7, 0.0), atol=1e-12)
