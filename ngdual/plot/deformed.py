"""The deformed body: the mesh moved by the displacement u_h, magnified so that it shows
(:func:`plot_deformed`), over the outline of the undeformed body."""

from __future__ import annotations

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np
from matplotlib.figure import Figure

from .scales import colorbar, coordinates, is_wide, length_unit, unit_label

SHOWN = 0.075               # the largest magnified displacement, a share of the body's size
NICE = (1.0, 2.0, 3.0, 5.0)  # a magnification is one of these times a power of ten


def magnification(largest: float, size: float, share: float = SHOWN) -> float:
    """The factor that makes a displacement ``largest`` about ``share`` of ``size``,
    rounded to 1, 2, 3 or 5 times a power of ten (nearest in ratio: the largest magnified
    displacement is then within a factor sqrt(2) of ``share``); 1 without displacement.

    >>> magnification(1e-3, 1.0), magnification(0.02, 8.0)
    (100.0, 30.0)
    """
    if not largest > 0 or not np.isfinite(largest):
        return 1.0
    raw = share * size / largest
    decade = 10.0 ** np.floor(np.log10(raw))
    candidates = [n * decade for n in (*NICE, 10.0)]
    return float(min(candidates, key=lambda c: abs(np.log(c / raw))))


def vertex_displacement(solution) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertex coordinates, triangles and u_h at the vertices (n, 2): the discontinuous u_h
    of :func:`ngdual.quantities.fields` set into continuous P1 (NGSolve's ``Set``, which
    averages the elements meeting at a vertex)."""
    import ngsolve as ngs

    from ..mesh import mesh_arrays
    from ..quantities import fields

    mesh = solution.problem.fes.mesh
    points, triangles = mesh_arrays(mesh)
    u = fields(solution).u
    space = ngs.H1(mesh, order=1)
    values = []
    for k in range(2):
        gf = ngs.GridFunction(space)
        gf.Set(u[k])
        values.append(gf.vec.FV().NumPy()[:len(points)].copy())
    return points, triangles, np.column_stack(values)


def _outline(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The boundary edges of the triangulation (m, 2, 2): those of one triangle only."""
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                    triangles[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    return points[unique[count == 1]]


def plot_deformed(solution, scale: float | None = None, title: str | None = None) -> Figure:
    """The body deformed by u_h, magnified ``scale`` times, coloured by |u_h|.

    ``scale=None`` chooses the magnification (:func:`magnification`) so that the largest
    displacement is about 7.5 % of the body's size (the longer side of its bounding box);
    the title states it. The undeformed outline is drawn in grey, the rigid foundation
    line (if the scene has one) dashed: it is not magnified, so the magnified body crosses it
    where it touches. Axes and colour bar carry the scene's units.

    >>> import ngdual as nd
    >>> solution = nd.solve(nd.load_scene("hertz-cylinder"), 1)
    >>> fig = nd.plot_deformed(solution)
    >>> fig.axes[0].get_title()
    'hertz-cylinder, level 1: deformed body, displacement magnified 30 times'
    """
    from ..scene import foundation_line

    scene = solution.problem.scene
    points, triangles, u = vertex_displacement(solution)
    size = float(max(np.ptp(points[:, 0]), np.ptp(points[:, 1])))
    magnitude = np.linalg.norm(u, axis=1)
    if scale is None:
        scale = magnification(float(magnitude.max()), size)
    moved = points + scale * u
    fig, ax = plt.subplots(figsize=(10, 7), constrained_layout=True)
    for edge in _outline(points, triangles):
        ax.plot(edge[:, 0], edge[:, 1], color="0.6", lw=0.8)
    tri = mtri.Triangulation(moved[:, 0], moved[:, 1], triangles)
    art = ax.tripcolor(tri, magnitude, shading="gouraud", cmap="viridis")
    ax.triplot(tri, color="k", lw=0.15, alpha=0.5)
    if scene.has_contact and scene.contact.foundation is not None:
        point, normal = foundation_line(scene.contact)
        ax.axline(point, point + np.array([normal[1], -normal[0]]), color="k", ls="--", lw=1.0,
                  label="rigid foundation (not magnified: the magnified body crosses it)")
    ax.plot([], [], color="0.6", lw=0.8, label="undeformed")
    ax.legend(loc="upper right", fontsize="small")
    colorbar(fig, art, ax, unit_label(r"displacement $|u_h|$", length_unit(scene.units)),
             "neither", "", is_wide(points))
    coordinates(ax, scene.units)
    ax.set_title(title or f"{scene.name}, level {solution.problem.level}: deformed body, "
                          f"displacement magnified {scale:g} times")
    return fig
