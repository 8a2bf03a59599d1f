"""Model re-use: a scene that differs from a model's only in gaps, support stiffnesses, the
bed's modulus and gap field, or loads shares its stiffness matrix and contact operator.

A sweep (:mod:`plateqp.studies.sweep`) and the stiffness design
(:func:`plateqp.studies.design.most_uniform_stiffness`) build one model and adapt it to each
value; the condensation of a contact problem that shares K and B is then computed once too.
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np

from ..model.assembly import Model

from ..model.generators import mesh_generator
from ..model.scene import PointLoad, Scene
from ..model.soil import couples


def same_structure(a: Scene, b: Scene) -> bool:
    """True if the two scenes have the same K and contact operator B (only gaps, stiffnesses,
    bed modulus and gap field, or loads differ; where the generator puts a node at every point
    load (``points_are_nodes``: the triangle meshes), a point load that moves changes the mesh)."""
    if (a.plate, a.mesh, a.edges, a.openings, a.pins) != (b.plate, b.mesh, b.edges, b.openings, b.pins):
        return False
    if [(s.x, s.y) for s in a.supports] != [(s.x, s.y) for s in b.supports]:
        return False
    if mesh_generator(a).points_are_nodes and _point_loads(a) != _point_loads(b):  # a moved node: a new mesh
        return False
    if (a.foundation is None) != (b.foundation is None):
        return False
    if a.foundation is None:
        return True
    fa, fb = a.foundation, b.foundation
    if fa.region != fb.region or fa.model != fb.model:
        return False
    # a soil with unknowns of its own holds its parameters in K (plateqp.model.soil): only its gap may differ
    return not couples(fa) or all(getattr(fa, k) == getattr(fb, k) for k in ("k", "shear", "E", "nu"))


def _point_loads(scene: Scene) -> list:
    return [(ld.x, ld.y) for ld in scene.loads if isinstance(ld, PointLoad)]


def _kept(base: Model, kind: str, build):
    """What ``build()`` gave for ``base``'s K before (kept in ``base.derived``, which the models
    adapted from it share), or that, built now and kept."""
    for K, _, k, value in base.derived:
        if K is base.K and k == kind:
            return value
    value = build()
    base.derived.append((base.K, None, kind, value))
    return value


def _prescribed_load(base: Model) -> np.ndarray:
    """K_fp u_p: the load the prescribed displacements put on the free dofs (the same whatever
    the loads), computed once per K."""
    return _kept(base, "prescribed-load", lambda: base.K_full[base.free][:, base.fixed] @ base.values)


def _load_vector(base: Model, scene: Scene) -> np.ndarray:
    """The load vector of ``scene.loads`` on ``base``'s mesh: each load's magnitude times its
    vector at magnitude 1, kept per place and shape of a load (a sweep of a load's magnitude
    assembles it once)."""
    units = _kept(base, "unit-loads", dict)
    f = np.zeros(base.n_full)
    for ld in scene.loads:
        key = "P" if isinstance(ld, PointLoad) else "q"
        unit = dataclasses.replace(ld, **{key: 1.0})
        tag = repr(unit)
        if tag not in units:
            one = copy.copy(scene)  # not validated: only its load vector is read
            one.loads = [unit]
            units[tag] = base.load_vector(one)
        f += getattr(ld, key) * units[tag]
    return f


def adapt_model(base: Model, scene: Scene) -> Model | None:
    """A copy of ``base`` for ``scene`` without re-assembly, or None if K or B would change.

    Gaps, support stiffnesses, the bed's modulus and gap field and the loads are changed in
    copies of the arrays; the stiffness matrix and contact operator B are shared. The gaps are
    the scene's, shifted by the prescribed dofs as in ``base``
    (:meth:`plateqp.model.assembly.ContactOperator.with_gaps`).
    """
    old = base.scene
    if not same_structure(old, scene):
        return None
    model = dataclasses.replace(base, scene=scene)
    if old.loads != scene.loads:
        f_full = _load_vector(base, scene)  # the load vector alone, on the same mesh
        model.f_full = f_full
        model.f = base.on_unknowns(f_full) - np.concatenate([_prescribed_load(base), np.zeros(base.n_soil)])
    c = base.contacts
    if c is not None:
        gaps, rho = c.scene_gaps.copy(), c.rho.copy()
        sup = c.source == "support"
        if np.any(sup):
            i = c.index[sup]
            gaps[sup] = [scene.supports[k].gap for k in i]
            rho[sup] = [0.0 if scene.supports[k].rigid else 1.0 / scene.supports[k].stiffness for k in i]
        bed = c.source == "bed"
        if np.any(bed):
            fo, fn = old.foundation, scene.foundation
            gaps[bed] = fn.gap_at(c.xy[bed, 0], c.xy[bed, 1])
            if not couples(fn):  # Winkler's springs: 1 / (k × the node's area) on their rows
                rho[bed] = c.rho[bed] * (fo.k / fn.k)
        model.contacts = c.with_gaps(gaps, rho)
    return model


__all__ = ["adapt_model", "same_structure"]
