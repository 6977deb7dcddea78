"""Piecewise constant fields on the triangulation: one field with its colour bar
(:func:`plot_element_field`), the von Mises stress of a solution (:func:`plot_von_mises`) and
fields side by side on one colour scale (:func:`plot_field_pair`, Figs. 3.11-3.14)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np
from matplotlib.figure import Figure

from .scales import (
    CORNER_CLIP,
    clipped_scale,
    colorbar,
    coordinates,
    is_wide,
    stress_unit,
    unit_label,
)


def plot_element_field(points: np.ndarray, triangles: np.ndarray, values: np.ndarray,
                       title: str, label: str, clip: float | None = None,
                       units=None, vmax: float | None = None) -> Figure:
    """A piecewise constant field on the triangulation, with a colour bar labelled ``label``.

    ``clip``: end the colour scale at this percentile (e.g. 99 for a von Mises stress
    with corner singularities); ``vmax``: end it at this value (to compare pictures);
    the colour bar states the clipping.
    """
    aspect = float(np.ptp(points[:, 1])) / max(float(np.ptp(points[:, 0])), 1e-300)
    fig, ax = plt.subplots(figsize=(11, min(9 * aspect, 12.0) + 2.0), constrained_layout=True)
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    vmin, vmax, extend, note = clipped_scale(values, clip, vmax)
    art = ax.tripcolor(tri, facecolors=values, cmap="viridis", vmin=vmin, vmax=vmax,
                       edgecolors="none")
    colorbar(fig, art, ax, label, extend, note, is_wide(points))
    coordinates(ax, units)
    ax.set_title(title)
    return fig


def plot_von_mises(mesh, sigma, nu: float, title: str, clip: float | None = CORNER_CLIP,
                   vmax: float | None = None, units=None) -> Figure:
    """The plane-strain von Mises stress of ``sigma`` (:func:`ngdual.post.von_mises`) per
    element, on a colour scale ending at the ``clip`` percentile (corner singularities)
    or at ``vmax`` (one scale for several pictures): :func:`plot_element_field`."""
    from ..post import element_values, von_mises

    points, triangles, values = element_values(mesh, von_mises(sigma, nu))
    return plot_element_field(points, triangles, values, title,
                              unit_label(r"von Mises stress $\sigma_0$", stress_unit(units)),
                              clip=clip, units=units, vmax=vmax)


def plot_field_pair(points: np.ndarray, triangles: np.ndarray, values: list[np.ndarray],
                    titles: list[str], label: str, suptitle: str, clip: float | None = None,
                    units=None) -> Figure:
    """Element fields on one mesh with one colour bar (Figs. 3.11-3.14): side by side, or one
    above the other where that fills a 16:9 frame better (wide domains, :func:`stacked`).

    ``clip``: the colour scale ends at this percentile of all values (the colour bar is
    extended and says so), so that corner singularities do not wash out the rest.
    """
    n = len(values)
    if stacked(points, n):
        fig, axes = plt.subplots(n, 1, figsize=(10.0, 2.8 * n + 1.2), sharex=True,
                                 constrained_layout=True)
    else:
        fig, axes = plt.subplots(1, n, figsize=(6.2 * n, 3.4), constrained_layout=True)
    axes = np.atleast_1d(axes)
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    vmin, vmax, extend, note = clipped_scale(np.concatenate(values), clip)
    for ax, v, title in zip(axes, values, titles):
        art = ax.tripcolor(tri, facecolors=v, cmap="viridis", vmin=vmin, vmax=vmax,
                           edgecolors="none", rasterized=True)
        coordinates(ax, units)
        ax.set_title(title)
    colorbar(fig, art, list(axes), label, extend, note, is_wide(points))
    fig.suptitle(suptitle)
    return fig


def stacked(points: np.ndarray, n: int) -> bool:
    """Whether ``n`` panels of the domain of ``points`` fill a 16:9 frame better one above
    the other than side by side (the aspect of the whole nearer 16:9, in ratio).

    >>> wide = np.array([[0.0, 0.0], [8.0, 2.0]])
    >>> stacked(wide, 2), stacked(wide[:, ::-1], 2)
    (True, False)
    """
    aspect = float(np.ptp(points[:, 0])) / max(float(np.ptp(points[:, 1])), 1e-300)
    return bool(abs(np.log(aspect / n / (16 / 9))) < abs(np.log(aspect * n / (16 / 9))))
