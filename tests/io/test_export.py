"""The exported contact problem (plateqp.io.export) and the ``plateqp export`` command.

The exported QP must be the very one a QP backend is handed; the command writes it where asked
(the file-safety cases are in tests/io/test_files.py). The external references (HiGHS on the QPS
files, Clarabel on the .npz) are in tests/io/test_qps.py and tests/io/test_qpbenchmark.py; here
Clarabel, called directly on the matrices read back from ``.npz`` and QPS files, solves the
problem of a scene on the rectangle grid and of a shaped scene on triangles (DKT), and gives
pq.solve's reactions; the reactions of a floating disc balance the load (statics: their sum is
the total load q × the mesh's area, their moment about the centre vanishes).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.sparse as sp
from io_reference import exported_problems, run_cli, small_scene

import plateqp as pq
from plateqp import scenes
from plateqp.io import contact_qp, read_qps
from plateqp.io.npz import npz_arrays, write_npz
from plateqp.io.qps import write_qps


@pytest.fixture(scope="module")
def exported():
    """{form: (ExportedQP, plateqp reference Result)} for the small scene."""
    return exported_problems()


def test_contact_qp_is_the_backends_problem(exported):
    """The exported QP is the one a QP backend is handed (same data, same formulation)."""
    from plateqp.model.assembly import build_model
    from plateqp.contact import Scaled, formulate

    e, _ = exported["primal"]
    qp = formulate(Scaled.from_model(build_model(small_scene())), "primal").problem(frozenset({"qp"}))
    assert (sp.csc_matrix(qp.P) != sp.csc_matrix(e.qp.P)).nnz == 0 and np.array_equal(qp.q, e.qp.q)
    assert e.meta["n_contacts"] == 5 and e.meta["n_elastic"] == 2 and len(e.row_names) == 5
    assert e.var_names[-2:] == ["t_1", "t_3"]  # the elastic supports' spring variables
    with pytest.raises(pq.ProblemError, match="formulation"):
        contact_qp(small_scene(), "auto")


# -- command line ------------------------------------------------------------------------------


def test_cli_export_qps_and_refuses_to_overwrite(capsys, tmp_path):
    out = tmp_path / "heave.qps"
    code, stdout, _ = run_cli(capsys, "export", "heave", "--formulation", "condensed", "--out", out)
    assert code == 0 and "heave_condensed" in stdout
    qp, info = read_qps(out, with_info=True)
    sc = scenes.load("heave")
    assert qp.n == len(sc.supports) and info.name == "heave_condensed"
    before = out.read_text()
    code, _, err = run_cli(capsys, "export", "heave", "--out", out)
    assert code == 2 and "exists" in err and "--force" in err and len(err.strip().splitlines()) == 1
    assert out.read_text() == before
    code, _, _ = run_cli(capsys, "export", "heave", "--out", out, "--force")  # primal now
    assert code == 0 and read_qps(out).n > len(sc.supports)


def test_cli_export_qpbenchmark_from_a_scene_file(capsys, tmp_path):
    scene_file = tmp_path / "small.toml"
    small_scene().to_toml(scene_file)
    out = tmp_path / "set"
    code, _, _ = run_cli(capsys, "export", scene_file, "--formulation", "dual", "--format", "qpbenchmark",
                         "--out", out, "--testset", "small_set")
    assert code == 0
    assert (out / "small_set.py").exists() and (out / "data" / "small_dual.npz").exists()
    code, _, err = run_cli(capsys, "export", scene_file, "--format", "qpbenchmark", "--out", out)
    assert code == 2 and "not an empty directory" in err
    assert sorted(p.name for p in (out / "data").iterdir()) == ["small_dual.npz"]  # untouched


@pytest.mark.parametrize("argv, words", [
    (["export", "no-such-scene", "--out", "{tmp}/x.qps"], "no such file"),
    (["export", "heave", "--formulation", "dual", "--out", "{tmp}/x.qps"], "floats"),
    (["export", "slab", "--out", "{tmp}/x.qps"], "no one-sided supports"),
    (["export", "heave", "--format", "qpbenchmark", "--testset", "9lives", "--out", "{tmp}/set"], "identifier"),
    (["export", "heave", "--out", "{tmp}"], "is a directory"),
])
def test_cli_export_errors(capsys, tmp_path, argv, words):
    code, _, err = run_cli(capsys, *[a.format(tmp=tmp_path) for a in argv])
    assert code == 2 and words in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.qps").exists() and not (tmp_path / "set").exists()


# -- the exported problem solved elsewhere, on the grid and on triangles ------------------------

R, Q = 1.0, 3.0


def posts(edge=None) -> pq.Scene:
    """A disc on three rigid posts at 120° (r = 0.7) and a central elastic one; free (floating)
    or with an edge support; a square hole off-centre (DKT triangles)."""
    sup = [pq.Support(0.7 * math.cos(t), 0.7 * math.sin(t), gap=0.0)
           for t in np.radians([90.0, 210.0, 330.0])] + [pq.Support(0.0, 0.0, gap=1e-4, stiffness=5e3)]
    return pq.Scene(name="posts", plate=pq.Plate(shape={"circle": [0.0, 0.0, R]}, h=0.05, E=1e7, nu=0.3),
                    mesh=pq.MeshSpec(element="dkt", size=R / 6), edges={"all": pq.Edge(edge)} if edge else {},
                    holes=[{"polygon": [[0.2, -0.5], [0.4, -0.5], [0.4, -0.3], [0.2, -0.3]]}],
                    loads=[pq.UniformLoad(Q)], supports=sup)


# the scenes by mesh: the grid's small scene (two simple edges), the disc floating or simply supported
SCENES = {"grid": small_scene, "triangles-floating": posts, "triangles": lambda: posts("simple")}


def scene_on(mesh) -> pq.Scene:
    if mesh.startswith("triangles"):
        pytest.importorskip("gmsh")
    return SCENES[mesh]()


def clarabel_solve(P, q, G=None, h=None, lb=None):
    """½ xᵀPx + qᵀx s.t. G x ≤ h, x ≥ lb, by Clarabel's own interface: (x, multipliers of G, of lb)."""
    clarabel = pytest.importorskip("clarabel")
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


@pytest.mark.parametrize("mesh, form", [("grid", "primal"), ("grid", "condensed"), ("grid", "dual"),
                                        ("triangles-floating", "primal"), ("triangles-floating", "condensed"),
                                        ("triangles", "primal"), ("triangles", "condensed"), ("triangles", "dual")])
def test_exported_qp_solved_elsewhere(tmp_path, mesh, form):
    sc = scene_on(mesh)
    e = contact_qp(sc, form)
    assert e.meta["mesh"]["element"] == sc.mesh.element
    if mesh == "grid":
        assert (e.meta["mesh"]["nx"], e.meta["mesh"]["ny"]) == (sc.mesh.nx, sc.mesh.ny)
    else:
        assert e.meta["mesh"]["element"] == "dkt" and e.meta["mesh"]["triangles"] == len(e.model.grid.triangles)
    path = write_npz(e, tmp_path / "p.npz")
    arrays = npz_arrays(path)
    meta = json.loads(arrays["meta"])
    R_ext = reactions_of(form, arrays, meta)
    ref = pq.solve(sc, formulation=form, accuracy="high")
    assert ref.kkt.ok
    np.testing.assert_allclose(R_ext, ref.reactions, rtol=0, atol=1e-6 * np.abs(ref.reactions).max())
    if mesh == "triangles-floating":  # statics: the supports carry all the load, with no moment about the centre
        total = Q * e.model.grid.areas().sum()
        assert total == pytest.approx(Q * (math.pi * R**2 - 0.04), rel=0.01)  # the mesh's area: chords
        assert R_ext.sum() == pytest.approx(total, rel=1e-7)
        xy = np.array([[s.x, s.y] for s in sc.supports])
        c = e.model.grid.nodes[e.model.grid.triangles].mean(axis=1)  # the load's moment: area × centroid
        load_moment = Q * (e.model.grid.areas()[:, None] * c).sum(axis=0)
        np.testing.assert_allclose(R_ext @ xy, load_moment, atol=1e-7 * total)


@pytest.mark.parametrize("mesh", ["grid", "triangles"])
def test_exported_qps_round_trip_solved_elsewhere(tmp_path, mesh):
    """The QPS file reads back as the same QP, names and all, and Clarabel's multipliers of the
    read-back problem are pq.solve's reactions."""
    e = contact_qp(scene_on(mesh), "primal")
    path = write_qps(e, tmp_path / "p.qps")
    qp, info = read_qps(path, with_info=True)
    assert qp.n == e.qp.n and info.name == e.name
    _, zG, _ = clarabel_solve(qp.P, qp.q, qp.G, qp.h)
    ref = pq.solve(scene_on(mesh), formulation="primal", accuracy="high")
    np.testing.assert_allclose(e.meta["F0"] * zG, ref.reactions, atol=1e-6 * ref.reactions.max())


@pytest.mark.parametrize("mesh", ["grid", "triangles-floating"])
def test_cli_export_of_a_scene_file(tmp_path, capsys, mesh):
    """``plateqp export SCENE.toml``: the condensed problem has one variable per support."""
    from plateqp.cli import main

    sc = scene_on(mesh)
    scene = tmp_path / "scene.toml"
    sc.to_toml(scene)
    assert main(["export", str(scene), "--formulation", "condensed", "--out", str(tmp_path / "x.qps")]) == 0
    assert read_qps(tmp_path / "x.qps").n == len(sc.supports)
