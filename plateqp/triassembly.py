"""From a triangle-meshed Scene to a Model: the DKT sibling of :mod:`plateqp.assembly`.

The mesh (:mod:`plateqp.trimesh`) has a node at every support, point load and pin. Node n
carries the dofs 3n, 3n + 1, 3n + 2 = (w, ∂w/∂x, ∂w/∂y), as on the ACM grid, so the contact
code (scaling, rigid modes, formulations, KKT) reads a :class:`TriModel` as it reads a Model.

Two-sided edges, by name (:func:`plateqp.geometry.edge_table`: ``all``, a whole boundary ``outer``
or ``holeK``, polygon segments ``outer_I``, ``outer_I-J``, ``holeK_I-J``, and on a rectangle
``left``/``right``/``bottom``/``top``): **simple** prescribes w (the edge's ``w``, 0 by default)
at its nodes and nothing else, the rotations stay free (imposing the tangential slope too would
make a curved simple support converge to the clamped plate: Babuška's paradox); **clamped** also
prescribes both
slopes, ∇w = (∂w/∂n) n with ∂w/∂n the edge's ``slope`` (w is constant along the edge; n the node's
outward normal, the mean of its two edges' on a curve; at a corner ∇w meets both edges' slopes).
An edge no name holds is free.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .assembly import BYTES_PER_DOF, MESH_BUILDERS, Model, _contacts, human_bytes, load_vector, memory_limit
from .elements import ELEMENTS
from .errors import ResourceError, SceneError
from .constraints import prescribed
from .geometry import inner_segments, lumped_region, mesh_size, region_outline, scene_domain
from .scene import PatchLoad, PointLoad, Scene, UniformLoad
from .trimesh import TriMesh, estimate_nodes, mesh_domain

@dataclass
class TriModel(Model):
    """A :class:`~plateqp.assembly.Model` on a triangle mesh (``grid`` is the :class:`TriMesh`,
    ``cells`` the triangles, ``cell_dofs`` their dofs)."""

    def bed_areas(self) -> np.ndarray:
        """(n_nodes,) each node's tributary area of the scene's tensionless bed: a third of every
        triangle (the whole plate), or of each triangle's part in the bed's region, weighted as
        a patch load is (:func:`patch_weights`). The region's outline is a line of the mesh
        (:func:`bed_lines`), so the region is a union of whole triangles and the areas sum to
        its area on the plate exactly."""
        mesh: TriMesh = self.grid
        region = self.scene.foundation.region
        if region is None:
            return np.bincount(mesh.triangles.ravel(), weights=np.repeat(mesh.areas() / 3, 3), minlength=mesh.n_nodes)
        area = patch_weights(mesh, region)
        if not area.any():
            raise SceneError(f"foundation.region: {region} does not overlap the plate's mesh")
        return area


def bed_lines(scene: Scene, domain) -> list:
    """The segments of the bed region's outline inside the plate (mesh lines: :func:`mesh_domain`)."""
    if scene.foundation is None or scene.foundation.region is None:
        return []
    return inner_segments(domain, region_outline(scene.foundation.region))


def patch_weights(mesh: TriMesh, box) -> np.ndarray:
    """(n_nodes,) each node's share of a unit pressure on the box [x0, x1] × [y0, y1] (or a
    polygon region, :func:`plateqp.geometry.region_outline`): over each
    triangle's part A_t in the box, ∫ λ_i dA = |A_t| λ_i(centroid of A_t) (λ the triangle's
    barycentric coordinates). The uniform load's lumping (area / 3 per vertex) where the box
    covers a triangle; statically exact everywhere: the total is the area of the box on the
    mesh, and the moment that of the pressure on it."""
    hit, weights = lumped_region(mesh.nodes[mesh.triangles], box)
    return np.bincount(mesh.triangles[hit].ravel(), weights=weights.ravel(), minlength=mesh.n_nodes)


def check_memory_tri(scene: Scene, h: float) -> None:
    """ResourceError before meshing if the triangle mesh would need more memory than allowed."""
    need = BYTES_PER_DOF * len(ELEMENTS[scene.mesh.element].node_dofs) * estimate_nodes(scene)
    if need > memory_limit():
        raise ResourceError(f"mesh.size: a triangle mesh of size {h:g} needs about {human_bytes(need)} to build "
                            f"and solve, above the limit of {human_bytes(memory_limit())}; use a larger mesh.size")


def build_tri_model(scene: Scene) -> TriModel:
    """Mesh a triangle-meshed scene with gmsh and assemble its DKT stiffness, loads, two-sided
    supports and contact operator."""
    domain = scene_domain(scene)
    h = mesh_size(scene)
    check_memory_tri(scene, h)
    points = [(s.x, s.y) for s in scene.supports] + [(ld.x, ld.y) for ld in scene.loads
                                                     if isinstance(ld, PointLoad)] + [(p.x, p.y) for p in scene.pins]
    mesh = mesh_domain(domain, h, points, bed_lines(scene, domain))
    el = ELEMENTS[scene.mesh.element]()
    nd = el.ndof_node
    p = scene.plate
    n_full = nd * mesh.n_nodes
    xy = mesh.nodes[mesh.triangles]
    cell_dofs = (mesh.triangles[:, :, None] * nd + np.arange(nd)).reshape(-1, el.ndof)
    Ke = el.stiffness(xy, p.D, p.nu)
    rows = np.repeat(cell_dofs, el.ndof, axis=1).ravel()
    cols = np.tile(cell_dofs, (1, el.ndof)).ravel()
    K_full = sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(n_full, n_full))
    K_full.sum_duplicates()

    f_full = load_vector(scene, mesh, el, cell_dofs, n_full)
    fixed, values = prescribed(scene, mesh, el)
    free = np.setdiff1d(np.arange(n_full), fixed)
    u_c = np.zeros(n_full)
    u_c[fixed] = values
    K = K_full[free][:, free].tocsr()
    f = f_full[free] - (K_full @ u_c)[free]
    model = TriModel(scene, mesh, el, K, f, free, fixed, values, n_full, cell_dofs, np.arange(len(cell_dofs)),
                     f_full, K_full)
    model.contacts = _contacts(scene, model)
    return model


MESH_BUILDERS["triangle"] = build_tri_model
