"""The memory a scene will need, checked before any allocation: the estimate per dof, the limit
(80 % of the machine's memory, or ``$PLATEQP_MAX_MEMORY`` / ``--max-memory``), and the refusal."""

from __future__ import annotations

import os

import numpy as np

from ..errors import ResourceError, SceneError
from .elements import ELEMENTS
from .generators import mesh_generator
from .scene import Scene


#: Peak memory of building and solving a scene, per dof of its grid: measured (resident set
#: size, grid_rigid family, auto backend) 11.7 KB at 128², 9.9 KB at 256², 9.2 KB at 512².
BYTES_PER_DOF = 12_000
#: The environment variable that overrides the memory limit (bytes, or with a K/M/G/T suffix).
MEMORY_ENV = "PLATEQP_MAX_MEMORY"


def estimate_memory(scene: Scene) -> int:
    """Bytes a build and solve of ``scene`` is expected to need at its peak (see BYTES_PER_DOF):
    the dofs of the mesh its generator expects (``estimate_nodes``)."""
    nd = len(ELEMENTS[scene.mesh.element].node_dofs)
    return int(BYTES_PER_DOF * nd * mesh_generator(scene).estimate_nodes(scene))


def memory_limit() -> int:
    """The memory a solve may plan to use: ``$PLATEQP_MAX_MEMORY`` if set, else 80 % of this
    machine's physical memory (no limit where that cannot be read)."""
    text = os.environ.get(MEMORY_ENV, "").strip()
    if text:
        return parse_bytes(text, MEMORY_ENV)
    try:
        return int(0.8 * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 2**63 - 1


def parse_bytes(text: str, where: str) -> int:
    """'8G', '512M', '1.5e9' → bytes; a SceneError naming ``where`` otherwise."""
    t = str(text).strip().upper().removesuffix("B")
    mult = {"K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}.get(t[-1:], 1)
    try:
        value = float(t[:-1] if t[-1:] in "KMGT" else t) * mult
    except ValueError:
        value = float("nan")
    if not (value > 0 and np.isfinite(value)):
        raise SceneError(f"{where}: {text!r} is not an amount of memory (e.g. 8G, 512M, 2e9)")
    return int(value)


def human_bytes(n: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.1f} {unit}"
    return f"{n:.0f} B"


def check_memory(scene: Scene) -> None:
    """ResourceError before any allocation if ``scene`` would need more memory than allowed."""
    need, limit = estimate_memory(scene), memory_limit()
    if need > limit:
        where, mesh, fix = mesh_generator(scene).describe(scene)
        raise ResourceError(f"{where}: a {mesh} needs about {human_bytes(need)} to build and solve, above the limit "
                            f"of {human_bytes(limit)}; {fix}, or raise the limit (--max-memory or ${MEMORY_ENV})")
