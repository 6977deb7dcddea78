"""REFINE: bisect the marked triangles and carry the coarse boundary meshes along.

:func:`refine` is netgen's bisection with its conforming closure; :func:`refine_graded`
refines the marked triangles and then, again, the triangles at the peaks of their estimate
until the mesh has grown by a least factor; :func:`refine_with_boundary` does either and
also carries the coarse boundary meshes h~, h^ over to the new mesh, nested and with
h~ ~ 2h locally (:meth:`ngdual.BoundaryMeshes.follow`), which the next SOLVE needs.
:data:`RESOLUTION` is the smallest triangle the adaptive loop refines.
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np

from ..boundary import BoundaryMeshes, nearest_vertex
from ..geometry import length_scale
from ..loop_defaults import MAX_GROWTH
from ..marking import peak_vertices
from ..mesh import element_diameters, mesh_arrays
from ..scene import Scene, SceneError, SceneTypeError

# The smallest triangle the loop refines, as a share of the scene's length scale L
# (:func:`ngdual.geometry.length_scale`): a thousand times the geometry's round-off
# (:data:`ngdual.geometry.ROUND_OFF`, below which two positions are one point), and far
# below what the studies' solutions need (their finest triangles: 1.2e-6 L, at the flat
# punch's edges). A marking that reaches below it stops the loop.
RESOLUTION = 1e-7
# The most times a graded refinement refines the triangles at the peaks after the marked
# ones (:func:`refine_graded`): a peak's triangles shrink by up to 2^-3 in one step. A third
# round never ran on the work-precision study's problems at tol = 0.01; at 0.001 it took the
# wedge's apex (order 1, the pressure goal) to the resolution at step 8 without reaching the
# tolerance, as two rounds do (the apex's kink; docs/theory/estimator.md, "Steps that
# pay").
GRADING_ROUNDS = 2


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


def refine_graded(scene: Scene, mesh: ngs.Mesh, marked: np.ndarray, indicators: np.ndarray,
                  growth: float) -> ngs.Mesh:
    """The marked triangles of ``mesh`` refined, then the triangles at the peaks of their
    estimate refined again until the triangles have grown by ``growth``.

    After :func:`refine` of the marked triangles, the triangles at the peak vertices
    (:func:`ngdual.marking.peak_vertices`: where the marked triangles' eta_T^2 add up to at
    least a quarter of the most at any vertex) are refined once, and again while the mesh
    has fewer than ``growth`` times the triangles of ``mesh``, at most
    :data:`GRADING_ROUNDS` times and never below :data:`RESOLUTION`. The unknowns of
    PEERS_k are about proportional to the triangles, so they grow by about ``growth`` too.

    Where the marked estimate sits at a point (a corner singularity, an end of the contact
    zone), Dörfler's set is a handful of triangles there and one bisection per step grows
    the mesh by a few percent; a graded step shrinks the triangles at the point by up to
    2^-3 and takes the grading several plain steps would, in one solve. Where it is spread
    (over Gamma_C at order 0), most vertices of the marked set are peaks and the step
    refines it twice (docs/theory/estimator.md, "Steps that pay").
    """
    peaks = peak_vertices(mesh_arrays(mesh)[1], indicators, marked)
    fine = refine(mesh, marked)
    for done in range(GRADING_ROUNDS):
        if done and fine.ne >= growth * mesh.ne:
            break
        _, triangles = mesh_arrays(fine)
        at_peak = np.zeros(fine.nv, dtype=bool)
        at_peak[:len(peaks)] = peaks   # refine keeps the vertex numbers
        around = at_peak[triangles].any(axis=1)
        if not around.any() or below_resolution(scene, element_diameters(fine), around):
            break
        fine = refine(fine, around)
    return fine


def check_growth(growth) -> float:
    """``growth`` if it is a number in [1, :data:`~ngdual.loop_defaults.MAX_GROWTH`]; a
    SceneError (SceneTypeError for a wrong type) naming it otherwise."""
    if isinstance(growth, bool) or not isinstance(growth, (int, float, np.integer,
                                                           np.floating)):
        raise SceneTypeError("growth", f"must be a number in [1, {MAX_GROWTH:g}], got "
                                       f"{type(growth).__name__}")
    if not 1 <= growth <= MAX_GROWTH:
        raise SceneError("growth", f"must lie in [1, {MAX_GROWTH:g}] (1: the marked "
                                   f"triangles alone), got {growth!r}")
    return float(growth)


def refine_with_boundary(scene: Scene, mesh: ngs.Mesh, coarse: BoundaryMeshes,
                         marked: np.ndarray, indicators: np.ndarray | None = None,
                         growth: float = 1.0) -> tuple[ngs.Mesh, BoundaryMeshes]:
    """REFINE: the marked triangles of ``mesh`` bisected (:func:`refine`; with a ``growth``
    above 1 graded towards the peaks of their ``indicators``, :func:`refine_graded`) and
    the coarse boundary meshes h~, h^ (``coarse``) carried over to the new mesh.

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
    indicators : array, optional
        The indicators that marked them; needed with a ``growth`` above 1.
    growth : float
        The least factor by which the triangles grow, in [1, 4]; 1 (the default) refines
        the marked triangles alone.

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
    if check_growth(growth) == 1:
        fine = refine(mesh, marked)
    elif indicators is None:
        raise ValueError("a growth above 1 grades the refinement towards the peaks of the "
                         "indicators: give them")
    else:
        fine = refine_graded(scene, mesh, marked, np.asarray(indicators, dtype=float), growth)
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
