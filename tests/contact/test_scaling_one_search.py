"""The scaled data search the contact points' neighbours once: the nearest-neighbour search of
their spacing also tells that no two of them are close enough for check_distinct_contacts to
look at (a second tree and pair search of every point: 1.2 ms of a bed's 64² solve). Points
that are that close are still found and refused. Where every point is a node of the grid, the
search runs on the grid's lattice (no tree): it finds what the tree and brute force find."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.spatial

import plateqp as pq
from plateqp.contact.scaling import Scaled
from plateqp.errors import ProblemError
from plateqp.model.assembly import build_model
from plateqp.scenes import families as F


def _counting_trees(monkeypatch) -> list:
    made = []
    real = scipy.spatial.cKDTree

    def tree(*a, **k):
        made.append(np.asarray(a[0]))
        return real(*a, **k)

    monkeypatch.setattr(scipy.spatial, "cKDTree", tree)
    return made


@pytest.mark.parametrize("scene,trees", [(F.bed(16), 0), (F.grid_rigid(16, 5), 1), (F.floating(16, 3), 1)],
                         ids=["bed", "walls", "floating"])
def test_one_search_of_the_contact_points(scene, trees, monkeypatch):
    model = build_model(scene)
    made = _counting_trees(monkeypatch)
    data = Scaled.from_model(model)
    assert data.m >= 2
    xy = model.contacts.xy
    points = [p for p in made if p.shape[0] >= data.m and np.array_equal(p[:data.m], xy)]  # not the edges'
    # every point here is a node of the grid: the lattice's search; a tree only for the points
    # with no other within a cell's reach (the posts here, a few cells apart)
    assert len(points) == trees


def test_close_points_are_still_refused(monkeypatch):
    scene = pq.Scene(name="close", plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(16, 16, "acm"),
                     loads=[pq.UniformLoad(1e3)],
                     supports=[pq.Support(x=0.5, y=0.5), pq.Support(x=0.5 + 1e-9, y=0.5), pq.Support(x=0.2, y=0.2),
                               pq.Support(x=0.8, y=0.3)])
    with pytest.raises(ProblemError, match="too stiff to tell apart"):
        Scaled.from_model(build_model(scene))


@pytest.mark.parametrize("scene", [F.bed(16), F.grid_rigid(16, 5), F.floating(16, 3)], ids=["bed", "walls", "floating"])
def test_the_spacing_is_the_nearest_point_by_brute_force(scene):
    """The bounded search finds each point's nearest other point exactly: against every distance
    computed (a point's own distance left out), walls' and pins' nodes and lines not met here
    closer than the other points (checked: the spacing is at most the nearest point's)."""
    from scipy.spatial.distance import cdist

    from plateqp.contact.scaling import contact_spacing

    model = build_model(scene)
    xy = model.contacts.xy
    nearest: list = []
    s = contact_spacing(model, nearest)
    nd = model.element.ndof_node
    held = model.fixed[model.fixed % nd == 0] // nd
    pts = np.vstack([xy, model.grid.node_xy()[held]])
    D = cdist(xy, pts)
    D[np.arange(len(xy)), np.arange(len(xy))] = np.inf
    assert np.array_equal(nearest[0], D.min(axis=1))
    assert np.all(s <= D.min(axis=1))


@pytest.mark.parametrize("nx,ny,a,b", [(12, 12, 1.0, 1.0), (10, 7, 1.3, 0.6), (9, 14, 2.0, 0.7)])
@pytest.mark.parametrize("share", [0.9, 0.2, 0.02])
def test_the_lattice_search_is_brute_force(nx, ny, a, b, share):
    """On a grid's nodes, some given twice (distance 0), some with no other point within the
    reach (inf, as the bounded search says), cells of unequal sides: every distance equals the
    brute-force one to the bit, inf exactly where that one is at or past the reach."""
    from scipy.spatial.distance import cdist

    from plateqp.model.grid import Grid

    rng = np.random.default_rng(nx * ny + int(100 * share))
    grid = Grid(a=a, b=b, nx=nx, ny=ny, cell_mask=np.ones(nx * ny, dtype=bool))
    nodes = grid.node_xy()
    pick = np.flatnonzero(rng.random(len(nodes)) < share)
    if pick.size < 3:
        pick = rng.choice(len(nodes), 3, replace=False)
    twice = rng.choice(pick, max(1, pick.size // 10), replace=False)
    held = rng.choice(len(nodes), 4, replace=False)  # nodes held, some of them contact points too
    m = pick.size + twice.size
    pts = np.vstack([nodes[pick], nodes[twice], nodes[held]])
    reach = 1.5 * max(grid.hx, grid.hy)
    got = grid.nearest_other(pts, m, reach)
    D = cdist(pts[:m], pts)
    D[np.arange(m), np.arange(m)] = np.inf
    want = D.min(axis=1)
    assert np.array_equal(np.isinf(got), want >= reach)
    assert np.array_equal(got[~np.isinf(got)], want[~np.isinf(got)])
    assert np.any(got == 0.0)


def test_the_lattice_search_leaves_lone_points_to_the_tree():
    """Points with no other within the reach: inf from the lattice, and the spacing then the
    unbounded search's, as brute force has it."""
    from plateqp.model.grid import Grid

    grid = Grid(a=1.0, b=1.0, nx=12, ny=12, cell_mask=np.ones(144, dtype=bool))
    nodes = grid.node_xy()
    pts = nodes[[0, 6, 100, 101]]
    got = grid.nearest_other(pts, 4, 1.5 * grid.hx)
    step = abs(pts[3, 0] - pts[2, 0])  # (10 h − 9 h as the coordinates have it)
    assert np.isinf(got[:2]).all() and np.array_equal(got[2:], [step, step])


def test_the_lattice_search_declines_points_off_the_nodes():
    from plateqp.model.grid import Grid

    grid = Grid(a=1.0, b=1.0, nx=8, ny=8, cell_mask=np.ones(64, dtype=bool))
    pts = grid.node_xy()[:5].copy()
    assert grid.nearest_other(pts, 5, 0.2) is not None
    pts[2, 0] += 1e-12  # a hair off its node: the tree decides
    assert grid.nearest_other(pts, 5, 0.2) is None
    assert grid.nearest_other(grid.node_xy()[:5] + 2.0, 5, 0.2) is None  # off the grid
