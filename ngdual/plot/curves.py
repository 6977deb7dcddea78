"""Line plots and iteration-count grids of the figures of Sections 3.4 and 4.2: panels of
curves (:func:`plot_curves`), heat maps over a parameter grid (:func:`plot_heatmaps`,
Fig. 3.23) and the convergence of an adaptive run (:func:`plot_convergence`)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure


def plot_curves(panels: list[dict], suptitle: str, ncols: int = 2,
                panel_size: tuple[float, float] = (5.6, 3.4),
                figure_legend: bool = False, legend_loc: str = "outside lower center",
                legend_ncol: int | None = None) -> Figure:
    """Line plots, one panel per dict: ``title``, ``xlabel``, ``ylabel``, ``curves`` (dicts of
    ``x``, ``y``, ``label`` and matplotlib style keywords), optional ``loglog``, ``hlines``
    (``(y, label, style)``), ``note`` (text in the corner), ``xlim``, ``ylim``.

    ``figure_legend``: one legend for all panels (the labels of all panels, once each)
    instead of one per panel, at ``legend_loc`` (below them; ``"outside right upper"``
    beside them) in ``legend_ncol`` columns (default: 3 below, 1 beside)."""
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
            ax.text(0.02, 0.03, panel["note"], transform=ax.transAxes, fontsize="small",
                    va="bottom", ha="left", bbox={"fc": "white", "alpha": 0.8, "lw": 0})
        ax.set_title(panel["title"])
        ax.set_xlabel(panel["xlabel"])
        ax.set_ylabel(panel["ylabel"])
        ax.grid(alpha=0.3, which="both" if panel.get("loglog") else "major")
        labelled = any(not line.get_label().startswith("_") for line in ax.get_lines())
        if labelled and not figure_legend:
            ax.legend(loc=panel.get("legend_loc", "best"), fontsize="small")
    for ax in axes.ravel()[n:]:
        ax.remove()
    if figure_legend:
        handles = {}
        for ax in axes.ravel()[:n]:
            for handle, label in zip(*ax.get_legend_handles_labels()):
                handles.setdefault(label, handle)
        ncol = legend_ncol or (1 if "right" in legend_loc or "left" in legend_loc else 3)
        fig.legend(handles.values(), handles.keys(), loc=legend_loc,
                   ncol=min(ncol, len(handles)), fontsize="small")
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
                        ha="center", va="center", fontsize="x-small")
        ax.set_xticks(np.arange(len(x)) + 0.5, [f"{v:g}" for v in x])
        ax.set_yticks(np.arange(len(y)) + 0.5, [f"{v:g}" for v in y])
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        fig.colorbar(art, ax=ax, label=clabel)
    fig.suptitle(suptitle)
    return fig


def plot_convergence(history: list[dict], tol: float | None = None, title: str = "") -> Figure:
    """The goal's relative estimate of every step of an adaptive run against the unknowns
    and against the wall time, with the tolerance line ``tol``.

    ``history``: the records of :func:`ngdual.afem.adapt` (``dofs["total"]``,
    ``relative_estimate``, ``goal``, ``elapsed_s``); where they carry the total error
    ``e_tot`` of (3.124) (reference norms given) and the goal is the stress, also e_tot
    relative to the same size
    (``goal_estimate`` / ``relative_estimate``), the true error the estimate is measured
    against. Steps without a finite estimate are left out, and the panels say so.

    >>> fig = plot_convergence([{"dofs": {"total": 100}, "relative_estimate": 0.1,
    ...                          "goal_estimate": 1.0, "goal": "stress", "elapsed_s": 0.5},
    ...                         {"dofs": {"total": 400}, "relative_estimate": 0.05,
    ...                          "goal_estimate": 0.5, "goal": "stress", "elapsed_s": 1.5}],
    ...                        tol=0.06)
    >>> [ax.get_xlabel() for ax in fig.axes]
    ['unknowns (all fields)', 'wall time since the start [s]']
    """
    goal = history[0]["goal"] if history else "stress"
    # a goal with nothing to measure (no contact in its window) has an infinite estimate
    shown = [r for r in history if 0 < r["relative_estimate"] < float("inf")]
    note = "" if len(shown) == len(history) else \
        f"{len(history) - len(shown)} step(s) without a finite estimate left out"
    history = shown
    curves = [{"y": [r["relative_estimate"] for r in history], "marker": "o",
               "label": f"{goal} estimate / size of the solution"}]
    if history and goal == "stress" and all(r.get("e_tot") is not None
                                            and r["relative_estimate"] > 0 for r in history):
        curves.append({"y": [r["e_tot"] * r["relative_estimate"] / r["goal_estimate"]
                             for r in history], "marker": "s", "ls": "--",
                       "label": "true error e_tot (3.124) / the same size"})
    panels = []
    for key, xlabel in ((lambda r: r["dofs"]["total"], "unknowns (all fields)"),
                        (lambda r: r["elapsed_s"], "wall time since the start [s]")):
        x = [key(r) for r in history]
        panels.append({"title": f"against {xlabel.split(' (')[0].split(' since')[0]}",
                       "xlabel": xlabel, "ylabel": f"relative {goal} error",
                       "loglog": bool(history), "note": note,
                       "curves": [{"x": x, **c} for c in curves],
                       "hlines": [(tol, f"tolerance {tol:g}", {"color": "tab:red", "ls": ":"})]
                       if tol is not None else []})
    return plot_curves(panels, title or "Convergence of the adaptive run")
