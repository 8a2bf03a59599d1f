"""The scaled data search the contact points' neighbours once: the nearest-neighbour search of
their spacing also tells that no two of them are close enough for check_distinct_contacts to
look at (a second tree and pair search of every point: 1.2 ms of a bed's 64² solve). Points
that are that close are still found and refused."""

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


@pytest.mark.parametrize("scene", [F.bed(16), F.grid_rigid(16, 5), F.floating(16, 3)], ids=["bed", "walls", "floating"])
def test_one_search_of_the_contact_points(scene, monkeypatch):
    model = build_model(scene)
    made = _counting_trees(monkeypatch)
    data = Scaled.from_model(model)
    assert data.m >= 2
    xy = model.contacts.xy
    points = [p for p in made if p.shape[0] >= data.m and np.array_equal(p[:data.m], xy)]  # not the edges'
    assert len(points) == 1


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
