"""REFINE: bisect the marked triangles and carry the coarse boundary meshes along.

:func:`refine` is netgen's bisection with its conforming closure; :func:`refine_with_boundary`
also carries the coarse boundary meshes h~, h^ over to the new mesh, nested and with
h~ ~ 2h locally (:meth:`ngdual.BoundaryMeshes.follow`), which the next SOLVE needs.
:data:`RESOLUTION` is the smallest triangle the adaptive loop refines.
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np

from ..boundary import BoundaryMeshes, nearest_vertex
from ..geometry import length_scale
from ..mesh import element_diameters, mesh_arrays
from ..scene import Scene

# The smallest triangle the loop refines, as a share of the scene's length scale L
# (:func:`ngdual.geometry.length_scale`): a thousand times the geometry's round-off
# (:data:`ngdual.geometry.ROUND_OFF`, below which two positions are one point), and far
# below what the studies' solutions need (their finest triangles: 1.2e-6 L, at the flat
# punch's edges). A marking that reaches below it stops the loop.
RESOLUTION = 1e-7


def refine(mesh: ngs.Mesh, marked: np.ndarray) -> ngs.Mesh:
    """A copy of ``mesh`` with the marked triangles refined (netgen bisection + closure).

    The copy keeps the vertex numbers (new vertices are appended), which the
    coarse boundary meshes rely on; refining a copy leaves the spaces built on
    ``mesh`` valid (NGSolve cannot update compressed spaces in place).
    """
    marked = np.asarray(marked, dtype=bool)
    if len(marked) != mesh.ne:
        raise ValueError(f"{len(marked)} marks for a mesh of {mesh.ne} elements")
    fine = ngs.Mesh(mesh.ngmesh.Copy())
    for el in fine.Elements(ngs.VOL):
        fine.SetRefinementFlag(el, bool(marked[el.nr]))
    fine.Refine()
    return fine


def refine_with_boundary(scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes,
                         marked: np.ndarray) -> tuple[ngs.Mesh, BoundaryMeshes]:
    """REFINE: the marked triangles of ``mesh`` bisected (:func:`refine`) and the coarse
    boundary meshes h~, h^ (``coarse``) carried over to the new mesh.

    Parameters
    ----------
    scene : Scene
        The scene ``mesh`` was built for (its ``htilde_factor`` and Gamma_C, Gamma_N labels).
    mesh : ngsolve.Mesh
        The mesh of the last SOLVE.
    coarse : BoundaryMeshes
        Its coarse boundary meshes (``BoundaryMeshes.for_scene(scene, mesh)`` on a fresh mesh).
    marked : array of bool
        One mark per triangle (:func:`ngdual.mark`).

    Returns
    -------
    (ngsolve.Mesh, BoundaryMeshes)
        The refined mesh and its coarse boundary meshes, for the next
        :func:`ngdual.solve_on_mesh`.

    Examples
    --------
    One step of the adaptive loop by hand, on Example 3.46's coarsest mesh:

    >>> import ngdual as nd
    >>> scene = nd.load_scene("thesis-3.46-frictionless", ["contact.ends='consistent'"])
    >>> mesh = nd.build_mesh(scene.geometry, 1)
    >>> coarse = nd.BoundaryMeshes.for_scene(scene, mesh)
    >>> solution = nd.solve_on_mesh(scene, mesh, coarse)                   # SOLVE
    >>> indicators = nd.estimate(solution).indicators                      # ESTIMATE
    >>> marked = nd.mark(indicators, 0.5, "dorfler")                       # MARK
    >>> fine, coarse = nd.refine_with_boundary(scene, mesh, coarse, marked)  # REFINE
    >>> mesh.ne, fine.ne > mesh.ne
    (32, True)
    """
    fine = refine(mesh, marked)
    return fine, coarse.follow(scene, fine)


def refine_towards(scene: Scene, mesh: ngs.Mesh, point, times: int
                   ) -> tuple[ngs.Mesh, BoundaryMeshes]:
    """``times`` refinements of the triangles touching the vertex nearest to ``point``, with
    the coarse boundary meshes following: a mesh graded towards ``point`` (h ratio about
    2^times). A grading that would refine a triangle smaller than :data:`RESOLUTION` times
    the scene's length scale is refused (ValueError), as the adaptive loop stops there."""
    coarse = BoundaryMeshes.for_scene(scene, mesh)
    for done in range(times):
        # the nearest vertex, not every vertex within a fixed distance of point: the graded
        # mesh's vertices come closer to it than any fixed distance
        points, triangles = mesh_arrays(mesh)
        touching = (triangles == nearest_vertex(dict(enumerate(points)), point)).any(axis=1)
        small = below_resolution(scene, element_diameters(mesh), touching)
        if small:
            raise ValueError(f"times: refinement {done + 1} of {times} would refine triangles "
                             f"at {tuple(point)} {small}")
        mesh, coarse = refine_with_boundary(scene, mesh, coarse, touching)
    return mesh, coarse


def below_resolution(scene: Scene, h: np.ndarray, marked: np.ndarray) -> str | None:
    """"of diameter ..., below the smallest the loop refines, ..." when a ``marked`` triangle's
    diameter ``h`` is below :data:`RESOLUTION` times the scene's length scale (else None)."""
    floor = RESOLUTION * length_scale(scene.geometry.curves())
    small = marked & (h < floor)
    if not small.any():
        return None
    return (f"of diameter {h[small].min():.2g}, below the smallest the loop refines, "
            f"{floor:.2g} ({RESOLUTION:g} of the scene's length scale)")
