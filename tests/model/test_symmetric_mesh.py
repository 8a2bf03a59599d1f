"""A symmetric plate meshed symmetrically (``[mesh] symmetry``): one part of the plate meshed by
gmsh and mirrored in the plate's centre lines.

References: exact properties. The mesh's mirror image is the mesh itself, node for node to the
last bit and triangle for triangle; a symmetric scene on a symmetric mesh is a symmetric discrete
problem, so mirrored posts carry equal reactions and mirrored points deflect equally (to rounding);
statics (the posts of a floating plate carry q times the meshed area, and its moment); the answer
on the mirrored mesh and on gmsh's whole-plate mesh are two discretisations of one plate, as near
each other as a mesh is to the mesh of half its size; an asymmetric scene cannot be meshed
symmetrically and is refused naming its first asymmetric item.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import plateqp as pq
from plateqp import scenes
from plateqp.errors import SceneError
from plateqp.model.paths import get_param, set_param

pytest.importorskip("gmsh")

from plateqp.model.trimesh import TriMesh


def ring(n, r, phase=0.0):
    return [(r * math.cos(phase + 2 * math.pi * k / n), r * math.sin(phase + 2 * math.pi * k / n)) for k in range(n)]


def disc_scene(symmetry="xy", points=None, **kw):
    """A unit disc on 1 + 8 + 4 posts (symmetric about both axes), uniform load, free edge."""
    points = points if points is not None else [(0.0, 0.0)] + ring(8, 0.5) + ring(4, 0.85, math.pi / 4)
    mesh = pq.MeshSpec(element="dkt", size=0.125, symmetry=symmetry)
    base = {"name": "disc", "plate": pq.Plate(h=0.1, E=3e7, nu=0.3, shape={"circle": [0.0, 0.0, 1.0]}),
                "mesh": mesh, "loads": [pq.UniformLoad(q=1000.0)], "supports": [pq.Support(x=x, y=y) for x, y in points]}
    return pq.Scene(**(base | kw))


def slab_scene(symmetry="x", **kw):
    """A 4 x 2 slab (its centre lines x = 2, y = 1): a round hole on both centre lines, two mirrored
    openings, posts in mirrored pairs and on the lines, a pin, a point load, and a bed whose
    outline is drawn into the mesh."""
    mesh = pq.MeshSpec(element="dkt", size=0.2, symmetry=symmetry)
    supports = [(0.5, 0.25), (3.5, 0.25), (0.5, 1.75), (3.5, 1.75), (2.0, 0.2), (2.0, 1.8), (1.1, 1.0), (2.9, 1.0)]
    base = {"name": "slab", "plate": pq.Plate(h=0.2, E=3e7, nu=0.2, shape={"polygon": [[0, 0], [4, 0], [4, 2], [0, 2]]}),
                "mesh": mesh, "edges": {"outer_1": "simple", "outer_3": "simple"},
                "holes": [{"circle": [2.0, 1.0, 0.3]}],
                "openings": [pq.Opening(0.5, 0.9, 0.6, 1.4), pq.Opening(3.1, 3.5, 0.6, 1.4)],
                "pins": [pq.Pin(2.0, 0.6), pq.Pin(2.0, 1.4)],
                "loads": [pq.UniformLoad(q=500.0), pq.PointLoad(P=100.0, x=1.5, y=1.0), pq.PointLoad(P=100.0, x=2.5, y=1.0)],
                "supports": [pq.Support(x=x, y=y, gap=0.0001) for x, y in supports],
                "foundation": pq.Foundation(k=1e5, region={"polygon": [[1.2, 0.1], [2.8, 0.1], [2.8, 1.9], [1.2, 1.9]]})}
    base.update(kw)
    return pq.Scene(**base)


def hexagon_scene(dx=-10.0, dy=-5.0):
    """A hexagon centred at (dx, dy) (lines at negative coordinates: the part kept is the one
    below and left of them), vertices and posts on the lines, openings across the line x = dx,
    a bed box across both."""
    hexa = [[-3, -1], [-1, -2], [1, -2], [3, -1], [3, 1], [1, 2], [-1, 2], [-3, 1]]
    posts = [(0, 2), (0, -2), (3, 0), (-3, 0), (1, 0.5), (-1, 0.5), (1, -0.5), (-1, -0.5)]
    return pq.Scene(plate=pq.Plate(h=0.2, E=3e7, nu=0.2, shape={"polygon": [[x + dx, y + dy] for x, y in hexa]}),
                    mesh=pq.MeshSpec(element="dkt", size=0.25, symmetry="xy"), loads=[pq.UniformLoad(1.0)],
                    openings=[pq.Opening(dx - 0.5, dx + 0.5, dy + 0.8, dy + 1.2), pq.Opening(dx - 0.5, dx + 0.5, dy - 1.2, dy - 0.8)],
                    supports=[pq.Support(x=x + dx, y=y + dy) for x, y in posts],
                    foundation=pq.Foundation(k=10.0, region=[dx - 2, dx + 2, dy - 1.5, dy + 1.5]))


def mirrored(nodes, axis, c):
    out = nodes.copy()
    out[:, axis] = 2 * c - nodes[:, axis]
    return out


def assert_mirror_symmetric(mesh, axis, c):
    """The mesh's mirror image in the line (coordinate ``axis``) = c is the mesh: every node's
    image is a node bit for bit, every triangle's image a triangle, every boundary edge's image a
    boundary edge of the mirrored boundary and segment."""
    key = {p.tobytes(): i for i, p in enumerate(mesh.nodes)}
    assert len(key) == mesh.n_nodes  # no two nodes at one point
    image = np.array([key.get(p.tobytes(), -1) for p in mirrored(mesh.nodes, axis, c)])
    assert (image >= 0).all(), f"{(image < 0).sum()} nodes without a mirror image"
    on = mesh.nodes[:, axis] == c
    assert (image[on] == np.flatnonzero(on)).all() and on.sum() > 0  # the nodes on the line stay
    tris = {frozenset(t) for t in mesh.triangles.tolist()}
    assert {frozenset(t) for t in image[mesh.triangles].tolist()} == tris
    edges = {frozenset(e) for e in mesh.edges.tolist()}
    assert {frozenset(e) for e in image[mesh.edges].tolist()} == edges


@pytest.mark.parametrize("make, lines", [
    (lambda: disc_scene("y"), [(1, 0.0)]),
    (lambda: disc_scene("x"), [(0, 0.0)]),
    (lambda: disc_scene("xy"), [(0, 0.0), (1, 0.0)]),
    (lambda: slab_scene("x"), [(0, 2.0)]),
    (lambda: slab_scene("xy"), [(0, 2.0), (1, 1.0)]),
    (hexagon_scene, [(0, -10.0), (1, -5.0)]),
], ids=["disc-y", "disc-x", "disc-xy", "slab-x", "slab-xy", "hexagon-xy"])
def test_the_mesh_is_its_own_mirror_image_bit_for_bit(make, lines):
    mesh = TriMesh.from_scene(make())
    assert np.all(mesh.areas() > 0)
    for axis, c in lines:
        assert_mirror_symmetric(mesh, axis, c)
    # every boundary edge once, a closed loop; outward unit normals
    assert np.all(np.bincount(mesh.edges.ravel())[np.unique(mesh.edges)] == 2)
    mid = 0.5 * (mesh.nodes[mesh.edges[:, 0]] + mesh.nodes[mesh.edges[:, 1]])
    assert np.allclose(np.hypot(*mesh.normals.T), 1.0)
    step = mesh.size / 4  # beyond a chord's sagitta
    assert not mesh.domain.covers(*(mid + step * mesh.normals).T).any()
    assert mesh.domain.covers(*(mid - step * mesh.normals).T).all()


def test_the_boundary_names_are_those_of_the_whole_plate_mesh():
    """Each boundary and polygon segment has the same length on the mirrored mesh and on gmsh's
    whole-plate mesh (polygons: exact), so edge names hold the same edges."""
    sym, whole = TriMesh.from_scene(slab_scene("xy")), TriMesh.from_scene(slab_scene(None))

    def lengths(m, circles=False):
        d = np.hypot(*(m.nodes[m.edges[:, 1]] - m.nodes[m.edges[:, 0]]).T)
        keep = (m.boundary == 1) if circles else (m.boundary != 1)
        return {(int(k), int(s)): float(d[(m.boundary == k) & (m.segment == s) & keep].sum())
                for k, s in set(zip(m.boundary.tolist(), m.segment.tolist()))}

    a, b = lengths(sym), lengths(whole)
    assert a.keys() == b.keys() and len(a) == 4 + 1 + 8
    for k in a:
        assert a[k] == pytest.approx(b[k], rel=1e-12), k
    assert sum(lengths(sym, True).values()) == pytest.approx(2 * math.pi * 0.3, rel=1e-2)  # the hole, boundary 1


def test_the_mirrored_mesh_is_as_well_shaped_as_the_whole_plate_mesh():
    """No sliver along the mirror lines: the smallest angle, over all triangles and over those
    with a corner on a line, near that of gmsh's mesh of the whole plate."""
    def angles(m):
        p = m.nodes[m.triangles]
        e = [p[:, (i + 1) % 3] - p[:, i] for i in range(3)]
        ang = [np.degrees(np.arccos(np.clip(-np.einsum("ij,ij->i", e[i - 1], e[i])
                                            / np.hypot(*e[i - 1].T) / np.hypot(*e[i].T), -1, 1))) for i in range(3)]
        return np.min(ang, axis=0)

    for make, centre in ((disc_scene, (0.0, 0.0)), (slab_scene, (2.0, 1.0))):
        sym, whole = TriMesh.from_scene(make("xy")), TriMesh.from_scene(make(None))
        a, a0 = angles(sym), angles(whole)
        p = sym.nodes[sym.triangles]
        on_line = ((p[:, :, 0] == centre[0]) | (p[:, :, 1] == centre[1])).any(axis=1)
        assert a.min() >= 0.8 * a0.min() and a[on_line].min() >= 0.8 * a0.min()
        assert np.percentile(a, 1) >= 0.8 * np.percentile(a0, 1)
        assert abs(sym.n_nodes / whole.n_nodes - 1) < 0.2  # the same size of mesh


@pytest.fixture(scope="module")
def tanks():
    """The tank (19 posts, heave on the side x > 0: symmetric about the line y = 0) on gmsh's
    whole-plate mesh, on the mirrored mesh, and on the mirrored mesh of half the size."""
    base = scenes.load("tank")
    whole = set_param(base, "mesh.symmetry", "none")
    sym = set_param(base, "mesh.symmetry", "y")
    fine = set_param(sym, "mesh.size", sym.mesh.size / 2)
    return {k: pq.solve(s, accuracy="high") for k, s in (("whole", whole), ("sym", sym), ("fine", fine))}


def tank_mirror(scene):
    xy = np.array([[s.x, s.y] for s in scene.supports])
    return xy, np.array([int(np.argmin(np.hypot(xy[:, 0] - x, xy[:, 1] + y))) for x, y in xy])


def test_mirrored_posts_on_the_tank_agree_to_rounding(tanks):
    res = tanks["sym"]
    assert res.scene.mesh.symmetry == "y" and res.ok and res.kkt.ok
    _xy, mirror = tank_mirror(res.scene)
    assert (mirror != np.arange(len(mirror))).sum() == 14  # 7 mirrored pairs, 5 posts on the line
    R = res.reactions
    np.testing.assert_allclose(R[mirror], R, rtol=1e-10, atol=1e-10 * R.max())
    assert (res.active == res.active[mirror]).all()
    pts = np.array([[120.0, 35.0], [-300.0, 150.0], [410.0, 90.0], [0.0, 480.0], [250.0, 250.0]])
    w = res.deflection(pts[:, 0], pts[:, 1])
    w_image = res.deflection(pts[:, 0], -pts[:, 1])
    np.testing.assert_allclose(w_image, w, rtol=1e-10, atol=1e-10 * np.abs(w).max())
    # gmsh's whole-plate mesh is not symmetric: there the posts agree only to the discretisation
    R0 = tanks["whole"].reactions
    assert np.abs(R0[mirror] - R0).max() > 1e-6 * R0.max()


def test_the_mirrored_tank_keeps_statics_and_agrees_with_the_whole_plate_mesh(tanks):
    res = tanks["sym"]
    mesh, q = res.model.grid, res.scene.loads[0].q
    area = mesh.areas()
    F = q * area.sum()
    centroid = (mesh.nodes[mesh.triangles].mean(axis=1) * area[:, None]).sum(axis=0)
    xy, _ = tank_mirror(res.scene)
    assert res.reactions.sum() == pytest.approx(F, rel=1e-8)
    np.testing.assert_allclose(res.reactions @ xy, q * centroid, atol=1e-8 * F * 500)
    assert abs(centroid[1]) <= 1e-12 * F * 500  # the meshed area itself is symmetric
    # two meshes of one size differ by less than a mesh differs from the mesh of half its size
    R, R0, Rf = res.reactions, tanks["whole"].reactions, tanks["fine"].reactions
    assert np.abs(R - R0).max() < np.abs(R - Rf).max()
    assert (res.active == tanks["whole"].active).all() and list(np.flatnonzero(~res.active) + 1) == [2, 3, 7, 10, 18]


def test_a_symmetric_rectangle_on_the_grid_is_accepted():
    """On the grid of equal cells the mesh is symmetric whenever the scene is: the option checks
    the scene and the mirrored posts agree to rounding."""
    posts = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75), (0.5, 0.5), (0.5, 0.1)]
    sc = pq.Scene(plate=pq.Plate(a=1.0, b=1.0), mesh=pq.MeshSpec(nx=16, ny=16, element="acm", symmetry="x"),
                  loads=[pq.UniformLoad(q=1.0), pq.PointLoad(P=0.1, x=0.3, y=0.6), pq.PointLoad(P=0.1, x=0.7, y=0.6)],
                  supports=[pq.Support(x=x, y=y, gap=1e-6 * y) for x, y in posts])
    res = pq.solve(sc, accuracy="high")
    R = res.reactions
    np.testing.assert_allclose(R[[1, 0, 3, 2, 4, 5]], R, rtol=1e-10, atol=1e-12 * R.max())
    with pytest.raises(SceneError, match=r"mesh\.symmetry: supports\.6 "):
        set_param(sc, "supports.6.x", 0.4)


@pytest.mark.parametrize("change, item", [
    ({"supports": [pq.Support(0.0, 0.0), pq.Support(0.5, 0.1), pq.Support(-0.5, 0.1)]}, None),
    ({"supports": [pq.Support(0.0, 0.0), pq.Support(0.5, 0.1)]}, "supports.2"),
    ({"pins": [pq.Pin(0.3, 0.3)]}, "pins.0"),
    ({"loads": [pq.UniformLoad(q=1.0), pq.PointLoad(P=1.0, x=0.2, y=-0.6)]}, "loads.1"),
    ({"holes": [{"circle": [0.3, 0.0, 0.1]}]}, "holes.0"),
    ({"openings": [pq.Opening(-0.6, -0.4, -0.1, 0.1)]}, "openings.0"),
    ({"foundation": pq.Foundation(k=1.0, region=[0.0, 0.5, -0.5, 0.5])}, "foundation.region"),
])
def test_an_asymmetric_scene_is_refused_naming_its_first_asymmetric_item(change, item):
    """Mirrored in the line x = 0 (``symmetry = "x"``): the pair (0.5, 0.1), (-0.5, 0.1) is
    symmetric; everything else here is not."""
    kw = {"supports": [pq.Support(0.0, 0.0)]} | change
    points = [(s.x, s.y) for s in kw.pop("supports")]
    if item is None:
        assert disc_scene("x", points=points, **kw).mesh.symmetry == "x"
        return
    with pytest.raises(SceneError) as exn:
        disc_scene("x", points=points, **kw)
    msg = str(exn.value)
    assert msg.startswith(f"mesh.symmetry: {item} ") and "\n" not in msg and "x = 0" in msg


def test_an_asymmetric_outline_and_a_bad_spelling_are_refused():
    L = {"polygon": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}
    sc = pq.Scene(plate=pq.Plate(shape=L), mesh=pq.MeshSpec(element="dkt", size=0.25))
    with pytest.raises(SceneError, match=r"^mesh\.symmetry: plate\.shape .*x = 1"):
        set_param(sc, "mesh.symmetry", "x")
    for bad in ("z", "yx", 1, ["x"]):
        with pytest.raises(SceneError, match=r'^mesh\.symmetry: must be "x"'):
            pq.Scene(plate=pq.Plate(shape=L), mesh=pq.MeshSpec(element="dkt", size=0.25, symmetry=bad))


def test_the_option_round_trips_through_toml_and_scene_paths(tmp_path):
    sc = slab_scene("xy")
    text = sc.to_toml(tmp_path / "slab.toml")
    assert 'symmetry = "xy"' in text
    back = pq.Scene.from_toml(tmp_path / "slab.toml")
    assert back.mesh == sc.mesh and get_param(back, "mesh.symmetry") == "xy"
    off = set_param(back, "mesh.symmetry", "none")
    assert off.mesh.symmetry is None and "symmetry" not in off.to_toml()
    assert set_param(off, "mesh.symmetry", "y").mesh.symmetry == "y"
