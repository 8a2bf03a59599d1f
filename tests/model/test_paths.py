"""Scene paths (plateqp.model.paths): get and set a scene field named with dots; bad paths and values
say what exists; on a triangle mesh the edges take its own names (``all``, ``outer_0-1``, ``hole0``).

External reference for the edge set by a path: the clamped circular plate's w0 = q R⁴ / 64 D
(Timoshenko & Woinowsky-Krieger § 62)."""

from __future__ import annotations

import numpy as np
import pytest

import plateqp as pq
import plateqp.studies
from plateqp.model.paths import as_number, get_param, set_param
from study_scenes import STIFF, fig5


def test_the_studies_package_keeps_the_names():
    assert plateqp.studies.get_param is get_param and plateqp.studies.set_param is set_param


def test_get_and_set_paths():
    sc = fig5()
    assert get_param(sc, "plate.h") == 20.0
    assert get_param(sc, "supports.1.gap") == -0.02
    assert get_param(sc, "supports.*.gap")[:3] == [-0.02, -0.02, 0.0]
    assert get_param(sc, "loads.0.P") == 20000.0
    assert get_param(sc, "edges.left") == "free"  # an edge not named is free

    s2 = set_param(sc, STIFF, 1e4)
    assert get_param(s2, STIFF) == [1e4] * 25 and get_param(sc, STIFF) == ["rigid"] * 25  # a copy
    assert get_param(set_param(s2, "supports.4.stiffness", float("inf")), "supports.4.stiffness") == "rigid"
    assert get_param(set_param(s2, STIFF, "rigid"), STIFF) == ["rigid"] * 25
    nx = get_param(set_param(sc, "mesh.nx", 16.0), "mesh.nx")
    assert nx == 16 and isinstance(nx, int)
    gaps = np.linspace(-0.01, 0.01, 25)
    assert get_param(set_param(sc, "supports.*.gap", gaps), "supports.*.gap") == pytest.approx(gaps)
    s3 = set_param(sc, "edges.left", "clamped")
    assert s3.edges["left"].kind == "clamped" and "left" not in sc.edges
    s4 = pq.Scene(foundation=pq.Foundation(k=100.0), loads=[pq.UniformLoad(q=1.0)])
    assert get_param(set_param(s4, "foundation.k", 50), "foundation.k") == 50


@pytest.mark.parametrize("path, value, words", [
    ("supports.26.gap", 0.0, ["supports.26", "25 supports", "numbered from 1 (1..25)"]),
    ("supports.4.gapp", 0.0, ["supports.4.gapp", "x, y, gap, stiffness"]),
    ("plat.h", 1.0, ["plat", "plate", "mesh", "supports"]),
    ("supports.x.gap", 0.0, ["supports.x", "numbered from 1", "'*'"]),
    ("supports.0.gap", 0.0, ["supports.0", "numbered from 1"]),
    ("loads.5.P", 0.0, ["loads.5", "indexed from 0 (0.."]),
    ("foundation.k", 1.0, ["foundation", "no foundation"]),
    ("plate.h.x", 1.0, ["plate.h", "value"]),
    ("supports.4.stiffness", -5.0, ["supports.4.stiffness", "> 0"]),
    ("supports.4.stiffness", "soft", ["supports.4.stiffness", "soft"]),
    ("mesh.nx", 2.5, ["mesh.nx", "integer"]),
    ("edges.middle", "simple", ["edges.middle", "left, right, bottom, top"]),
    ("supports..gap", 0.0, ["bad path"]),
])
def test_bad_paths_and_values_say_what_exists(path, value, words):
    with pytest.raises(pq.SceneError) as exn:
        set_param(fig5(), path, value)
    for w in words:
        assert w in str(exn.value)


@pytest.mark.parametrize("value, number", [("rigid", np.inf), ("inf", np.inf), (" Infinity ", np.inf), ("2.5", 2.5),
                                           (3, 3.0), (np.float32(0.5), 0.5)])
def test_as_number(value, number):
    assert as_number(value) == number


@pytest.mark.parametrize("path, words", [
    ("plate", ["plate", "a table", "plate.h"]),
    ("mesh", ["mesh", "a table", "mesh.nx"]),
    ("supports", ["supports", "list", "supports.1.gap"]),
    ("supports.1", ["supports.1", "a table", "supports.1.gap"]),
    ("supports.*", ["supports.*", "a table", "supports.*.gap"]),
    ("loads", ["loads", "list"]),
    ("loads.0", ["loads.0", "a table", "loads.0.P"]),
    ("edges", ["edges", "edges.left"]),
    ("pins", ["pins", "list"]),
    ("openings", ["openings", "list"]),
])
def test_a_path_that_names_a_table_is_refused(path, words):
    """A path must name a number (or a word such as an edge kind), never a whole table or list:
    setting one to a number used to leave an int where the scene expects its section."""
    with pytest.raises(pq.SceneError) as exn:
        set_param(fig5(), path, 1.0)
    for w in words:
        assert w in str(exn.value), str(exn.value)
    s4 = pq.Scene(foundation=pq.Foundation(k=100.0), loads=[pq.UniformLoad(q=1.0)])
    with pytest.raises(pq.SceneError, match="foundation.k"):
        set_param(s4, "foundation", 2.0)


@pytest.mark.parametrize("path", ["plate", "supports", "supports.1", "loads.0", "edges", "mesh", "foundation"])
def test_sweep_of_a_table_is_one_line_exit_2(capsys, path):
    from plateqp.cli import main

    code = main(["sweep", "heave", "--param", path, "--values", "1,2", "--workers", "1"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and err.startswith("plateqp: ") and "internal error" not in err, err
    assert path in err


# -- the triangle meshes' edge names ------------------------------------------------------------

L_SHAPE = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]


def l_plate() -> pq.Scene:
    pytest.importorskip("gmsh")
    return pq.Scene(plate=pq.Plate(shape={"polygon": L_SHAPE}), mesh=pq.MeshSpec(element="dkt", size=0.25),
                    loads=[pq.UniformLoad(1.0)])


def test_paths_take_the_triangle_edge_names():
    pytest.importorskip("gmsh")
    sc = pq.Scene(plate=pq.Plate(shape={"circle": [0.0, 0.0, 1.0]}, h=0.01, E=1e7, nu=0.3),
                  mesh=pq.MeshSpec(element="dkt", size=1 / 8), edges={"all": "simple"}, loads=[pq.UniformLoad(1.0)])
    assert get_param(sc, "edges.all") == "simple"
    clamped = set_param(sc, "edges.all", "clamped")
    D = sc.plate.D
    assert pq.solve(clamped).deflection(0.0, 0.0) == pytest.approx(1.0 / (64 * D), rel=0.01)
    L = l_plate()
    L2 = set_param(set_param(L, "edges.outer_0-1", "clamped"), "edges.outer_4-5.kind", "simple")
    assert L2.edges["outer_0-1"].kind == "clamped" and L2.edges["outer_4-5"].kind == "simple"
    holed = set_param(pq.Scene(plate=L.plate, mesh=L.mesh, holes=[{"circle": [0.5, 0.5, 0.2]}]), "edges.hole0", "clamped")
    assert holed.edges["hole0"].kind == "clamped"


@pytest.mark.parametrize("path, words", [("edges.outr", "unknown edge"), ("edges.hole3", "no hole 3"),
                                         ("edges.outer_2-9", "segments")])
def test_paths_refuse_bad_triangle_edge_names(path, words):
    with pytest.raises(pq.SceneError, match=words):
        set_param(l_plate(), path, "simple")
