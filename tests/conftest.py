"""Shared test helpers (kept minimal): a builder for rectangular plate scenes."""

from __future__ import annotations

import pytest

import plateqp as pq

EDGES = ("left", "right", "bottom", "top")


def rect_scene(element="acm", nx=8, ny=None, edges="simple", loads=(), *, a=1.0, b=1.0, h=0.01,
               E=1.0e7, nu=0.3, **kw) -> pq.Scene:
    """A rectangle [0, a] × [0, b] on an nx × ny mesh.

    ``edges``: one kind for all four edges (str), or a dict {edge name: kind or Edge}.
    Further keyword arguments (openings, pins, supports, ...) go to :class:`plateqp.Scene`.
    """
    if isinstance(edges, str):
        edges = {k: edges for k in EDGES}
    edges = {k: (v if isinstance(v, pq.Edge) else pq.Edge(v)) for k, v in edges.items()}
    return pq.Scene(plate=pq.Plate(a=a, b=b, h=h, E=E, nu=nu),
                    mesh=pq.MeshSpec(nx, nx if ny is None else ny, element),
                    edges=edges, loads=list(loads), **kw)


@pytest.fixture
def make_scene():
    """The :func:`rect_scene` builder, as a fixture."""
    return rect_scene


@pytest.fixture(scope="session")
def solved():
    """``solved(**kw)``: pq.solve(rect_scene(**kw)), cached for the session (treat as read-only)."""
    cache: dict[str, pq.Result] = {}

    def get(**kw) -> pq.Result:
        key = repr(sorted(kw.items()))
        if key not in cache:
            cache[key] = pq.solve(rect_scene(**kw))
        return cache[key]

    return get
