"""The model floor: from a scene to the plate's matrices, and the fields recovered from its dofs.

=========================  =======================================================================
module                     job
=========================  =======================================================================
:mod:`.scene`              the scene's dataclasses, TOML load and save, validation
:mod:`.parts`              the scene's parts checked for their types (NumPy numbers made Python)
:mod:`.checks`             the scene's field checks, in the order a reader meets the fields
:mod:`.geometry`           shaped plates: outlines, holes, openings, regions
:mod:`.crossings`          whether polygon segments cross (shapely's STRtree)
:mod:`.paths`              scene fields named with dots (``plate.h``, ``loads.0.P``)
:mod:`.scales`             the magnitudes of a scene, checked before any work
:mod:`.grid`               the structured rectangle mesh (:class:`~.grid.Grid`)
:mod:`.trimesh`            the triangle mesh from gmsh (:class:`~.trimesh.TriMesh`)
:mod:`.generators`         the mesh generator of each element's cell type
:mod:`.views`              what the meshes show of themselves: outlines, sections, dataset layouts
:mod:`.elements`           the plate elements (ACM, BFS on rectangles; DKT on triangles), one
                           registry
:mod:`.constraints`        prescribed dofs from named edges and pins; the rigid motions left free
:mod:`.assembly`           :func:`~.assembly.build_model`: mesh, stiffness, load, contact operator
:mod:`.soil`               soils whose surface has unknowns of its own (Pasternak, half-space)
:mod:`.halfspace`          Boussinesq's surface flexibility: polygons exactly, a grid's by FFT
:mod:`.halfspace_grid`     a half-space bed's force flexibility on a grid, matrix-free (FFT)
:mod:`.variation`          a scene with one value changed, checked where it changed (sweeps)
:mod:`.recovery`           moments and stresses from the curvatures, nodal averages
=========================  =======================================================================

Both meshes answer the same questions (nodes, cells, boundary edges with outward normals,
locate, tributary areas), so nothing downstream of :mod:`.assembly` asks which one it holds.
Importing this package imports none of its modules.
"""
