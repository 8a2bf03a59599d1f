"""plateqp: thin Kirchhoff plates on one-sided supports, contact solved as a convex QP.

>>> import plateqp as pq
>>> scene = pq.Scene.from_toml("scene.toml")
>>> result = pq.solve(scene, backend="lemke", formulation="condensed", accuracy="high")
>>> result.reactions, result.active, result.kkt.ok

Conventions: the plate occupies [0, a] × [0, b]; w, loads and support compression are
positive downward; a gap g0 > 0 is settlement, g0 < 0 heave; reactions R ≥ 0 push the plate up.
"""

from .accuracy import Accuracy, Status
from .backends import available_backends, get_backend, registry
from .errors import (
    ArgumentError,
    MechanismError,
    NoEquilibriumError,
    PlateQPError,
    PlateQPWarning,
    ExportError,
    ProblemError,
    ResourceError,
    SceneError,
    SolverError,
)
from .results import KKTReport, Result
from .model.scene import (
    Edge,
    Foundation,
    MeshSpec,
    Opening,
    PatchLoad,
    Pin,
    Plate,
    PointLoad,
    Scene,
    Support,
    UniformLoad,
)
from .sensitivity import Sensitivity, sensitivity
from .solving import solve, solve_bilateral

__version__ = "0.1.0"


__all__ = [
    "Accuracy", "ArgumentError", "Edge", "ExportError", "Foundation", "KKTReport", "MechanismError", "MeshSpec", "NoEquilibriumError", "Opening",
    "PatchLoad", "Pin", "Plate", "PlateQPError", "PlateQPWarning", "PointLoad", "ProblemError", "ResourceError", "Result",
    "Scene", "SceneError", "Sensitivity", "SolverError", "Status", "Support", "UniformLoad", "available_backends",
    "get_backend", "registry", "sensitivity", "solve", "solve_bilateral",
]
