"""The generated reference of scene keys (plateqp.model.schema) names every key the parser accepts.

The reference is the code's own behaviour, asked from outside: each table of a scene file is
given an unknown key, and the keys the error says are allowed must all appear in the reference;
the same for a bed's gap profiles and a shape's kinds; and every key of every built-in scene
file appears there too.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import fields
from importlib import resources

import pytest

import plateqp as pq
from plateqp.model import schema


def documented() -> set[str]:
    return {r["key"] for r in schema.rows()}


def test_every_field_has_words_and_every_word_a_field():
    for _, klass, _ in schema.TABLES:
        names = {f.name for f in fields(klass) if f.init}
        assert names == set(schema.WORDS[klass]), klass.__name__
    assert {k for _, k, _ in schema.TABLES} == set(schema.WORDS)


TABLE_OF = {"plate": "plate", "mesh": "mesh", "openings": "openings", "pins": "pins", "supports": "supports",
            "foundation": "foundation"}


def _allowed(data: dict) -> list[str]:
    with pytest.raises(pq.SceneError) as exn:
        pq.Scene.from_dict(data)
    m = re.search(r"allowed(?: top-level keys)?:? \[([^\]]*)\]", str(exn.value)) or re.search(
        r"allowed: ([\w, ]+)$", str(exn.value))
    assert m, str(exn.value)
    return [s.strip().strip("'\"") for s in m.group(1).split(",")]


@pytest.mark.parametrize("data, prefix", [
    ({"plate": {"zz": 1}}, "plate"),
    ({"mesh": {"zz": 1}}, "mesh"),
    ({"openings": [{"zz": 1}]}, "openings"),
    ({"pins": [{"zz": 1}]}, "pins"),
    ({"supports": [{"zz": 1}]}, "supports"),
    ({"foundation": {"zz": 1}}, "foundation"),
    ({"loads": [{"type": "uniform", "zz": 1}]}, "loads"),
    ({"loads": [{"type": "patch", "zz": 1}]}, "loads"),
    ({"loads": [{"type": "point", "zz": 1}]}, "loads"),
    ({"edges": {"left": {"zz": 1}}}, "edges.NAME"),
])
def test_every_key_a_table_accepts_is_documented(data, prefix):
    keys = {f"{prefix}.{k}" for k in _allowed(data)}
    assert keys <= documented(), keys - documented()


def test_every_top_level_key_is_documented():
    top = set(_allowed({"zz": 1}))
    doc = {k.split(".")[0] for k in documented()}
    assert top <= doc, top - doc


@pytest.mark.parametrize("profile", ["uniform", "linear", "trough", "bump"])
def test_every_gap_profile_key_is_documented(profile):
    sc = pq.Scene(loads=[pq.UniformLoad(1.0)], foundation=pq.Foundation(k=1.0))
    sc.foundation.gap = {"profile": profile, "zz": 1.0, "x": 0.5, "y": 0.5, "radius": 0.2, "depth": 0.01,
                         "g0": 0.0}
    with pytest.raises(pq.SceneError) as exn:
        sc.validate()
    m = re.search(r"allowed \[([^\]]*)\]", str(exn.value))
    assert m, str(exn.value)
    keys = {f"foundation.gap.{s.strip().strip(chr(39))}" for s in m.group(1).split(",")}
    assert keys <= documented(), keys - documented()
    assert f'"{profile}"' in schema.markdown()


def test_shape_kinds_are_documented():
    with pytest.raises(pq.SceneError) as exn:
        pq.Scene(plate=pq.Plate(shape={"zz": 1}), mesh=pq.MeshSpec(element="dkt"))
    kinds = set(re.findall(r"\{ (\w+) =", str(exn.value)))
    assert kinds and {f"plate.shape.{k}" for k in kinds} <= documented()
    assert {f"holes.{k}" for k in kinds} <= documented()


def _paths(d, prefix=""):
    for k, v in d.items():
        key = f"{prefix}.{k}" if prefix else k
        if isinstance(v, dict):
            yield from _paths(v, key)
        elif isinstance(v, list) and v and all(isinstance(i, dict) for i in v):
            for item in v:
                yield from _paths(item, key)
        else:
            yield key


def test_every_key_of_the_built_in_scenes_is_documented():
    doc = documented() | {k.rsplit(".", 1)[0] for k in documented()}
    for f in resources.files("plateqp.scenes").iterdir():
        if not f.name.endswith(".toml"):
            continue
        data = tomllib.loads(f.read_text(encoding="utf-8"))
        for key in _paths(data):
            parts = key.split(".")
            if parts[0] == "edges":  # edges.NAME or edges.NAME.kind
                key = ".".join(["edges", "NAME", *parts[2:]]) if len(parts) > 2 else "edges.NAME.kind"
            if key == "loads.type":
                continue
            assert key in doc, f"{f.name}: {key}"


def test_the_reference_renders_every_row():
    md = schema.markdown()
    for r in schema.rows():
        assert f"`{r['key']}`" in md


def test_the_committed_reference_is_what_the_code_gives():
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "docs" / "guide" / "scene-keys.md"
    assert path.read_text(encoding="utf-8") == schema.markdown(), (
        "docs/guide/scene-keys.md is stale: python -m plateqp.model.schema docs/guide/scene-keys.md")
