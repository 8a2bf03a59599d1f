"""Built-in example scenes (TOML files beside this module)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from ..errors import SceneError
from ..model.scene import Scene


def names() -> list[str]:
    """Names of the built-in scenes."""
    return sorted(p.name[:-5] for p in resources.files(__name__).iterdir() if p.name.endswith(".toml"))


def path(name: str) -> Path:
    """Path of a built-in scene file."""
    if name not in names():
        raise SceneError(f"no built-in scene {name!r}; built-in scenes: {', '.join(names())}")
    return Path(str(resources.files(__name__).joinpath(f"{name}.toml")))


def load(name: str) -> Scene:
    """A built-in scene by name."""
    return Scene.from_toml(path(name))
