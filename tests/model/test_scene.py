"""Scene validation and TOML round trips.

Every invalid scene must raise SceneError whose message names the offending field (dotted path,
e.g. ``supports.2.gap``) and, for a scene read from a file, the file. A scene written to TOML
and read back must compare equal (dataclass equality) to the one written.
"""

from __future__ import annotations

import math

import numpy as np

import pytest

import plateqp as pq
from plateqp import scenes

BASE = """\
name = "base"

[plate]
a = 2.0
b = 1.0
h = 0.02
E = 3.0e4
nu = 0.3

[mesh]
nx = 8
ny = 4
element = "acm"

[edges]
left = "clamped"
right = "simple"

[[loads]]
type = "uniform"
q = 1.0
"""

# (id, TOML text appended to / replacing parts of BASE, field the message must name)
# "sub": (old, new) replacements of BASE; "add": text appended
BAD = [
    ("zero-thickness", {"sub": ("h = 0.02", "h = 0.0")}, "plate.h"),
    ("negative-thickness", {"sub": ("h = 0.02", "h = -0.02")}, "plate.h"),
    ("nu-half", {"sub": ("nu = 0.3", "nu = 0.5")}, "plate.nu"),
    ("nu-minus-one", {"sub": ("nu = 0.3", "nu = -1.0")}, "plate.nu"),
    ("nu-large", {"sub": ("nu = 0.3", "nu = 0.7")}, "plate.nu"),
    ("nu-string", {"sub": ("nu = 0.3", 'nu = "0.3"')}, "plate.nu"),
    ("E-nan", {"sub": ("E = 3.0e4", "E = nan")}, "plate.E"),
    ("a-inf", {"sub": ("a = 2.0", "a = inf")}, "plate.a"),
    ("zero-elements-x", {"sub": ("nx = 8", "nx = 0")}, "mesh.nx"),
    ("zero-elements-y", {"sub": ("ny = 4", "ny = 0")}, "mesh.ny"),
    ("fractional-elements", {"sub": ("nx = 8", "nx = 2.5")}, "mesh.nx"),
    ("unknown-element", {"sub": ('element = "acm"', 'element = "quad9"')}, "mesh.element"),
    ("unknown-edge-kind", {"sub": ('right = "simple"', 'right = "hinged"')}, "edges.right"),
    ("unknown-edge-name", {"sub": ('right = "simple"', 'front = "simple"')}, "edges.front"),
    ("unknown-edge-key", {"sub": ('right = "simple"', 'right = { kind = "simple", angle = 1.0 }')},
     "edges.right.angle"),
    ("slope-on-simple-edge", {"sub": ('right = "simple"', 'right = { kind = "simple", slope = 0.1 }')},
     "edges.right.slope"),
    ("edge-w-nan", {"sub": ('right = "simple"', 'right = { kind = "simple", w = nan }')}, "edges.right.w"),
    ("unknown-top-level-key", {"add": 'colour = "red"\n', "top": True}, "colour"),
    ("unknown-plate-key", {"sub": ("nu = 0.3", "nu = 0.3\nthickness = 1.0")}, "plate.thickness"),
    ("unknown-mesh-key", {"sub": ("ny = 4", "ny = 4\nsize = 0.1")}, "mesh.size"),
    ("unknown-load-key", {"sub": ("q = 1.0", "q = 1.0\nQ = 2.0")}, "loads.0.Q"),
    ("unknown-load-type", {"sub": ('type = "uniform"', 'type = "line"')}, "loads.0.type"),
    ("loads-not-an-array", {"sub": ("[[loads]]", "[loads]")}, "loads"),
    ("supports-not-an-array", {"add": "[supports]\nx = 0.5\ny = 0.5\n"}, "supports"),
    ("load-q-nan", {"sub": ("q = 1.0", "q = nan")}, "loads.0.q"),
    ("point-load-outside", {"add": '[[loads]]\ntype = "point"\nP = 1.0\nx = 2.5\ny = 0.5\n'}, "loads.1"),
    ("point-load-negative-y", {"add": '[[loads]]\ntype = "point"\nP = 1.0\nx = 0.5\ny = -0.1\n'}, "loads.1"),
    ("point-load-in-opening", {"add": '[[openings]]\nx0 = 1.0\nx1 = 2.0\ny0 = 0.5\ny1 = 1.0\n'
                                      '[[loads]]\ntype = "point"\nP = 1.0\nx = 1.6\ny = 0.8\n'}, "loads.1"),
    ("patch-outside", {"add": '[[loads]]\ntype = "patch"\nq = 1.0\nx0 = 2.5\nx1 = 3.0\ny0 = 0.0\ny1 = 1.0\n'},
     "loads.1"),
    ("patch-in-opening", {"add": '[[openings]]\nx0 = 1.0\nx1 = 2.0\ny0 = 0.5\ny1 = 1.0\n'
                                 '[[loads]]\ntype = "patch"\nq = 1.0\nx0 = 1.1\nx1 = 1.9\ny0 = 0.6\ny1 = 0.9\n'},
     "loads.1"),
    ("patch-inverted", {"add": '[[loads]]\ntype = "patch"\nq = 1.0\nx0 = 1.0\nx1 = 0.5\ny0 = 0.0\ny1 = 1.0\n'},
     "loads.1"),
    ("support-outside", {"add": "[[supports]]\nx = 0.5\ny = 1.5\n"}, "supports.1"),
    ("support-in-opening", {"add": '[[openings]]\nx0 = 1.0\nx1 = 2.0\ny0 = 0.5\ny1 = 1.0\n'
                                   "[[supports]]\nx = 1.5\ny = 0.9\n"}, "supports.1"),
    ("two-supports-one-point", {"add": "[[supports]]\nx = 0.5\ny = 0.5\n[[supports]]\nx = 0.7\ny = 0.5\n"
                                       "[[supports]]\nx = 0.5\ny = 0.5\ngap = 0.1\n"}, "supports.3"),
    ("negative-stiffness", {"add": "[[supports]]\nx = 0.5\ny = 0.5\nstiffness = -10.0\n"}, "supports.1.stiffness"),
    ("zero-stiffness", {"add": "[[supports]]\nx = 0.5\ny = 0.5\nstiffness = 0.0\n"}, "supports.1.stiffness"),
    ("stiffness-word", {"add": '[[supports]]\nx = 0.5\ny = 0.5\nstiffness = "soft"\n'}, "supports.1.stiffness"),
    ("gap-nan", {"add": "[[supports]]\nx = 0.5\ny = 0.5\ngap = nan\n"}, "supports.1.gap"),
    ("gap-string", {"add": '[[supports]]\nx = 0.5\ny = 0.5\ngap = "0"\n'}, "supports.1.gap"),
    ("unknown-support-key", {"add": "[[supports]]\nx = 0.5\ny = 0.5\nk = 1.0\n"}, "supports.1.k"),
    ("pin-outside", {"add": "[[pins]]\nx = -0.5\ny = 0.0\n"}, "pins.0"),
    ("pin-off-node", {"add": "[[pins]]\nx = 0.3\ny = 0.0\n"}, "pins.0"),
    ("opening-inverted", {"add": "[[openings]]\nx0 = 1.0\nx1 = 0.5\ny0 = 0.0\ny1 = 1.0\n"}, "openings.0"),
    ("opening-everything", {"add": "[[openings]]\nx0 = -1.0\nx1 = 3.0\ny0 = -1.0\ny1 = 2.0\n"}, "openings"),
    ("foundation-k-negative", {"add": "[foundation]\nk = -1.0\n"}, "foundation.k"),
    ("foundation-unknown-key", {"add": "[foundation]\nk = 1.0\nmodulus = 2.0\n"}, "foundation.modulus"),
    ("foundation-region-short", {"add": "[foundation]\nk = 1.0\nregion = [0.0, 1.0]\n"}, "foundation.region"),
    ("foundation-gap-nan", {"add": "[foundation]\nk = 1.0\ngap = nan\n"}, "foundation.gap"),
    ("foundation-bad-profile", {"add": '[foundation]\nk = 1.0\ngap = { profile = "ramp" }\n'},
     "foundation.gap.profile"),
    ("foundation-profile-missing-key", {"add": '[foundation]\nk = 1.0\ngap = { profile = "trough", x = 0.5, y = 0.5, '
                                               'radius = 0.3 }\n'}, "foundation.gap.depth"),
    ("foundation-profile-unknown-key", {"add": '[foundation]\nk = 1.0\ngap = { profile = "bump", x = 0.5, y = 0.5, '
                                               'radius = 0.3, depth = 0.01, width = 1.0 }\n'}, "foundation.gap.width"),
    ("foundation-profile-zero-radius", {"add": '[foundation]\nk = 1.0\ngap = { profile = "bump", x = 0.5, y = 0.5, '
                                               'radius = 0.0, depth = 0.01 }\n'}, "foundation.gap.radius"),
    # hostile input: each of these was a traceback, not a SceneError
    ("load-type-array", {"sub": ('type = "uniform"', "type = []")}, "loads.0.type"),
    ("load-type-table", {"sub": ('type = "uniform"', "type = { a = 1 }")}, "loads.0.type"),
    ("foundation-region-number", {"add": "[foundation]\nk = 1.0\nregion = 5\n"}, "foundation.region"),
    ("foundation-region-string", {"add": '[foundation]\nk = 1.0\nregion = "all"\n'}, "foundation.region"),
    ("foundation-region-off-plate", {"add": "[foundation]\nk = 1.0\nregion = [5.0, 6.0, 0.0, 1.0]\n"},
     "foundation.region"),
    ("foundation-region-between-nodes", {"add": "[foundation]\nk = 1.0\nregion = [0.01, 0.02, 0.01, 0.02]\n"},
     "foundation.region"),
    ("huge-integer-mesh", {"sub": ("nx = 8", "nx = 100000000000000000000000")}, "mesh.nx"),
    ("thick-beyond-range", {"sub": ("h = 0.02", "h = 1e120")}, "plate.h"),
    ("thin-beyond-range", {"sub": ("h = 0.02", "h = 1e-120")}, "plate.h"),
    ("load-beyond-range", {"sub": ("q = 1.0", "q = 1e300")}, "loads.0.q"),
    ("load-below-range", {"sub": ("q = 1.0", "q = 1e-300")}, "loads.0.q"),
    ("gap-beyond-range", {"add": "[[supports]]\nx = 1.0\ny = 0.5\ngap = 1e300\n"}, "supports.1.gap"),
    ("stiffness-denormal", {"add": "[[supports]]\nx = 1.0\ny = 0.5\nstiffness = 5e-324\n"},
     "supports.1.stiffness"),
    ("stiffness-string", {"add": '[[supports]]\nx = 1.0\ny = 0.5\nstiffness = "soft"\n'}, "supports.1.stiffness"),
    ("name-not-a-string", {"sub": ('name = "base"', "name = [1, 2]")}, "name"),
    ("supports-a-table", {"add": "[supports]\nx = 1.0\n"}, "supports"),
]


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def bad_text(edit):
    text = BASE
    if "sub" in edit:
        old, new = edit["sub"]
        assert old in text
        text = text.replace(old, new, 1)
    if "add" in edit:
        text = edit["add"] + text if edit.get("top") else text + "\n" + edit["add"]
    return text


def test_base_is_valid(tmp_path):
    scene = pq.Scene.from_toml(write(tmp_path, BASE))
    assert scene.name == "base" and scene.plate.a == 2.0 and scene.mesh.nx == 8
    assert scene.edges == {"left": pq.Edge("clamped"), "right": pq.Edge("simple")}


@pytest.mark.parametrize("edit, field", [(e, f) for _, e, f in BAD], ids=[i for i, _, _ in BAD])
def test_invalid_scene_names_field_and_file(tmp_path, edit, field):
    path = write(tmp_path, bad_text(edit), "bad-scene.toml")
    with pytest.raises(pq.SceneError) as info:
        pq.Scene.from_toml(path)
    msg = str(info.value)
    assert str(path) in msg, msg
    assert f"{field}:" in msg or f"{field} " in msg, msg
    assert "\n" not in msg.strip()


def test_scene_error_is_a_plateqp_error():
    assert issubclass(pq.SceneError, pq.PlateQPError)
    assert issubclass(pq.SceneError, ValueError)


def test_invalid_scene_in_python_names_field():
    """Built in Python (no file), the message still names the field."""
    with pytest.raises(pq.SceneError, match=r"^plate\.h:"):
        pq.Scene(plate=pq.Plate(h=-1.0))
    with pytest.raises(pq.SceneError, match=r"^supports\.1\.gap:"):
        pq.Scene(supports=[pq.Support(0.5, 0.5, gap=math.nan)])
    with pytest.raises(pq.SceneError, match=r"^supports\.2:.*supports\.1"):
        pq.Scene(supports=[pq.Support(0.5, 0.5), pq.Support(0.5, 0.5, stiffness=10.0)])
    with pytest.raises(pq.SceneError, match=r"^loads\.0:"):
        pq.Scene(loads=[pq.PointLoad(1.0, 1.5, 0.5)])
    with pytest.raises(pq.SceneError, match=r"^mesh\.nx:"):
        pq.Scene(mesh=pq.MeshSpec(nx=0))


def test_bending_stiffness_out_of_range_names_the_plate(tmp_path):
    """Each number in range, their product not: D = E h³ / 12(1 − ν²) overflows the safe range."""
    path = write(tmp_path, BASE.replace("E = 3.0e4", "E = 1e99").replace("h = 0.02", "h = 1e40"))
    with pytest.raises(pq.SceneError, match=r"plate: .*bending stiffness"):
        pq.Scene.from_toml(path)


@pytest.mark.parametrize("value", ["1e-90", "1e90"])
def test_extreme_but_safe_magnitudes_solve(value):
    """Inside the safe range the nondimensional solve works at any scale: a load of 1e±90 gives
    deflections and reactions scaled by exactly that factor (statics: R sums to the load)."""
    q = float(value)

    def scene(load):
        return pq.Scene(plate=pq.Plate(), mesh=pq.MeshSpec(4, 4), loads=[pq.UniformLoad(load)],
                        supports=[pq.Support(x, y) for x in (0.0, 1.0) for y in (0.0, 1.0)],
                        pins=[pq.Pin(0.5, 0.5)])

    ref = pq.solve(scene(1.0), backend="lemke")
    res = pq.solve(scene(q), backend="lemke")
    assert res.status == pq.Status.OPTIMAL
    import numpy as np

    np.testing.assert_allclose(res.reactions / q, ref.reactions, rtol=1e-9)
    np.testing.assert_allclose(res.u / q, ref.u, rtol=1e-9, atol=1e-12 * np.abs(ref.u).max())


def test_hostile_files(tmp_path):
    """A directory, an empty path, bytes that are not UTF-8, deeply nested arrays and a file too
    large to be a scene are SceneErrors naming the file; a UTF-8 byte-order mark is accepted."""
    with pytest.raises(pq.SceneError, match="is a directory"):
        pq.Scene.from_toml(tmp_path)
    with pytest.raises(pq.SceneError, match="empty path"):
        pq.Scene.from_toml("")
    raw = tmp_path / "latin1.toml"
    raw.write_bytes(BASE.replace("base", "b\xe4se").encode("latin-1"))
    with pytest.raises(pq.SceneError, match=r"latin1\.toml: .*UTF-8"):
        pq.Scene.from_toml(raw)
    nested = tmp_path / "nested.toml"
    nested.write_text("name = " + "[" * 100_000 + "]" * 100_000 + "\n")
    with pytest.raises(pq.SceneError, match=r"nested\.toml"):
        pq.Scene.from_toml(nested)
    big = tmp_path / "big.toml"
    with open(big, "w") as fh:
        fh.write(BASE)
        fh.write("# padding\n" * 2_000_000)
    with pytest.raises(pq.SceneError, match=r"big\.toml: .*larger than"):
        pq.Scene.from_toml(big)
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + BASE.encode())
    assert pq.Scene.from_toml(bom).name == "base"


def test_endless_file_is_refused(tmp_path):
    """/dev/zero (a file with no end) is read only up to the size limit, then refused."""
    import os

    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero here")
    with pytest.raises(pq.SceneError, match="larger than"):
        pq.Scene.from_toml("/dev/zero")


def test_missing_and_malformed_files(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(pq.SceneError, match="nope.toml"):
        pq.Scene.from_toml(missing)
    broken = write(tmp_path, "[plate\na = 1", "broken.toml")
    with pytest.raises(pq.SceneError, match="broken.toml.*TOML"):
        pq.Scene.from_toml(broken)


# --------------------------------------------------------------------------------------------
# round trips
# --------------------------------------------------------------------------------------------
def everything() -> pq.Scene:
    """A scene with every feature the TOML shape has."""
    return pq.Scene(
        name="everything",
        plate=pq.Plate(a=4.0, b=3.0, h=0.2, E=2.1e5, nu=0.2),
        mesh=pq.MeshSpec(8, 6, "bfs"),
        edges={"left": pq.Edge("clamped", w=0.01, slope=-0.002), "right": pq.Edge("simple", w=0.003),
               "bottom": pq.Edge("free"), "top": pq.Edge("simple")},
        openings=[pq.Opening(2.5, 3.5, 1.0, 2.0)],
        pins=[pq.Pin(2.0, 0.0), pq.Pin(4.0, 3.0, w=0.001)],
        loads=[pq.UniformLoad(0.05), pq.PatchLoad(1.5, 0.25, 1.75, 0.5, 1.0), pq.PointLoad(-20.0, 1.1, 2.3)],
        supports=[pq.Support(0.5, 0.5), pq.Support(1.0, 2.5, gap=-0.02),
                  pq.Support(1.5, 1.5, gap=0.01, stiffness=1.0e4), pq.Support(2.25, 0.75, stiffness=350)],
        foundation=pq.Foundation(k=100.0, region=[0.0, 2.0, 0.0, 3.0],
                                 gap={"profile": "trough", "x": 1.0, "y": 1.5, "radius": 0.8, "depth": 0.01}),
    )


def foundation_variants():
    return [pq.Foundation(k=5.0), pq.Foundation(k=5.0, gap=-0.003),
            pq.Foundation(k=5.0, gap={"profile": "linear", "g0": 0.01, "gx": -0.001, "gy": 0.002}),
            pq.Foundation(k=5.0, gap={"profile": "uniform", "g0": 0.004}),
            pq.Foundation(k=5.0, region=[0.5, 1.0, 0.5, 1.0],  # on the default 1 x 1 plate
                          gap={"profile": "bump", "x": 2.0, "y": 1.0, "radius": 0.5, "depth": 0.02})]


def round_trip(tmp_path, scene):
    path = tmp_path / "out.toml"
    text = scene.to_toml(path)
    assert path.read_text() == text
    back = pq.Scene.from_toml(path)
    assert back.source == str(path)
    return back


@pytest.mark.parametrize("name", scenes.names())
def test_builtin_scenes_round_trip(tmp_path, name):
    scene = scenes.load(name)
    back = round_trip(tmp_path, scene)
    assert back == scene
    assert round_trip(tmp_path, back) == scene  # and again: a fixed point
    assert back.to_toml() == scene.to_toml()


def test_everything_round_trips(tmp_path):
    scene = everything()
    back = round_trip(tmp_path, scene)
    assert back == scene
    assert back.to_dict() == scene.to_dict()
    for f in foundation_variants():
        s = pq.Scene(name="f", foundation=f)
        assert round_trip(tmp_path, s) == s


def test_builtin_names():
    assert {"heave", "slab"} <= set(scenes.names())
    with pytest.raises(pq.SceneError, match="no built-in scene"):
        scenes.path("no-such-scene")


def test_round_trip_is_not_vacuous(tmp_path):
    """Equality sees a changed field, so the round-trip tests can fail."""
    a, b = everything(), everything()
    b.supports[2].gap = 0.0100000001
    assert a != b
    b = everything()
    b.edges["left"].slope = -0.0021
    assert a != b


def test_python_tuples_round_trip(tmp_path):
    """Sequences given as tuples in Python come back from TOML as lists; the scene stays equal."""
    scene = pq.Scene(loads=(pq.UniformLoad(1.0),), supports=(pq.Support(0.5, 0.5),), pins=(pq.Pin(0.0, 0.0),),
                     openings=(pq.Opening(0.5, 1.0, 0.5, 1.0),), foundation=pq.Foundation(1.0, region=(0, 0.5, 0, 1)))
    assert round_trip(tmp_path, scene) == scene


def test_callable_gap_cannot_be_saved():
    scene = pq.Scene(foundation=pq.Foundation(k=1.0, gap=lambda x, y: 0.01 * x))
    with pytest.raises(pq.SceneError, match="foundation.gap"):
        scene.to_toml()


def test_edge_tables_and_strings_agree(tmp_path):
    a = pq.Scene.from_toml(write(tmp_path, BASE))
    b = pq.Scene.from_toml(write(tmp_path, BASE.replace('left = "clamped"', 'left = { kind = "clamped" }'), "b.toml"))
    assert a == b


def test_validation_locates_all_supports_at_once_with_the_same_answer():
    """validate() locates every support in one vectorised call on one grid: the same answer,
    point by point, as in_opening, on cell boundaries and the openings' edges too."""
    import numpy as np

    opening = pq.Opening(0.5, 1.0, 0.5, 1.0)  # removes the cells whose centres lie in it
    base = pq.Scene(plate=pq.Plate(a=1.0, b=1.0), mesh=pq.MeshSpec(4, 4), openings=[opening],
                    loads=[pq.UniformLoad(q=1.0)])
    pts = [(x, y) for x in np.linspace(0.0, 1.0, 9) for y in np.linspace(0.0, 1.0, 9)]
    on_plate = [(x, y) for x, y in pts if not base.in_opening(x, y)]
    off_plate = [(x, y) for x, y in pts if base.in_opening(x, y)]
    assert len(on_plate) > 20 and len(off_plate) > 4  # both kinds, boundaries included
    ok = pq.Scene(plate=base.plate, mesh=base.mesh, openings=[opening], loads=base.loads,
                  supports=[pq.Support(x, y) for x, y in on_plate])
    assert len(ok.supports) == len(on_plate)
    for x, y in off_plate[:3]:  # one bad support among good ones: named by its own number (from 1)
        sup = [pq.Support(*p) for p in on_plate[:5]] + [pq.Support(x, y)] + [pq.Support(*p) for p in on_plate[5:8]]
        with pytest.raises(pq.SceneError, match=r"supports\.6: point .* lies in an opening"):
            pq.Scene(plate=base.plate, mesh=base.mesh, openings=[opening], loads=base.loads, supports=sup)
    # a bad coordinate after a good one still names the first bad field, in order
    sup = [pq.Support(0.1, 0.1), pq.Support("x", 0.2), pq.Support(0.75, 0.75)]
    with pytest.raises(pq.SceneError, match=r"supports\.2\.x: must be a number"):
        pq.Scene(plate=base.plate, mesh=base.mesh, openings=[opening], loads=base.loads, supports=sup)
    sup = [pq.Support(0.1, 0.1), pq.Support(0.75, 0.75, gap=math.nan)]
    with pytest.raises(pq.SceneError, match=r"supports\.2\.gap: must be finite"):
        pq.Scene(plate=base.plate, mesh=base.mesh, openings=[opening], loads=base.loads, supports=sup)


def test_edges_all_on_a_rectangle_holds_every_side():
    """``[edges] all = ...`` on a grid rectangle is the four sides named one by one (the most
    specific name holds), and the simply supported square meets Navier's series."""
    plate, mesh, loads = pq.Plate(1.0, 1.0, 0.01, 1.0e7, 0.3), pq.MeshSpec(16, 16), [pq.UniformLoad(1.0)]
    four = pq.Scene(name="four", plate=plate, mesh=mesh, loads=loads,
                    edges={e: "simple" for e in ("left", "right", "bottom", "top")})
    every = pq.Scene(name="all", plate=plate, mesh=mesh, loads=loads, edges={"all": "simple"})
    w4, wa = pq.solve(four), pq.solve(every)
    np.testing.assert_array_equal(wa.u, w4.u)
    assert wa.deflection(0.5, 0.5) == pytest.approx(0.00406235 / plate.D, rel=5e-3)  # Navier, 16 x 16 ACM
    mixed = pq.Scene(name="mixed", plate=plate, mesh=mesh, loads=loads, edges={"all": "clamped", "top": "free"})
    sides = mixed.side_edges()
    assert {k: e.kind for k, e in sides.items()} == {"left": "clamped", "right": "clamped", "bottom": "clamped",
                                                     "top": "free"}
    ref = pq.Scene(name="ref", plate=plate, mesh=mesh, loads=loads,
                   edges={"left": "clamped", "right": "clamped", "bottom": "clamped"})
    np.testing.assert_array_equal(pq.solve(mixed).u, pq.solve(ref).u)
    with pytest.raises(pq.SceneError, match="edges.everything: unknown edge"):
        pq.Scene(name="bad", plate=plate, mesh=mesh, loads=loads, edges={"everything": "simple"})
