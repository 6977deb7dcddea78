"""Matplotlib figures (no computation here: inputs are arrays from :mod:`ngdual.post`).

Every ``plot_*`` function returns a :class:`matplotlib.figure.Figure`; saving it is the
caller's choice, :func:`save_figure`. Importing this module leaves matplotlib's backend
alone: a notebook keeps its inline backend, a headless run gets Agg by matplotlib's own
fallback.

Axis labels carry the units the scene declares in its ``[units]`` table
(:class:`ngdual.scene.Units`, passed as ``units``); where it declares none a label names
the quantity only ("$x_1$", "von Mises stress"), never a made-up unit. Fields with
corner singularities take ``clip``: the colour scale ends at that percentile and the
colour bar says so.

>>> import numpy as np
>>> fig = plot_mesh(np.array([[0., 0.], [1., 0.], [0., 1.]]), np.array([[0, 1, 2]]))
>>> type(fig).__name__
'Figure'
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np
from matplotlib.figure import Figure

SIDECAR_FORMATS = (".png", ".pdf")  # what a stem without suffix becomes, with its .json
CORNER_CLIP = 99.0  # percentile where the colour scale of a field with corner singularities ends
TRACE_CLIP = 90.0   # the same for the y-range of a trace on Gamma_C (fewer values, more at corners)


def unit_label(quantity: str, unit: str | None) -> str:
    """``quantity [unit]``, or the quantity alone where no unit is declared.

    >>> unit_label("stress", "MPa"), unit_label("stress", None)
    ('stress [MPa]', 'stress')
    """
    return f"{quantity} [{unit}]" if unit else quantity


def _length(units) -> str | None:
    return getattr(units, "length", None)


def _stress(units) -> str | None:
    return getattr(units, "stress", None)


def clipped_scale(values: np.ndarray, clip: float | None,
                  vmax: float | None = None) -> tuple[float, float, str, str]:
    """``(vmin, vmax, extend, note)`` of a colour scale ending at the ``clip`` percentile.

    A field that changes sign is clipped symmetrically in |value|. ``note`` states the
    clipping and the largest value beyond it (empty without clipping, or when nothing
    lies beyond the percentile). ``vmax`` ends the scale at a given value instead (one
    scale for several pictures), stated the same way where values lie beyond it.

    >>> clipped_scale(np.array([0.0, 1.0, 4.0]), None, vmax=2.0)[1:3]
    (2.0, 'max')
    """
    values = np.asarray(values, float)
    low, high = float(values.min()), float(values.max())
    if vmax is not None:
        if vmax >= high:
            return low, vmax, "neither", ""
        return low, vmax, "max", f"colour scale ends at {vmax:.3g} (max {high:.3g})"
    if clip is None or not 0 < clip < 100:
        return low, high, "neither", ""
    if low < 0 < high:
        top = float(np.percentile(np.abs(values), clip))
        if top >= max(-low, high):
            return low, high, "neither", ""
        return -top, top, "both", (f"colour scale clipped at the {clip:g}th percentile of |value| "
                                   f"(range {low:.3g} to {high:.3g})")
    top = float(np.percentile(values, clip))
    if top >= high:
        return low, high, "neither", ""
    return low, top, "max", f"colour scale clipped at the {clip:g}th percentile (max {high:.3g})"


def _clip_axis(ax, values: np.ndarray, clip: float | None) -> None:
    """y-range 1.25 times the ``clip`` percentile of |values| when the largest is more than
    twice that (a corner singularity), with a note in the panel saying so."""
    values = np.abs(np.asarray(values, float))
    if clip is None or not len(values):
        return
    span = 1.25 * float(np.percentile(values, clip))
    top = float(values.max())
    if span > 0 and top > 2 * span:
        ax.set_ylim(-span, span)
        ax.text(0.02, 0.03, f"y-range clipped ({clip:g}th percentile of |value|): values up "
                            f"to {top:.3g} off scale", transform=ax.transAxes,
                fontsize=7, va="bottom", ha="left",
                bbox={"fc": "white", "alpha": 0.8, "lw": 0})


def _coordinates(ax, units) -> None:
    ax.set_aspect("equal")
    ax.set_xlabel(unit_label(r"$x_1$", _length(units)))
    ax.set_ylabel(unit_label(r"$x_2$", _length(units)))


def _colorbar(fig, art, ax, label: str, extend: str, note: str, wide: bool) -> None:
    """A colour bar labelled ``label`` and the clipping ``note``: below a wide domain (the
    label then has room for both on one line), to the right of a tall one."""
    if wide:
        fig.colorbar(art, ax=ax, label=f"{label}; {note}" if note else label, extend=extend,
                     location="bottom", shrink=0.6, aspect=40)
    else:
        fig.colorbar(art, ax=ax, label=f"{label}\n{note}" if note else label, extend=extend)


def _is_wide(points: np.ndarray) -> bool:
    return float(np.ptp(points[:, 1])) < 0.6 * float(np.ptp(points[:, 0]))


def plot_contact_traces(traces, title: str = "", units=None,
                        clip: float | None = TRACE_CLIP) -> Figure:
    """sigma_n, sigma_t (per fine edge), lambda_n - g and lambda_t (nodal) along Gamma_C.

    ``traces``: :func:`ngdual.post.contact_traces`; ``units``: the scene's ``units``;
    ``clip``: the stress panels' y-range follows this percentile of |sigma| where corner
    singularities would flatten the rest (the panel says so; None: the full range).
    """
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    x_edge, x_node = traces.edge_xy[:, 0], traces.node_xy[:, 0]
    order = np.argsort(x_node)
    stress, length = _stress(units), _length(units)
    panels = [
        (axes[0, 0], x_edge, traces.sigma_n, unit_label(r"$\sigma_n^h$", stress), "steps-mid"),
        (axes[0, 1], x_edge, traces.sigma_t, unit_label(r"$\sigma_t^h$", stress), "steps-mid"),
        (axes[1, 0], x_node[order], (traces.lam_n - traces.gap)[order],
         unit_label(r"$\lambda_n^{\tilde h} - g$", length), "default"),
        (axes[1, 1], x_node[order], traces.lam_t[order],
         unit_label(r"$\lambda_t^{\tilde h}$", length), "default"),
    ]
    for ax, xs, ys, label, style in panels:
        idx = np.argsort(xs)
        ax.plot(xs[idx], ys[idx], drawstyle=style, lw=1.2)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for ax, values in ((axes[0, 0], traces.sigma_n), (axes[0, 1], traces.sigma_t)):
        _clip_axis(ax, values, clip)
    contact = traces.coarse_xy[traces.coarse_in_contact, 0]
    level = np.interp(contact, x_node[order], (traces.lam_n - traces.gap)[order])
    axes[1, 0].plot(contact, level, "rv", ms=4, label=r"$\tilde h$-node in contact")
    axes[1, 0].legend(loc="best")
    for ax in axes[1]:
        ax.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", length))
    fig.suptitle(title or r"Traces on the contact boundary $\Gamma_C$")
    fig.tight_layout()
    return fig


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
    _colorbar(fig, art, ax, label, extend, note, _is_wide(points))
    _coordinates(ax, units)
    ax.set_title(title)
    return fig


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
    _coordinates(ax, units)
    ax.set_title(title or f"{len(triangles)} triangles")
    ax.legend(handles=[*ax.get_legend_handles_labels()[0][:1], *handles], loc="upper center",
              bbox_to_anchor=(0.5, -0.25 if aspect < 0.5 else -0.12), ncol=2, fontsize=8)
    return fig


# --- saving, and the JSON sidecar of ngdual figures ----------------------------------------------

def figure_texts(fig: Figure) -> dict:
    """Titles, axis labels, legend entries and colour bars of a figure (the JSON sidecar)."""
    axes = []
    for ax in fig.axes:
        colorbar = getattr(ax, "_colorbar", None)
        if colorbar is not None:
            axes.append({"colorbar": True, "label": colorbar.ax.get_ylabel()
                         or colorbar.ax.get_xlabel()})
            continue
        legend = ax.get_legend()
        axes.append({"colorbar": False, "title": ax.get_title(), "xlabel": ax.get_xlabel(),
                     "ylabel": ax.get_ylabel(),
                     "legend": [t.get_text() for t in legend.get_texts()] if legend else [],
                     "labelled_lines": sum(1 for line in ax.get_lines()
                                           if not line.get_label().startswith("_")),
                     "filled": bool(ax.collections or ax.images)})
    suptitle = fig._suptitle.get_text() if fig._suptitle is not None else ""
    legends = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    return {"suptitle": suptitle, "axes": axes, "figure_legend": legends}


def save_figure(fig: Figure, target: str | Path, dpi: int = 130) -> list[Path]:
    """Write ``fig`` atomically and close it; returns the files written.

    ``target`` with a suffix (``out/von_mises.png``) is that one file; a stem without
    suffix (``figures/fig_3_11``) becomes ``stem.png``, ``stem.pdf`` and ``stem.json``
    (:func:`figure_texts`: what the figure says, for tests and indexes).
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    texts = figure_texts(fig) if not target.suffix else None
    written = []
    try:
        for path in [target] if target.suffix else [target.with_suffix(s)
                                                    for s in SIDECAR_FORMATS]:
            tmp = path.with_name(path.stem + ".part" + path.suffix)
            fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
            tmp.replace(path)
            written.append(path)
    finally:
        plt.close(fig)
    if texts is not None:
        sidecar = target.with_suffix(".json")
        tmp = target.with_name(target.name + ".part.json")
        tmp.write_text(json.dumps(texts, indent=1))
        tmp.replace(sidecar)
    return written


# --- figures of Sections 3.4 and 4.2 (ngdual figures) -------------------------------------------

def plot_field_pair(points: np.ndarray, triangles: np.ndarray, values: list[np.ndarray],
                    titles: list[str], label: str, suptitle: str, clip: float | None = None,
                    units=None) -> Figure:
    """Element fields on one mesh side by side with one colour bar (Figs. 3.11-3.14).

    ``clip``: the colour scale ends at this percentile of all values (the colour bar is
    extended and says so), so that corner singularities do not wash out the rest.
    """
    fig, axes = plt.subplots(1, len(values), figsize=(6.2 * len(values), 3.4),
                             constrained_layout=True)
    axes = np.atleast_1d(axes)
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    vmin, vmax, extend, note = clipped_scale(np.concatenate(values), clip)
    for ax, v, title in zip(axes, values, titles):
        art = ax.tripcolor(tri, facecolors=v, cmap="viridis", vmin=vmin, vmax=vmax,
                           edgecolors="none", rasterized=True)
        _coordinates(ax, units)
        ax.set_title(title)
    _colorbar(fig, art, list(axes), label, extend, note, _is_wide(points))
    fig.suptitle(suptitle)
    return fig


def plot_curves(panels: list[dict], suptitle: str, ncols: int = 2,
                panel_size: tuple[float, float] = (5.6, 3.4),
                figure_legend: bool = False) -> Figure:
    """Line plots, one panel per dict: ``title``, ``xlabel``, ``ylabel``, ``curves`` (dicts of
    ``x``, ``y``, ``label`` and matplotlib style keywords), optional ``loglog``, ``hlines``
    (``(y, label, style)``), ``note`` (text in the corner), ``xlim``, ``ylim``.

    ``figure_legend``: one legend below all panels (the labels of all panels, once each)
    instead of one per panel."""
    n = len(panels)
    ncols = min(ncols, n)
    nrows = int(np.ceil(n / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(panel_size[0] * ncols,
                                                    panel_size[1] * nrows),
                             constrained_layout=True, squeeze=False)
    for ax, panel in zip(axes.ravel(), panels):
        for curve in panel.get("curves", []):
            curve = dict(curve)
            x, y = np.asarray(curve.pop("x"), float), np.asarray(curve.pop("y"), float)
            ax.plot(x, y, **curve)
        for y, label, style in panel.get("hlines", []):
            ax.axhline(y, label=label, **style)
        if panel.get("loglog"):
            ax.set_xscale("log")
            ax.set_yscale("log")
        if panel.get("xlim"):
            ax.set_xlim(*panel["xlim"])
        if panel.get("ylim"):
            ax.set_ylim(*panel["ylim"])
        if panel.get("note"):
            ax.text(0.02, 0.03, panel["note"], transform=ax.transAxes, fontsize=8,
                    va="bottom", ha="left", bbox={"fc": "white", "alpha": 0.8, "lw": 0})
        ax.set_title(panel["title"])
        ax.set_xlabel(panel["xlabel"])
        ax.set_ylabel(panel["ylabel"])
        ax.grid(alpha=0.3, which="both" if panel.get("loglog") else "major")
        labelled = any(not line.get_label().startswith("_") for line in ax.get_lines())
        if labelled and not figure_legend:
            ax.legend(loc=panel.get("legend_loc", "best"), fontsize=8)
    for ax in axes.ravel()[n:]:
        ax.remove()
    if figure_legend:
        handles = {}
        for ax in axes.ravel()[:n]:
            for handle, label in zip(*ax.get_legend_handles_labels()):
                handles.setdefault(label, handle)
        fig.legend(handles.values(), handles.keys(), loc="outside lower center",
                   ncol=min(3, len(handles)), fontsize=8)
    fig.suptitle(suptitle)
    return fig


def plot_heatmaps(x: np.ndarray, y: np.ndarray, grids: list[np.ndarray], titles: list[str],
                  xlabel: str, ylabel: str, cbar_labels: list[str], suptitle: str) -> Figure:
    """Iteration counts over a parameter grid (Fig. 3.23): blue few, red many, numbers in the
    cells, NaN cells (did not converge) hatched and marked with a cross."""
    fig, axes = plt.subplots(1, len(grids), figsize=(5.4 * len(grids), 4.2),
                             constrained_layout=True)
    for ax, grid, title, clabel in zip(np.atleast_1d(axes), grids, titles, cbar_labels):
        data = np.ma.masked_invalid(np.asarray(grid, float))
        art = ax.pcolormesh(np.arange(len(x) + 1), np.arange(len(y) + 1), data.T,
                            cmap="coolwarm", shading="flat")
        ax.set_facecolor("0.85")
        for i in range(len(x)):
            for j in range(len(y)):
                v = grid[i][j]
                ax.text(i + 0.5, j + 0.5, "x" if not np.isfinite(v) else f"{v:.0f}",
                        ha="center", va="center", fontsize=7)
        ax.set_xticks(np.arange(len(x)) + 0.5, [f"{v:g}" for v in x])
        ax.set_yticks(np.arange(len(y)) + 0.5, [f"{v:g}" for v in y])
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        fig.colorbar(art, ax=ax, label=clabel)
    fig.suptitle(suptitle)
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
    peak = float(np.max(np.abs(load)))
    ax.plot([], [], color="tab:orange", marker=r"$\downarrow$", ls="none",
            label=rf"$t_0$ (max {peak:.0f}{' ' + _stress(units) if _stress(units) else ''})")
    for fx, fy, label, style in foundations:
        ax.plot(fx, fy, label=label, **style)
    _coordinates(ax, units)
    ax.set_ylim(-3.3, 1.9)
    ax.set_title(r"$\Omega = [-4, 4] \times [-1, 1]$, level-1 mesh")
    ax.legend(loc="upper center", ncol=3, fontsize=8)
    for gx, gy, label, style in gaps:
        ag.plot(gx, gy, label=label, **style)
    ag.set_xlabel(unit_label(r"$x_1$ on $\Gamma_C$", _length(units)))
    ag.set_ylabel(unit_label(r"gap $g(x_1)$", _length(units)))
    ag.set_title("Gap functions of the shipped scenes")
    ag.grid(alpha=0.3)
    ag.legend(fontsize=8)
    fig.suptitle(suptitle)
    return fig
