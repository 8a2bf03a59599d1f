"""QP export on triangle meshes: the contact problem of a shaped (DKT) scene,
written as ``.npz`` and QPS, read back and solved by an independent solver (Clarabel, called
directly on the loaded matrices), gives pq.solve's reactions, and the reactions of a floating
disc balance the load (statics: their sum is the total load q × the mesh's area, their moment
about the centre vanishes).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.sparse as sp

import plateqp as pq
from plateqp.io import contact_qp, read_qps
from plateqp.io.npz import npz_arrays, write_npz
from plateqp.io.qps import write_qps

pytest.importorskip("gmsh")
clarabel = pytest.importorskip("clarabel")

R, Q = 1.0, 3.0


def posts(edge=None) -> pq.Scene:
    """A disc on three rigid posts at 120° (r = 0.7) and a central elastic one; free (floating)
    or with an edge support; a square hole off-centre."""
    sup = [pq.Support(0.7 * math.cos(t), 0.7 * math.sin(t), gap=0.0)
           for t in np.radians([90.0, 210.0, 330.0])] + [pq.Support(0.0, 0.0, gap=1e-4, stiffness=5e3)]
    return pq.Scene(name="posts", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.05, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=R / 6), edges={"all": pq.Edge(edge)} if edge else {},
                    holes=[{"polygon": [[0.2, -0.5], [0.4, -0.5], [0.4, -0.3], [0.2, -0.3]]}],
                    loads=[pq.UniformLoad(Q)], supports=sup)


def clarabel_solve(P, q, G=None, h=None, lb=None):
    """½ xᵀPx + qᵀx s.t. G x ≤ h, x ≥ lb, by Clarabel's own interface: (x, multipliers of G, of lb)."""
    n = q.size
    rows, rhs = [], []
    if G is not None:
        rows.append(sp.csc_matrix(G))
        rhs.append(h)
    if lb is not None:
        rows.append(-sp.identity(n, format="csc"))
        rhs.append(-lb)
    A = sp.vstack(rows).tocsc()
    st = clarabel.DefaultSettings()
    st.verbose = False
    st.tol_gap_abs = st.tol_gap_rel = st.tol_feas = 1e-12
    sol = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(P)).tocsc(), q, A, np.concatenate(rhs),
                                 [clarabel.NonnegativeConeT(A.shape[0])], st).solve()
    assert "Solved" in str(sol.status)
    z = np.array(sol.z)
    mG = 0 if G is None else G.shape[0]
    return np.array(sol.x), z[:mG], z[mG:]


def reactions_of(form, arrays, meta):
    """The reactions in user units from an independent solve of the loaded problem."""
    F0 = meta["F0"]
    if form == "primal":
        _, zG, _ = clarabel_solve(arrays["P"], arrays["q"], arrays["G"], arrays["h"])
        return F0 * zG
    x, _, _ = clarabel_solve(arrays["P"], arrays["q"], lb=arrays["lb"])
    if form == "condensed":
        return F0 * (arrays["P"] @ x + arrays["q"])
    return F0 * x


@pytest.mark.parametrize("edge, form", [(None, "primal"), (None, "condensed"), ("simple", "primal"),
                                        ("simple", "condensed"), ("simple", "dual")])
def test_exported_triangle_qp_solved_elsewhere(tmp_path, edge, form):
    sc = posts(edge)
    e = contact_qp(sc, form)
    assert e.meta["mesh"]["element"] == "dkt" and e.meta["mesh"]["triangles"] == len(e.model.grid.triangles)
    path = write_npz(e, tmp_path / "p.npz")
    arrays = npz_arrays(path)
    meta = json.loads(arrays["meta"])
    R_ext = reactions_of(form, arrays, meta)
    ref = pq.solve(sc, formulation=form, accuracy="high")
    assert ref.kkt.ok
    np.testing.assert_allclose(R_ext, ref.reactions, rtol=0, atol=1e-6 * np.abs(ref.reactions).max())
    if edge is None:  # statics: the supports carry all the load, with no moment about the centre
        total = Q * e.model.grid.areas().sum()
        assert total == pytest.approx(Q * (math.pi * R**2 - 0.04), rel=0.01)  # the mesh's area: chords
        assert R_ext.sum() == pytest.approx(total, rel=1e-7)
        xy = np.array([[s.x, s.y] for s in sc.supports])
        c = e.model.grid.nodes[e.model.grid.triangles].mean(axis=1)  # the load's moment: area × centroid
        load_moment = Q * (e.model.grid.areas()[:, None] * c).sum(axis=0)
        np.testing.assert_allclose(R_ext @ xy, load_moment, atol=1e-7 * total)


def test_exported_triangle_qps_round_trip(tmp_path):
    """The QPS file of a triangle scene reads back as the same QP, names and all."""
    e = contact_qp(posts("simple"), "primal")
    path = write_qps(e, tmp_path / "p.qps")
    qp, info = read_qps(path, with_info=True)
    assert qp.n == e.qp.n and info.name == e.name
    x, zG, _ = clarabel_solve(qp.P, qp.q, qp.G, qp.h)
    ref = pq.solve(posts("simple"), formulation="primal", accuracy="high")
    np.testing.assert_allclose(e.meta["F0"] * zG, ref.reactions, atol=1e-6 * ref.reactions.max())


def test_cli_export_circle(tmp_path, capsys):
    from plateqp.cli import main

    scene = tmp_path / "posts.toml"
    posts().to_toml(scene)
    assert main(["export", str(scene), "--formulation", "condensed", "--out", str(tmp_path / "x.qps")]) == 0
    assert read_qps(tmp_path / "x.qps").n == 4
