"""Meshes: the structured mesh of Example 3.46 and netgen meshes of labelled polygons.

Level k of Example 3.46 is the rectangle [-4,4]x[-1,1] cut into 8x2 unit
squares, each split by its diagonal from lower-left to upper-right, refined
k-1 times uniformly (every triangle into four). Red refinement of that mesh is
again the structured mesh with the same diagonal direction, so level k is
built directly as 8*2^(k-1) x 2*2^(k-1) squares; this gives the DOF counts of
Table 3.1 exactly.
"""

from __future__ import annotations

import ngsolve as ngs
import numpy as np
from netgen.geom2d import SplineGeometry
from netgen.meshing import Element1D, FaceDescriptor, NgException
from netgen.meshing import Mesh as NetgenMesh

from . import geometry
from .scene import Geometry, SceneError, check_level, validate_geometry

THESIS_LABELS = ("bottom", "right", "top", "left")


def thesis_mesh(level: int) -> ngs.Mesh:
    """The structured mesh of Example 3.46 on ``level`` (1 = 32 triangles).

    >>> thesis_mesh(1).ne
    32
    """
    if level < 1:
        raise ValueError(f"level must be >= 1, got {level}")
    k = 2 ** (level - 1)
    nx, ny = 8 * k, 2 * k
    xs, ys = np.linspace(-4, 4, nx + 1), np.linspace(-1, 1, ny + 1)
    m = NetgenMesh(dim=2)
    # points column by column (x outer, y inner) and two triangles per square in the same
    # order, added as arrays: a Python loop over the 1.6e6 triangles of level 8 takes seconds
    x, y = np.meshgrid(xs, ys, indexing="ij")
    m.AddPoints(np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)]))
    m.Add(FaceDescriptor(surfnr=1, domin=1, domout=0, bc=1))
    m.SetMaterial(1, "body")
    corner = np.arange(x.size).reshape(nx + 1, ny + 1)
    a, b, c, d = corner[:-1, :-1], corner[1:, :-1], corner[1:, 1:], corner[:-1, 1:]
    triangles = np.stack([np.stack([a, b, c], axis=-1), np.stack([a, c, d], axis=-1)], axis=2)
    m.AddElements(dim=2, index=1, data=triangles.reshape(-1, 3).astype(np.int32), base=0)

    def pid(i: int, j: int) -> int:
        return int(corner[i, j]) + 1  # netgen numbers points from 1

    # counter-clockwise segments, so the body lies to their left
    for i in range(nx):
        m.Add(Element1D([pid(i, 0), pid(i + 1, 0)], index=1))
        m.Add(Element1D([pid(i + 1, ny), pid(i, ny)], index=3))
    for j in range(ny):
        m.Add(Element1D([pid(nx, j), pid(nx, j + 1)], index=2))
        m.Add(Element1D([pid(0, j + 1), pid(0, j)], index=4))
    for index, label in enumerate(THESIS_LABELS, start=1):
        m.SetBCName(index - 1, label)
    return ngs.Mesh(m)


def polygon_mesh(points, labels, maxh: float, level: int = 1, arcs: dict | None = None,
                 side_maxh: dict | None = None) -> ngs.Mesh:
    """A netgen mesh of the counter-clockwise polygon ``points`` with side labels.

    Side ``i`` (from ``points[i]`` to ``points[i+1]``) gets boundary label
    ``labels[i]``; sides whose label is a key of ``arcs`` are circular arcs around
    ``arcs[label]`` (:mod:`ngdual.geometry`), given to netgen as rational quadratic
    splines that are the arc exactly; ``side_maxh[label]`` is a mesh size on those sides.
    ``level`` k applies k-1 uniform refinements, which put the new boundary vertices on
    the curves.

    The elements stay affine (straight-sided): the lowest-order PEERS spaces converge
    at O(h), and vertices on the exact curve leave a geometric error of O(h^2) in
    position and O(h) in the normal, which does not limit that order; straight edges
    also keep the normal constant on every fine edge, which the hybridised solver
    (:mod:`ngdual.solvers.hybrid`) and the friction terms rely on.
    """
    geo = SplineGeometry()
    ids: dict[tuple, int] = {}

    def point(p) -> int:
        key = (float(p[0]), float(p[1]))
        if key not in ids:
            ids[key] = geo.AppendPoint(*key)
        return ids[key]

    side_maxh = side_maxh or {}
    for side in geometry.sides(points, labels, arcs):
        options = {"bc": side.label, "leftdomain": 1, "rightdomain": 0}
        if side.label in side_maxh:
            options["maxh"] = float(side_maxh[side.label])
        if side.is_arc:
            for a, control, b in side.spline_pieces():
                geo.Append(["spline3", point(a), point(control), point(b)], **options)
        else:
            geo.Append(["line", point(side.start), point(side.end)], **options)
    try:
        mesh = ngs.Mesh(geo.GenerateMesh(maxh=maxh))
    except NgException as err:
        # validation refuses every geometry known to fail; this names the fields if one slips
        raise SceneError("geometry", f"netgen could not mesh the domain ({err}); check "
                                     "geometry.points, geometry.arcs, geometry.maxh and "
                                     "geometry.side_maxh") from None
    refine_uniformly(mesh, level - 1)
    return mesh


def refine_uniformly(mesh: ngs.Mesh, times: int) -> ngs.Mesh:
    """Refine every triangle into four, ``times`` times (in place)."""
    for _ in range(times):
        mesh.Refine()
    return mesh


def build_mesh(geo: Geometry, level: int | None = None) -> ngs.Mesh:
    """The mesh of a scene geometry on ``level`` (default: the geometry's own level).

    The geometry is checked first (:func:`ngdual.scene.validate_geometry`): netgen never
    sees a degenerate polygon. The size is not checked here; :func:`ngdual.budget.check`
    does that for the runs that build meshes on a user's request.
    """
    validate_geometry(geo)
    level = geo.level if level is None else check_level(level, "level")
    if geo.kind == "thesis-3.46":
        return thesis_mesh(level)
    return polygon_mesh(geo.points, geo.labels, geo.maxh, level, geo.arcs, geo.side_maxh)


def moved_mesh(mesh: ngs.Mesh, matrix, shift=(0.0, 0.0)) -> ngs.Mesh:
    """A copy of ``mesh`` with every vertex x moved to ``matrix @ x + shift``.

    Vertex and element numbers and boundary labels are those of ``mesh``: a rotated (or
    otherwise moved, the orientation kept) copy of a scene's mesh, on which the equally moved
    scene is solved on the same triangles as the original. The copy has no curved geometry,
    so refining it splits its boundary edges at their midpoints.

    >>> quarter = np.array([[0.0, -1.0], [1.0, 0.0]])
    >>> moved_mesh(thesis_mesh(1), quarter).ne
    32
    """
    matrix = np.asarray(matrix, dtype=float)
    if matrix.shape != (2, 2) or not np.linalg.det(matrix) > 0:
        # a reflection would turn the boundary clockwise, the body to the right of its edges
        raise ValueError(f"matrix must be a 2x2 matrix with positive determinant, got "
                         f"{matrix.tolist()}")
    copy = mesh.ngmesh.Copy()
    copy.SetGeometry(None)  # the curves belong to the unmoved domain
    xy = copy.Coordinates()
    xy[:] = xy @ matrix.T + np.asarray(shift, dtype=float)
    return ngs.Mesh(copy)


def boundary_segments(mesh: ngs.Mesh) -> tuple[np.ndarray, dict[frozenset, int]]:
    """The vertex numbers (n, 2) of every boundary element, in NGSolve's order of its
    vertices, and the number of the boundary element on every boundary edge, keyed by the
    edge's two vertex numbers.

    Read from netgen's segments, which are NGSolve's boundary elements, in the same order and
    with the same order of their vertices: a loop over ``mesh.Elements(BND)`` reading
    ``el.vertices`` costs a Python object per element.
    """
    ends = mesh.ngmesh.Elements1D().NumPy()["nodes"][:, :2].astype(np.int64) - 1
    return ends, {frozenset(pair): nr for nr, pair in enumerate(ends.tolist())}


def edge_dofs(space: ngs.FESpace, pairs) -> list[tuple[int, ...]]:
    """The dofs of ``space`` on the boundary edges with the vertex numbers ``pairs`` (n, 2),
    each oriented from its first vertex: that vertex's dof, the other vertex's, then the
    edge's own in NGSolve's order.

    Read by ``ElementId`` from the boundary element on each edge
    (:func:`boundary_segments`): ``GetDofNrs`` of a compressed space by element object or
    vertex ``NodeId`` costs ten times as much, seconds on level 8. A RuntimeError names an
    edge on which ``space`` has not two vertex dofs.
    """
    ends, number = boundary_segments(space.mesh)
    out = []
    for a, b in np.asarray(pairs).tolist():
        nr = number[frozenset((a, b))]
        dofs = space.GetDofNrs(ngs.ElementId(ngs.BND, nr))
        if len(dofs) < 2 or min(dofs) < 0:
            raise RuntimeError(f"the boundary edge ({a}, {b}) has no dofs of the space at "
                               "both its vertices")
        out.append(tuple(dofs) if ends[nr, 0] == a else (dofs[1], dofs[0], *dofs[2:]))
    return out


def triangles_at(mesh: ngs.Mesh, labels: list[str]) -> np.ndarray:
    """The triangles with an edge on the boundary parts ``labels``, by number (sorted).

    >>> mesh = thesis_mesh(1)       # 32 triangles, eight edges on the bottom
    >>> len(triangles_at(mesh, ["bottom"])), len(triangles_at(mesh, []))
    (8, 0)
    """
    found: set[int] = set()
    if labels:
        for segment in mesh.Boundaries("|".join(labels)).Elements():
            for edge in segment.edges:
                found.update(el.nr for el in mesh[edge].elements)
    return np.array(sorted(found), dtype=np.int64)


def mesh_arrays(mesh: ngs.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Vertex coordinates (n, 2) and the vertex numbers of every triangle (ne, 3).

    Read from netgen's arrays (its triangles are NGSolve's elements, in the same order, with
    1-based vertex numbers): a loop over the elements costs 0.15 s per 50 000 triangles.
    These are the arrays :func:`ngdual.plot.plot_mesh` and ``plot_element_field`` take.

    Examples
    --------
    >>> import ngdual as nd
    >>> mesh = nd.build_mesh(nd.load_scene("thesis-3.46-frictionless").geometry, 1)
    >>> points, triangles = nd.mesh_arrays(mesh)
    >>> points.shape, triangles.shape                 # V = 27 vertices, T = 32 (Table 3.1)
    ((27, 2), (32, 3))
    """
    points = np.array(mesh.ngmesh.Coordinates(), dtype=float)
    triangles = mesh.ngmesh.Elements2D().NumPy()["nodes"][:, :3].astype(np.int64) - 1
    return points, triangles


def element_diameters(mesh: ngs.Mesh) -> np.ndarray:
    """h_T = the longest edge of every triangle."""
    points, triangles = mesh_arrays(mesh)
    p = points[triangles]
    return np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2).max(axis=1)


def mesh_size(mesh: ngs.Mesh) -> float:
    """The largest triangle diameter h (the first column of Table 3.1)."""
    return float(element_diameters(mesh).max())
