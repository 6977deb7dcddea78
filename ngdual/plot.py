"""Matplotlib figures (no computation here: inputs are arrays from :mod:`ngdual.post`)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.tri as mtri  # noqa: E402
import numpy as np  # noqa: E402


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.stem + ".part" + path.suffix)
    fig.savefig(tmp, dpi=150, bbox_inches="tight")
    plt.close(fig)
    tmp.replace(path)
    return path


def plot_contact_traces(traces, path: Path, title: str = "") -> Path:
    """sigma_n, sigma_t (per fine edge), lambda_n - g and lambda_t (nodal) along Gamma_C."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    x_edge, x_node = traces.edge_xy[:, 0], traces.node_xy[:, 0]
    order = np.argsort(x_node)
    panels = [
        (axes[0, 0], x_edge, traces.sigma_n, r"$\sigma_n^h$ [stress units]", "steps-mid"),
        (axes[0, 1], x_edge, traces.sigma_t, r"$\sigma_t^h$ [stress units]", "steps-mid"),
        (axes[1, 0], x_node[order], (traces.lam_n - traces.gap)[order],
         r"$\lambda_n^{\tilde h} - g$ [length]", "default"),
        (axes[1, 1], x_node[order], traces.lam_t[order], r"$\lambda_t^{\tilde h}$ [length]",
         "default"),
    ]
    for ax, xs, ys, label, style in panels:
        idx = np.argsort(xs)
        ax.plot(xs[idx], ys[idx], drawstyle=style, lw=1.2)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    contact = traces.coarse_xy[traces.coarse_in_contact, 0]
    level = np.interp(contact, x_node[order], (traces.lam_n - traces.gap)[order])
    axes[1, 0].plot(contact, level, "rv", ms=4, label=r"$\tilde h$-node in contact")
    axes[1, 0].legend(loc="best")
    for ax in axes[1]:
        ax.set_xlabel(r"$x_1$ on $\Gamma_C$ [length]")
    fig.suptitle(title or r"Traces on the contact boundary $\Gamma_C$")
    fig.tight_layout()
    return _save(fig, path)


def plot_element_field(points: np.ndarray, triangles: np.ndarray, values: np.ndarray,
                       path: Path, title: str, label: str) -> Path:
    """A piecewise constant field on the triangulation, with a colour bar."""
    fig, ax = plt.subplots(figsize=(11, 3.6))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    art = ax.tripcolor(tri, facecolors=values, cmap="viridis", edgecolors="none")
    fig.colorbar(art, ax=ax, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x_1$ [length]")
    ax.set_ylabel(r"$x_2$ [length]")
    ax.set_title(title)
    return _save(fig, path)


def plot_mesh(points: np.ndarray, triangles: np.ndarray, path: Path, title: str = "",
              marked: np.ndarray | None = None) -> Path:
    """The triangulation, with the elements marked for refinement shaded (Figs. 4.1-4.13)."""
    fig, ax = plt.subplots(figsize=(8, 8 * np.ptp(points[:, 1]) / max(np.ptp(points[:, 0]), 1e-300)
                                    + 0.8))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    if marked is not None and np.any(marked):
        ax.tripcolor(tri, facecolors=np.asarray(marked, dtype=float), cmap="Oranges",
                     vmin=0, vmax=2.5, edgecolors="none")
    ax.triplot(tri, color="k", lw=0.3)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x_1$ [length]")
    ax.set_ylabel(r"$x_2$ [length]")
    ax.set_title(title or f"{len(triangles)} triangles")
    return _save(fig, path)


# --- figures of Sections 3.4 and 4.2 (ngdual figures) -------------------------------------------

def figure_texts(fig) -> dict:
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


def save_figure(fig, stem: Path, dpi: int = 130) -> list[Path]:
    """Write ``stem``.png, ``stem``.pdf and ``stem``.json (:func:`figure_texts`), atomically."""
    import json

    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    texts = figure_texts(fig)
    written = []
    for suffix in (".png", ".pdf"):
        path = stem.with_suffix(suffix)
        tmp = stem.with_name(stem.name + ".part" + suffix)
        fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
        tmp.replace(path)
        written.append(path)
    plt.close(fig)
    sidecar = stem.with_suffix(".json")
    tmp = stem.with_name(stem.name + ".part.json")
    tmp.write_text(json.dumps(texts, indent=1))
    tmp.replace(sidecar)
    return written


def plot_field_pair(points: np.ndarray, triangles: np.ndarray, values: list[np.ndarray],
                    titles: list[str], label: str, suptitle: str, stem: Path,
                    vmax: float | None = None) -> list[Path]:
    """Element fields on one mesh side by side with one colour bar (Figs. 3.11-3.14).

    With ``vmax`` below the largest value the colour scale ends there (the colour bar
    is extended), so that corner singularities do not wash out the rest.
    """
    fig, axes = plt.subplots(1, len(values), figsize=(6.2 * len(values), 2.6),
                             constrained_layout=True)
    axes = np.atleast_1d(axes)
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    allv = np.concatenate(values)
    vmin = float(allv.min())
    extend = "neither"
    if vmax is not None and vmax < allv.max():
        extend = "max"
    else:
        vmax = float(allv.max())
    for ax, v, title in zip(axes, values, titles):
        art = ax.tripcolor(tri, facecolors=v, cmap="viridis", vmin=vmin, vmax=vmax,
                           edgecolors="none", rasterized=True)
        ax.set_aspect("equal")
        ax.set_xlabel(r"$x_1$ [length]")
        ax.set_ylabel(r"$x_2$ [length]")
        ax.set_title(title)
    fig.colorbar(art, ax=list(axes), label=label, extend=extend, shrink=0.9)
    fig.suptitle(suptitle)
    return save_figure(fig, stem)


def plot_curves(panels: list[dict], stem: Path, suptitle: str, ncols: int = 2,
                panel_size: tuple[float, float] = (5.6, 3.4),
                figure_legend: bool = False) -> list[Path]:
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
    return save_figure(fig, stem)


def plot_heatmaps(x: np.ndarray, y: np.ndarray, grids: list[np.ndarray], titles: list[str],
                  xlabel: str, ylabel: str, cbar_labels: list[str], stem: Path,
                  suptitle: str) -> list[Path]:
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
    return save_figure(fig, stem)


def plot_adaptive_mesh(points: np.ndarray, triangles: np.ndarray, marked: np.ndarray,
                       stem: Path, title: str) -> list[Path]:
    """An adaptive mesh with the triangles marked for the next refinement shaded (Figs. 4.x)."""
    from matplotlib.patches import Patch

    fig, ax = plt.subplots(figsize=(9.5, 3.0))
    tri = mtri.Triangulation(points[:, 0], points[:, 1], triangles)
    handles = []
    if marked is not None and np.any(marked):
        ax.tripcolor(tri, facecolors=np.asarray(marked, float), cmap="Oranges", vmin=0,
                     vmax=1.6, edgecolors="none", rasterized=True)
        handles.append(Patch(color=plt.get_cmap("Oranges")(1 / 1.6),
                             label="marked for the next refinement"))
    ax.triplot(tri, color="k", lw=0.25, label=f"{len(triangles)} triangles")
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x_1$ [length]")
    ax.set_ylabel(r"$x_2$ [length]")
    ax.set_title(title)
    ax.legend(handles=[*ax.get_legend_handles_labels()[0][:1], *handles], loc="upper center",
              bbox_to_anchor=(0.5, -0.25), ncol=2, fontsize=8)
    return save_figure(fig, stem)


def plot_domain(points: np.ndarray, triangles: np.ndarray, x: np.ndarray, load: np.ndarray,
                foundations: list, gaps: list, stem: Path, suptitle: str) -> list[Path]:
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
    ax.plot([], [], color="tab:orange", marker=r"$\downarrow$", ls="none",
            label=rf"$t_0$ (max {float(np.max(np.abs(load))):.0f})")
    for fx, fy, label, style in foundations:
        ax.plot(fx, fy, label=label, **style)
    ax.set_aspect("equal")
    ax.set_ylim(-3.3, 1.9)
    ax.set_xlabel(r"$x_1$ [length]")
    ax.set_ylabel(r"$x_2$ [length]")
    ax.set_title(r"$\Omega = [-4, 4] \times [-1, 1]$, level-1 mesh")
    ax.legend(loc="upper center", ncol=3, fontsize=8)
    for gx, gy, label, style in gaps:
        ag.plot(gx, gy, label=label, **style)
    ag.set_xlabel(r"$x_1$ on $\Gamma_C$ [length]")
    ag.set_ylabel(r"gap $g(x_1)$ [length]")
    ag.set_title("Gap functions of the shipped scenes")
    ag.grid(alpha=0.3)
    ag.legend(fontsize=8)
    fig.suptitle(suptitle)
    return save_figure(fig, stem)
