"""The magnitudes of a scene, checked before any work: the bending stiffness D, each load's
deflection scale 0.01 F L²/D and each spring's flexibility relative to the plate's, D/(c L²),
must lie in the scene's derived range (:data:`plateqp.model.scene.SAFE_DERIVED`), computed in
logarithms so that an overflow is reported, not computed.

The scene calls :func:`check_scales` at the end of its validation (``Scene._check_scales``).
Lengths come from the plate: [0, a] × [0, b], or a shaped plate's bounding box (and its area);
a bed's node spring is k × a node's area, about k h² with h the element size (the grid's cell,
or a triangle mesh's ``mesh.size``).
"""

from __future__ import annotations

import math


def _load_force_log(scene, ld) -> float:
    """log10 of the load's total force (bounded above for a patch: its overlap with the plate's box)."""
    kind = getattr(ld, "type", None)
    if kind == "point":
        return math.log10(abs(ld.P))
    from .geometry import scene_domain

    outer = scene_domain(scene).outer  # the plate's outline, its cut-outs not taken off: a bound
    X0, X1, Y0, Y1 = outer.bbox
    area = outer.area
    if kind == "patch":  # its area, at most its bounding box's overlap with the plate's
        from .regions import as_shape

        shape = as_shape(ld.extent)
        x0, x1, y0, y1 = shape.bbox
        area = min(shape.area, max(min(x1, X1) - max(x0, X0), 1e-300) * max(min(y1, Y1) - max(y0, Y0), 1e-300))
    return math.log10(abs(ld.q)) + math.log10(area)


def bed_springs(scene) -> list[tuple[str, float]]:
    """About the largest node springs of the scene's soil, h the element size: Winkler's and
    Pasternak's k × h² (and the shear layer's c2), a half-space's E h / (1 − ν²) (a cell's
    stiffness on it)."""
    from .geometry import mesh_size

    f = scene.foundation
    h = mesh_size(scene)
    if f.model == "halfspace":
        return [("foundation.E", f.E * h / (1.0 - f.nu**2))]
    return [("foundation.k", f.k * h**2)] + ([("foundation.shear", f.shear)] if f.shear else [])


def check_scales(scene, derived: tuple[float, float]) -> None:
    """SceneError (through ``scene._fail``, naming the field) if a magnitude falls outside ``derived``."""
    p = scene.plate
    lo, hi = math.log10(derived[0]), math.log10(derived[1])
    logD = math.log10(p.E) + 3 * math.log10(p.h) - math.log10(12.0 * (1.0 - p.nu**2))
    if not lo <= logD <= hi:
        scene._fail("plate", f"the bending stiffness D = E h³/12(1 − ν²) = 1e{logD:.0f} is outside "
                    f"{derived[0]:.0e} … {derived[1]:.0e}; change units")
    logL = math.log10(max(p.a, p.b))
    for i, ld in enumerate(scene.loads):
        if (ld.P if getattr(ld, "type", None) == "point" else ld.q) == 0.0:
            continue
        logW = -2.0 + _load_force_log(scene, ld) + 2 * logL - logD
        if not lo <= logW <= hi:
            scene._fail(f"loads.{i}", f"deflects the plate by about 1e{logW:.0f} (0.01 F L²/D), outside "
                        f"{derived[0]:.0e} … {derived[1]:.0e}; change units")
    springs = [(f"supports.{i + 1}.stiffness", s.stiffness) for i, s in enumerate(scene.supports) if not s.rigid]
    if scene.foundation is not None:
        springs += bed_springs(scene)
    for where, c in springs:
        logr = logD - math.log10(c) - 2 * logL
        if not lo <= logr <= hi:
            scene._fail(where, f"is 1e{-logr:.0f} times the plate's own stiffness D/L², outside what "
                        "double precision can weigh against it; make the support rigid, or remove it")
