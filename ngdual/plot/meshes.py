"""Pictures of the domain: the triangulation with the elements marked for refinement
(:func:`plot_mesh`), a scene's boundary parts Gamma_D, Gamma_N, Gamma_C on its mesh
(:func:`plot_geometry`) and Example 3.46 with its loads and gap functions (:func:`plot_domain`,
Fig. 3.10)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np
from matplotlib.figure import Figure

from .scales import coordinates, length_unit, stress_unit, unit_label


def plot_mesh(points: np.ndarray, triangles: np.ndarray, title: str = "",
              marked: np.ndarray | None = None, units=None) -> Figure:
    """The triangulation, with the elements marked for refinement shaded (Figs. 4.1-4.13).

    ``marked``: one flag per triangle (the MARK step of the adaptive loop); the legend
    counts them.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    width = max(float(np.ptp(points[:, 0])), 1e-300)
    aspect = float(np.ptp(points[:, 1])) / width
    fig, ax = plt.subplots(figsize=(9.5, min(9.5 * aspect, 12.0) + 1.2))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    handles = []
    if marked is not None and np.any(marked):
        marked = np.asarray(marked, bool)
        colour = plt.get_cmap("Oranges")(0.6)
        ax.tripcolor(mtri.Triangulation(points[:, 0], points[:, 1], triangles[marked]),
                     facecolors=np.ones(int(marked.sum())), cmap=ListedColormap([colour]),
                     edgecolors="none", rasterized=True)
        handles.append(Patch(color=colour,
                             label=f"{int(marked.sum())} marked for refinement"))
    ax.triplot(tri, color="k", lw=0.25, label=f"{len(triangles)} triangles")
    coordinates(ax, units)
    ax.set_title(title or f"{len(triangles)} triangles")
    ax.legend(handles=[*ax.get_legend_handles_labels()[0][:1], *handles], loc="upper center",
              bbox_to_anchor=(0.5, -0.25 if aspect < 0.5 else -0.12), ncol=2, fontsize="small")
    return fig


BOUNDARY_ROLES = {"dirichlet": (r"$\Gamma_D$", "tab:blue"), "neumann": (r"$\Gamma_N$", "tab:green"),
                  "contact": (r"$\Gamma_C$", "tab:red")}


def plot_geometry(scene, mesh=None, level: int | None = None, title: str = "") -> Figure:
    """The domain of ``scene`` with its boundary parts Γ_D, Γ_N, Γ_C in colour, every side
    named, and the mesh (``mesh``, or the one of ``level``, default the scene's level).

    >>> import ngdual as nd
    >>> fig = nd.plot_geometry(nd.load_scene("thesis-3.46-coulomb"), level=1)  # doctest: +SKIP
    """
    import ngsolve as ngs
    from matplotlib.collections import LineCollection

    from ..mesh import build_mesh, mesh_arrays

    mesh = build_mesh(scene.geometry, level) if mesh is None else mesh
    points, triangles = mesh_arrays(mesh)
    edges: dict = {}
    for element in mesh.Elements(ngs.BND):
        edges.setdefault(element.mat, []).append([v.nr for v in element.vertices])
    width, height = np.ptp(points, axis=0)
    fig, ax = plt.subplots(figsize=(9, max(3.2, 7 * height / width + 1.6)))
    ax.triplot(points[:, 0], points[:, 1], triangles, color="0.6", lw=0.4)
    centre = points.mean(axis=0)
    for role, (symbol, colour) in BOUNDARY_ROLES.items():
        sides = {label: points[np.array(edges[label])] for label in scene.labels(role)
                 if label in edges}
        if not sides:
            continue
        ax.add_collection(LineCollection(np.concatenate(list(sides.values())), colors=colour,
                                         lw=3.5, label=f"{symbol}: {', '.join(sides)}"))
        for label, side in sides.items():
            middle = side.mean(axis=(0, 1))
            inward = 22 * (centre - middle) / (np.linalg.norm(centre - middle) or 1.0)
            ax.annotate(f"{symbol} ({label})", middle, xytext=tuple(inward),
                        textcoords="offset points", color=colour, ha="center", va="center",
                        fontsize="small",
                        bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 1})
    coordinates(ax, scene.units)
    ax.margins(0.1)
    ax.set_title(title or f"{scene.name}: boundary parts and mesh ({mesh.ne} triangles)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, fontsize="small",
              frameon=False)
    fig.tight_layout()
    return fig


def plot_domain(points: np.ndarray, triangles: np.ndarray, x: np.ndarray, load: np.ndarray,
                foundations: list, gaps: list, suptitle: str, units=None) -> Figure:
    """Fig. 3.10: Example 3.46 with Gamma_D, Gamma_N (load arrows), Gamma_C and foundations
    (``(x, y, label, style)``) on the left, the gap functions (same form) on the right."""
    fig, (ax, ag) = plt.subplots(1, 2, figsize=(13, 3.8), constrained_layout=True,
                                 gridspec_kw={"width_ratios": [1.6, 1]})
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    ax.triplot(tri, color="0.75", lw=0.5)
    ax.plot([-4, -4], [-1, 1], color="k", lw=4, label=r"$\Gamma_D$ (clamped)")
    ax.plot([4, 4], [-1, 1], color="k", lw=4)
    ax.plot([-4, 4], [1, 1], color="tab:orange", lw=3, label=r"$\Gamma_N$")
    ax.plot([-4, 4], [-1, -1], color="tab:green", lw=3, label=r"$\Gamma_C$")
    scale = 0.6 / max(float(np.max(np.abs(load))), 1e-300)
    for xi, ti in zip(x[::40], load[::40]):
        if abs(ti) > 0:
            ax.annotate("", (xi, 1), (xi, 1 - ti * scale),
                        arrowprops={"arrowstyle": "->", "color": "tab:orange", "lw": 1})
    peak, stress = float(np.max(np.abs(load))), stress_unit(units)
    ax.plot([], [], color="tab:orange", marker=r"$\downarrow$", ls="none",
            label=rf"$t_0$ (max {peak:.0f}{' ' + stress if stress else ''})")
    for fx, fy, label, style in foundations:
        ax.plot(fx, fy, label=label, **style)
    coordinates(ax, units)
    ax.set_ylim(-3.3, 1.9)
    ax.set_title(r"$\Omega = [-4, 4] \times [-1, 1]$, level-1 mesh")
    ax.legend(loc="upper center", ncol=3, fontsize="small")
    for gx, gy, label, style in gaps:
        ag.plot(gx, gy, label=label, **style)
    ag.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", length_unit(units)))
    ag.set_ylabel(unit_label(r"gap $g(x_1)$", length_unit(units)))
    ag.set_title("Gap functions of the shipped scenes")
    ag.grid(alpha=0.3)
    ag.legend(fontsize="small")
    fig.suptitle(suptitle)
    return fig
